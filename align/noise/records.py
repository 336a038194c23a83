"""Static records for the Allan deviation: read through the one static reader, and checked.

:func:`read_records` reads each record with :func:`align.io.read_static_log` (``.csv``, ``.csv.gz``,
``.parquet``, ``.npy`` and raw binary, the last two in chunks, and a stream of every registered format of
several: its unit and time as the file states them), by the one column convention
(:func:`allan_columns`), and refuses, naming the file and the option, what an Allan deviation cannot use
(:func:`check_static`): a moving sensor (a rate-table session), an accelerometer that reads gravity in
another unit than the one given (g read as m/s^2), raw counts read as a rate; and
a sample rate the time column contradicts, or a time unit that gives no IMU's rate.

Public names
------------
AllanInputs, read_records, allan_unit, allan_columns, check_static, MOTION_RATE, MOTION_ACCELERATION
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from align.errors import InputError, UnitError, literal
from align.io.formats import DETECT_BAND_HZ, TIME_UNITS, time_unit
from align.io.source import DEFAULT_TIME, LogSource, column_names
from align.units import DIMENSIONS, STANDARD_GRAVITY, parse_unit
from align.vocab import Sensor

if TYPE_CHECKING:
    from align.noise.jobs import AllanOptions

__all__ = ["AllanInputs", "read_records", "allan_unit", "allan_columns", "check_static", "MOTION_RATE",
           "MOTION_ACCELERATION"]

#: the widest range of 1-s means a gyro at rest shows, rad/s (bias drift over temperature stays well inside)
MOTION_RATE = 10 * math.pi / 180
#: the widest range of 1-s means an accelerometer at rest shows, m/s^2 (about 0.2 g: a turn of the sensor)
MOTION_ACCELERATION = 2.0
#: blocks sampled over a record for the static checks (evenly spaced; a chunked record is never read whole)
_CHECK_BLOCKS = 128
#: relative difference between a given sample rate and the time column's beyond which they conflict
_RATE_TOLERANCE = 0.01

@dataclass(frozen=True)
class AllanInputs:
    """The checked records of an ``allan`` job.

    Attributes
    ----------
    runs : tuple of ndarray, shape (n_k, C), or chunk sources
        Each record's readings in ``unit`` (the size of one count applied), not in SI.
    fs : float
        Common sample rate, Hz.
    names : tuple of str
        The data columns, C of them.
    unit : str
        The unit ``runs`` are in (a rate or an acceleration unit).
    files : tuple of str
        The records, as given.
    time_notes : tuple of str
        How each text record's time column was read, when not in seconds.
    streams : tuple of dict
        Per record, the stream read and the unit the file states (``stream``, ``units_stated``; empty for a
        record of one stream that states none).
    notes : tuple of str
        The readers' remarks (a truncated last record), each after its file.
    """

    runs: tuple
    fs: float
    names: tuple[str, ...]
    unit: str
    files: tuple[str, ...]
    time_notes: tuple[str, ...] = ()
    streams: tuple[dict, ...] = ()
    notes: tuple[str, ...] = ()

    @property
    def samples(self) -> int:
        """Samples over all runs (the units of ``progress``)."""
        return int(sum(r.shape[0] for r in self.runs))


def allan_unit(gyro_units: str | None = "deg/s", units: str | None = None) -> tuple[str, float]:
    """The unit the deviations are shown in, and the size of one count in it (1: the logs hold that unit).

    ``gyro_units`` is an angular rate (None: deg/s), ``units`` an angular rate or an acceleration; either may be the
    size of one count (``'0.0076336 deg/s'``, ``'131 LSB/(deg/s)'``, ``'16384 LSB/g'``): the deviations are
    then shown in deg/s or m/s^2. Raw ``counts`` are refused with the advice to give the count size.

    Returns
    -------
    shown : str
    scale : float
        Multiplies a number of the record into ``shown``.

    Examples
    --------
    >>> allan_unit("131 LSB/(deg/s)")[0]
    'deg/s'
    >>> allan_unit(units="g")
    ('g', 1.0)
    """
    from align.io import sensor_scale

    if units is None:
        factor, shown = sensor_scale(gyro_units or Sensor.GYROSCOPE.unit, "angular_rate", "gyro_units")
        return shown, factor / parse_unit(shown).factor
    for expect in ("angular_rate", "acceleration"):
        try:
            factor, shown = sensor_scale(units, expect, "units")
        except UnitError as exc:
            if "raw counts" in exc.message:
                raise
            continue
        return shown, factor / parse_unit(shown).factor
    raise InputError(f"'{literal(units)}' is neither an angular rate nor an acceleration (nor the size of one count "
                     "of either)", "{units}")


def allan_columns(columns: Sequence[str] | None, time_column: str | None, rate_hz: float | None,
                  header: Sequence[str] | None = None, sensor: Sensor = Sensor.GYROSCOPE) -> tuple[str | None, list[str]]:
    """The time column (None: none read) and the data columns of a static record, by the one convention.

    Three names (any count but four) are data columns; four keep meaning "time first"; with ``rate_hz``
    no time column is read (the first of four names is not analysed). None: the sensor's default names,
    or the first set of its old names (then the gyro's) that ``header`` holds.

    Raises
    ------
    InputError
        A name given twice, or the time column among the data columns (``{columns}``).

    Examples
    --------
    >>> allan_columns(("time", "gx", "gy", "gz"), None, None)
    ('time', ['gx', 'gy', 'gz'])
    >>> allan_columns(("time", "gx", "gy", "gz"), None, 100.0)
    (None, ['gx', 'gy', 'gz'])
    >>> allan_columns(("gx",), "stamp", None)
    ('stamp', ['gx'])
    """
    if columns is None:
        given = list(sensor.columns)
        if header is not None and not all(c in header for c in given):
            sets = [*sensor.old_columns, *([] if sensor is Sensor.GYROSCOPE else
                                           [Sensor.GYROSCOPE.columns, *Sensor.GYROSCOPE.old_columns])]
            given = list(next((s for s in sets if all(c in header for c in s)), given))
    else:
        given = [str(c).strip() for c in columns if str(c).strip()]
    k = 3 if len(given) in (3, 4) else len(given)
    if k == 0:
        raise InputError("give the data columns, e.g. gyro_x,gyro_y,gyro_z", "{columns}")
    return column_names(given, time_column, rate_hz, tuple(given[-k:]) if len(given) != 4 else tuple(given[1:]))


def _time_name(options: AllanOptions) -> str:
    """The time column a record may have: ``time_column``, the first of four names, or ``time``."""
    if options.time_column:
        return options.time_column
    if options.columns is not None and len(options.columns) == 4:
        return options.columns[0]
    return DEFAULT_TIME


def _mapped(source: Any) -> np.ndarray:
    """A chunk source's array mapped from its file (read lazily: only the rows indexed are read)."""
    path = Path(source.path)
    if path.suffix.lower() == ".npy":
        arr = np.load(path, mmap_mode="r")
        return arr.reshape(-1, 1) if arr.ndim == 1 else arr
    return np.memmap(path, dtype=source.dtype, mode="r", shape=tuple(source.shape))


def _sample_blocks(run: Any, fs: float) -> np.ndarray:
    """Evenly spaced blocks of about 1 s over a record, shape (B, L, C), in the record's unit."""
    n = int(run.shape[0])
    length = int(max(1, min(round(fs), n // 16)))
    count = max(1, min(_CHECK_BLOCKS, n // length))
    starts = np.linspace(0, n - length, count).astype(np.int64)
    if hasattr(run, "chunks"):
        arr, scale = _mapped(run), float(getattr(run, "scale", 1.0))
    else:
        arr, scale = np.asarray(run), 1.0
    blocks = np.stack([np.asarray(arr[s:s + length], dtype=float) for s in starts])
    if blocks.ndim == 2:
        blocks = blocks[:, :, None]
    return blocks * scale if scale != 1 else blocks


def _num(x: float) -> str:
    return f"{float(x):#.3g}".rstrip(".")


def check_static(run: Any, fs: float, names: Sequence[str], unit: str, typed: str, field: str, where: str) -> None:
    """Refuse a record that is no static record of the sensor in the unit given.

    Looks at up to 256 evenly spaced 1-s blocks (a chunked record is not read whole): the mean rate a
    gyro at rest reads (raw counts read as a rate, :func:`align.plausible.check_static_rates`); the range
    of the blocks' means, beyond :data:`MOTION_RATE` (:data:`MOTION_ACCELERATION`) and the noise, a moving
    sensor (a rate-table session); and, for three accelerometer channels, the mean ``|a|`` against gravity
    (g read as m/s^2 reads 1.0). Records with non-finite samples are left to the reader's own refusal.

    Parameters
    ----------
    run : ndarray, shape (n, C), or chunk source
        Readings in ``unit``.
    fs : float
        Sample rate, Hz.
    names : sequence of str
        The C channels.
    unit : str
        The unit of ``run`` (a rate or an acceleration).
    typed : str
        The unit as the user gave it (a count size, ...), for messages.
    field : str
        The option that gave it.
    where : str
        The record, for messages.

    Raises
    ------
    InputError
        A moving sensor, or an accelerometer whose mean ``|a|`` is gravity in another unit
        (:class:`~align.errors.UnitError`, naming the unit to give).
    TestError
        A gyro mean rate no gyro at rest reads.
    """
    from align.plausible import ACCELERATION_UNITS, AT_REST_RANGE, check_static_rates, mixup_hint

    blocks = _sample_blocks(run, fs)
    if not np.all(np.isfinite(blocks)):
        return
    u = parse_unit(unit)
    gyro = u.dim == DIMENSIONS["angular_rate"][0].dim
    si = blocks * u.factor
    means = si.reshape(-1, si.shape[2]).mean(axis=0)
    if gyro:
        check_static_rates(means, typed, list(names), field, where)
    block_means = si.mean(axis=1)
    spread = block_means.max(axis=0) - block_means.min(axis=0)
    noise = (np.std(np.diff(si, axis=1), axis=(0, 1)) / math.sqrt(2 * si.shape[1]) if si.shape[1] > 1
             else np.zeros(si.shape[2]))
    limit = MOTION_RATE if gyro else MOTION_ACCELERATION
    moving = np.flatnonzero((spread > limit) & (spread > 16 * noise))
    if len(moving):
        j = int(moving[0])
        shown = "deg/s" if gyro else "m/s^2"
        f = parse_unit(shown).factor
        raise InputError(
            f"not a static record: channel {literal(names[j])} moves, its 1-s means range from "
            f"{_num(block_means[:, j].min() / f)} to {_num(block_means[:, j].max() / f)} {shown} (a sensor at rest "
            f"stays within {_num(limit / f)} {shown}); an Allan deviation needs the sensor at rest (a rate-table "
            "session is no noise record): record it static, or check {columns}", where)
    if not gyro and len(names) == 3:
        norm = float(np.linalg.norm(means))
        lo, hi = AT_REST_RANGE
        try:
            hint = mixup_hint(norm, typed, "acceleration", ACCELERATION_UNITS,
                              (lo * STANDARD_GRAVITY, hi * STANDARD_GRAVITY), field)
        except InputError:
            hint = None
        if hint is not None:
            raise UnitError(f"mean |a| at rest is {_num(norm)} m/s^2 read as {literal(typed)}, gravity is "
                            f"{_num(STANDARD_GRAVITY)} m/s^2: {hint}", where)


def _check_time(got: Any, options: AllanOptions, time_name: str, where: str) -> None:
    """A given sample rate against the record's time column, and a given time unit against its rate."""
    step = got.time_step
    rate_hz = options.rate_hz
    if step is not None and rate_hz is not None and math.isfinite(step) and step > 0:
        rates = {u: 1.0 / (step * TIME_UNITS[u]) for u in TIME_UNITS}
        if not any(abs(r / rate_hz - 1) <= _RATE_TOLERANCE for r in rates.values()):
            try:
                unit, _ = time_unit(step, time_name, where)
            except InputError:
                unit = None
            if unit is not None:
                said = rates[unit]
                raise InputError(
                    f"{{rate_hz}} says {rate_hz:g} Hz, but the time column '{literal(time_name)}' steps at "
                    f"{said:.6g} Hz (median step {step:.6g} {unit}): every tau would be off by a factor "
                    f"{said / rate_hz:.4g}; leave {{rate_hz}} out to use the time column, or give "
                    f"{{rate_hz={said:.6g}}}", where)
    given = options.format.time_units
    if given is not None and got.time_units == given and not got.time_detected and got.rate_hz > DETECT_BAND_HZ[1]:
        raw = 1.0 / (got.rate_hz * TIME_UNITS[given])
        lo, hi = DETECT_BAND_HZ
        other = [u for u in TIME_UNITS if u != given and lo <= 1.0 / (raw * TIME_UNITS[u]) <= hi]
        if other:
            u = other[0]
            raise InputError(
                f"{{time_units={given}}} makes the time column '{literal(time_name)}' a {got.rate_hz / 1e3:.4g} kHz "
                f"record (median step {raw:.4g} {given}), no IMU's static record; in {u} it is "
                f"{1.0 / (raw * TIME_UNITS[u]):.4g} Hz: give {{time_units={u}}} or leave {{time_units}} out (a record "
                f"really at {got.rate_hz / 1e3:.4g} kHz: give {{rate_hz}} without {{time_units}})", where)


def _stated_unit(stated: str, options: AllanOptions, where: str) -> str:
    """The unit a record states (a ULog's, a bag's), as the deviations are shown in; a unit typed that disagrees
    is refused naming its option (:func:`align.io.readings.units_of`)."""
    from align.io.readings import units_of

    rate = parse_unit(stated).dim == DIMENSIONS["angular_rate"][0].dim
    units_of(options.units if options.units is not None else options.gyro_units, stated, None,
             "angular_rate" if rate else "acceleration", options.unit_field, where)
    return allan_unit(units=stated)[0]


def read_records(options: AllanOptions) -> AllanInputs:
    """Read and check the static records of an ``allan`` job.

    Parameters
    ----------
    options : AllanOptions

    Returns
    -------
    AllanInputs
        The runs in the unit shown (not SI: the deviations are scaled afterwards), their common rate.

    Raises
    ------
    InputError
        ``rate`` without ``accuracy`` (or the reverse); a unit that is not a rate or an acceleration; a
        duplicate or missing column; a record that is not static, an accelerometer not reading gravity in
        the unit given, a sample rate the time column contradicts, a time unit that makes no IMU rate; runs
        at different rates. Each names the file and the option.
    TestError
        A gyro mean rate no gyro at rest reads (raw counts read as a rate).
    """
    from align.io import read_static_log
    from align.io.logs import chunked

    if (options.rate is None) != (options.accuracy is None):
        raise InputError("give both {rate} and {accuracy} to plan", "{rate}" if options.rate is None else "{accuracy}")
    if not options.logs:
        raise InputError("no recording given", "{logs}")
    unit, scale = allan_unit(options.gyro_units, options.units)
    sensor = Sensor.GYROSCOPE if parse_unit(unit).dim == DIMENSIONS["angular_rate"][0].dim else Sensor.ACCELEROMETER
    fmt = options.format
    time_name = _time_name(options)
    runs, files, notes, streams, remarks = [], [], [], [], []
    fs: float | None = None
    names: list[str] | None = None
    shown: str | None = None
    for path in options.logs:
        where = str(path)
        header = None if chunked(path) else LogSource(path=path, format=fmt).header()  # a DataFlash .bin has one
        _, cols = allan_columns(options.columns, options.time_column, options.rate_hz, header, sensor)
        if names is not None and cols != names:
            raise InputError(f"holds columns {', '.join(cols)}, the first run {', '.join(names)}", where)
        names = cols
        time_step = options.rate_hz is not None and header is not None and time_name in header
        got = read_static_log(path, cols, options.rate_hz, fmt, scale, time_column=time_name, time_step=time_step)
        _check_time(got, options, time_name, where)
        if fs is not None and abs(got.rate_hz - fs) > 1e-9 * fs:
            raise InputError(f"sample rate {got.rate_hz:g} Hz differs from the first run's {fs:g} Hz", where)
        fs = got.rate_hz
        mine = unit if got.units is None else _stated_unit(got.units, options, where)
        if shown is not None and mine != shown:
            raise InputError(f"holds readings in {literal(mine)}, the first run in {literal(shown)}; give runs of one "
                             "unit", where)
        shown = mine
        check_static(got.data, fs, cols, mine, options.typed_units or mine, options.unit_field, where)
        streams.append({**({"stream": dict(got.source)} if got.source else {}),
                        **({"units_stated": got.units} if got.units is not None else {})})
        remarks += [f"{where}: {n}" for n in got.notes]
        if got.time_units not in (None, "s"):
            how = "detected from the median step" if got.time_detected else "as given"
            notes.append(f"{where}: time column read in {got.time_units} ({how}: {fs:.6g} Hz)")
        runs.append(got.data)
        files.append(where)
    assert fs is not None and shown is not None  # at least one record was read
    return AllanInputs(tuple(runs), float(fs), tuple(names or ()), shown, tuple(files), tuple(notes),
                       tuple(streams) if any(streams) else (), tuple(remarks))
