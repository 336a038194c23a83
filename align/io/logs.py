"""Sensor logs: the one place that reads recorded data.

CSV (optionally .gz, read with pyarrow), blank-separated text, .parquet, .npy, raw
binary and every registered format (a stream of a ROS bag, a ULog, a DataFlash log:
:mod:`align.io.readers`; columns by name: :mod:`align.io.tables`); a logger's preamble, comments,
delimiter and the unit of its time column (:class:`~align.io.formats.LogFormat`:
the time unit is detected from the sample interval unless given); data converted
to SI once, here, from a unit or the size of one count (``"131 LSB/(deg/s)"``).
Every problem becomes an :class:`~align.errors.InputError` naming the file,
row or column; every reader applies the same checks of a log's rows and time
stamps (:mod:`align.io.checks`, re-exported here).

Public names
------------
read_sensor_log, SensorLog, read_log, read_static_log, StaticLog, read_static, read_columns, sensor_scale,
NpyChunks, check_finite, check_readings, check_time, check_log, MAX_READING
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from align.errors import InputError
from align.io.checks import MAX_READING, check_finite, check_log, check_readings, check_repeats, check_time
from align.io.files import existing_file
from align.io.formats import TIME_UNITS, LogFormat, time_unit
from align.io.readings import celsius as _celsius
from align.io.readings import sensor_scale
from align.io.readings import units_of as _units_of
from align.io.tables import MissingColumns, read_columns, read_table, shown

__all__ = ["read_sensor_log", "SensorLog", "read_log", "read_static_log", "StaticLog", "read_static", "read_columns",
           "sensor_scale", "NpyChunks", "check_finite", "check_readings", "check_time", "check_log", "MAX_READING"]


def _check_rate(rate_hz: float | None, path, missing: str = "no time column: give {rate_hz}") -> float:
    """A sample rate given for a log without time: present, finite and positive (returned)."""
    if rate_hz is None:
        raise InputError(missing, str(path))
    if not (np.isfinite(rate_hz) and rate_hz > 0):
        raise InputError(f"the sample rate must be a finite number of Hz > 0, not {float(rate_hz)!r}; give e.g. "
                         "{rate_hz=100}", str(path))
    return rate_hz


@dataclass(frozen=True, eq=False)
class SensorLog:
    """A sensor log as read: time in s, readings in SI, and how the file was read.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Time, s (from the time column in ``time_units``, or ``arange(n) / rate_hz``).
    data : ndarray, shape (n, k)
        Readings in SI (or counts, when read in counts).
    units : str
        The unit the readings were given in, as typed (``"131 LSB/(deg/s)"``).
    shown : str
        The unit results show them in (``"deg/s"`` for that count size).
    time_units : str or None
        Unit of the time column (a key of :data:`~align.io.formats.TIME_UNITS`); None: no time column.
    time_detected : bool
        True when ``time_units`` was detected from the sample interval, False when given.
    rate_hz : float
        The sample rate: the median one of the time column, or the one given, Hz.
    format : LogFormat
        The preamble, comments and delimiter the file was read with.
    temperature : ndarray, shape (n,), or None
        The temperature column, degrees Celsius (None: not read).
    source : mapping
        The stream read from a log of several (topic, instance, device id; :class:`align.io.readers.Columns`).
    notes : tuple of str
        The reader's remarks (a truncated last record left out).
    stated : bool
        Whether the unit of the readings is the one the file states (not typed by the user).
    """

    t: np.ndarray
    data: np.ndarray
    units: str
    shown: str
    time_units: str | None
    time_detected: bool
    rate_hz: float
    format: LogFormat = field(default_factory=LogFormat)
    temperature: np.ndarray | None = None
    source: Mapping[str, Any] = field(default_factory=dict)
    notes: tuple[str, ...] = ()
    stated: bool = False

    def inputs(self) -> dict:
        """How the file was read, for a result's ``inputs``: the format options and the time unit
        (``time_units``, with ``time_units_detected``), and the stream and stated unit (:meth:`stream_inputs`)."""
        return {**self.format.to_dict(), "time_units": self.time_units, "time_units_detected": self.time_detected,
                **self.stream_inputs()}

    def stream_inputs(self, prefix: str = "") -> dict:
        """The stream read (``stream``) and the unit the file states (``units_stated``), when it has them, each key
        after ``prefix`` (``accel_``): what a result records of a log of several streams beside its own keys."""
        return {prefix + k: v for k, v, has in (("stream", dict(self.source), bool(self.source)),
                                                 ("units_stated", self.units, self.stated)) if has}

    def remarks(self, where: str) -> tuple[str, ...]:
        """The reader's notes (a truncated last record left out) as a result states them: after the log's name."""
        return tuple(f"{where}: {n}" for n in self.notes)

    def time_note(self) -> str | None:
        """One sentence on the time column's unit when it is not seconds (None otherwise): results state it."""
        if self.time_units in (None, "s"):
            return None
        how = "detected from the median step" if self.time_detected else "as given"
        return f"time column read in {self.time_units} ({how}: {self.rate_hz:.6g} Hz)"


def _time_of(raw: np.ndarray, column: str, where: str, fmt: LogFormat, stated: bool = False) -> tuple[np.ndarray, str, bool]:
    """Time in s from a time column's numbers; its unit detected, given or ``stated`` (:func:`~align.io.formats.time_unit`)."""
    check_repeats(raw, where)  # before the step is judged: a coarse clock's median step means nothing
    step = float(np.median(np.diff(raw))) if len(raw) > 1 else float("nan")
    unit, detected = time_unit(step, column, where, fmt.time_units, float(raw[0]) if len(raw) else None,
                               stated=stated)
    return (raw * TIME_UNITS[unit] if unit != "s" else raw), unit, detected


def _rate_only(fmt: LogFormat, path) -> None:
    """A time unit goes with a time column: refused for a log read at a given sample rate."""
    if fmt.time_units is not None:
        raise InputError("{time_units} applies to a time column, and this log is read without one ({rate_hz}); "
                         "leave one of them out", str(path))


def read_sensor_log(path: str | Path, columns: list[str], units: str | None, time_column: str | None = "time",
                    rate_hz: float | None = None, expect: str | None = "angular_rate",
                    log_format: LogFormat | None = None, counts: bool = False, field: str | None = None, *,
                    default_units: str | None = None, temperature_column: str | None = None,
                    temperature_units: str | None = None) -> SensorLog:
    """Read a sensor log: time (s) and data columns converted to SI, and how the file was read.

    Parameters
    ----------
    path : str or Path
    columns : list of str
        The data columns, e.g. ``["gyro_x", "gyro_y", "gyro_z"]``.
    units : str or None
        Unit of the data columns, e.g. ``"deg/s"``, or the size of one count (``"0.0076336 deg/s"``,
        ``"131 LSB/(deg/s)"``); checked against ``expect`` (see :func:`sensor_scale`). None: the unit the
        file states (a ULog, a bag), else ``default_units``. A unit given for a file that states another
        is refused.
    time_column : str or None
        Name of the time column; None when ``rate_hz`` is given.
    rate_hz : float, optional
        Sample rate for logs without a time column (the time column, if any, is then not read).
    expect : str or None
        Dimension of the readings (a key of :data:`align.units.DIMENSIONS`); None: any unit.
    log_format : LogFormat, optional
        Preamble, comments, delimiter and the unit of the time column (detected when not given); the
        topic of a log of several streams.
    counts : bool
        Whether the readings may stay in raw counts (``units="counts"``).
    field : str, optional
        The input that gave ``units``, for messages; default ``gyro_units`` for an angular rate,
        ``units`` otherwise.
    default_units : str, optional
        The unit when neither ``units`` nor the file gives one.
    temperature_column : str, optional
        A temperature column to read beside the data (``SensorLog.temperature``, degrees Celsius).
    temperature_units : str, optional
        Its unit (``"degC"``, ``"K"``, ``"degF"``); None: the file's, else degrees Celsius.

    Returns
    -------
    SensorLog
        ``t`` (n,) s, ``data`` (n, len(columns)) SI, the time unit used and whether it was detected.
    """
    fmt = log_format or LogFormat()
    field = field or ("gyro_units" if expect == "angular_rate" else "units")
    time_col = time_column if rate_hz is None else None  # the column read as time (none with a given rate)
    use_time = time_col is not None
    temp = [temperature_column] if temperature_column is not None else []
    wanted = ([time_col] if time_col is not None else []) + list(columns) + temp
    p = Path(path)
    if p.suffix.lower() == ".npy":
        _, data = read_columns(p, log_format=fmt)
        if data.shape[1] != len(wanted):
            raise InputError(f"has {data.shape[1]} columns; expected {len(wanted)} ({', '.join(map(shown, wanted))})"
                             + ("; give {rate_hz} for a file without time" if use_time else ""), str(path))
        got = None
    else:
        try:
            got = read_table(p, wanted, time_col, fmt)
        except MissingColumns as e:  # the temperature column alone missing: its option, not the data columns'
            raise e if not temp or e.missing != temp else InputError(
                f"no temperature column {shown(temp[0])!r} (columns: {e.listed}); name it with {{temperature_column}}, "
                "or leave it out for a log without temperature", str(path)) from None
        data = got.data
    stated = got.unit(list(columns)) if got is not None else None
    units, from_file = _units_of(units, stated, default_units, expect, field, str(path))
    factor, unit_shown = sensor_scale(units, expect, field, counts)
    celsius = None
    if temp:
        celsius = _celsius(data[:, -1], temperature_units or (got.units.get(temperature_column) if got else None),
                           str(path))
        data = data[:, :-1]
    if got is not None and time_col is not None and got.units.get(time_col) in TIME_UNITS and fmt.time_units is None:
        fmt_time = replace(fmt, time_units=got.units[time_col])
    else:
        fmt_time = fmt
    if time_col is not None:
        raw_t, values = data[:, 0], data[:, 1:]
        check_readings(values, str(path), raw_t)
        t, tu, detected = _time_of(raw_t, time_col, str(path), fmt_time, stated=fmt_time is not fmt)
        step = float(np.median(np.diff(t))) if len(t) > 1 else float("nan")
        fs = 1.0 / step if step > 0 else float("nan")
    else:
        rate = _check_rate(rate_hz, path)
        _rate_only(fmt, path)
        t, values, tu, detected, fs = np.arange(len(data)) / rate, data, None, False, float(rate)
        check_readings(values, str(path), t)
    return SensorLog(np.ascontiguousarray(t), values * factor, units, unit_shown, tu, detected, fs, fmt, celsius,
                     dict(got.source) if got is not None else {}, tuple(got.notes) if got is not None else (),
                     from_file)


def read_log(path: str | Path, columns: list[str], units: str, time_column: str | None = "time",
             rate_hz: float | None = None, expect: str | None = "angular_rate",
             log_format: LogFormat | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Read a sensor log: ``(t, data)``, time (n,) in s and the columns (n, len(columns)) in SI
    (:func:`read_sensor_log`, which also tells how the file was read)."""
    log = read_sensor_log(path, columns, units, time_column, rate_hz, expect, log_format,
                          counts=expect == "counts")
    return log.t, log.data


class NpyChunks:
    """Row chunks of a 2-D .npy file (or raw binary) read with ``numpy.fromfile``: bounded memory.

    Raw binary files (``.bin``/``.f8``: little-endian float64, ``.f4``: float32)
    hold ``channels`` interleaved columns and no header.

    Attributes
    ----------
    shape : tuple
        ``(n, C)`` of the stored array.
    scale : float
        Multiplies every value read (the size of one count; 1: the numbers as stored).
    """

    def __init__(self, path: str | Path, channels: int | None = None, scale: float = 1.0) -> None:
        p = existing_file(path)
        self.scale = scale
        if p.suffix.lower() in (".bin", ".f8", ".f4", ".raw"):
            dtype = np.dtype("<f4" if p.suffix.lower() == ".f4" else "<f8")
            if not channels:
                raise InputError("a raw binary file needs its number of columns ({columns})", str(path))
            size = p.stat().st_size
            if size % (dtype.itemsize * channels):
                raise InputError(f"{size} bytes is not a whole number of {channels}-column {dtype} rows", str(path))
            self.path, self.offset, self.fortran, self.dtype = p, 0, False, dtype
            self.shape = (size // (dtype.itemsize * channels), channels)
            return
        try:
            with open(p, "rb") as fh:
                version = np.lib.format.read_magic(fh)
                read = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
                shape, fortran, dtype = read(fh)
                self.offset = fh.tell()
        except (ValueError, OSError) as exc:
            raise InputError(f"cannot read .npy ({exc})", str(path)) from None
        if len(shape) == 1:
            shape = (shape[0], 1)
        if dtype.kind not in "fiu":
            raise InputError(f"holds {dtype} values; expected numbers (an integer or float array)", str(path))
        if len(shape) != 2:
            raise InputError(f"expected an n x k array, got shape {tuple(int(k) for k in shape)}", str(path))
        self.path, self.shape, self.fortran, self.dtype = p, shape, fortran, dtype

    def chunks(self, rows: int = 1 << 20, columns: list[int] | None = None):
        """Yield float64 arrays of up to ``rows`` rows (all columns, or the ones listed)."""
        n, c = self.shape
        cols = list(range(c)) if columns is None else columns
        with open(self.path, "rb") as fh:
            for start in range(0, n, rows):
                k = min(rows, n - start)
                if self.fortran:
                    block = np.empty((k, len(cols)))
                    for j, col in enumerate(cols):
                        fh.seek(self.offset + (col * n + start) * self.dtype.itemsize)
                        block[:, j] = np.fromfile(fh, self.dtype, k)
                else:
                    fh.seek(self.offset + start * c * self.dtype.itemsize)
                    block = np.fromfile(fh, self.dtype, k * c).reshape(k, c)
                    if columns is not None:
                        block = block[:, cols]
                    block = block.astype(np.float64, copy=False)
                yield block * self.scale if self.scale != 1 else block


@dataclass(frozen=True, eq=False)
class StaticLog:
    """A static record for the Allan deviation, as read.

    Attributes
    ----------
    data : ndarray, shape (n, C), or NpyChunks
        The raw numbers times ``scale`` (no SI conversion: deviations are scaled afterwards).
    rate_hz : float
        Sample rate, Hz.
    time_units : str or None
        Unit of the time column (None: no time column, ``rate_hz`` given).
    time_detected : bool
        True when ``time_units`` was detected from the sample interval.
    time_step : float or None
        The median step of the time column in the file's numbers, when it was read beside a given ``rate_hz``.
    units : str or None
        The one unit the file states for the data columns (a ULog, a bag); None: it states none.
    source, notes
        The stream read and the reader's remarks (:class:`align.io.readers.Columns`).
    """

    data: object
    rate_hz: float
    time_units: str | None
    time_detected: bool
    time_step: float | None = None
    units: str | None = None
    source: Mapping[str, Any] = field(default_factory=dict)
    notes: tuple[str, ...] = ()


#: file endings of records read in chunks (numpy's own, raw binary) unless a registered reader claims the file
CHUNKED = (".npy", ".bin", ".f8", ".f4", ".raw")


def chunked(log: Path) -> bool:
    """Whether a static record is read in chunks (:class:`NpyChunks`): a ``.npy`` file, or raw binary that no
    registered reader owning its ending claims by its first bytes (a DataFlash ``.bin`` goes to its reader)."""
    suffix = log.suffix.lower()
    if suffix not in CHUNKED or suffix == ".npy":
        return suffix == ".npy"
    from align.io.readers import READERS

    try:
        with open(log, "rb") as fh:
            head = fh.read(1 << 12)
    except OSError:  # NpyChunks names the problem
        return True
    return not any(suffix in r.suffixes and r.sniff is not None and r.sniff(head) for r in READERS)


def read_static_log(log: str | Path, names: list[str], rate_hz: float | None, log_format: LogFormat | None = None,
                    scale: float = 1.0, *, time_column: str = "time", time_step: bool = False) -> StaticLog:
    """Raw columns of a static log and its sample rate, for the Allan deviation.

    No unit conversion (the deviations are scaled afterwards, so no SI copy of a
    large record is made) but for ``scale``, the size of one count in the unit the
    deviations are shown in (1 for readings in a unit). ``.npy`` and raw binary files
    come back as a :class:`NpyChunks` source read in chunks (:func:`chunked`); other logs (text, Parquet, a
    stream of a bag, ULog or DataFlash log, whose units and time unit the file states) need a uniform time
    column ``time_column`` (gaps are refused with their position; its unit stated, detected or given by
    ``log_format``) unless ``rate_hz`` is given. With ``rate_hz`` and ``time_step``, the time column is read
    too (not checked) and its median step, in the file's numbers, returned as ``time_step`` (a caller compares
    it with ``rate_hz``). A long stream log (:data:`align.io.streamchunks.CHUNKED_BYTES`) without ``rate_hz`` is
    read in blocks, in bounded memory (:func:`align.io.streamchunks.stream_source`): a chunk source too.
    """
    log = Path(log)
    fmt = log_format or LogFormat()
    if chunked(log):
        rate = _check_rate(rate_hz, log, f"a {log.suffix} file has no time: give {{rate_hz}}")
        if fmt.given() or fmt.streams_given():
            given = fmt.given() + fmt.streams_given()
            raise InputError(f"{', '.join('{' + k + '}' for k in given)} apply to text logs or logs of several "
                             f"streams, not to a {log.suffix} file; leave them out", str(log))
        _rate_only(fmt, log)
        source = NpyChunks(log, len(names), scale)
        if source.shape[1] != len(names):
            raise InputError(f"has {source.shape[1]} columns but {len(names)} names were given; name each column with "
                             "{columns}", str(log))
        if source.shape[0] == 0:
            raise InputError("holds no samples", str(log))
        return StaticLog(source, float(rate), None, False)  # its samples are checked as read (align.noise.allan)
    from align.io.streamchunks import stream_source  # it builds on NpyChunks

    if rate_hz is not None:
        _check_rate(rate_hz, log)
        _rate_only(fmt, log)
    elif (blocks := stream_source(log, names, fmt, scale, time_column)) is not None:  # a long ULog or bag
        return StaticLog(blocks, blocks.rate_hz, blocks.time_units, False, None, blocks.stated(), blocks.source,
                         blocks.notes)
    with_time = rate_hz is None or time_step
    got = read_table(log, ([time_column] if with_time else []) + names, time_column if with_time else None, fmt)
    stated = (got.unit(names), dict(got.source), tuple(got.notes))
    data = got.data
    if rate_hz is not None:
        head = data[:100_001, 0] if time_step else data[:0, 0]
        step = float(np.median(np.diff(head))) if len(head) > 1 else None
        values = np.ascontiguousarray(data[:, 1:] if time_step else data)
        check_readings(values, str(log))
        return StaticLog(values * scale if scale != 1 else values, float(rate_hz), None, False, step, *stated)
    check_readings(data[:, 1:], str(log), data[:, 0])
    said = got.units.get(time_column)
    stated_time = fmt.time_units is None and said in TIME_UNITS
    t, unit, detected = _time_of(data[:, 0], time_column, str(log), replace(fmt, time_units=said) if stated_time else fmt,
                                 stated=stated_time)
    check_log(t, data[:, 1:], str(log), min_rows=3)
    check_time(t, str(log), gap=1.5, jitter=True)  # an Allan deviation needs uniform samples
    values = np.ascontiguousarray(data[:, 1:])
    return StaticLog(values * scale if scale != 1 else values, 1.0 / float(np.median(np.diff(t))), unit, detected,
                     None, *stated)


def read_static(log: str | Path, names: list[str], rate_hz: float | None, log_format: LogFormat | None = None):
    """Raw columns of a static log and its sample rate (:func:`read_static_log`): ``(data, rate_hz)``."""
    got = read_static_log(log, names, rate_hz, log_format)
    return got.data, got.rate_hz
