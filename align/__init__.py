"""imu-align: MEMS IMU mounting-misalignment analysis and electronic alignment.

Conventions shared by every module (see ``docs`` in README and the reference
``alignment-basics.md``, section 1):

* measurement model ``g = M w + b``: row ``i`` of ``M`` is gyro ``i``'s sensitive
  axis in the system frame times its scale factor;
* correction ``w = A (g - b)`` with the alignment matrix ``A = M^-1``;
* time series are arrays of shape ``(n, 3)``; everything inside is SI
  (rad, rad/s, m, s). Units appear only at the edges (files, command line).

Modules
-------
errors     user-facing exception hierarchy
units      parsing of unit strings ("100 deg/s", "0.3 deg/sqrt(h)")
model      the measurement model ``SensorModel`` and its angles
plan       the rate-table test plan (steps) and its TOML loader
fileio     log readers and result writers (CSV, .npy, .parquet, JSON, C header)
segment    automatic segmentation of a log into dwells, turns and static periods
estimate   estimators of ``[M | b]`` (Eq 19-31, Eq 35-36, weighted least squares)
checks     checks that turn a bad test into a clear error
earth      Earth rotation rate
simulate   rate-table session simulator
alignment  the end-to-end alignment job and its result type
sensitivity  what misalignment does to a manoeuvre; allowable misalignment (sympy)
parts      datasheet presets shared by the budget and the planner
allan      overlapping / modified Allan deviation (numba kernels in _allan_kernels)
noisefit   five-term noise fit, IEEE readouts, the seed's noise figures
noisesim   sensor-error simulator and the seed's error models
planner    averaging time and test plan (Example 3)
noisereport  the Allan job, its JSON form and plot
calibration  accelerometer and gyro calibration (multi-position, Ferraris)
magnetometer hard/soft-iron ellipsoid fit with gates
summary    readable text summaries; report: the HTML report; story: demo and report job
cli        the ``imu-align`` command line (a thin layer)
"""

__version__ = "0.1.0"
CONVENTION = "g = M w + b; w = A (g - b); A = M^-1; rows of M are gyros"
