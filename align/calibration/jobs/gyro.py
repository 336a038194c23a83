"""The ``calibrate gyro`` job: gyro and accelerometer from rotations between static poses (imu_tk's method, no
rate table), optionally turned into a rate-table result's or a mounting's system frame.

The package :mod:`align.calibration.jobs` re-exports its names.

Public names
------------
GyroOptions, GyroInputs, GYRO, calibrate_gyro
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from align.calibration.accel import StaticDetector
from align.calibration.jobs.common import (
    accel_source,
    accel_stream,
    log_source,
    read_sensor,
    same_file,
    shown_columns,
    static_detector,
    with_remarks,
)
from align.calibration.results import CalibrationSet
from align.errors import InputError
from align.io.logs import SensorLog
from align.io.source import LogSource
from align.job import Job, Progress, fields_signature, quantity
from align.units import STANDARD_GRAVITY
from align.vocab import Sensor

__all__ = ["GyroOptions", "GyroInputs", "GYRO", "calibrate_gyro"]


@dataclass(frozen=True, kw_only=True)
class GyroOptions:
    """Options of ``calibrate gyro``: static poses reached by free rotations (imu_tk's method, no rate table).

    Attributes
    ----------
    log : LogSource
        The session log: its time column (or ``rate_hz``, Hz), format, and the gyro's ``columns``
        (default ``gyro_x, gyro_y, gyro_z`` or the old ``gyr_x, ...``) and ``units`` (deg/s, ``"counts"``,
        or the size of one count ``"131 LSB/(deg/s)"``; None: the unit the file states, else deg/s).
    accel : LogSource or None
        The accelerometer: columns and unit in ``log``'s file, or a second file with the same time
        stamps; None: ``acc_x, acc_y, acc_z`` (or the old names) in ``log``, in the unit the file states, else
        m/s^2.
    gravity : float
        Local gravity, m/s^2.
    window_s : float
        Variance window of the static detector, s.
    factor : float
        Static threshold: this many times the variance of the initial static period.
    gyro_factor : float
        The gyro's static threshold, times its variance over the initial static period.
    init_static_s : float or None
        Length of the initial static period, s; None: detected.
    min_static_s : float
        Shortest static pose, s.
    intervals : str or tuple of (int, int) or None
        The static poses as sample ranges (end exclusive), the first the initial static period; None: detected.
    gyro_range : float or None
        The gyro's full scale, rad/s (counts when read in counts); None: flat tops at the extremes.
    drop_rotations : tuple of int
        Rotations (numbers from 1) left out of the fit.
    g_sensitivity : bool
        Model the gyro's g-sensitivity ``K_ga``.
    frame : Path or None
        A rate-table result of the same gyro (alignment or calibration JSON) giving the system frame.
    mounting : tuple of 3 tuples of 3 float, or None
        Nominal mounting (rows: the system axis of the accelerometer's x, y, z) giving the system frame.
    mounting_text : str or None
        How the mounting was written (``"+y,-x,+z"``), for the result and messages; default: the rows.
    limits : Path or None
        A limits file (:mod:`align.limits`) to judge the figures of merit against; None: the default limits.
    """

    log: LogSource
    accel: LogSource | None = None
    gravity: float = quantity(STANDARD_GRAVITY, "acceleration", gt=0)
    window_s: float = quantity(1.0, "time", gt=0)
    factor: float = quantity(6.0, "dimensionless", gt=0)
    gyro_factor: float = quantity(1000.0, "dimensionless", gt=0)
    init_static_s: float | None = quantity(None, "time", gt=0)
    min_static_s: float = quantity(1.0, "time", gt=0)
    intervals: str | tuple[tuple[int, int], ...] | None = None
    gyro_range: float | None = quantity(None, "angular_rate", gt=0)
    drop_rotations: tuple[int, ...] = ()
    g_sensitivity: bool = False
    frame: Path | None = None
    mounting: tuple[tuple[float, float, float], ...] | None = None
    mounting_text: str | None = None
    limits: Path | None = None

    @property
    def detector(self) -> StaticDetector:
        """The static detector these options set (window, factors, initial and shortest static period)."""
        return static_detector(self)

    def __post_init__(self) -> None:
        if self.frame is not None:
            object.__setattr__(self, "frame", Path(self.frame))
        object.__setattr__(self, "drop_rotations", tuple(sorted({int(k) for k in self.drop_rotations})))
        if self.mounting is not None:
            object.__setattr__(self, "mounting", tuple(tuple(float(x) for x in r) for r in self.mounting))
        if self.intervals is not None and not isinstance(self.intervals, str):
            object.__setattr__(self, "intervals", tuple((int(a), int(b)) for a, b in self.intervals))


@dataclass(frozen=True)
class GyroInputs:
    """The checked inputs of a multi-position session.

    Attributes
    ----------
    acc, gyr : SensorLog
        The accelerometer (m/s^2 or counts) and gyro (rad/s or counts) readings, (n, 3) at the gyro's times.
    table : tuple of (ndarray (3, 3), ndarray (3, 3) or None) or None
        The rate-table result's gyro ``M`` and its 1-sigma (``frame``).
    gyro_columns, accel_columns : str
        The columns read, as the result's ``inputs`` records them.
    session : dict
        Filled by the computation: ``"session"``, the :class:`~align.calibration.gyro.GyroSession` before
        the turn into the system frame (what a picture of the session shows).
    """

    acc: SensorLog
    gyr: SensorLog
    table: tuple[np.ndarray, np.ndarray | None] | None
    gyro_columns: str
    accel_columns: str
    session: dict = field(default_factory=dict, compare=False, repr=False)


def _table_m(frame: Path) -> tuple[np.ndarray, np.ndarray | None]:
    """``M`` and its 1-sigma of the rate-table result in ``frame`` (an alignment, or a calibration file's gyroscope)."""
    from align.alignment.result import AlignmentResult
    from align.results import load_result

    got: Any = load_result(frame, (AlignmentResult, CalibrationSet)).correction(Sensor.GYROSCOPE.value, str(frame))
    return got.M, got.sigma_M


def _gyro_read(o: GyroOptions) -> GyroInputs:
    if o.frame is not None and o.mounting is not None:
        raise InputError("give the system frame once: a rate-table result or a mounting", "{frame}")
    gtime, gcols = o.log.names(Sensor.GYROSCOPE, field="gyro_columns")
    gyr = read_sensor(o.log, Sensor.GYROSCOPE, field="gyro_units", columns_field="gyro_columns", counts=True,
                expect=Sensor.GYROSCOPE.dimension)
    if o.log.columns is None:
        gcols = o.log._defaults_present(Sensor.GYROSCOPE, list(gcols), gtime)
    acc_src = accel_source(o.log, o.accel)
    same = same_file(o.log, acc_src)
    if same and acc_src.time_column is None and acc_src.rate_hz is None:  # read at the gyro's time column
        acc_src = replace(acc_src, time_column=gtime, rate_hz=o.log.rate_hz if gtime is None else None)
    atime, acols = acc_src.names(Sensor.ACCELEROMETER, field="accel_columns")
    acc = read_sensor(acc_src, Sensor.ACCELEROMETER, field="accel_units", columns_field="accel_columns", counts=True)
    if acc_src.columns is None:
        acols = acc_src._defaults_present(Sensor.ACCELEROMETER, list(acols), atime)
    if not same:
        step = float(np.median(np.diff(gyr.t)))
        if len(acc.t) != len(gyr.t) or np.abs(acc.t - gyr.t).max() > 0.5 * step:
            bad = min(len(acc.t), len(gyr.t))
            row = int(np.argmax(np.abs(acc.t[:bad] - gyr.t[:bad]) > 0.5 * step)) if bad else 0
            raise InputError(f"its {len(acc.t)} time stamps are not the gyro log's {len(gyr.t)} (first difference at "
                             f"row {row}); both sensors must be sampled together", str(acc_src.path))
    elif len(acc.data) != len(gyr.data):
        raise InputError(f"has {len(acc.data)} accelerometer rows, {len(gyr.data)} gyro rows; both sensors must be "
                         "sampled together", str(o.log.path))
    if o.gyro_range is not None and not o.gyro_range > 0:
        raise InputError("give the full scale > 0, e.g. '250 deg/s'", "{gyro_range}")
    table = _table_m(o.frame) if o.frame is not None else None
    return GyroInputs(acc, gyr, table, shown_columns(gtime, gcols),
                      shown_columns(atime if not same else None, acols))


def _mounting_text(o: GyroOptions) -> str | None:
    if o.mounting is None:
        return None
    return o.mounting_text or ";".join(",".join(f"{x:g}" for x in r) for r in o.mounting)


def _gyro_compute(i: GyroInputs, o: GyroOptions, progress: Progress | None) -> CalibrationSet:
    from align.calibration.gyro import calibrate_gyro_session
    from align.calibration.gyroframe import in_system_frame

    acc_src = accel_source(o.log, o.accel)
    session = calibrate_gyro_session(i.gyr.t, i.acc.data, i.gyr.data, i.acc.shown, i.gyr.shown, o.gravity,
                                     static_detector(o), o.intervals if not isinstance(o.intervals, tuple) else
                                     [list(p) for p in o.intervals], o.gyro_range, o.drop_rotations, o.g_sensitivity,
                                     str(o.log.path), None if same_file(o.log, acc_src) else str(acc_src.path))
    i.session["session"] = session
    acc_cal, gyr_cal = with_remarks(session.accelerometer, (i.acc, acc_src)), with_remarks(session.gyroscope,
                                                                                          (i.gyr, o.log))
    if o.frame is not None or o.mounting is not None:
        table, table_sigma = i.table if i.table is not None else (None, None)
        nominal = np.array(o.mounting, float) if o.mounting is not None else None
        acc_cal, gyr_cal, _ = in_system_frame(acc_cal, gyr_cal, table, nominal,
                                              str(o.frame) if o.frame is not None else str(_mounting_text(o)),
                                              table_sigma)
    if progress is not None:
        progress(len(i.gyr.t))
    intervals = o.intervals if not isinstance(o.intervals, tuple) else ",".join(f"{a}:{b}" for a, b in o.intervals)
    inputs = {"log": str(o.log.path), "accel_log": None if same_file(o.log, acc_src) else str(acc_src.path),
              "gyro_columns": i.gyro_columns, "accel_columns": i.accel_columns,
              "accel_units": i.acc.units, "gyro_units": i.gyr.units,
              "intervals": intervals, "poses": [list(p) for p in session.poses],
              "dropped_rotations": list(o.drop_rotations), "g_sensitivity": o.g_sensitivity,
              "frame": None if o.frame is None else str(o.frame), "mounting": _mounting_text(o),
              **i.gyr.inputs(), **accel_stream(i.acc, i.gyr)}
    return CalibrationSet({Sensor.ACCELEROMETER.value: acc_cal, Sensor.GYROSCOPE.value: gyr_cal}, inputs)


def _gyro_files(o: GyroOptions) -> dict[str, Path | None]:
    acc = accel_source(o.log, o.accel)
    return {"log": o.log.path, "accel_log": None if same_file(o.log, acc) else acc.path, "frame": o.frame}


GYRO: Job[GyroOptions, GyroInputs, CalibrationSet] = Job(
    "calibrate gyro", GyroOptions, _gyro_read, _gyro_compute, _gyro_files,
    "gyro and accelerometer from rotations between static poses (imu_tk's method, no rate table)")


@fields_signature(GyroOptions)
def calibrate_gyro(*, log: LogSource | str | Path, progress: Progress | None = None, **fields: Any) -> CalibrationSet:
    """Calibrate the gyro and the accelerometer of a multi-position session (``imu-align calibrate gyro``).

    Parameters
    ----------
    log : LogSource or str or Path
        The session log; a path takes ``columns`` (the gyro's), ``time_column``, ``rate_hz`` (Hz), ``units``
        (the gyro's) and ``format`` beside it.
    progress : callable, optional
        Called with the samples done.
    **fields
        The other fields of :class:`GyroOptions` (``accel``, ``gravity`` m/s^2, ``intervals``, ``frame``, ...).

    Returns
    -------
    CalibrationSet
        ``accelerometer`` and ``gyroscope`` calibrations (``M`` (3, 3), ``b`` (3,) SI or counts), the gyro's
        relative to the accelerometer frame unless ``frame`` or ``mounting`` is given; with provenance.

    Examples
    --------
    >>> import align.api as ia                                   # doctest: +SKIP
    >>> cal = ia.calibrate_gyro(log="session.csv", units="deg/s")  # doctest: +SKIP
    >>> cal.sensor("gyroscope").rotations[0]["residual_deg"] < 1   # doctest: +SKIP
    True
    """
    src = log_source(log, fields)
    return GYRO.run(GyroOptions(log=src, **fields), progress=progress)
