"""The alignment family's jobs: ``matrix`` (rate-table log + plan -> ``M``, ``A``) and ``apply`` (a result
corrects a log), as library calls.

``imu-align matrix``, ``imu-align apply``, the report's alignment step, the batch and a notebook all run
:data:`MATRIX` and :data:`APPLY`::

    from align.alignment.jobs import matrix, apply
    r = matrix(log="examples/alignment/session.csv", plan="examples/alignment/plan.toml")
    corrected = apply(log="flight.csv", alignment="alignment.json")

The jobs live in :mod:`align.alignment.jobs.matrix_job` and :mod:`align.alignment.jobs.apply_job` (what they share in
:mod:`align.alignment.jobs.common`); this package re-exports their public names.

Public names
------------
MatrixOptions, MatrixInputs, MATRIX, matrix, ApplyOptions, ApplyInputs, APPLY, apply, CorrectedLog,
MAX_GYRO_RATE
"""

from align.alignment.jobs.apply_job import APPLY, MAX_GYRO_RATE, ApplyInputs, ApplyOptions, CorrectedLog, apply
from align.alignment.jobs.matrix_job import MATRIX, MatrixInputs, MatrixOptions, matrix

__all__ = ["MatrixOptions", "MatrixInputs", "MATRIX", "matrix", "ApplyOptions", "ApplyInputs", "APPLY", "apply",
           "CorrectedLog", "MAX_GYRO_RATE"]

# the classes keep the package as their home (their documented, shown and pickled name: align.alignment.jobs.X), as
# before the jobs were split into modules; one page documents each once
for _cls in (MatrixOptions, MatrixInputs, ApplyOptions, ApplyInputs):
    _cls.__module__ = __name__
del _cls
