"""The ``calibrate ferraris`` job: accelerometer and gyro from a Ferraris session (six faces, three turns).

The package :mod:`align.calibration.jobs` re-exports its names.

Public names
------------
FerrarisOptions, FerrarisInputs, FERRARIS, ferraris
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from align.calibration.jobs.common import accel_source, accel_stream, log_source, read_sensor, same_file, with_remarks
from align.calibration.results import CalibrationSet
from align.errors import InputError, literal
from align.io.logs import SensorLog
from align.io.source import LogSource
from align.job import Job, Progress, fields_signature, quantity
from align.units import STANDARD_GRAVITY
from align.vocab import Sensor

__all__ = ["FerrarisOptions", "FerrarisInputs", "FERRARIS", "ferraris"]


@dataclass(frozen=True, kw_only=True)
class FerrarisOptions:
    """Options of ``calibrate ferraris``: a Ferraris session (six static faces, a turn about each axis).

    Attributes
    ----------
    log : LogSource
        The session log, read at its sample rate (``rate_hz`` required, Hz); its ``columns`` and
        ``units`` are the gyro's (default ``gyro_x, gyro_y, gyro_z`` or the old ``gyr_x, ...``; the unit the
        file states, else deg/s).
    sections : Path
        imucal's section list (JSON): ``x_p`` ... ``z_a``, ``x_rot``, ``y_rot``, ``z_rot``.
    accel : LogSource or None
        The accelerometer's columns and unit (default: ``acc_x, acc_y, acc_z`` in ``log``, in the unit the file
        states, else m/s^2).
    turn_angle : float
        Signed angle of each turn about the axis pointing up, rad (imucal's -360 deg).
    gravity : float
        Local gravity, m/s^2.
    bias : {"pairwise", "lsq"}
        Accelerometer bias: pairwise (Ferraris, tilt-robust) or least squares.
    g_sensitivity : bool
        Estimate the gyro's g-sensitivity from the static faces.
    limits : Path or None
        A limits file (:mod:`align.limits`) to judge the figures of merit against; None: the default limits.
    """

    log: LogSource
    sections: Path
    accel: LogSource | None = None
    turn_angle: float = float(np.deg2rad(-360.0))
    gravity: float = quantity(STANDARD_GRAVITY, "acceleration", gt=0)
    bias: Literal["pairwise", "lsq"] = "pairwise"
    g_sensitivity: bool = True
    limits: Path | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "sections", Path(self.sections))


@dataclass(frozen=True)
class FerrarisInputs:
    """The checked inputs of a Ferraris session.

    Attributes
    ----------
    acc, gyr : SensorLog
        The accelerometer's (m/s^2) and the gyro's (rad/s) readings, shape (n, 3) each.
    sections : dict of str -> (int, int)
        The section list, samples (end exclusive).
    """

    acc: SensorLog
    gyr: SensorLog
    sections: dict[str, tuple[int, int]]


def _ferraris_read(o: FerrarisOptions) -> FerrarisInputs:
    import align.io as fileio
    from align.calibration.ferraris import sections_from_dict

    if o.log.rate_hz is None:
        raise InputError("a Ferraris session is read at its sample rate: give {rate_hz}", str(o.log.path))
    if o.bias not in ("pairwise", "lsq"):
        raise InputError(f"'{literal(str(o.bias))}' is no bias method; give pairwise or lsq", "{bias}")
    acc_src = accel_source(o.log, o.accel)
    acc = read_sensor(acc_src, Sensor.ACCELEROMETER, field="accel_units", columns_field="accel_columns", counts=False)
    gyr = read_sensor(o.log, Sensor.GYROSCOPE, field="gyro_units", columns_field="gyro_columns", counts=False)
    if len(acc.data) != len(gyr.data):
        raise InputError(f"has {len(acc.data)} accelerometer samples, the gyro log {len(gyr.data)}; both sensors "
                         "must be sampled together", str(acc_src.path))
    sections = sections_from_dict(fileio.read_json(o.sections), str(o.sections))
    return FerrarisInputs(acc, gyr, sections)


def _ferraris_compute(i: FerrarisInputs, o: FerrarisOptions, progress: Progress | None) -> CalibrationSet:
    from align.calibration.ferraris import ferraris as ferraris_fit

    assert o.log.rate_hz is not None
    acc_cal, gyr_cal = ferraris_fit(i.acc.data, i.gyr.data, o.log.rate_hz, i.sections, o.turn_angle, o.gravity,
                                    i.acc.shown, i.gyr.shown, pairwise_bias=o.bias == "pairwise",
                                    g_sensitivity=o.g_sensitivity, where=str(o.log.path))
    if progress is not None:
        progress(len(i.gyr.data))
    acc_src = accel_source(o.log, o.accel)
    inputs = {"log": str(o.log.path), "sections": str(o.sections), "accel_units": i.acc.units,
              "gyro_units": i.gyr.units, **o.log.format.to_dict(), **i.gyr.stream_inputs()}
    inputs.update(accel_stream(i.acc, i.gyr))
    if not same_file(o.log, acc_src):
        inputs["accel_log"] = str(acc_src.path)
    return CalibrationSet({Sensor.ACCELEROMETER.value: with_remarks(acc_cal, (i.acc, acc_src)),
                           Sensor.GYROSCOPE.value: with_remarks(gyr_cal, (i.gyr, o.log))}, inputs)


def _ferraris_files(o: FerrarisOptions) -> dict[str, Path | None]:
    acc = accel_source(o.log, o.accel)
    return {"log": o.log.path, "sections": o.sections, "accel_log": None if same_file(o.log, acc) else acc.path}


FERRARIS: Job[FerrarisOptions, FerrarisInputs, CalibrationSet] = Job(
    "calibrate ferraris", FerrarisOptions, _ferraris_read, _ferraris_compute, _ferraris_files,
    "accelerometer and gyro from a Ferraris session (six faces, three turns), as imucal records it")


@fields_signature(FerrarisOptions)
def ferraris(*, log: LogSource | str | Path, sections: str | Path, progress: Progress | None = None,
             **fields: Any) -> CalibrationSet:
    """Calibrate the accelerometer and the gyro of a Ferraris session (``imu-align calibrate ferraris``).

    Parameters
    ----------
    log : LogSource or str or Path
        The session log; a path takes ``rate_hz`` (Hz, required), ``columns``, ``units`` (the gyro's)
        and ``format`` beside it.
    sections : str or Path
        imucal's section list (JSON).
    progress : callable, optional
        Called with the samples done.
    **fields
        The other fields of :class:`FerrarisOptions` (``accel``, ``turn_angle`` rad, ``gravity`` m/s^2,
        ``bias``, ``g_sensitivity``).

    Returns
    -------
    CalibrationSet
        ``accelerometer`` and ``gyroscope`` calibrations (``[M | b]``, SI), with provenance.

    Examples
    --------
    >>> import align.api as ia                                   # doctest: +SKIP
    >>> cal = ia.ferraris(log="session.csv", rate_hz=102.4, sections="sections.json")  # doctest: +SKIP
    >>> cal.sensor("gyroscope").M.shape                          # doctest: +SKIP
    (3, 3)
    """
    src = log_source(log, fields)
    return FERRARIS.run(FerrarisOptions(log=src, sections=Path(sections), **fields), progress=progress)
