"""Thermal calibration: each sensor axis' bias against temperature (``imu-align calibrate thermal``).

From a static log with a temperature column (soak steps or ramps, one orientation): per axis a polynomial in
temperature, its order chosen by blocked cross-validation, an optional thermal-lag term in dT/dt, heating and
cooling branches and the hysteresis between them, the residual before and after, the uncertainty band of the
curve; the reference temperature and the valid range, outside which the compensation clamps as firmware does;
ArduPilot's and PX4's parameter files.

Modules
-------
model      the model of one sensor: polynomial (+ lag) per axis, clamping, evaluation, band
sums       the one pass over the samples: per-segment sums every fit is solved from
fit        order by cross-validation, the fit, its covariance inflated for autocorrelated residuals
branches   temperature rate, heating/cooling branches, hysteresis, the held-out branch check
checks     the refusals (span, resolution, motion, unit, branch size)
sensor     one sensor's calibration from its readings and temperature
result     ThermalCalibration, the ``imu-align.thermal`` file
firmware   ArduPilot's and PX4's parameter files, written and read back
simulate   a chamber profile with known bias cubic, lag and hysteresis
job        the ``calibrate thermal`` job

Public names
------------
ThermalOptions, ThermalInputs, THERMAL, calibrate_thermal, ThermalCalibration, ThermalModel
"""

from align.calibration.thermal.job import THERMAL, ThermalInputs, ThermalOptions, calibrate_thermal
from align.calibration.thermal.model import ThermalModel
from align.calibration.thermal.result import ThermalCalibration

__all__ = ["ThermalOptions", "ThermalInputs", "THERMAL", "calibrate_thermal", "ThermalCalibration", "ThermalModel"]
