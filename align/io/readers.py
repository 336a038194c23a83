"""The registry of log formats: a file resolves to its reader by suffix, else by content.

Every command reads its logs through :func:`align.io.tables.read_columns` (and the sensor and static
readers above it, :mod:`align.io.logs`, :mod:`align.io.source`), which asks :func:`reader_for` which
reader holds the file. A new format is one module that defines its reader function and one
:func:`register` call (here, for the built-in ones): ``read(path, names, time_column, log_format)
-> (names, data)`` returning float64 columns by name.

Public names
------------
LogReader, READERS, register, reader_for, formats
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from align.errors import InputError
from align.io.formats import LogFormat

__all__ = ["LogReader", "READERS", "register", "reader_for", "formats"]

ReadFn = Callable[[Path, "list[str] | None", "str | None", LogFormat], "tuple[list[str], np.ndarray]"]


@dataclass(frozen=True)
class LogReader:
    """One log format.

    Attributes
    ----------
    name : str
        Its name in messages and in a result's provenance (``"csv"``, ``"parquet"``).
    suffixes : tuple of str
        File endings it owns, lower case with the dot (``".csv"``, ``".csv.gz"``).
    read : callable
        ``read(path, names, time_column, log_format) -> (names, data (n, k) float64)``.
    sniff : callable, optional
        ``sniff(first_bytes) -> bool``: whether a file of no known suffix is of this format.
    text : bool
        Whether the logger's text options (preamble, comment, delimiter) apply.
    """

    name: str
    suffixes: tuple[str, ...]
    read: ReadFn
    sniff: Callable[[bytes], bool] | None = None
    text: bool = False


#: the registered readers, in the order they are tried by content
READERS: list[LogReader] = []


def register(reader: LogReader) -> LogReader:
    """Add a reader (a later one with the same name replaces the earlier)."""
    READERS[:] = [r for r in READERS if r.name != reader.name] + [reader]
    return reader


def formats() -> list[str]:
    """Every suffix a reader owns, for messages (``.csv, .csv.gz, ...``)."""
    return [s for r in READERS for s in r.suffixes]


def reader_for(path: Path, log_format: LogFormat | None = None) -> LogReader:
    """The reader of ``path``: the one owning its suffix (the longest match: ``.csv.gz`` before ``.gz``),
    else the first whose ``sniff`` accepts its first bytes.

    Raises
    ------
    InputError
        Naming the file and the formats there are.
    """
    name = path.name.lower()
    owned = [(len(s), r) for r in READERS for s in r.suffixes if name.endswith(s)]
    if owned:
        return max(owned, key=lambda pair: pair[0])[1]
    try:
        with open(path, "rb") as fh:
            head = fh.read(1 << 12)
    except OSError:
        head = b""
    for r in READERS:
        if r.sniff is not None and r.sniff(head):
            return r
    raise InputError(f"unknown file type; use one of {', '.join(formats())}", str(path))


def _text_sniff(head: bytes) -> bool:
    """Printable text whose first line looks like a header or a row of numbers."""
    if not head or b"\x00" in head:
        return False
    try:
        head.decode("utf-8")
    except UnicodeDecodeError:
        return False
    return True


def _builtin() -> None:
    from align.io import tables

    register(LogReader("csv", (".csv", ".csv.gz", ".txt", ".txt.gz", ".tsv", ".gz"), tables.csv_columns,
                       _text_sniff, text=True))
    register(LogReader("npy", (".npy",), tables.npy_columns, lambda head: head.startswith(b"\x93NUMPY")))
    register(LogReader("parquet", (".parquet",), tables.parquet_columns, lambda head: head.startswith(b"PAR1")))


_builtin()
