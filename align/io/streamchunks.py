"""One stream of a log of several streams (a ULog, a ROS bag) as a chunk source, read in bounded memory.

The reader's ``chunks`` (:attr:`align.io.readers.LogReader.chunks`: ``chunks(path, log_format, names, rows)``
yielding :class:`~align.io.readers.Columns` blocks) is run once: the time column of each block counts the samples,
gives the sample rate (the median step of the first :data:`HEAD` steps) and is checked: a time that does not
increase or a gap (a step beyond 1.5 times the median, or below half of it: the uniform samples an Allan deviation
needs) is refused with its position, as :func:`align.io.checks.check_time` does for a log read whole; the data
columns are checked (NaN, inf, absurd readings refused by sample, as allan does: ``checked``) and written, as read
(float64), to a temporary raw file, removed once the source is released (at exit at the latest). That file is then
read in chunks, as :class:`align.io.logs.NpyChunks` reads raw binary but through a mapping let go behind each chunk
(fast enough for one pass per group of channels, see :func:`align.noise.allan.allan`), and mapped for the sampled
checks of a record (a second decoding of the log would double the time; the file costs a write of ``8 n C`` bytes
and reads from the page cache).

Public names
------------
StreamChunks, stream_source, HEAD, CHUNKED_BYTES, ROWS
"""

from __future__ import annotations

import mmap
import os
import tempfile
import weakref
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from align.errors import InputError
from align.io.checks import check_readings
from align.io.formats import TIME_UNITS, LogFormat
from align.io.logs import NpyChunks

__all__ = ["StreamChunks", "stream_source", "HEAD", "CHUNKED_BYTES", "ROWS"]

#: the number of time steps whose median gives the sample rate
HEAD = 100_000
#: a stream log at least this large is read in blocks (below it, whole, as other logs): a 200 MB ULog holds some
#: 2.5 hours of 400 Hz IMU samples, about 0.5 GB as the float64 columns a whole read holds at once
CHUNKED_BYTES = 200 << 20
#: rows (messages) per block asked of the reader: some 0.1 GB of a bag's messages held at once
ROWS = 100_000


class StreamChunks(NpyChunks):
    """The data columns of one stream of a log, read once in blocks and kept in a temporary raw float64 file.

    Parameters
    ----------
    log : Path
        The log (a file, or a bag folder).
    names : list of str
        The data columns (``gyro_x`` ...), in the order of the chunks' columns.
    log_format : LogFormat
        The stream (``topic``) and ``stamps``.
    chunks : callable
        The reader's ``chunks(path, log_format, names, rows) -> Iterator[Columns]``.
    scale : float
        Multiplies every value read (1: the numbers as stored).
    time_column : str
        The time column's name (``time``, in the unit the reader states, seconds when it states none).
    rows : int
        Rows per block asked of the reader.

    Attributes
    ----------
    shape : tuple
        ``(n, C)``: samples and data columns (:class:`~align.io.logs.NpyChunks`'s, with ``chunks`` and ``path``,
        the temporary file).
    log : Path
        The log read.
    rate_hz : float
        1 / the median time step of the first :data:`HEAD` steps, Hz.
    units : mapping
        The units the reader states (``{"gyro_x": "rad/s", "time": "s"}``).
    source, notes
        The stream read and the reader's remarks (those of the last block).
    checked : bool
        True: every reading was checked as written (:func:`align.noise.allan.allan` need not check them again).

    Examples
    --------
    >>> from align.io.readers import Columns
    >>> def blocks(path, fmt, names, rows):
    ...     t = np.arange(10) / 100.0
    ...     for s in range(0, 10, rows):
    ...         yield Columns(names, np.column_stack([t[s:s + rows], t[s:s + rows] * 0 + 1.0]), {"time": "s"})
    >>> src = StreamChunks(Path("x.ulg"), ["gyro_x"], LogFormat(), blocks, rows=4)
    >>> src.shape, round(src.rate_hz, 9), [len(b) for b in src.chunks(rows=3)]
    ((10, 1), 100.0, [3, 3, 3, 1])
    """

    def __init__(self, log: Path, names: list[str], log_format: LogFormat,
                 chunks: Callable[..., Iterator[Any]], scale: float = 1.0, *, time_column: str = "time",
                 rows: int = ROWS) -> None:
        self.log, self.time_column, self.names = Path(log), time_column, list(names)
        self.units: Mapping[str, str] = {}
        self.source: Mapping[str, Any] = {}
        self.notes: tuple[str, ...] = ()
        fd, spill = tempfile.mkstemp(prefix="imu_align_stream_", suffix=".f8")
        weakref.finalize(self, _remove, spill)  # when released, or at exit
        with os.fdopen(fd, "wb") as fh:
            self.rate_hz = self._read(chunks(self.log, log_format, [time_column, *self.names], rows), fh, scale)
        super().__init__(spill, len(self.names), scale)
        self.checked = True  # every reading checked as written: allan need not read all columns again to check

    def chunks(self, rows: int = 1 << 20, columns: list[int] | None = None) -> Iterator[np.ndarray]:
        """Yield float64 arrays of up to ``rows`` rows (all columns, or the ones listed), as
        :meth:`NpyChunks.chunks <align.io.logs.NpyChunks.chunks>` does, but gathered from a read-only mapping of
        the temporary file whose pages are let go behind each block (Linux: bounded memory). Gathering a column
        costs one pass over the mapped rows, about a fifth of reading them into a buffer first: allan reads a
        long record once per group of channels."""
        n, c = self.shape
        with open(self.path, "rb") as fh, mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as mm:
            arr = np.frombuffer(mm, self.dtype, n * c).reshape(n, c)
            try:
                for start in range(0, n, rows):
                    stop = min(n, start + rows)
                    block = np.asarray(arr[start:stop].copy() if columns is None else arr[start:stop, columns],
                                       dtype=np.float64)  # a copy: no view of the mapping
                    lo, hi = (r * c * self.dtype.itemsize // mmap.PAGESIZE * mmap.PAGESIZE for r in (start, stop))
                    if hasattr(mmap, "MADV_DONTNEED") and hi > lo:  # the pages read go (kept in the page cache)
                        mm.madvise(mmap.MADV_DONTNEED, lo, hi - lo)
                    yield block * self.scale if self.scale != 1 else block
            finally:
                del arr  # no view may outlive the mapping

    @property
    def time_units(self) -> str:
        """The unit the reader states for the time column (seconds when it states none)."""
        return self.units.get(self.time_column, "s")

    def stated(self) -> str | None:
        """The one unit the reader states for every data column (None: none, or not one)."""
        units = {self.units.get(n) for n in self.names}
        return units.pop() if len(units) == 1 else None

    def _read(self, blocks: Iterator[Any], fh, scale: float) -> float:
        """Write each block's data columns to ``fh``, refusing readings that are none (times ``scale``: NaN, inf,
        absurd; :func:`align.io.checks.check_readings`, named by sample as allan names them); count the samples, take
        the rate from the head's median step, refuse steps back and gaps. Returns the rate, Hz."""
        where = str(self.log)
        head: list[np.ndarray] = []
        n, factor, med, prev, written = 0, 1.0, None, None, 0
        gaps, first = 0, None  # gaps beyond the median's tolerance; the first (t, step)
        for got in blocks:
            if not self.units:
                self.units = dict(got.units)
                factor = TIME_UNITS.get(self.units.get(self.time_column, "s"), 1.0)
            self.source, self.notes = dict(got.source), tuple(got.notes)
            if not len(got.data):
                continue
            data = np.ascontiguousarray(got.data[:, 1:], dtype=np.float64)
            try:
                check_readings(data * scale if scale != 1 else data, where, first_row=written)  # samples from 0
            except InputError as exc:
                raise InputError(exc.message.replace("data row", "sample"), exc.where) from None
            data.tofile(fh)
            written += len(data)
            t = np.asarray(got.data[:, 0], dtype=np.float64) * factor
            if med is None:
                head.append(t)
                if sum(len(h) for h in head) <= HEAD:
                    continue
                t, head = np.concatenate(head), []
                med = _median(t, where)
            gaps, first, prev = _check(t, prev, med, n, gaps, first, where)
            n += len(t)
        if med is None:  # the whole stream fits the head
            t = np.concatenate(head) if head else np.zeros(0)
            if len(t) < 3:
                raise InputError(f"only {len(t)} rows; at least 3 are needed", where)
            med = _median(t, where)
            gaps, first, prev = _check(t, prev, med, 0, gaps, first, where)
        if gaps:
            assert first is not None
            raise InputError(f"{gaps} time gaps or jitter beyond 50 % of the {med:.4g} s median step: gap in the "
                             f"time series at t={first[0]:.6g} s (step {first[1]:.4g} s); resample or split the file",
                             where)
        return 1.0 / med


def _remove(path: str) -> None:
    try:
        os.unlink(path)
    except OSError:
        pass


def _median(t: np.ndarray, where: str) -> float:
    """The median of the first :data:`HEAD` steps of ``t`` (s), refused unless positive."""
    step = float(np.median(np.diff(t[: HEAD + 1])))
    if not step > 0:
        raise InputError(f"time stamps repeat (median step {step:.4g} s): the clock is coarser than the sample "
                         "interval; read the log without its time column at its sample rate ({rate_hz})", where)
    return step


def _check(t: np.ndarray, prev: float | None, med: float, n0: int, gaps: int, first, where: str):
    """The steps of ``t`` (after ``prev``, the time before it): a step back or none refused at once (its data row),
    gaps counted (the first kept). Returns (gaps, first, the last time)."""
    if not len(t):
        return gaps, first, prev
    tt = t if prev is None else np.concatenate([[prev], t])
    dt = np.diff(tt)
    if np.any(dt <= 0):
        k = int(np.argmax(dt <= 0))
        row = n0 + k + (2 if prev is None else 1)
        raise InputError(f"time does not increase at data row {row} (t={tt[k + 1]:.9g} s after {tt[k]:.9g} s); "
                         "sort the log or fix the time column", where)
    off = (dt > 1.5 * med) | (dt < 0.5 * med)
    if off.any():
        k = int(np.argmax(off))
        first = first or (float(tt[k]), float(dt[k]))
        gaps += int(off.sum())
    return gaps, first, float(t[-1])


def stream_source(log: Path, names: list[str], log_format: LogFormat, scale: float = 1.0, time_column: str = "time"
                  ) -> StreamChunks | None:
    """A :class:`StreamChunks` of ``log`` when its reader offers ``chunks`` and it holds at least
    :data:`CHUNKED_BYTES` (a file, or a bag folder's files), else None (read whole, as other logs; so too with text
    options, which the whole read refuses, or a time unit given).

    Examples
    --------
    >>> stream_source(Path("no-such.ulg"), ["gyro_x"], LogFormat()) is None
    True
    """
    from align.io.readers import reader_for

    try:
        reader = reader_for(log, log_format)
        size = sum(p.stat().st_size for p in log.rglob("*") if p.is_file()) if log.is_dir() else log.stat().st_size
    except (InputError, OSError):  # read whole: its reader names the problem
        return None
    if reader.chunks is None or size < CHUNKED_BYTES or log_format.given() or log_format.time_units is not None:
        return None
    return StreamChunks(log, names, log_format, reader.chunks, scale, time_column=time_column, rows=ROWS)
