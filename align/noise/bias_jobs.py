"""The bias jobs of the test series (issue 26): ``warmup`` (one static record from turn-on -> warm-up time per
channel, with its criterion) and ``repeatability`` (several turn-ons of one unit -> bias repeatability with its
chi-square interval, and the in-run stability of each).

Each is an :class:`align.job.Job` modelled on the ``allan`` job (:mod:`align.noise.jobs`): the records are read and
checked by :func:`align.noise.records.read_records` (the same columns, units, rates and formats, a static record
refused when it moves), converted to SI, and analysed by :mod:`align.noise.warmup` and
:mod:`align.noise.repeatability`. Results (defined beside their analyses): :class:`WarmupResult`
(``imu-align.warmup``) and :class:`RepeatabilityResult` (``imu-align.repeatability``), with figures of merit
``warmup_x..`` (s) and ``bias_repeatability_x..`` (rad/s or m/s^2).

Public names
------------
WarmupOptions, WarmupResult, WARMUP, warmup, RepeatabilityOptions, RepeatabilityResult, REPEATABILITY,
repeatability_job
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np

from align.errors import InputError
from align.io.formats import LogFormat
from align.io.source import LogSource
from align.job import Job, Progress, fields_signature, quantity
from align.noise.records import AllanInputs, read_records
from align.noise.repeatability import RepeatabilityResult, RunBias, record_bias, repeatability
from align.noise.warmup import WarmupResult, warmup_time
from align.units import DIMENSIONS, parse_quantity, parse_unit

__all__ = ["WarmupOptions", "WarmupResult", "WARMUP", "warmup", "RepeatabilityOptions", "RepeatabilityResult",
           "REPEATABILITY", "repeatability_job"]



@dataclass(frozen=True, kw_only=True)
class _Reading:
    """The reading options both jobs share with ``allan`` (:class:`align.noise.jobs.AllanOptions`)."""

    columns: tuple[str, ...] | None = None
    time_column: str | None = None
    rate_hz: float | None = quantity(None, "frequency", gt=0)
    gyro_units: str | None = None
    units: str | None = None
    format: LogFormat = field(default_factory=LogFormat)
    window: float = quantity(10.0, "time", gt=0)
    final: float | None = quantity(None, "time", gt=0)
    band: str | None = None
    limits: Path | None = None

    def __post_init__(self) -> None:
        if isinstance(self.columns, str):
            object.__setattr__(self, "columns", tuple(c.strip() for c in self.columns.split(",") if c.strip()))
        elif self.columns is not None:
            object.__setattr__(self, "columns", tuple(self.columns))


@dataclass(frozen=True, kw_only=True)
class WarmupOptions(_Reading):
    """Options of the ``warmup`` job (SI inside).

    Attributes
    ----------
    log : Path
        One static record from turn-on (any format ``allan`` reads).
    columns, time_column, rate_hz, gyro_units, units, format
        As :class:`align.noise.jobs.AllanOptions`.
    window : float
        Moving-mean window, s.
    final : float or None
        Final segment whose mean is the settled value, s (None: the last quarter of the record).
    band : str or None
        Half-width of the band, a rate or an acceleration (``"0.01 deg/s"``, ``"1 mg"``; a number is SI); None: five
        times the moving mean's noise (:mod:`align.noise.warmup`).
    limits : Path or None
        A limits file to judge the figures against.
    """

    log: Path

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "log", Path(self.log))


@dataclass(frozen=True, kw_only=True)
class RepeatabilityOptions(_Reading):
    """Options of the ``repeatability`` job (SI inside).

    Attributes
    ----------
    logs : tuple of Path
        Static records of one unit, one per turn-on (at least two).
    skip : float or None
        Warm-up left out of every record, s; None: each record's own warm-up time (``window``, ``final``, ``band``
        as :class:`WarmupOptions`, the longest of its channels).
    period : float
        Averaging period of the in-run bias stability, s.
    level : float
        Confidence level of the repeatability's chi-square interval.
    """

    logs: tuple[Path, ...]
    skip: float | None = quantity(None, "time", ge=0)
    period: float = quantity(10.0, "time", gt=0)
    level: float = quantity(0.95, "dimensionless", gt=0, lt=1)

    def __post_init__(self) -> None:
        super().__post_init__()
        logs = (self.logs,) if isinstance(self.logs, (str, Path)) else self.logs
        object.__setattr__(self, "logs", tuple(Path(p) for p in logs))


def _allan_options(logs: tuple[Path, ...], o: _Reading) -> Any:
    from align.noise.jobs import AllanOptions

    return AllanOptions(logs=logs, columns=o.columns, time_column=o.time_column, rate_hz=o.rate_hz,
                        gyro_units=o.gyro_units, units=o.units, format=o.format)


def _si(run: Any, unit: str, where: str) -> np.ndarray:
    """A record's readings (array or chunk source, in ``unit``) as an SI array (n, C); non-finite refused."""
    data = np.concatenate(list(run.chunks())) if hasattr(run, "chunks") else np.asarray(run, float)
    data = np.asarray(data, float).reshape(len(data), -1) * parse_unit(unit).factor
    bad = np.flatnonzero(~np.all(np.isfinite(data), axis=1))
    if len(bad):
        raise InputError(f"sample {int(bad[0])} is not a finite number ({len(bad)} such); a static record needs "
                         "every sample", where)
    return data


def _sensor(unit: str) -> str:
    return "gyroscope" if parse_unit(unit).dim == DIMENSIONS["angular_rate"][0].dim else "accelerometer"


def _band(band: Any, sensor: str) -> float | None:
    """The band in SI: a quantity string of the sensor's dimension, or a positive number (SI)."""
    if band is None:
        return None
    if isinstance(band, str):
        value = parse_quantity(band, "angular_rate" if sensor == "gyroscope" else "acceleration", "{band}")
    elif isinstance(band, (int, float)) and not isinstance(band, bool):
        value = float(band)
    else:
        raise InputError(f"{band!r} is not a band; give a rate or an acceleration such as '0.01 deg/s'", "{band}")
    if not (math.isfinite(value) and value > 0):
        raise InputError(f"a band of {band!r} is not a positive finite size; give one such as '0.01 deg/s'", "{band}")
    return value


def criterion(o: _Reading) -> str:
    """The warm-up criterion as words (:mod:`align.noise.warmup`)."""
    final = "the last quarter of the record" if o.final is None else f"the last {o.final:g} s"
    band = "five times the 1-sigma noise of the moving mean" if o.band is None else f"+/- {o.band}"
    return (f"warm-up: the time from the first sample after which the centred {o.window:g} s moving mean stays within "
            f"{band} of the settled value (the mean of {final}); not settled when that time falls in the final segment "
            "or the final segment still drifts by more than half the band (and 3 sigma)")


# ---------------------------------------------------------------------------------------------- warmup

def read_warmup(options: WarmupOptions) -> AllanInputs:
    """The record, read and checked as ``allan`` reads one (:func:`align.noise.records.read_records`)."""
    return read_records(_allan_options((options.log,), options))


def compute_warmup(inputs: AllanInputs, options: WarmupOptions, progress: Progress | None = None) -> WarmupResult:
    """The warm-up time of every channel (:func:`align.noise.warmup.warmup_time`)."""
    data = _si(inputs.runs[0], inputs.unit, inputs.files[0])
    sensor = _sensor(inputs.unit)
    band = _band(options.band, sensor)
    chans = tuple(warmup_time(data[:, j], inputs.fs, window=options.window, final=options.final, band=band)
                  for j in range(data.shape[1]))
    if progress is not None:
        progress(len(data))
    final = options.final if options.final is not None else len(data) / inputs.fs / 4
    return WarmupResult(sensor, inputs.names, inputs.fs, len(data), options.window, final, criterion(options), chans,
                        inputs.files, inputs.streams, inputs.notes)


WARMUP: Job[WarmupOptions, AllanInputs, WarmupResult] = Job(
    "warmup", WarmupOptions, read_warmup, compute_warmup, lambda o: {"log": o.log},
    "Warm-up time of a static record from turn-on: the bias settled within a stated band")


def _known(options: type, given: dict[str, Any], name: str) -> None:
    unknown = sorted(set(given) - {f.name for f in fields(options)})
    if unknown:
        raise TypeError(f"{name}() got unknown options: {', '.join(unknown)}")


@fields_signature(WarmupOptions)
def warmup(*, log: str | Path | LogSource, progress: Progress | None = None, **fields_: Any) -> WarmupResult:
    """Warm-up time of a static record from turn-on: ``imu-align warmup``.

    Parameters
    ----------
    log : path or LogSource
        The record (a LogSource gives its columns, time column, rate, unit and format).
    progress : callable, optional
    **fields_
        Any field of :class:`WarmupOptions` (``window=10.0`` s, ``band="0.01 deg/s"``, ``rate_hz=100.0``, ...).

    Returns
    -------
    WarmupResult

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> from align.noise.warmup import simulate_warmup
    >>> path = Path(tempfile.mkdtemp()) / "rec.npy"
    >>> np.save(path, simulate_warmup(600.0, 10.0, [1e-3], [4e-3], 30.0, 1e-4, seed=1)[1])
    >>> res = warmup(log=path, columns="gyro_x", rate_hz=10.0, gyro_units="rad/s", window=5.0, band=1e-4)
    >>> bool(abs(res.channels[0].time - 30 * np.log(40)) < 0.1 * 30 * np.log(40)), res.figures_of_merit()[0].name
    (True, 'warmup_x')
    """
    from align.noise.jobs import sources_fields

    paths, given = sources_fields(log, fields_)
    _known(WarmupOptions, given, "warmup")
    return WARMUP.run(WarmupOptions(log=paths[0], **given), progress=progress)


# ---------------------------------------------------------------------------------------------- repeatability


def read_repeatability(options: RepeatabilityOptions) -> AllanInputs:
    """The records, read and checked as ``allan`` reads several runs; fewer than two refused."""
    if len(options.logs) < 2:
        raise InputError(f"{len(options.logs)} record given; the turn-on to turn-on repeatability needs at least two "
                         "records of the unit, one per turn-on", "{logs}")
    return read_records(_allan_options(options.logs, options))


def _skip_of(data: np.ndarray, fs: float, options: RepeatabilityOptions, sensor: str, where: str) -> float:
    """Seconds to leave out: ``options.skip``, else the record's own warm-up (the longest channel's)."""
    if options.skip is not None:
        return options.skip
    band = _band(options.band, sensor)
    times = []
    for j in range(data.shape[1]):
        w = warmup_time(data[:, j], fs, window=options.window, final=options.final, band=band)
        if not w.settled:
            raise InputError(f"channel {j + 1} has not warmed up ({w.note}); give {{skip}} to set the warm-up left "
                             "out of every record", where)
        times.append(w.time)
    return float(max(times))


def compute_repeatability(inputs: AllanInputs, options: RepeatabilityOptions,
                          progress: Progress | None = None) -> RepeatabilityResult:
    """Each record's bias after warm-up, and their spread (:mod:`align.noise.repeatability`)."""
    sensor = _sensor(inputs.unit)
    runs: list[RunBias] = []
    rows = []
    for run, where in zip(inputs.runs, inputs.files):
        data = _si(run, inputs.unit, where)
        got = record_bias(data, inputs.fs, _skip_of(data, inputs.fs, options, sensor, where), options.period, where)
        runs.append(got)
        rows.append({"input": where, "skip_s": got.skip, "samples": got.samples,
                     **{k: [None if not math.isfinite(v) else float(v) for v in getattr(got, k)]
                        for k in ("bias", "sigma", "stability")}})
        if progress is not None:
            progress(len(data))
    rep = repeatability(runs, options.level)
    rule = (f"the first {options.skip:g} s left out" if options.skip is not None else
            "each record's own warm-up left out, the longest channel's; " + criterion(options))
    return RepeatabilityResult(sensor, inputs.names, inputs.fs, tuple(rows), rep.value, rep.sigma, rep.low, rep.high,
                               rep.level, rep.within, rep.mean, options.period, rule, inputs.files, inputs.streams,
                               inputs.notes)


def _repeatability_files(options: RepeatabilityOptions) -> dict[str, Path | None]:
    return {f"log {k}": p for k, p in enumerate(options.logs, 1)}


REPEATABILITY: Job[RepeatabilityOptions, AllanInputs, RepeatabilityResult] = Job(
    "repeatability", RepeatabilityOptions, read_repeatability, compute_repeatability, _repeatability_files,
    "Bias repeatability (turn-on to turn-on) with its confidence interval, and in-run bias stability")


@fields_signature(RepeatabilityOptions)
def repeatability_job(*, logs: Sequence[str | Path | LogSource], progress: Progress | None = None,
                      **fields_: Any) -> RepeatabilityResult:
    """Bias repeatability of several turn-ons of one unit: ``imu-align repeatability``.

    Parameters
    ----------
    logs : sequence of paths or LogSources
        One static record per turn-on (at least two).
    progress : callable, optional
    **fields_
        Any field of :class:`RepeatabilityOptions` (``skip=60.0`` s, ``level=0.95``, ``period=10.0`` s, ...).

    Returns
    -------
    RepeatabilityResult
    """
    from align.noise.jobs import sources_fields

    paths, given = sources_fields(logs, fields_)
    _known(RepeatabilityOptions, given, "repeatability_job")
    return REPEATABILITY.run(RepeatabilityOptions(logs=paths, **given), progress=progress)

