"""The lot's table: one row per unit, sensor and run, in one Parquet file that grows by appending.

``OUT/results.parquet`` is a single Parquet file (not a folder of parts), so that every reader
takes it as one table as it is: ``duckdb.sql("SELECT * FROM 'OUT/results.parquet'")``,
``pandas.read_parquet(path)``, ``polars.read_parquet(path)``, ``pyarrow.parquet.read_table(path)``.
An append reads the file, adds the new rows and writes the whole table to a temporary file
beside it, renamed over it (atomic: a reader sees the old table or the new one, never half).
Columns a newer release adds appear as nulls in older rows.

While a batch runs, each finished unit's row is first appended as one JSON line to a journal
beside the table (``results.parquet.journal``, flushed per unit); the journal is folded into the
table at the end of the run, or at the start of the next one when the run was killed. So a killed
batch loses at most the units that were running.

The table is read, built and written with pyarrow alone (its file reader, arrays made from their buffers):
``pyarrow.array`` on Python objects, ``pyarrow.parquet.read_table`` (the dataset layer) and a timestamp's
``to_pylist`` import pandas, a third of a second a batch would spend before or between its units.

Columns: :data:`META` (serial, slot, order, run, time (UTC), job, sensor, status, exit_code,
message, verdict, checks, input_hash, result, seconds, worker, bias_unit), then every figure of
:data:`align.production.keyfigures.FIGURES` (float64, SI; each field's metadata holds its unit).

Public names
------------
SCHEMA, META, Journal, append_rows, read_table, latest_rows, rows_of
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable
from datetime import UTC, datetime, timedelta
from pathlib import Path
from typing import Any, TextIO

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from align.errors import InputError
from align.io.files import write_bytes
from align.production.keyfigures import FIGURES, KIND, si_unit

#: the non-figure columns, in order, with their Arrow types
META: tuple[tuple[str, pa.DataType], ...] = (
    ("serial", pa.string()), ("slot", pa.string()), ("order", pa.int64()), ("run", pa.string()),
    ("time", pa.timestamp("us", tz="UTC")), ("job", pa.string()), ("sensor", pa.string()), ("status", pa.string()),
    ("exit_code", pa.int64()), ("message", pa.string()), ("verdict", pa.string()), ("checks", pa.string()),
    ("input_hash", pa.string()), ("result", pa.string()), ("seconds", pa.float64()), ("worker", pa.string()),
    ("bias_unit", pa.string()),
)


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
                   metadata={"format": "imu-align.lot-table", "version": "1",
                             "convention": "raw = M true + bias; rows of M are sensor axes; figures SI"})


def _clean(row: dict) -> dict:
    """A row as the schema takes it: the time as a datetime, non-finite figures as null, unknown keys dropped."""
    out = {}
    for name in SCHEMA.names:
        v = row.get(name)
        if name == "time" and isinstance(v, str):
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


def read_table(path: str | Path) -> pa.Table:
    """The table at ``path`` (an empty one with :data:`SCHEMA` when the file does not exist).

    Raises
    ------
    InputError
        The file is not a Parquet table.
    """
    p = Path(path)
    if not p.exists():
        return pa.Table.from_batches([], schema=SCHEMA)  # not SCHEMA.empty_table(): that imports pandas (0.5 s)
    if p.is_dir():
        raise InputError("is a folder; give the table's .parquet file", str(p))
    try:
        with pq.ParquetFile(p) as fh:  # not pq.read_table: its dataset layer imports pandas
            table = fh.read()
    except Exception as exc:  # pyarrow raises several types for a damaged or foreign file
        raise InputError(f"not a readable Parquet table ({' '.join(str(exc).split())[:200]})", str(p)) from None
    fmt = (table.schema.metadata or {}).get(b"format", b"").decode(errors="replace")
    lacking = [n for n in ("serial", "job", "time", "run", "status") if n not in table.column_names]
    if fmt != SCHEMA.metadata[b"format"].decode() or lacking:
        what = f"no column {lacking[0]}" if lacking else f"format '{fmt or 'none'}'"
        raise InputError(f"not an imu-align lot table ({what}); give results.parquet of imu-align batch", str(p))
    return table


def append_rows(path: str | Path, rows: Iterable[dict], chunk: int = 256, old: pa.Table | None = None) -> int:
    """Append rows to the table at ``path`` (created when missing): read, concatenate, rewrite atomically.

    The rows are turned into Arrow ``chunk`` at a time, so that appending a long run holds few of them as
    Python objects at once. ``old``: the table at ``path`` when the caller has read it already.

    Returns
    -------
    int
        The number of rows appended.
    """
    parts, batch = [], []
    for r in rows:
        batch.append(_clean(r))
        if len(batch) == chunk:
            parts.append(_table(batch))
            batch = []
    if batch:
        parts.append(_table(batch))
    added = sum(p.num_rows for p in parts)
    if not added:
        return 0
    old = read_table(path) if old is None else old
    table = pa.concat_tables(_unified([old, *parts]) if old.num_rows else parts)
    sink = pa.BufferOutputStream()
    pq.write_table(table.replace_schema_metadata({**(table.schema.metadata or {}), **SCHEMA.metadata}), sink,
                   compression="zstd")
    write_bytes(path, sink.getvalue().to_pybytes())
    return added


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


class Journal:
    """The rows of a running batch, one JSON line each, beside the table: ``journal.add(rows)`` per unit,
    :meth:`fold` into the table at the end (or at the start of the next run after a kill)."""

    def __init__(self, table: str | Path) -> None:
        self.table = Path(table)
        self.path = self.table.with_name(self.table.name + ".journal")
        self._fh: TextIO | None = None

    def recover(self) -> int:
        """Fold a journal a killed run left into the table; the number of rows it held."""
        return self.fold()

    def add(self, rows: list[dict]) -> None:
        """Append one unit's rows, flushed to the operating system before returning (so that a killed batch
        keeps them; not synced to the disk: a power cut may lose the last units, which a rerun then redoes)."""
        if self._fh is None:
            self._fh = open(self.path, "a", encoding="utf-8")
        fh = self._fh
        for r in rows:
            fh.write(json.dumps({k: (v.isoformat() if isinstance(v, datetime) else v) for k, v in r.items()},
                                allow_nan=True) + "\n")
        fh.flush()

    def fold(self) -> int:
        """Move the journal's rows into the table (one atomic rewrite) and remove the journal."""
        if self._fh is not None:
            self._fh.close()
            self._fh = None
        if not self.path.exists():
            return 0
        old = read_table(self.table)
        with open(self.path, encoding="utf-8") as fh:
            n = append_rows(self.table, _fresh(old, _lines(fh)), old=old)
        self.path.unlink()
        return n


def _key(row: dict) -> tuple:
    """A row's identity: one unit's job, sensor and run."""
    return (row.get("serial"), row.get("job"), row.get("run"), row.get("sensor"))


def _fresh(table: pa.Table, rows: Iterable[dict]) -> Iterable[dict]:
    """``rows`` less those the table (and the rows before them) already hold: folding a journal twice (a kill
    between the table's rewrite and the journal's removal) adds nothing the second time."""
    have = {_key(r) for r in table.select(["serial", "job", "run", "sensor"]).to_pylist()}
    for r in rows:
        k = _key(r)
        if k not in have:
            have.add(k)
            yield r


def _lines(fh) -> Iterable[dict]:
    for line in fh:
        try:
            yield json.loads(line)
        except ValueError:  # the last line of a run killed while writing it
            continue


def now() -> datetime:
    """The current time, UTC (the table's ``time``)."""
    return datetime.now(UTC)
