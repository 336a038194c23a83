"""The calibration jobs: ``imu-align calibrate ferraris | accel | mag | gyro`` as library calls.

Each job (:class:`align.job.Job`) reads its logs through the one log reader
(:class:`align.io.source.LogSource`, the one column convention), checks them, calibrates and
returns the result with its provenance (input files with size and SHA-256, the options, the
tool version). The command line, the report, the batch and a notebook call the same jobs::

    import align.api as ia

    cal = ia.calibrate_accel(log="accel.csv", positions="positions.toml")
    cal = ia.job("calibrate accel").run(ia.AccelOptions(log=ia.LogSource(path="accel.csv")))

Two sensors of one log (``calibrate ferraris``, ``calibrate gyro``) are two sources: ``log`` holds
the gyro's columns and unit (with the file's time column, sample rate and format), ``accel`` the
accelerometer's; ``accel=None`` reads the accelerometer's default columns (``acc_x, acc_y, acc_z``,
or the old names the file has) in m/s^2 from the same file.

One module per job (:mod:`align.calibration.jobs.ferraris_job`, ``.accel``, ``.mag``, ``.gyro``; what they share in
:mod:`align.calibration.jobs.common`); this package re-exports their public names.

Public names
------------
FerrarisOptions, FerrarisInputs, FERRARIS, ferraris,
AccelOptions, AccelInputs, ACCEL, calibrate_accel,
MagOptions, MagInputs, MAG, calibrate_mag,
GyroOptions, GyroInputs, GYRO, calibrate_gyro
"""

from align.calibration.jobs.accel import ACCEL, AccelInputs, AccelOptions, calibrate_accel
from align.calibration.jobs.ferraris_job import FERRARIS, FerrarisInputs, FerrarisOptions, ferraris
from align.calibration.jobs.gyro import GYRO, GyroInputs, GyroOptions, calibrate_gyro
from align.calibration.jobs.mag import MAG, MagInputs, MagOptions, calibrate_mag

__all__ = ["FerrarisOptions", "FerrarisInputs", "FERRARIS", "ferraris",
           "AccelOptions", "AccelInputs", "ACCEL", "calibrate_accel",
           "MagOptions", "MagInputs", "MAG", "calibrate_mag",
           "GyroOptions", "GyroInputs", "GYRO", "calibrate_gyro"]

# the classes keep the package as their home (their documented, shown and pickled name: align.calibration.jobs.X),
# as before the jobs were split into modules; one page documents each once
for _cls in (FerrarisOptions, FerrarisInputs, AccelOptions, AccelInputs, MagOptions, MagInputs, GyroOptions, GyroInputs):
    _cls.__module__ = __name__
del _cls
