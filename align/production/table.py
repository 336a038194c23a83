"""The lot's table: one row per unit, sensor and run; its schema, and its rows to and from Arrow (the files:
:mod:`align.production.store`).

The table is read, built and written with pyarrow alone (its file reader, arrays made from their buffers):
``pyarrow.array`` on Python objects, ``pyarrow.parquet.read_table`` (the dataset layer) and a timestamp's
``to_pylist`` import pandas, a third of a second a batch would spend before or between its units.

Columns: :data:`META` (serial, slot, order, run, time (UTC, when the row was made), job, sensor, status,
exit_code, message, verdict, checks, input_hash, result, seconds, worker, bias_unit, and the unit's identity:
station, fixture, operator, device_id, test_time (UTC, when the unit was tested, as the manifest states it, else
its log: :mod:`align.production.identity`)),
then every figure of :data:`align.production.keyfigures.FIGURES` (float64, SI; each field's metadata holds its
unit).

Public names
------------
SCHEMA, META, IDENTITY, latest_rows, rows_of, now
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from datetime import UTC, datetime, timedelta
from typing import Any

import numpy as np
import pyarrow as pa

from align.production.keyfigures import FIGURES, KIND, si_unit

#: the non-figure columns, in order, with their Arrow types
META: tuple[tuple[str, pa.DataType], ...] = (
    ("serial", pa.string()), ("slot", pa.string()), ("order", pa.int64()), ("run", pa.string()),
    ("time", pa.timestamp("us", tz="UTC")), ("job", pa.string()), ("sensor", pa.string()), ("status", pa.string()),
    ("exit_code", pa.int64()), ("message", pa.string()), ("verdict", pa.string()), ("checks", pa.string()),
    ("input_hash", pa.string()), ("result", pa.string()), ("seconds", pa.float64()), ("worker", pa.string()),
    ("bias_unit", pa.string()),
    ("station", pa.string()), ("fixture", pa.string()), ("operator", pa.string()), ("device_id", pa.string()),
    ("test_time", pa.timestamp("us", tz="UTC")),
)
#: the unit's identity columns (a manifest's optional columns of the same names)
IDENTITY = ("station", "fixture", "operator", "device_id", "test_time")


def _column_unit(figure: str) -> str:
    """A figure column's unit, as its field's metadata states it (per sensor where the sensors differ)."""
    if KIND[figure] == "reading":
        return "SI of the sensor's readings (bias_unit)"
    units = {s: si_unit(figure, s) for s in ("gyroscope", "accelerometer")}
    if len(set(units.values())) == 1:
        return units["gyroscope"] or ""
    return ", ".join(f"{u} ({s})" for s, u in units.items())


#: the table's schema: :data:`META` then every figure (float64, SI)
SCHEMA = pa.schema([pa.field(n, t) for n, t in META]
                   + [pa.field(f, pa.float64(), metadata={"unit": _column_unit(f)}) for f in FIGURES],
                   metadata={"format": "imu-align.lot-table", "version": "2",
                             "convention": "raw = M true + bias; rows of M are sensor axes; figures SI"})


def _clean(row: dict) -> dict:
    """A row as the schema takes it: the time as a datetime, non-finite figures as null, unknown keys dropped."""
    out = {}
    for name in SCHEMA.names:
        v = row.get(name)
        if name in ("time", "test_time") and isinstance(v, str):
            v = datetime.fromisoformat(v)
        elif isinstance(v, float) and not math.isfinite(v):
            v = None
        out[name] = v
    return out


def _unified(tables: list[pa.Table]) -> list[pa.Table]:
    """The tables with the union of their columns (missing ones as nulls), in one column order."""
    schema = pa.unify_schemas([t.schema for t in tables])
    out = []
    for t in tables:
        cols = [_as(t.column(f.name), f.type) if f.name in t.column_names else pa.nulls(len(t), f.type)
                for f in schema]
        out.append(pa.Table.from_arrays(cols, schema=schema))
    return out


def _as(column: pa.ChunkedArray, kind: pa.DataType) -> pa.ChunkedArray:
    """``column`` of type ``kind`` (cast only when it is another: a cast loads pyarrow's compute functions)."""
    return column if column.type == kind else column.cast(kind)


#: the types of a row's values a column takes as they are (the common case, checked at once)
_WHOLE = frozenset({type(None), int, np.int64, np.int32})
_REAL = _WHOLE | {float, np.float64}
_EPOCH = datetime(1970, 1, 1)
_EPOCH_UTC = _EPOCH.replace(tzinfo=UTC)
_MICRO = timedelta(microseconds=1)


def _array(name: str, values: list, kind: pa.DataType) -> pa.Array:
    """An Arrow array of ``values`` (None: null) of the schema's ``kind`` (string, int64, float64 or a timestamp
    in microseconds), built from its buffers (Arrow columnar format: validity bitmap, offsets, data).

    Examples
    --------
    >>> _array("x", [1.5, None], pa.float64()).to_pylist()
    [1.5, None]
    >>> _array("s", ["a", None, "bc"], pa.string()).to_pylist()
    ['a', None, 'bc']
    """
    n = len(values)
    valid = np.fromiter((v is not None for v in values), dtype=bool, count=n)
    nulls = n - int(valid.sum())
    bitmap = pa.py_buffer(np.packbits(valid, bitorder="little")) if nulls else None
    if pa.types.is_string(kind):
        data = [_text(name, v).encode() for v in values]
        offsets = np.zeros(n + 1, dtype=np.int32)
        np.cumsum([len(b) for b in data], out=offsets[1:])
        return pa.Array.from_buffers(kind, n, [bitmap, pa.py_buffer(offsets), pa.py_buffer(b"".join(data))], nulls)
    if pa.types.is_timestamp(kind) and kind.unit == "us":
        numbers = np.array([_micros(name, v) for v in values], dtype=np.int64)
    elif pa.types.is_int64(kind):
        plain = all(type(v) in _WHOLE for v in values)  # else each value checked (and refused with its column)
        numbers = np.array([0 if v is None else v for v in values] if plain else
                           [_number(name, v, int) for v in values], dtype=np.int64)
    elif pa.types.is_float64(kind):
        plain = all(type(v) in _REAL for v in values)
        numbers = np.array([0.0 if v is None else v for v in values] if plain else
                           [_number(name, v, float) for v in values], dtype=np.float64)
    else:  # not a type of SCHEMA
        raise TypeError(f"column {name}: no builder for {kind}")
    return pa.Array.from_buffers(kind, n, [bitmap, pa.py_buffer(numbers)], nulls)


def _text(name: str, v: Any) -> str:
    if v is None:
        return ""
    if not isinstance(v, str):
        raise TypeError(f"column {name}: {v!r} is not text")
    return v


def _number(name: str, v: Any, kind: type) -> Any:
    """A number for the column (as pyarrow takes one: a bool as 0/1, a whole float in an integer column)."""
    if v is None:
        return 0
    if not isinstance(v, (int, float, np.integer, np.floating)):
        raise TypeError(f"column {name}: {v!r} is not a number")
    if kind is int and isinstance(v, (float, np.floating)) and not float(v).is_integer():
        raise TypeError(f"column {name}: {v!r} is not a whole number")
    return v


def _micros(name: str, v: Any) -> int:
    """Microseconds since 1970-01-01 UTC (a time without a zone taken as UTC, as pyarrow takes it; an integer
    as the count itself)."""
    if v is None:
        return 0
    if isinstance(v, (int, np.integer)) and not isinstance(v, bool):
        return int(v)
    if not isinstance(v, datetime):
        raise TypeError(f"column {name}: {v!r} is not a time")
    return (v - (_EPOCH if v.tzinfo is None else _EPOCH_UTC)) // _MICRO


def _table(rows: list[dict]) -> pa.Table:
    """The rows (cleaned, :func:`_clean`) as a table of :data:`SCHEMA`."""
    return pa.Table.from_arrays([_array(f.name, [r[f.name] for r in rows], f.type) for f in SCHEMA], schema=SCHEMA)


def _times(column: pa.ChunkedArray) -> list[datetime | None]:
    """A timestamp column's values as datetimes (from its integers: a timestamp's own ``to_pylist`` imports pandas).

    Examples
    --------
    >>> _times(pa.chunked_array([pa.array([1_500_000, None], pa.int64()).view(pa.timestamp("us", tz="UTC"))]))
    [datetime.datetime(1970, 1, 1, 0, 0, 1, 500000, tzinfo=datetime.timezone.utc), None]
    """
    kind = column.type
    epoch = _EPOCH_UTC if kind.tz else _EPOCH
    zone = _zone(kind.tz) if kind.tz not in (None, "UTC", "utc", "Z", "+00:00") else None
    out: list[datetime | None] = []
    for v in column.combine_chunks().view(pa.int64()).to_pylist() if len(column) else []:
        if v is None:
            out.append(None)
            continue
        micros = v // 1000 if kind.unit == "ns" else v * {"s": 1_000_000, "ms": 1_000, "us": 1}[kind.unit]
        t = epoch + timedelta(microseconds=micros)
        out.append(t.astimezone(zone) if zone is not None else t)
    return out


def _zone(name: str) -> Any:
    from zoneinfo import ZoneInfo

    return ZoneInfo(name)


def rows_of(table: pa.Table, figures: Iterable[str] | None = None) -> list[dict]:
    """The table's rows as dicts (figures as floats, NaN for null); only the ``figures`` named, when given."""
    if figures is not None:
        keep = [n for n, _ in META] + list(figures)
        table = table.select([n for n in table.column_names if n in keep])
    stamps = [n for n, t in zip(table.column_names, table.schema.types) if pa.types.is_timestamp(t)]
    rows = table.drop_columns(stamps).to_pylist() if stamps else table.to_pylist()
    for name in stamps:
        for r, t in zip(rows, _times(table.column(name))):
            r[name] = t
    if stamps:  # the table's column order
        rows = [{n: r[n] for n in table.column_names} for r in rows]
    figures = [f for f in FIGURES if f in table.column_names]
    for r in rows:
        for f in figures:
            if r[f] is None:
                r[f] = math.nan
    return rows


def latest_rows(table: pa.Table, figures: Iterable[str] | None = None) -> list[dict]:
    """The last run of every unit: per (serial, job), the rows of its latest ``time``, in the lot's order
    (with only the ``figures`` named, when given: a long table's rows stay small)."""
    best: dict[tuple, list[dict]] = {}
    for r in rows_of(table, figures):
        key = (r["serial"], r["job"])
        have = best.get(key)
        if have is None or r["time"] > have[0]["time"]:
            best[key] = [r]
        elif r["time"] == have[0]["time"] and r["run"] == have[0]["run"]:
            have.append(r)
    rows = [r for group in best.values() for r in group]
    return sorted(rows, key=lambda r: (r["order"] if r["order"] is not None else math.inf, r["serial"]))


def now() -> datetime:
    """The current time, UTC (the table's ``time``)."""
    return datetime.now(UTC)
