"""The ``calibrate accel`` job: an accelerometer from static positions (known orientations, or ``|a| = g``).

The package :mod:`align.calibration.jobs` re-exports its names.

Public names
------------
AccelOptions, AccelInputs, ACCEL, calibrate_accel
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from align.calibration.accel import StaticDetector
from align.calibration.jobs.common import (
    detector_dict,
    log_source,
    read_sensor,
    shown_columns,
    static_detector,
    with_remarks,
)
from align.calibration.results import CalibrationSet
from align.io.logs import SensorLog
from align.io.source import LogSource
from align.job import Job, Progress, fields_signature, quantity
from align.vocab import Sensor

__all__ = ["AccelOptions", "AccelInputs", "ACCEL", "calibrate_accel"]


@dataclass(frozen=True, kw_only=True)
class AccelOptions:
    """Options of ``calibrate accel``: static positions separated by moves.

    Attributes
    ----------
    log : LogSource
        The accelerometer log (default columns ``acc_x, acc_y, acc_z`` or the old names, time ``time``;
        unit m/s^2, ``"counts"`` or the size of one count ``"16384 LSB/g"``; None: the unit the file states,
        else m/s^2).
    positions : Path or None
        The positions file (TOML, ``[[position]]`` tables); None: orientations unknown, ``|a| = g`` fitted.
    gravity : float or None
        Local gravity, m/s^2; None: the positions file's, else 9.80665.
    window_s : float
        Variance window of the static detector, s.
    factor : float
        Static threshold: this many times the quiet variance (> 0).
    init_static_s : float or None
        Initial static period for the threshold (imu_tk), s; None: none.
    min_static_s : float
        Shortest static interval, s.
    limits : Path or None
        A limits file (:mod:`align.limits`) to judge the figures of merit against; None: the default limits.
    """

    log: LogSource
    positions: Path | None = None
    gravity: float | None = quantity(None, "acceleration", gt=0)
    window_s: float = quantity(1.0, "time", gt=0)
    factor: float = quantity(6.0, "dimensionless", gt=0)
    init_static_s: float | None = quantity(None, "time", gt=0)
    min_static_s: float = quantity(1.0, "time", gt=0)
    limits: Path | None = None

    @property
    def detector(self) -> StaticDetector:
        """The static detector these options set (window, factors, initial and shortest static period)."""
        return static_detector(self)

    def __post_init__(self) -> None:
        if self.positions is not None:
            object.__setattr__(self, "positions", Path(self.positions))


@dataclass(frozen=True)
class AccelInputs:
    """The checked inputs of an accelerometer session.

    Attributes
    ----------
    acc : SensorLog
        ``t`` (n,) s and the readings (n, 3), m/s^2 or counts.
    spec : dict or None
        The positions file as read.
    columns : str
        The columns read, ``time,x,y,z`` (``x,y,z`` at a given rate).
    """

    acc: SensorLog
    spec: dict | None
    columns: str


def _accel_read(o: AccelOptions) -> AccelInputs:
    import align.io as fileio

    time, data = o.log.names(Sensor.ACCELEROMETER)
    got = read_sensor(o.log, Sensor.ACCELEROMETER, field="accel_units", columns_field="columns", counts=True)
    if o.log.columns is None:  # the names read: the defaults or the old ones the file has
        data = o.log._defaults_present(Sensor.ACCELEROMETER, list(data), time)
    spec = fileio.read_toml(o.positions) if o.positions is not None else None
    return AccelInputs(got, spec, shown_columns(time, data))


def _accel_compute(i: AccelInputs, o: AccelOptions, progress: Progress | None) -> CalibrationSet:
    from align.calibration.accel import calibrate_accel_log

    got = i.acc
    cal = with_remarks(calibrate_accel_log(got.t, got.data, i.spec, got.shown, o.gravity, static_detector(o),
                                           str(o.log.path), str(o.positions)), (got, o.log))
    if progress is not None:
        progress(len(got.t))
    # how the log was read and the detector set: what the report needs to draw the session again
    return CalibrationSet({Sensor.ACCELEROMETER.value: cal}, {
        "log": str(o.log.path), "positions": None if o.positions is None else str(o.positions),
        "accel_units": got.units, "columns": i.columns, "rate_hz": o.log.rate_hz,
        "detector": detector_dict(o), **got.inputs()})


def _accel_files(o: AccelOptions) -> dict[str, Path | None]:
    return {"log": o.log.path, "positions": o.positions}


ACCEL: Job[AccelOptions, AccelInputs, CalibrationSet] = Job(
    "calibrate accel", AccelOptions, _accel_read, _accel_compute, _accel_files,
    "accelerometer multi-position calibration (known orientations, or |a| = g over many attitudes)")


@fields_signature(AccelOptions)
def calibrate_accel(*, log: LogSource | str | Path, progress: Progress | None = None, **fields: Any) -> CalibrationSet:
    r"""Calibrate an accelerometer from static positions (``imu-align calibrate accel``).

    Parameters
    ----------
    log : LogSource or str or Path
        The accelerometer log; a path takes ``columns``, ``time_column``, ``rate_hz`` (Hz), ``units`` and
        ``format`` beside it.
    progress : callable, optional
        Called with the samples done.
    **fields
        The other fields of :class:`AccelOptions` (``positions``, ``gravity`` m/s^2, ``window_s`` s, ...).

    Returns
    -------
    CalibrationSet
        The ``accelerometer`` calibration: ``M`` (3, 3), ``b`` (3,) m/s^2 (or counts), with provenance.

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> from pathlib import Path
    >>> rng = np.random.default_rng(0)
    >>> rows = [np.r_[s * 9.80665 * np.eye(3)[k]] + rng.normal(0, 1e-3, (300, 3))
    ...         for k in range(3) for s in (1, -1)]
    >>> moves = [rng.normal(0, 3, (100, 3)) for _ in rows]
    >>> a = np.vstack([x for pair in zip(rows, moves) for x in pair])
    >>> d = Path(tempfile.mkdtemp())
    >>> np.savetxt(d / "acc.csv", np.column_stack([np.arange(len(a)) / 100, a]), delimiter=",",
    ...            header="time,acc_x,acc_y,acc_z", comments="")
    >>> ups = ["+x", "-x", "+y", "-y", "+z", "-z"]
    >>> _ = (d / "positions.toml").write_text("".join(f'[[position]]\nup = "{u}"\n' for u in ups))
    >>> cal = calibrate_accel(log=d / "acc.csv", positions=d / "positions.toml")
    >>> bool(np.allclose(cal.sensor("accelerometer").M, np.eye(3), atol=0.01))
    True
    """
    src = log_source(log, fields)
    return ACCEL.run(AccelOptions(log=src, **fields), progress=progress)
