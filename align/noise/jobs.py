"""The noise family's jobs: ``allan`` (static records -> Allan deviation, fit, noise figures, plan) and ``plan``
(an alignment goal and a noise source -> averaging time and test plan).

Each is an :class:`align.job.Job`: a frozen options value (the one place defaults live, SI inside) and
``run(options) -> Result`` with its provenance; ``imu-align allan``, ``imu-align plan``, the report's noise
step, the batch and scripts call them (``allan(logs=["static.csv"], units="131 LSB/(deg/s)")``). The
records are read and checked by :mod:`align.noise.records`.

Public names
------------
AllanOptions, ALLAN, allan, PlanOptions, PlanInputs, PLAN, plan, sources_fields (and, from records: AllanInputs,
allan_unit, allan_columns, MOTION_RATE, MOTION_ACCELERATION)
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from align.errors import InputError
from align.io.formats import LogFormat
from align.io.source import LogSource
from align.job import Job, Progress, fields_signature, quantity
from align.noise.analysis import AllanAnalysis, plan_from_allan, run_allan
from align.noise.planner import PlanResult, make_plan, model_curve, preset_model
from align.noise.records import MOTION_ACCELERATION, MOTION_RATE, AllanInputs, allan_columns, allan_unit, read_records
from align.units import to_unit

__all__ = ["AllanOptions", "AllanInputs", "ALLAN", "allan", "sources_fields", "allan_unit", "allan_columns", "PlanOptions",
           "PlanInputs", "PLAN", "plan", "MOTION_RATE", "MOTION_ACCELERATION"]

# ---------------------------------------------------------------------------------------------- allan


@dataclass(frozen=True, kw_only=True)
class AllanOptions:
    """Options of the ``allan`` job (SI inside; units of the readings as typed).

    Attributes
    ----------
    logs : tuple of Path
        Static recordings of one sensor (``.csv``, ``.csv.gz``, ``.parquet``, ``.npy``, raw float64 ``.bin``, a
        stream of a log of several: ``format.topic``); several are several runs, pooled.
    columns : tuple of str or None
        Data columns, C of them (three for x, y, z; four names keep meaning "time first"). None:
        ``gyro_x, gyro_y, gyro_z`` (or the old default names the file has).
    time_column : str or None
        Name of the time column (None: ``time``, or the first of four names); not read at ``rate_hz``.
    rate_hz : float or None
        Sample rate, Hz, for records without a time column (``.npy`` always). A text record's time
        column, when it has one, must agree with it.
    gyro_units : str or None
        Unit of the readings, an angular rate (``"deg/s"``) or the size of one count (``"131 LSB/(deg/s)"``);
        None: the unit the file states (a ULog, a bag), else deg/s.
    units : str or None
        Any rate or acceleration unit (or count size) instead of ``gyro_units`` (``"g"``, ``"16384 LSB/g"``).
    format : LogFormat
        Preamble, comments, delimiter and time unit of a text record; the topic of a log of several streams.
    grid, per_decade : str or tuple of float, int
        ``"dense"`` (``per_decade`` points per decade, 1 to 1000), ``"octave"``, ``"decade"`` or explicit taus, s.
    modified : bool
        Also the modified Allan deviation.
    rate, accuracy : float or None
        Table rate (rad/s) and alignment goal (rad) to plan for, both or neither (gyro records only).
    noise_ratio : float
        Plan for noise this many times below the goal (> 0).
    memory_limit : float
        Bytes of phase kept in memory; beyond it, a temporary file.
    periods : tuple of float
        Averaging periods of the bias stability figures, s.
    limits : Path or None
        A limits file (:mod:`align.limits`) to judge the figures of merit against; None: the default limits.
    """

    logs: tuple[Path, ...]
    columns: tuple[str, ...] | None = None
    time_column: str | None = None
    rate_hz: float | None = quantity(None, "frequency", gt=0)
    gyro_units: str | None = None
    units: str | None = None
    format: LogFormat = field(default_factory=LogFormat)
    grid: str | tuple[float, ...] = "dense"
    per_decade: int = 10
    modified: bool = False
    rate: float | None = quantity(None, "angular_rate", gt=0)
    accuracy: float | None = quantity(None, "angle", gt=0, le=math.pi / 2)
    noise_ratio: float = quantity(10.0, "dimensionless", gt=0)
    memory_limit: float = quantity(2e9, "dimensionless", gt=0)
    periods: tuple[float, ...] = (1.0, 10.0)
    limits: Path | None = None

    def __post_init__(self) -> None:
        logs = (self.logs,) if isinstance(self.logs, (str, Path)) else self.logs
        object.__setattr__(self, "logs", tuple(Path(p) for p in logs))
        if isinstance(self.columns, str):
            object.__setattr__(self, "columns", tuple(c.strip() for c in self.columns.split(",") if c.strip()))
        elif self.columns is not None:
            object.__setattr__(self, "columns", tuple(self.columns))
        if not isinstance(self.grid, str):
            object.__setattr__(self, "grid", tuple(float(t) for t in self.grid))
        object.__setattr__(self, "periods", tuple(float(p) for p in self.periods))

    @property
    def unit_field(self) -> str:
        """The option that gives the unit (``units`` when given, else ``gyro_units``), for messages."""
        return "gyro_units" if self.units is None else "units"

    @property
    def typed_units(self) -> str | None:
        """The unit of the readings as typed (None: none typed)."""
        return self.gyro_units if self.units is None else self.units


read_allan = read_records


def compute_allan(inputs: AllanInputs, options: AllanOptions, progress: Progress | None = None) -> AllanAnalysis:
    """The Allan deviation, fit and figures of the checked records (:func:`align.noise.analysis.run_allan`), and
    the plan when ``options.rate`` and ``options.accuracy`` are given.

    Returns
    -------
    AllanAnalysis
        ``inputs`` the records as given; ``plan`` set when asked for.
    """
    grid = options.grid if isinstance(options.grid, str) else list(options.grid)
    result = run_allan(list(inputs.runs), inputs.fs, list(inputs.names), inputs.unit, grid, options.per_decade,
                       options.modified, periods=options.periods, progress=progress, memory_limit=options.memory_limit,
                       where=list(inputs.files))
    result = result.replace(inputs=inputs.files)
    said = {"streams": inputs.streams, "notes": inputs.notes}  # the records' streams and readers' remarks, where the
    said = {k: v for k, v in said.items() if v and k in type(result).__dataclass_fields__}  # result type holds them
    if said:
        result = result.replace(**said)
    if options.rate is not None and options.accuracy is not None:
        result = result.replace(plan=plan_from_allan(result, options.rate, options.accuracy, options.noise_ratio,
                                                     "measured curve (worst channel)"))
    return result


def allan_files(options: AllanOptions) -> dict[str, Path | None]:
    """The records, by role (``log``, or ``log 1``, ``log 2``, ... for several runs)."""
    if len(options.logs) == 1:
        return {"log": options.logs[0]}
    return {f"log {k}": p for k, p in enumerate(options.logs, 1)}


ALLAN: Job[AllanOptions, AllanInputs, AllanAnalysis] = Job(
    "allan", AllanOptions, read_allan, compute_allan, allan_files,
    "Allan deviation, noise-model fit and noise figures of static recordings")


def sources_fields(logs: Any, fields_: dict[str, Any]) -> tuple[tuple[Path, ...], dict[str, Any]]:
    """Paths from paths or LogSources (their columns, time, rate, unit and format, alike, become the options')."""
    items = [logs] if isinstance(logs, (str, Path, LogSource)) else list(logs)
    paths: list[Path] = []
    shared: dict[str, Any] = {}
    for item in items:
        if isinstance(item, LogSource):
            said = {"columns": item.columns, "time_column": item.time_column, "rate_hz": item.rate_hz,
                    "units": item.units, "format": item.format}
            said = {k: v for k, v in said.items() if v is not None and v != LogFormat()}
            if shared and said != shared:
                raise InputError("the runs' sources differ in columns, time, rate, unit or format; give them alike",
                                 "{logs}")
            shared = said
            paths.append(item.path)
        else:
            paths.append(Path(item))
    return tuple(paths), {**shared, **fields_}


@fields_signature(AllanOptions)
def allan(*, logs: str | Path | LogSource | Sequence[str | Path | LogSource], progress: Progress | None = None,
          **fields_: Any) -> AllanAnalysis:
    """Allan deviation, five-term noise fit and noise figures of static recordings: ``imu-align allan``.

    Parameters
    ----------
    logs : path, LogSource, or a sequence of them
        One static recording, or several runs of one sensor (pooled). A :class:`~align.io.source.LogSource`
        gives its columns, time column, rate, unit and format to the job.
    progress : callable, optional
        Called with the samples read so far.
    **fields_
        Any field of :class:`AllanOptions` (``columns="gx,gy,gz"``, ``rate_hz=100.0``,
        ``units="131 LSB/(deg/s)"``, ``rate=...`` rad/s and ``accuracy=...`` rad to plan, ...).

    Returns
    -------
    AllanAnalysis
        The deviations (in the unit of the readings, SI inside), the fits, the figures, the plan, and the
        provenance of the run.

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> from pathlib import Path
    >>> from align.noise.sim import NoiseSpec, simulate_noise
    >>> folder = Path(tempfile.mkdtemp())
    >>> np.save(folder / "rec.npy", simulate_noise(20_000, 100.0, NoiseSpec(white=1e-3), channels=3, seed=1))
    >>> res = allan(logs=folder / "rec.npy", rate_hz=100.0, gyro_units="rad/s")
    >>> res.result.adev.shape[0], res.runs
    (3, 1)
    """
    paths, given = sources_fields(logs, fields_)
    known = {f.name for f in fields(AllanOptions)}
    unknown = sorted(set(given) - known)
    if unknown:
        raise TypeError(f"allan() got unknown options: {', '.join(unknown)}")
    return ALLAN.run(AllanOptions(logs=paths, **given), progress=progress)


# ---------------------------------------------------------------------------------------------- plan


@dataclass(frozen=True, kw_only=True)
class PlanOptions:
    """Options of the ``plan`` job: an alignment goal and exactly one noise source.

    Attributes
    ----------
    rate : float
        Table rate, rad/s.
    accuracy : float
        Alignment goal, rad.
    noise_ratio : float
        Plan for noise this many times below the goal (> 0).
    arw : float or None
        Angle random walk, rad/sqrt(s) (a datasheet figure; with ``bias_instability``, ``rate_random_walk``).
    bias_instability : float or None
        Bias instability, rad/s (with ``arw``).
    rate_random_walk : float or None
        Rate random walk, rad/s/sqrt(s) (with ``arw``).
    imu : str or None
        A datasheet preset; a name that is not a preset labels the figures given with ``arw``.
    allan : Path or None
        A result of the ``allan`` job (``imu-align.allan`` JSON).
    parts : Path or None
        A parts file whose parts are laid over the presets.
    turn_angle : float
        Turn of the angle method, rad.
    settle : float
        Settling time added to each step, s.
    steps : int
        Table steps (6: +/- about three axes).
    """

    rate: float
    accuracy: float
    noise_ratio: float = quantity(10.0, "dimensionless", gt=0)
    arw: float | None = quantity(None, "angle_random_walk", ge=0)
    bias_instability: float | None = quantity(None, "angular_rate", ge=0)
    rate_random_walk: float | None = quantity(None, "rate_random_walk", ge=0)
    imu: str | None = None
    allan: Path | None = None
    parts: Path | None = None
    turn_angle: float = quantity(2 * math.pi, "angle", gt=0)
    settle: float = quantity(2.0, "time", ge=0)
    steps: int = 6

    def __post_init__(self) -> None:
        for name in ("allan", "parts"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, Path(value))


@dataclass(frozen=True)
class PlanInputs:
    """The checked noise source of a ``plan`` job.

    Attributes
    ----------
    allan : AllanAnalysis or None
        The Allan result read from ``options.allan``.
    preset : Part or None
        The datasheet preset named by ``options.imu``.
    parts : Mapping or None
        The parts table the preset was looked up in.
    """

    allan: AllanAnalysis | None = None
    preset: Any = None
    parts: Mapping | None = None


def _figure(value: float, unit: str) -> str:
    return f"{to_unit(value, unit):g} {unit}"


def read_plan(options: PlanOptions) -> PlanInputs:
    """The noise source of a ``plan`` job, read and checked: exactly one of ``arw``, a preset ``imu`` and ``allan``.

    Raises
    ------
    InputError
        No noise source or several; ``bias_instability`` or ``rate_random_walk`` without ``arw``; an unknown
        part without ``arw``; an Allan file that is not one (or holds accelerometer data: see :func:`compute_plan`).
    """
    from align.parts import find_part, get_part

    table = None
    if options.parts is not None:
        from align.io import read_toml
        from align.parts import merge_parts, parts_from_dict

        table = merge_parts(parts_from_dict(read_toml(options.parts), str(options.parts)))
    preset = None if options.imu is None else find_part(options.imu, table)
    if options.imu is not None and preset is None and options.arw is None:
        try:
            get_part(options.imu, "{imu}", table)
        except InputError as exc:  # naming the known parts and the parts file; or the label
            raise InputError(f"{exc.message}, or give {{arw}} (and {{bias_instability}}) to use it as a label",
                             exc.where) from None
    if sum(x is not None for x in (options.arw, preset, options.allan)) != 1:
        raise InputError("give exactly one noise source: {arw} X [{bias_instability} Y] (with {imu} NAME, a name that "
                         "is not a preset, as its label), {imu} PART (a preset) or {allan_json} RESULT.json", "plan")
    if options.arw is None and (options.bias_instability or options.rate_random_walk):
        raise InputError("goes with {arw}", "{bias_instability}" if options.bias_instability else "{rate_random_walk}")
    job: AllanAnalysis | None = None
    if options.allan is not None:
        from align.results import load_result

        job = load_result(options.allan, expect=(AllanAnalysis,))  # type: ignore[assignment]
    return PlanInputs(job, preset, table)


def compute_plan(inputs: PlanInputs, options: PlanOptions, progress: Progress | None = None) -> PlanResult:
    """The averaging time and the whole test plan (reference Example 3) from the noise source.

    Returns
    -------
    PlanResult
        Its ``inputs``: the preset (and parts file) or the label used.
    """
    common: dict[str, Any] = dict(turn_angle=options.turn_angle, steps=options.steps, settle=options.settle)
    if inputs.allan is not None:
        return plan_from_allan(inputs.allan, options.rate, options.accuracy, options.noise_ratio,
                               where=str(options.allan), **common)
    record: dict[str, Any] = {}
    if options.arw is not None:
        b, k = options.bias_instability or 0.0, options.rate_random_walk or 0.0
        label = (f"model: ARW {_figure(options.arw, 'deg/sqrt(h)')}" + (f", bias instability {_figure(b, 'deg/h')}"
                                                                        if b else "")
                 + (f", RRW {_figure(k, 'deg/h/sqrt(h)')}" if k else ""))
        curve = model_curve(options.arw, b, k)
        if options.imu is not None:
            label, record = f"{options.imu.strip()} (a label, not a preset): {label}", {"imu": options.imu.strip()}
    else:
        preset = inputs.preset
        label, curve = preset_model(preset)  # its N: arw, else noise_density; its B when stated
        used = ["arw" if preset.arw is not None else "noise_density", "bias_instability"]
        record = {"imu": preset.name, "preset": preset.provenance(used)}
    if options.parts is not None and options.imu is not None:
        record["parts"] = str(options.parts)
    return make_plan(options.rate, options.accuracy, options.noise_ratio, label, sigma=curve, **common).replace(
        inputs=record)


def plan_files(options: PlanOptions) -> dict[str, Path | None]:
    """The Allan result and the parts file, when given."""
    return {"allan": options.allan, "parts": options.parts}


PLAN: Job[PlanOptions, PlanInputs, PlanResult] = Job(
    "plan", PlanOptions, read_plan, compute_plan, plan_files,
    "Averaging time per table step for an alignment goal (Example 3), and the whole plan")


@fields_signature(PlanOptions)
def plan(*, progress: Progress | None = None, **fields_: Any) -> PlanResult:
    """The test plan for an alignment goal: ``imu-align plan``.

    Parameters
    ----------
    progress : callable, optional
        Unused (the plan is immediate).
    **fields_
        The fields of :class:`PlanOptions`: ``rate`` (rad/s), ``accuracy`` (rad) and one noise source
        (``arw`` rad/sqrt(s) [``bias_instability`` rad/s], ``imu`` a preset, or ``allan`` a result file).

    Returns
    -------
    PlanResult
        Noise target, averaging time per step and the whole plan, with its provenance.

    Examples
    --------
    >>> from align.units import DEG
    >>> p = plan(rate=100 * DEG, accuracy=0.1 * DEG, arw=0.3 * DEG / 60)
    >>> round(p.noise_target * 3600 / DEG, 2)
    62.83
    """
    return PLAN.run(PlanOptions(**fields_), progress=progress)
