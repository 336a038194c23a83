"""The Python API: every command's job by name, its options type, and a keyword-only call per job.

One short, stable import path for scripts and notebooks::

    import align.api as ia

    result = ia.matrix(log="session.csv", plan="plan.toml")          # the same as `imu-align matrix`
    opts = ia.MatrixOptions(log=ia.LogSource(path="session.csv"), plan="plan.toml")
    result = ia.job("matrix").run(opts)                               # the same, through the registry

Every job is an :class:`align.job.Job`: ``run(options) -> Result`` with its provenance. The command
line, the report and the batch call these same jobs; :data:`JOBS` names where each one lives, and
nothing is imported before it is asked for (``imu-align --help`` stays fast).

Public names
------------
JOBS, job, names, and, lazily, every job's options type and call (``MatrixOptions``, ``matrix``, ...),
LogSource, LogFormat, Sensor, Status, load_result, save_result
"""

from __future__ import annotations

import importlib
from typing import Any

#: command -> "module:JOB" of its job (the module defines the job, its options and its call)
JOBS: dict[str, str] = {
    "matrix": "align.alignment.jobs:MATRIX",
    "apply": "align.alignment.jobs:APPLY",
    "allan": "align.noise.jobs:ALLAN",
    "plan": "align.noise.jobs:PLAN",
    "calibrate ferraris": "align.calibration.jobs:FERRARIS",
    "calibrate accel": "align.calibration.jobs:ACCEL",
    "calibrate mag": "align.calibration.jobs:MAG",
    "calibrate gyro": "align.calibration.jobs:GYRO",
    "calibrate thermal": "align.calibration.thermal:THERMAL",
    "calibrate thermal-matrix": "align.calibration.thermal.matrix_job:THERMAL_MATRIX",
    "calibrate positions": "align.calibration.jobs.positions:POSITIONS",
    "warmup": "align.noise.bias_jobs:WARMUP",
    "repeatability": "align.noise.bias_jobs:REPEATABILITY",
    "verify": "align.alignment.jobs.verify_job:VERIFY",
    "budget": "mechanics.jobs:BUDGET",
    "allowable": "align.sensitivity.jobs:ALLOWABLE",
    "check": "align.sensitivity.jobs:CHECK",
    "drift": "align.navigation.jobs:DRIFT",
}

#: names this module gives lazily -> "module:name"
_LAZY: dict[str, str] = {
    "LogSource": "align.io.source:LogSource",
    "LogFormat": "align.io.formats:LogFormat",
    "Sensor": "align.vocab:Sensor",
    "Status": "align.vocab:Status",
    "Job": "align.job:Job",
    "load_result": "align.results:load_result",
    "save_result": "align.results:save_result",
    # the jobs' options and calls
    "MatrixOptions": "align.alignment.jobs:MatrixOptions", "matrix": "align.alignment.jobs:matrix",
    "ApplyOptions": "align.alignment.jobs:ApplyOptions", "apply": "align.alignment.jobs:apply",
    "AllanOptions": "align.noise.jobs:AllanOptions", "allan": "align.noise.jobs:allan",
    "PlanOptions": "align.noise.jobs:PlanOptions", "plan": "align.noise.jobs:plan",
    "FerrarisOptions": "align.calibration.jobs:FerrarisOptions", "ferraris": "align.calibration.jobs:ferraris",
    "AccelOptions": "align.calibration.jobs:AccelOptions", "calibrate_accel": "align.calibration.jobs:calibrate_accel",
    "MagOptions": "align.calibration.jobs:MagOptions", "calibrate_mag": "align.calibration.jobs:calibrate_mag",
    "GyroOptions": "align.calibration.jobs:GyroOptions", "calibrate_gyro": "align.calibration.jobs:calibrate_gyro",
    "ThermalOptions": "align.calibration.thermal:ThermalOptions",
    "calibrate_thermal": "align.calibration.thermal:calibrate_thermal",
    "MatrixThermalOptions": "align.calibration.thermal.matrix_job:MatrixThermalOptions",
    "calibrate_thermal_matrix": "align.calibration.thermal.matrix_job:calibrate_thermal_matrix",
    "MatrixThermal": "align.calibration.thermal.matrix_t:MatrixThermal",
    "PositionsOptions": "align.calibration.jobs.positions:PositionsOptions",
    "calibrate_positions": "align.calibration.jobs.positions:calibrate_positions",
    "WarmupOptions": "align.noise.bias_jobs:WarmupOptions", "warmup": "align.noise.bias_jobs:warmup",
    "RepeatabilityOptions": "align.noise.bias_jobs:RepeatabilityOptions",
    "repeatability": "align.noise.bias_jobs:repeatability_job",
    "VerifyOptions": "align.alignment.jobs.verify_job:VerifyOptions", "verify": "align.alignment.jobs.verify_job:verify",
    "BudgetOptions": "mechanics.jobs:BudgetOptions", "budget": "mechanics.jobs:budget",
    "AllowableOptions": "align.sensitivity.jobs:AllowableOptions", "allowable": "align.sensitivity.jobs:allowable",
    "CheckOptions": "align.sensitivity.jobs:CheckOptions", "check": "align.sensitivity.jobs:check",
    "DriftOptions": "align.navigation.jobs:DriftOptions", "drift": "align.navigation.jobs:drift",
}

__all__ = ["JOBS", "job", "names", *_LAZY]


def _load(target: str) -> Any:
    module, _, name = target.partition(":")
    return getattr(importlib.import_module(module), name)


def names() -> list[str]:
    """The commands that have a job, in the order of :data:`JOBS`."""
    return list(JOBS)


def job(name: str) -> Any:
    """The :class:`~align.job.Job` of the command ``name`` (``"matrix"``, ``"calibrate accel"``).

    Raises
    ------
    KeyError
        For a name that is no job, listing the jobs there are.
    """
    if name not in JOBS:
        raise KeyError(f"no job {name!r}; jobs: {', '.join(JOBS)}")
    return _load(JOBS[name])


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = _load(_LAZY[name])
        globals()[name] = value
        return value
    raise AttributeError(f"module 'align.api' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
