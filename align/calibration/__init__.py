"""Sensor calibration: accelerometers, gyros (Ferraris sessions) and magnetometers.

Every sensor but the magnetometer shares the alignment convention
``raw = M true + bias``; the magnetometer's is ``m_cal = soft_iron (m_raw - hard_iron)``.

Modules
-------
results       Calibration (one sensor's ``[M | b]``) and CalibrationSet (the ``imu-align.calibration`` file)
accel         accelerometer: multi-position least squares, the ``|a| = g`` fit, sessions from a log
positions     the positions file of an accelerometer session (``gravity``, ``[[position]]`` tables), keys checked
ferraris      Ferraris sessions (six faces and three turns, as imucal records them): accelerometer and gyro
statics       the static-interval detector (imu_tk's moving variance), the initial static period
gyro          gyro (and accelerometer) from rotations between static poses, no rate table (imu_tk's method)
gyrofit       its least-squares core: gravity directions after integration, covariance, observability
gyrochecks    its refusals: too few poses, short or moving poses, rotations at the gyro's range
gyroframe     a multi-position calibration turned into the system frame (rate-table result or mounting)
posesim       simulated multi-position sessions of known truth (analytic attitude)
ellipsoid     algebraic ellipsoid fits and the soft-iron parametrisation
magnetometer  MagCalibration (the ``imu-align.magnetometer`` file): hard and soft iron with gates,
              rotation to the accelerometer frame from gravity

Public names
------------
Calibration, CalibrationSet, SENSORS, FACES, face_ups, static_means, accel_session, calibrate_accel_log,
StaticDetector, calibrate_accel, Position, parse_positions, positions_of,
calibrate_accel_free, ferraris, sections_from_dict, SECTIONS, MagCalibration, calibrate_magnetometer, with_gravity_alignment,
alignment_to_gravity, misalignment_from_axes_down, MODELS, GyroSession, RotationReport, calibrate_gyro_session,
in_system_frame, session_intervals
"""

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # the names for type checkers; at run time each is imported when first asked for
    from align.calibration.accel import (
                                         FACES,
                                         StaticDetector,
                                         accel_session,
                                         calibrate_accel,
                                         calibrate_accel_free,
                                         calibrate_accel_log,
                                         face_ups,
                                         session_intervals,
                                         static_means,
    )
    from align.calibration.ellipsoid import MODELS
    from align.calibration.ferraris import SECTIONS, ferraris, sections_from_dict
    from align.calibration.gyro import GyroSession, RotationReport, calibrate_gyro_session
    from align.calibration.gyroframe import in_system_frame
    from align.calibration.magnetometer import (
                                         MagCalibration,
                                         alignment_to_gravity,
                                         calibrate_magnetometer,
                                         misalignment_from_axes_down,
                                         with_gravity_alignment,
    )
    from align.calibration.positions import Position, parse_positions, positions_of
    from align.calibration.results import SENSORS, Calibration, CalibrationSet

#: name -> the module that defines it (imported on first use: `import align.calibration.thermal` stays light)
_WHERE = {
    "FACES": "accel",
    "StaticDetector": "accel",
    "accel_session": "accel",
    "calibrate_accel": "accel",
    "calibrate_accel_free": "accel",
    "calibrate_accel_log": "accel",
    "face_ups": "accel",
    "session_intervals": "accel",
    "static_means": "accel",
    "MODELS": "ellipsoid",
    "SECTIONS": "ferraris",
    "ferraris": "ferraris",
    "sections_from_dict": "ferraris",
    "GyroSession": "gyro",
    "RotationReport": "gyro",
    "calibrate_gyro_session": "gyro",
    "in_system_frame": "gyroframe",
    "MagCalibration": "magnetometer",
    "alignment_to_gravity": "magnetometer",
    "calibrate_magnetometer": "magnetometer",
    "misalignment_from_axes_down": "magnetometer",
    "with_gravity_alignment": "magnetometer",
    "Position": "positions",
    "parse_positions": "positions",
    "positions_of": "positions",
    "SENSORS": "results",
    "Calibration": "results",
    "CalibrationSet": "results",
}


__all__ = ["Calibration", "CalibrationSet", "SENSORS", "FACES", "face_ups", "static_means", "accel_session",
           "calibrate_accel_log", "StaticDetector", "Position", "parse_positions", "positions_of",
           "calibrate_accel", "calibrate_accel_free", "ferraris", "sections_from_dict", "SECTIONS", "MagCalibration",
           "calibrate_magnetometer", "with_gravity_alignment", "alignment_to_gravity",
           "misalignment_from_axes_down", "MODELS", "GyroSession", "RotationReport", "calibrate_gyro_session",
           "in_system_frame", "session_intervals"]


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        value = getattr(importlib.import_module(f"align.calibration.{_WHERE[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'align.calibration' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
