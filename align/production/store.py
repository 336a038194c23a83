"""The lot's results store: a folder of Parquet parts, appended without rewriting, read lazily.

``OUT/results.parquet`` is a folder (a Parquet dataset, as Spark and DuckDB write one): every fold of a batch's
journal adds one part, ``date=YYYY-MM-DD/part-<UTC time>-<random>.parquet`` (the day it was written, as a Hive
partition), written row group by row group to a hidden temporary name and renamed into place (atomic: a reader
sees the part whole or not at all). Nothing already written is read or rewritten by an append, so a run costs
the same whatever the store holds; a resume reads only the key columns it needs (:func:`read_table` with
``columns``), and ``lot`` only the figures it judges.

Every reader takes the folder as one table::

    pandas.read_parquet("OUT/results.parquet")                      # pyarrow's dataset; adds the column `date`
    duckdb.sql("SELECT * FROM read_parquet('OUT/results.parquet/**/*.parquet', union_by_name = true)")
    polars.read_parquet("OUT/results.parquet/**/*.parquet")

(``union_by_name``: parts written by different releases may hold different figure columns; this module's
:func:`read_table` unifies them, missing columns as nulls.) Names starting with ``.`` or ``_`` are not parts
(temporaries), as the dataset readers skip them.

A store written before release 0.3 is one file at the same path; :func:`read_table` reads it as it is, and the
first append moves it, untouched, into the folder as its first part.

While a batch runs, each finished unit's rows are first appended as JSON lines to a journal beside the store
(``results.parquet.journal``, flushed per unit); the journal is folded into a new part at the end of the run, or
at the start of the next one when the run was killed. So a killed batch loses at most the units that were running.

Public names
------------
read_table, append_rows, part_files, Journal, LatestRuns
"""

from __future__ import annotations

import json
import os
import uuid
from collections.abc import Iterable, Sequence
from datetime import datetime
from pathlib import Path
from typing import TextIO

import pyarrow as pa
import pyarrow.parquet as pq

from align.errors import InputError
from align.production.table import SCHEMA, _clean, _table, _unified, now, rows_of

#: the columns that name a row (one unit's job, sensor and run)
KEY = ("serial", "job", "run", "sensor")
#: the columns a table must hold to be a lot's
_REQUIRED = ("serial", "job", "time", "run", "status")


def _hidden(path: Path, root: Path) -> bool:
    return any(part.startswith((".", "_")) for part in path.relative_to(root).parts)


def part_files(path: str | Path) -> list[Path]:
    """The Parquet files of the store at ``path``, in the order written (a file: itself; missing: none).

    Examples
    --------
    >>> part_files("no/such/store")
    []
    """
    p = Path(path)
    if p.is_file():
        return [p]
    if not p.is_dir():
        return []
    parts = [f for f in p.rglob("*.parquet") if f.is_file() and not _hidden(f, p)]
    return sorted(parts, key=lambda f: (f.name, str(f)))  # names start with their UTC time: written order


def _part(p: Path, columns: Sequence[str] | None, where: str) -> pa.Table:
    """One part, only the ``columns`` it has of those asked for; a foreign or damaged file refused."""
    try:
        with pq.ParquetFile(p) as fh:  # not pq.read_table: its dataset layer imports pandas
            names = fh.schema_arrow.names
            fmt = (fh.schema_arrow.metadata or {}).get(b"format", b"").decode(errors="replace")
            lacking = [n for n in _REQUIRED if n not in names]
            if fmt != SCHEMA.metadata[b"format"].decode() or lacking:
                what = f"no column {lacking[0]}" if lacking else f"format '{fmt or 'none'}'"
                raise InputError(f"not an imu-align lot table ({what}); give results.parquet of imu-align batch",
                                 where if p == Path(where) else f"{where}: {p.name}")
            return fh.read(columns=None if columns is None else [c for c in columns if c in names])
    except InputError:
        raise
    except Exception as exc:  # pyarrow raises several types for a damaged or foreign file
        raise InputError(f"not a readable Parquet table ({' '.join(str(exc).split())[:200]})",
                         where if p == Path(where) else f"{where}: {p.name}") from None


def read_table(path: str | Path, columns: Sequence[str] | None = None) -> pa.Table:
    """The store at ``path`` as one table (an empty one with :data:`~align.production.table.SCHEMA` when it does
    not exist): every part, with only the ``columns`` asked for when given (a resume reads its keys alone).

    Raises
    ------
    InputError
        A part is not a lot's Parquet table; a folder holds no part.
    """
    p = Path(path)
    if p.is_file() and (p.parent.name.startswith("date=") or p.name.startswith("part-")):
        store = p.parent.parent if p.parent.name.startswith("date=") else p.parent
        raise InputError(f"is one part of the results store {store}, which holds {len(part_files(store))}; give the "
                         "store's folder to read every part", str(p))
    files = part_files(p)
    if not files and p.is_dir():
        if any(p.iterdir()):
            raise InputError("holds no Parquet part of a lot; give OUT/results.parquet of imu-align batch", str(p))
        files = []
    tables = [_part(f, columns, str(p)) for f in files]
    if not tables:  # not SCHEMA.empty_table(): that imports pandas (0.5 s)
        empty = pa.Table.from_batches([], schema=SCHEMA)
        return empty if columns is None else empty.select([c for c in columns if c in SCHEMA.names])
    return tables[0] if len(tables) == 1 else pa.concat_tables(_unified(tables))


def _settle(path: Path) -> None:
    """A store of one file (before 0.3) moved, untouched, into the folder as its first part; a move a kill cut
    short is finished."""
    moving = path.with_name("." + path.name + ".moving")
    if path.is_file():
        os.replace(path, moving)
    if moving.exists():
        path.mkdir(parents=True, exist_ok=True)
        os.replace(moving, path / "part-00000000T000000-single-file.parquet")


def append_rows(path: str | Path, rows: Iterable[dict], chunk: int = 256) -> int:
    """Append rows to the store at ``path`` (created when missing) as one new part; nothing written is read again.

    The rows are turned into Arrow ``chunk`` at a time and written as row groups, so that appending a long run
    holds few of them as Python objects at once.

    Returns
    -------
    int
        The number of rows appended (0: no part written).
    """
    store = Path(path)
    _settle(store)
    stamp = now()
    folder = store / f"date={stamp:%Y-%m-%d}"
    name = f"part-{stamp:%Y%m%dT%H%M%S%f}-{uuid.uuid4().hex[:8]}.parquet"
    folder.mkdir(parents=True, exist_ok=True)
    temp = folder / ("." + name + ".tmp")
    added, batch = 0, []
    writer = None
    try:
        for r in rows:
            batch.append(_clean(r))
            if len(batch) == chunk:
                writer = writer or pq.ParquetWriter(temp, SCHEMA, compression="zstd")
                writer.write_table(_table(batch))
                added, batch = added + len(batch), []
        if batch:
            writer = writer or pq.ParquetWriter(temp, SCHEMA, compression="zstd")
            writer.write_table(_table(batch))
            added += len(batch)
        if writer is not None:
            writer.close()
            writer = None
            os.replace(temp, folder / name)
    finally:
        if writer is not None:
            writer.close()
        temp.unlink(missing_ok=True)
        if not any(folder.iterdir()):
            folder.rmdir()
    return added


class Journal:
    """The rows of a running batch, one JSON line each, beside the store: ``journal.add(rows)`` per unit,
    :meth:`fold` into a new part at the end (or at the start of the next run after a kill)."""

    def __init__(self, table: str | Path) -> None:
        self.table = Path(table)
        self.path = self.table.with_name(self.table.name + ".journal")
        self._fh: TextIO | None = None

    def recover(self) -> int:
        """Fold a journal a killed run left into the store; the number of rows it held."""
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
        """Move the journal's rows into a new part of the store and remove the journal (rows the store holds
        already, from a fold a kill cut short, are not added twice)."""
        if self._fh is not None:
            self._fh.close()
            self._fh = None
        if not self.path.exists():
            return 0
        have = read_table(self.table, KEY)
        with open(self.path, encoding="utf-8") as fh:
            n = append_rows(self.table, _fresh(have, _lines(fh)))
        self.path.unlink()
        return n


def _key(row: dict) -> tuple:
    """A row's identity: one unit's job, sensor and run."""
    return tuple(row.get(k) for k in KEY)


def _fresh(table: pa.Table, rows: Iterable[dict]) -> Iterable[dict]:
    """``rows`` less those the store (and the rows before them) already hold: folding a journal twice (a kill
    between the part's rename and the journal's removal) adds nothing the second time."""
    have = {_key(r) for r in table.select(list(KEY)).to_pylist()}
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


def _indices(at) -> pa.Array:
    """Row indices as an Arrow array, from their bytes (``pa.array`` of a list imports pandas: 0.2 s, 55 MB)."""
    import numpy as np

    idx = np.asarray(at, dtype=np.int64)
    return pa.Array.from_buffers(pa.int64(), len(idx), [None, pa.py_buffer(idx)])


def _codes(indices: pa.Array, null: int):
    """A dictionary's integer indices as numpy, from their bytes (``to_numpy`` imports pandas), ``null`` for a null."""
    import numpy as np

    codes = np.frombuffer(indices.buffers()[1], dtype=f"<i{indices.type.bit_width // 8}")
    codes = codes[indices.offset : indices.offset + len(indices)].astype(np.int64)
    if indices.null_count:  # none is written (serial is required); a foreign part's, read as none of the lot
        valid = np.unpackbits(np.frombuffer(indices.buffers()[0], np.uint8), bitorder="little")
        codes[valid[indices.offset : indices.offset + len(indices)] == 0] = null
    return codes


class LatestRuns:
    """A resume's view of a store (:func:`align.production.batch.plan_tasks`): the latest run of each (serial,
    job) of a lot (:func:`align.production.table.latest_rows`), kept as Arrow columns: a row becomes a dict only
    when a unit is skipped.

    Parameters
    ----------
    table : pyarrow.Table
        The store's rows (:func:`read_table`, META and ``figures`` at least).
    serials : set of str
        The lot's serials: the store's other rows (other lots, a line's years) are left out without being made
        Python objects (the serial column dictionary-encoded, its distinct values tested).
    figures : list of str
        The figures a skipped unit's rows carry.

    Attributes
    ----------
    at : dict of (str, str) -> list of int
        The rows of the latest run of each (serial, job), as indices into the kept table.
    """

    def __init__(self, table: pa.Table, serials: set[str], figures: list[str]) -> None:
        import numpy as np

        if table.num_rows:  # the manifest's serials alone (a store holds every lot a line ran)
            coded = table.column("serial").combine_chunks().dictionary_encode()
            known = np.array([v in serials for v in coded.dictionary.to_pylist()] + [False])
            codes = _codes(coded.indices, len(known) - 1)
            table = table.take(_indices(np.flatnonzero(known[codes])))
        keys = zip(table.column("serial").to_pylist(), table.column("job").to_pylist(),
                   table.column("time").cast(pa.int64()).to_pylist(), table.column("run").to_pylist())
        best: dict[tuple[str, str], tuple[int, str, list[int]]] = {}
        for i, (serial, job, stamp, run) in enumerate(keys):
            have = best.get((serial, job))
            if have is None or stamp > have[0]:
                best[(serial, job)] = (stamp, run, [i])
            elif stamp == have[0] and run == have[1]:
                have[2].append(i)
        latest = [i for v in best.values() for i in v[2]]  # only the latest runs kept, renumbered
        table, where = table.take(_indices(latest)), {i: k for k, i in enumerate(latest)}
        self.table, self.figures = table, figures
        self.at = {k: [where[i] for i in v[2]] for k, v in best.items()}
        status, digest = table.column("status").to_pylist(), table.column("input_hash").to_pylist()
        self.first = {k: (status[v[0]], digest[v[0]]) for k, v in self.at.items()}

    def status(self, serial: str, job: str) -> str | None:
        """The status of (serial, job)'s latest run (None: none in the store)."""
        return self.first.get((serial, job), (None, None))[0]

    def input_hash(self, serial: str, job: str) -> str | None:
        """The content hash of (serial, job)'s latest run's inputs (None: none in the store)."""
        return self.first.get((serial, job), (None, None))[1]

    def rows(self, at: list[int]) -> list[dict]:
        """The rows at ``at`` (indices of :attr:`at`'s lists) as dicts: META and the figures asked for."""
        return rows_of(self.table.take(_indices(at)), self.figures)
