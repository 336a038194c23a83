"""The ``drift`` job: what the residual sensor errors cost in navigation, as one library call.

``imu-align drift``, the batch and a notebook run :data:`DRIFT` with a :class:`DriftOptions`::

    from align.navigation.jobs import drift
    res = drift(imu="ADIS16485", gyro_bias=1e-5, duration=60.0, runs=200)

The mission is static (``duration`` at ``rate_hz``), a manoeuvre file's rotations, or a recorded log
(``trajectory``, a :class:`~align.io.source.LogSource` of its gyro columns; the accelerometer's are
``accel_columns`` of the same file, read with the same time column or rate).

Public names
------------
DriftOptions, DriftInputs, DRIFT, drift, LEVEL_TIME, MAX_RUNS
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from align.errors import InputError
from align.io.source import LogSource, check_distinct
from align.job import Job, Progress, fields_signature, quantity
from align.navigation.mission import Mission
from align.navigation.residuals import MOUNT_ERRORS, ResidualErrors
from align.navigation.result import DriftResult
from align.units import DEG
from align.vocab import Sensor

__all__ = ["DriftOptions", "DriftInputs", "DRIFT", "drift", "LEVEL_TIME", "MAX_RUNS"]

#: the initial attitude of a recorded trajectory is levelled on its first samples, over this long (s)
LEVEL_TIME = 1.0
#: the most Monte Carlo runs
MAX_RUNS = 1_000_000


@dataclass(frozen=True, kw_only=True)
class DriftOptions:
    """What the error growth is computed from.

    Attributes
    ----------
    duration : float or None
        Mission length, s (with ``trajectory``: its first part; None: the whole log). Required otherwise.
    allan : tuple of Path
        Allan results (``imu-align allan --json``) of the gyros and/or the accelerometers.
    alignment : Path or None
        An alignment or calibration result: its 1-sigma of M and bias are the residuals.
    budget : Path or None
        A mount TOML: its budget's per-axis misalignment (rms angle), uncompensated (not with ``alignment``).
    mount_error : str
        What the budget is: ``"attitude"`` (a rigid rotation of the IMU: an initial attitude error) or
        ``"turns"`` (the gyro axes' misalignment, costing only when the body turns).
    imu : str or None
        A datasheet preset's name (gyro noise when no gyro Allan result is given).
    parts : Path or None
        A user's parts file laid over the presets (for ``imu`` and the budget's part).
    parts_table : mapping of str to Part, or None
        A parts table already made (overrides reading ``parts``); not part of the provenance.
    manoeuvre : Path or None
        A manoeuvre TOML (``[[rotation]]`` or ``[series]``); static mission when None.
    trajectory : LogSource or None
        A recorded log as the true motion (instead of ``manoeuvre``): its gyro columns, time column or rate,
        gyro unit (None: the unit the file states, else deg/s) and format.
    accel_columns : tuple of str or None
        The accelerometer columns of ``trajectory`` (None: the accelerometer's default names).
    accel_units : str or None
        Unit of the accelerometer columns of ``trajectory`` (``"m/s^2"``, ``"g"``); None: the unit the file
        states, else m/s^2.
    runs : int
        Monte Carlo runs, 2 to :data:`MAX_RUNS`.
    rate_hz : float
        Sensor sample rate of a static or manoeuvre mission, Hz.
    nav_rate : float or None
        Navigation update rate, Hz (None: 10 Hz, at most the sample rate).
    turn_rate : float
        Mean rate of a manoeuvre's rotations, rad/s.
    heading : float
        Initial heading, rad.
    latitude : float
        Latitude, rad (gravity, the Earth rate).
    earth_rate : bool
        Whether the Earth rate and the Coriolis term are included.
    gyro_bias : float or None
        Residual gyro turn-on bias, 1 sigma, rad/s (replaces any other source).
    accel_bias : float or None
        Residual accelerometer turn-on bias, 1 sigma, m/s^2.
    flicker_span : int
        Flicker is drawn down to ``1 / (flicker_span T)``, 2 to 256 mission lengths.
    seed : int
        Random seed of the Monte Carlo.
    """

    duration: float | None = quantity(None, "time", gt=0)
    allan: tuple[Path, ...] = ()
    alignment: Path | None = None
    budget: Path | None = None
    mount_error: str = "attitude"
    imu: str | None = None
    parts: Path | None = None
    parts_table: Mapping | None = field(default=None, repr=False, compare=False)
    manoeuvre: Path | None = None
    trajectory: LogSource | None = None
    accel_columns: tuple[str, ...] | None = None
    accel_units: str | None = None
    runs: int = 1000
    rate_hz: float = quantity(100.0, "frequency", gt=0)
    nav_rate: float | None = quantity(None, "frequency", gt=0)
    turn_rate: float = 10 * DEG
    heading: float = 0.0
    latitude: float = quantity(45 * DEG, "angle", ge=-math.pi / 2, le=math.pi / 2)
    earth_rate: bool = False
    gyro_bias: float | None = None
    accel_bias: float | None = None
    flicker_span: int = 8
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("alignment", "budget", "parts", "manoeuvre"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, Path(value))
        allan = (self.allan,) if isinstance(self.allan, (str, Path)) else tuple(self.allan or ())
        object.__setattr__(self, "allan", tuple(Path(p) for p in allan))
        if isinstance(self.trajectory, (str, Path)):
            object.__setattr__(self, "trajectory", LogSource(path=Path(self.trajectory)))
        if isinstance(self.accel_columns, str):
            object.__setattr__(self, "accel_columns", tuple(c.strip() for c in self.accel_columns.split(",")
                                                            if c.strip()))
        object.__setattr__(self, "mount_error", str(getattr(self.mount_error, "value", self.mount_error)))
        if self.alignment is not None and self.budget is not None:
            raise InputError("give {alignment} (residuals after an alignment) or {budget} (no alignment), not both",
                             "{budget}")
        if self.manoeuvre is not None and self.trajectory is not None:
            raise InputError("give one mission: {manoeuvre} (rotations) or {trajectory} (a recorded log), not both",
                             "{trajectory}")
        if self.duration is None and self.trajectory is None:
            raise InputError("give the mission length, e.g. '10 min'", "{duration}")
        if self.mount_error not in MOUNT_ERRORS:
            raise InputError(f"choose {' or '.join(MOUNT_ERRORS)} (got {self.mount_error!r})", "{mount_error}")
        if not 2 <= self.runs <= MAX_RUNS:
            raise InputError(f"give 2 to {MAX_RUNS:,} runs, not {self.runs}", "{runs}")

    def table(self) -> Mapping | None:
        """The parts table presets are looked up in (None: the built-in presets)."""
        if self.parts_table is not None:
            return self.parts_table
        if self.parts is None:
            return None
        from mechanics.jobs import PartsFileTable

        return PartsFileTable(self.parts)


@dataclass(frozen=True)
class DriftInputs:
    """The checked inputs of the drift analysis.

    Attributes
    ----------
    mission : Mission
        The true motion (sample rate, increments, initial attitude).
    errors : ResidualErrors
        The residual sensor errors and where each came from.
    inputs : dict
        The files and figures, as the result records them.
    notes : tuple of str
        The trajectory reader's remarks (a truncated last record), after its file.
    """

    mission: Mission
    errors: ResidualErrors
    inputs: dict
    notes: tuple[str, ...] = ()


def _read_correction(path: Path) -> Any:
    from align.alignment.result import AlignmentResult
    from align.calibration.results import CalibrationSet
    from align.results import load_result

    return load_result(path, expect=(AlignmentResult, CalibrationSet))


def _read_budget(options: DriftOptions) -> Any:
    from mechanics.budget import budget
    from mechanics.jobs import BudgetOptions, read_mount

    assert options.budget is not None
    return budget(read_mount(BudgetOptions(mount=options.budget, parts_table=options.table())))


def _trajectory(options: DriftOptions, settings: dict[str, Any]) -> tuple[Mission, dict[str, Any], tuple[str, ...]]:
    """A recorded log as the mission's true motion: its readings from the attitude levelled on its first second;
    what the result records of the log read (units, stream) and the reader's remarks."""
    from align.navigation.mission import recorded_mission
    from align.navigation.strapdown import level_attitude

    src = options.trajectory
    assert src is not None
    time_col, _ = src.names(Sensor.GYROSCOPE, field="gyro_columns")
    acc_src = dataclasses.replace(src, columns=options.accel_columns, units=options.accel_units,
                                  time_column=time_col or src.time_column)
    if src.columns is not None or acc_src.columns is not None:  # one file: no column named for both sensors
        check_distinct((Sensor.GYROSCOPE, src.data_names(Sensor.GYROSCOPE, "gyro_columns"), "gyro_columns"),
                       (Sensor.ACCELEROMETER, acc_src.data_names(Sensor.ACCELEROMETER, "accel_columns"), "accel_columns"))
    gyr = src.read(Sensor.GYROSCOPE, field="gyro_units", columns_field="gyro_columns")
    acc = acc_src.read(Sensor.ACCELEROMETER, field="accel_units", columns_field="accel_columns")
    path = src.path
    step = np.diff(gyr.t)
    if len(step) and (step.max() > 1.5 / gyr.rate_hz or step.min() < 0.5 / gyr.rate_hz):
        raise InputError(f"its time steps run from {step.min():.4g} to {step.max():.4g} s (gaps or repeated samples); "
                         f"the trajectory is read at one rate, {gyr.rate_hz:g} Hz: resample it", str(path))
    n = len(gyr.t)
    if options.duration is not None:
        n = int(round(options.duration * gyr.rate_hz)) + 1
        if n > len(gyr.t):
            raise InputError(f"{options.duration:g} s is longer than the trajectory's "
                             f"{(len(gyr.t) - 1) / gyr.rate_hz:g} s; give a shorter {{duration}} or leave it out",
                             "{duration}")
    first = max(1, min(n, int(round(LEVEL_TIME * gyr.rate_hz))))
    q0 = level_attitude(acc.data[:first].mean(axis=0), options.heading)
    mission = recorded_mission(gyr.data[:n], acc.data[:n], gyr.rate_hz, q0, description=(
        f"recorded trajectory {path.name}, {n:,} samples at {gyr.rate_hz:g} Hz, initial attitude levelled on its first "
        f"{first / gyr.rate_hz:g} s"), latitude=settings["latitude"], earth_rate=settings["earth_rate"])
    said = {**gyr.stream_inputs("trajectory_"), **acc.stream_inputs("trajectory_accel_")}
    if acc.source == gyr.source:
        said.pop("trajectory_accel_stream", None)
    return mission, said, tuple(dict.fromkeys(gyr.remarks(str(path)) + acc.remarks(str(path))))  # one file: once


def read(options: DriftOptions) -> DriftInputs:
    """The residual errors (Allan results, a correction's uncertainty or a budget, a preset, given biases) and
    the mission (static, a manoeuvre file, or a recorded log), read and checked."""
    from align.io import read_toml
    from align.navigation.mission import manoeuvre_mission, static_mission
    from align.navigation.residuals import residual_errors
    from align.noise import AllanJob
    from align.parts import get_part
    from align.results import load_result

    allan = list(options.allan)
    jobs = [load_result(p, expect=(AllanJob,)) for p in allan]
    part = None if options.imu is None else get_part(options.imu, "{imu}", options.table())
    errors = residual_errors(
        jobs, None if options.alignment is None else _read_correction(options.alignment),
        None if options.budget is None else _read_budget(options), part, options.gyro_bias, options.accel_bias,
        where={"allan": [str(p) for p in allan], "correction": str(options.alignment), "budget": str(options.budget)},
        mount_error=options.mount_error)
    settings: dict[str, Any] = dict(heading=options.heading, latitude=options.latitude, earth_rate=options.earth_rate)
    said: dict[str, Any] = {}
    notes: tuple[str, ...] = ()
    if options.trajectory is not None:
        mission, said, notes = _trajectory(options, settings)
    elif options.manoeuvre is None:
        assert options.duration is not None
        mission = static_mission(options.duration, options.rate_hz, **settings)
    else:
        assert options.duration is not None
        mission = manoeuvre_mission(read_toml(options.manoeuvre), str(options.manoeuvre), options.manoeuvre.parent,
                                    options.duration, options.rate_hz, options.turn_rate, **settings)
    trajectory = options.trajectory
    inputs = {k: v for k, v in {
        "allan": [str(p) for p in allan] or None, "alignment": options.alignment and str(options.alignment),
        "budget": options.budget and str(options.budget), "imu": part and part.name,
        "manoeuvre": options.manoeuvre and str(options.manoeuvre),
        "trajectory": trajectory and str(trajectory.path),
        "mount_error": options.budget and options.mount_error}.items() if v}
    return DriftInputs(mission, errors, {**inputs, **said}, notes)


def compute(inputs: DriftInputs, options: DriftOptions, progress: Progress | None = None) -> DriftResult:
    """The Monte Carlo through the integrator, the closed forms and which error dominates
    (:func:`align.navigation.drift.drift`); ``progress`` is called with the runs done."""
    from align.navigation.drift import drift as analyse

    result = analyse(inputs.mission, inputs.errors, options.runs, options.seed, options.nav_rate, inputs=inputs.inputs,
                     progress=progress, flicker_span=options.flicker_span)
    return result.replace(notes=tuple(result.notes) + inputs.notes) if inputs.notes else result


def files(options: DriftOptions) -> dict[str, Path | None]:
    """The input files: Allan results, the correction, the mount, the manoeuvre, the trajectory, the parts file."""
    out: dict[str, Path | None] = {f"allan.{k}": p for k, p in enumerate(options.allan)}
    out.update({"alignment": options.alignment, "budget": options.budget, "manoeuvre": options.manoeuvre,
                "trajectory": None if options.trajectory is None else options.trajectory.path,
                "parts": options.parts})
    return out


DRIFT: Job[DriftOptions, DriftInputs, DriftResult] = Job(
    "drift", DriftOptions, read, compute, files,
    "attitude, velocity and position error growth from the residual sensor errors over a mission")


@fields_signature(DriftOptions)
def drift(*, progress: Progress | None = None, **fields: Any) -> DriftResult:
    """Attitude, velocity and position error growth over a mission, as ``imu-align drift`` computes it.

    Parameters
    ----------
    progress : callable, optional
        Called with the Monte Carlo runs done.
    **fields
        The fields of :class:`DriftOptions`, in SI (``duration`` s, ``gyro_bias`` rad/s, ``accel_bias`` m/s^2,
        angles rad); paths as str or Path; ``trajectory`` a path or a :class:`~align.io.source.LogSource`.

    Returns
    -------
    DriftResult
        ``t`` (k,) s; the mean and 1-sigma of the attitude (rad), velocity (m/s) and position (m) errors, each
        (k, 3); the closed forms of a static mission; with its provenance.

    Examples
    --------
    A 10 deg/h gyro bias for a minute at rest turns the heading by 10/60 deg:

    >>> from align.units import DEG, DEG_H
    >>> res = drift(gyro_bias=10 * DEG_H, duration=60.0, runs=20, rate_hz=10.0)
    >>> _, heading = res.component("attitude_deg", "heading")
    >>> bool(abs(heading[-1] - 10 / 60) < 0.1)
    True
    """
    return DRIFT.run(DriftOptions(**fields), progress=progress)
