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
from datetime import UTC, datetime
from pathlib import Path
from typing import TextIO

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
        cols = [t.column(f.name).cast(f.type) if f.name in t.column_names else pa.nulls(len(t), f.type)
                for f in schema]
        out.append(pa.Table.from_arrays(cols, schema=schema))
    return out


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
        table = pq.read_table(p)
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
            parts.append(pa.Table.from_pylist(batch, schema=SCHEMA))
            batch = []
    if batch:
        parts.append(pa.Table.from_pylist(batch, schema=SCHEMA))
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
    rows = table.to_pylist()
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
            _warm()
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


def _warm() -> None:
    """Make pyarrow ready to turn Python rows into a table now, while the workers compute, rather than in the
    fold at the end: its first conversion imports pandas (a third of a second)."""
    pa.array([0.0], type=pa.float64())


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
