"""The registry of log formats: a file resolves to its reader by suffix, else by content.

Every command reads its logs through :func:`align.io.tables.read_columns` (and the sensor and static
readers above it, :mod:`align.io.logs`, :mod:`align.io.source`), which asks :func:`reader_for` which
reader holds the file. A new format is one module that defines its reader function and one
:func:`register` call (in :func:`_builtin`): ``read(path, names, time_column, log_format)`` returning
float64 columns by name, as ``(names, data)`` or as :class:`Columns` (which also carries the units the
format states, the stream read and remarks such as a truncated last record).

A log that holds several streams (a ROS bag's topics, a ULog's topics and instances, a DataFlash log's
messages) is read one stream at a time, chosen by :attr:`~align.io.formats.LogFormat.topic`; its reader
names the columns by the one convention of :class:`align.vocab.Sensor` (``gyro_x`` ..., ``accel_x``
..., ``mag_x`` ..., ``temperature``, time as ``time`` in seconds) and states their units, so a user
never types a unit the file already says. ``describe(path, log_format)`` lists its streams for
``inspect``.

Public names
------------
LogReader, Columns, Stream, READERS, PLUGINS, register, reader_for, formats, all_readers
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from align.errors import InputError
from align.io.formats import LogFormat

__all__ = ["LogReader", "Columns", "Stream", "READERS", "PLUGINS", "register", "reader_for", "formats", "all_readers"]


@dataclass(frozen=True, eq=False)
class Columns:
    """Named columns as a reader read them.

    Attributes
    ----------
    names : list of str
        Column names, in the order of ``data``'s columns.
    data : ndarray, shape (n, k), float64
    units : mapping of str to str
        The unit the file states for a column (``{"gyro_x": "rad/s", "time": "s", "temperature": "degC"}``);
        a column it does not name has no stated unit (a CSV states none).
    source : mapping of str to object
        The stream read, for a result's provenance (``{"topic": "sensor_gyro", "instance": 1,
        "device_id": 2293768}``); empty for a single-stream file.
    notes : tuple of str
        Remarks a result states (``"last record truncated (12 of 40 bytes), left out"``).
    """

    names: list[str]
    data: np.ndarray
    units: Mapping[str, str] = field(default_factory=dict)
    source: Mapping[str, Any] = field(default_factory=dict)
    notes: tuple[str, ...] = ()

    @classmethod
    def of(cls, got: Columns | tuple[list[str], np.ndarray]) -> Columns:
        """A reader's answer as :class:`Columns` (a ``(names, data)`` pair has no units, source or notes)."""
        return got if isinstance(got, Columns) else cls(list(got[0]), got[1])

    def unit(self, names: list[str]) -> str | None:
        """The one unit the file states for all of ``names`` (None: none stated, or not one unit)."""
        units = {self.units.get(n) for n in names}
        return units.pop() if len(units) == 1 else None


@dataclass(frozen=True)
class Stream:
    """One stream of a log, as ``inspect`` lists it (:attr:`LogReader.describe`).

    Attributes
    ----------
    topic : str
        What :attr:`~align.io.formats.LogFormat.topic` selects it by (``"/imu0"``, ``"sensor_gyro:1"``, ``"IMU:0"``).
    kind : str
        Its message type (``"sensor_msgs/msg/Imu"``, ``"sensor_gyro"``, ``"IMU"``).
    count : int
        Its number of samples.
    columns : tuple of str
        The columns it gives, by the one convention (``gyro_x`` ...).
    units : mapping of str to str
        Their units as the format states them.
    extra : mapping of str to object
        What else the format says of it (``device_id``, a nominal rate).
    """

    topic: str
    kind: str
    count: int
    columns: tuple[str, ...] = ()
    units: Mapping[str, str] = field(default_factory=dict)
    extra: Mapping[str, Any] = field(default_factory=dict)


ReadFn = Callable[[Path, "list[str] | None", "str | None", LogFormat], "Columns | tuple[list[str], np.ndarray]"]


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
        ``read(path, names, time_column, log_format) -> Columns`` (or ``(names, data (n, k) float64)``).
    sniff : callable, optional
        ``sniff(first_bytes) -> bool``: whether a file of no known suffix (or of a suffix two formats use,
        ``.bin``) is of this format.
    text : bool
        Whether the logger's text options (preamble, comment, delimiter) apply.
    streams : bool
        Whether the format holds several streams (``topic`` and ``stamps`` apply).
    describe : callable, optional
        ``describe(path, log_format) -> list of Stream``: what the log holds (``inspect``).
    folder : bool
        Whether a folder is a log of this format (a ROS 2 bag, an EuRoC dataset): ``sniff`` is then
        given the folder's file names, one per line, instead of first bytes.
    chunks : callable, optional
        ``chunks(path, log_format, names, rows) -> Iterator[Columns]``: the columns ``read`` gives, in blocks of
        at most ``rows`` rows, in bounded memory (a long recording: :mod:`align.io.streamchunks`).
    """

    name: str
    suffixes: tuple[str, ...]
    read: ReadFn
    sniff: Callable[[bytes], bool] | None = None
    text: bool = False
    streams: bool = False
    describe: Callable[[Path, LogFormat], list[Stream]] | None = None
    folder: bool = False
    chunks: Callable[..., Any] | None = None


#: the registered readers, in the order they are tried by content
READERS: list[LogReader] = []


def register(reader: LogReader) -> LogReader:
    """Add a reader (a later one with the same name replaces the earlier)."""
    READERS[:] = [r for r in READERS if r.name != reader.name] + [reader]
    return reader


def formats() -> list[str]:
    """Every suffix a reader owns, for messages (``.csv, .csv.gz, ...``)."""
    return [s for r in all_readers() for s in r.suffixes]


def all_readers() -> list[LogReader]:
    """Every reader of this installation, the plugins' imported (:data:`PLUGINS`)."""
    _load(PLUGINS)
    return list(READERS)


def _load(names) -> None:
    """Register the ``READER`` of each plugin module of ``names`` that the registry lacks (a module imported
    before is not imported again: ``sys.modules``)."""
    import importlib

    for name in names:
        reader = importlib.import_module(name).READER
        if not any(r is reader for r in READERS):
            register(reader)


def reader_for(path: Path, log_format: LogFormat | None = None) -> LogReader:
    """The reader of ``path``: the one owning its suffix (the longest match: ``.csv.gz`` before ``.gz``),
    else the first whose ``sniff`` accepts its first bytes.

    Raises
    ------
    InputError
        Naming the file and the formats there are.
    """
    name = path.name.lower()
    _load([m for m, suffixes in PLUGINS.items() if any(name.endswith(x) for x in suffixes)])
    if path.is_dir() or not any(name.endswith(x) for r in READERS for x in r.suffixes):
        _load(PLUGINS)  # by content, or a folder: every format asked
    if path.is_dir():
        names = sorted((str(p.relative_to(path)) for p in path.rglob("*")), key=lambda n: (n.count("/") > 2, n))
        listing = "\n".join(names[:10_000]).encode()  # the shallow names first (a dataset's images are deep)
        for r in READERS:
            if r.folder and r.sniff is not None and r.sniff(listing):
                return r
        folders = [r.name for r in READERS if r.folder]
        raise InputError("is a folder, and not a log folder of a known kind"
                         + (f" ({', '.join(folders)})" if folders else "") + "; give a log file", str(path))
    owned = [(len(s), r) for r in READERS for s in r.suffixes if name.endswith(s)]
    try:
        with open(path, "rb") as fh:
            head = fh.read(1 << 12)
    except OSError:
        head = b""
    if owned:
        longest = max(n for n, _ in owned)
        mine = [r for n, r in owned if n == longest]
        if len(mine) == 1:  # its reader says so when the file is not of its format (a raw float64 .bin)
            return mine[0]
        for r in mine:  # one suffix, several formats (.bin): by content
            if r.sniff is not None and r.sniff(head):
                return r
        raise InputError(f"is not a {' or '.join(r.name for r in mine)} file (its first bytes are neither); "
                         "check the file", str(path))
    for r in READERS:
        if r.sniff is not None and not r.folder and r.sniff(head):
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
    """The formats this installation reads (a new format: its module's ``READER`` added here)."""
    from align.io import tables

    register(LogReader("csv", (".csv", ".csv.gz", ".txt", ".txt.gz", ".tsv", ".gz"), tables.csv_columns,
                       _text_sniff, text=True))
    register(LogReader("npy", (".npy",), tables.npy_columns, lambda head: head.startswith(b"\x93NUMPY")))
    register(LogReader("parquet", (".parquet",), tables.parquet_columns, lambda head: head.startswith(b"PAR1")))


#: modules of formats, each defining ``READER`` (:class:`LogReader`), with the suffixes it owns: a module is
#: imported when a file of its suffix is read, or when a file or folder is told by its content (a CSV never
#: imports them: the command line's start-up stays as it was)
PLUGINS: dict[str, tuple[str, ...]] = {"align.io.ulog": (".ulg",), "align.io.dataflash": (".bin",),
                                       "align.io.rosbag": (".bag", ".db3", ".mcap"), "align.io.euroc": ()}


_builtin()
