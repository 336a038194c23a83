"""The ``matrix`` job: a rate-table gyro log and its plan -> the alignment ``M``, ``A = M^-1`` (and bias).

``imu-align matrix``, the report's alignment step, the batch and a notebook run
:data:`~align.alignment.jobs.MATRIX`; the package :mod:`align.alignment.jobs` re-exports its names.

Public names
------------
TWO_AXIS_VARIANTS, MatrixOptions, MatrixInputs, read_matrix, compute_matrix, matrix_input_files, MATRIX, matrix
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from align.alignment.jobs.common import check_unit_given, names_read, source
from align.alignment.pipeline import METHODS, AlignOptions, align
from align.alignment.plan import Plan
from align.alignment.result import AlignmentResult
from align.alignment.segment import Segment, SegmentOptions
from align.errors import InputError, literal
from align.io.logs import SensorLog
from align.io.source import LogSource
from align.job import Job, Progress, fields_signature, quantity
from align.units import DEG, DEG_S
from align.vocab import Sensor

__all__ = ["TWO_AXIS_VARIANTS", "MatrixOptions", "MatrixInputs", "read_matrix", "compute_matrix", "matrix_input_files",
           "MATRIX", "matrix"]

#: the two-axis shortcut's variants (``procrustes``, or ``cross``: the source's Eq 36)
TWO_AXIS_VARIANTS = ("procrustes", "cross")


@dataclass(frozen=True, kw_only=True)
class MatrixOptions:
    """What ``matrix`` estimates ``M`` and ``A = M^-1`` from, and how (every quantity in SI).

    Attributes
    ----------
    log : LogSource
        The rate-table gyro log (a str or Path is read with the defaults: columns ``gyro_x,gyro_y,gyro_z``,
        time column ``time``, the unit the file states, else deg/s). Its ``units`` is the gyro unit (None: the
        unit the file states, a ULog's or a bag's, else deg/s; one that disagrees with the file's is refused).
    plan : Path
        Test plan TOML: ``[[step]]`` tables (axis, rate or angle), optional ``[mounting]`` and ``[test]``.
    method : str
        ``"auto"``, ``"rate"``, ``"angle"``, ``"lsq"`` or ``"two-axis"``; auto: lsq for three turned axes,
        two-axis for two.
    two_axis_variant : str
        ``"procrustes"``, or ``"cross"`` (the source's Eq 36).
    segments : Path or None
        Explicit segments JSON ``{name: {start, end}}`` instead of automatic ones.
    gyro_range : float or None
        Gyro full scale, rad/s: segments reaching 99 % of it are rejected as saturated; None: not checked.
    min_dwell : float
        Shortest acceptable step, s.
    window : float
        Moving-mean window of the segmentation, s.
    margin : float
        Trimmed from each end of a dwell beyond the ramp, s.
    static_threshold : float
        Static periods lie within this of the quietest one, rad/s (angle plans).
    rate_tolerance : float
        Largest relative difference of a measured turn from the plan, dimensionless.
    scale_tolerance : float
        Scale factors must lie within ``1 +/- scale_tolerance``, dimensionless.
    axis_to_axis : float
        Axis-to-axis spec for the two-axis shortcut's error, rad.
    scale_spec : float
        Scale-factor spec (1 sigma, relative) of the gyro the two-axis shortcut cannot measure, dimensionless.
    earth : bool
        Model the Earth rate, as far as the plan's table geometry allows, when the plan gives a latitude.
    limits : Path or None
        A limits file (:mod:`align.limits`) to judge the figures of merit against; None: the default limits.
    """

    log: LogSource
    plan: Path
    method: str = "auto"
    two_axis_variant: str = "procrustes"
    segments: Path | None = None
    gyro_range: float | None = quantity(None, "angular_rate", gt=0)
    min_dwell: float = quantity(1.0, "time", gt=0, le=86400)
    window: float = quantity(0.1, "time", gt=0, le=86400)
    margin: float = quantity(0.1, "time", ge=0, le=86400)
    static_threshold: float = quantity(1.0 * DEG_S, "angular_rate", gt=0)
    rate_tolerance: float = quantity(0.10, "dimensionless", gt=0, le=1)
    scale_tolerance: float = quantity(0.05, "dimensionless", gt=0, le=1)
    axis_to_axis: float = quantity(0.05 * DEG, "angle", gt=0)
    scale_spec: float = quantity(0.01, "dimensionless", gt=0, le=1)
    earth: bool = True
    limits: Path | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "log", source(self.log))
        object.__setattr__(self, "plan", Path(self.plan))
        if self.segments is not None:
            object.__setattr__(self, "segments", Path(self.segments))
        object.__setattr__(self, "method", getattr(self.method, "value", self.method))
        object.__setattr__(self, "two_axis_variant", getattr(self.two_axis_variant, "value", self.two_axis_variant))
        if self.method not in METHODS:
            raise InputError(f"unknown method '{literal(str(self.method))}'; choose one of {', '.join(METHODS)}",
                             "{method}")
        if self.two_axis_variant not in TWO_AXIS_VARIANTS:
            raise InputError(f"unknown variant '{literal(str(self.two_axis_variant))}'; choose one of "
                             f"{', '.join(TWO_AXIS_VARIANTS)}", "{two_axis_variant}")

    def align_options(self) -> AlignOptions:
        """The estimator pipeline's settings (:class:`~align.alignment.pipeline.AlignOptions`)."""
        return AlignOptions(method=self.method, two_axis_variant=self.two_axis_variant, axis_to_axis=self.axis_to_axis,
                            segmentation=SegmentOptions(window_s=self.window, margin_s=self.margin,
                                                        static_threshold=self.static_threshold),
                            min_dwell=self.min_dwell, rate_tolerance=self.rate_tolerance,
                            scale_tolerance=self.scale_tolerance, gyro_range=self.gyro_range,
                            earth_correction=self.earth, scale_spec=self.scale_spec)


@dataclass(frozen=True)
class MatrixInputs:
    """The checked inputs of ``matrix``.

    Attributes
    ----------
    log : SensorLog
        The gyro log: ``t`` (n,) s, ``data`` (n, 3) rad/s.
    plan : Plan
    segments : list of Segment or None
        The explicit segments, checked against the plan and the log; None: found automatically.
    time_column : str or None
        The time column read (None: read at ``rate_hz``).
    columns : tuple of str
        The three gyro columns read.
    """

    log: SensorLog
    plan: Plan
    segments: list[Segment] | None
    time_column: str | None
    columns: tuple[str, ...]


def read_matrix(options: MatrixOptions) -> MatrixInputs:
    """Read and check the plan, the gyro log (through :meth:`LogSource.read`) and the explicit segments.

    Raises
    ------
    InputError, UnitError
        One line naming the file and the option (``{columns}``, ``{gyro_units}``, ``{rate_hz}``, ...).
    """
    from align.alignment.segment import segments_from_ranges
    from align.io import read_json, read_toml

    plan = Plan.from_dict(read_toml(options.plan), str(options.plan))
    src = options.log
    check_unit_given(src.units, Sensor.GYROSCOPE.dimension, "gyro_units")
    time, cols = names_read(src, Sensor.GYROSCOPE)
    got = src.read(Sensor.GYROSCOPE, field="gyro_units")
    segs = None if options.segments is None else \
        segments_from_ranges(read_json(options.segments), plan, len(got.t), str(options.segments))
    return MatrixInputs(got, plan, segs, time, tuple(cols))


def compute_matrix(inputs: MatrixInputs, options: MatrixOptions, progress: Progress | None = None) -> AlignmentResult:
    """Segmentation, checks and the estimator (:func:`align.alignment.pipeline.align`) on the checked inputs."""
    got, src = inputs.log, options.log
    result = align(got.t, got.data, inputs.plan, options.align_options(), inputs.segments, got.shown, str(src.path))
    columns = ",".join(([inputs.time_column] if inputs.time_column else []) + list(inputs.columns))
    result = result.replace(
        inputs={"log": str(src.path), "plan": str(options.plan), "gyro_units": got.units,
                "columns": columns, "segments": None if options.segments is None else str(options.segments),
                "rate_hz": src.rate_hz, "time_column": inputs.time_column, **got.inputs()},
        notes=result.notes + tuple(filter(None, [got.time_note()])) + got.remarks(str(src.path)))
    if progress is not None:
        progress(len(got.t))
    return result


def matrix_input_files(options: MatrixOptions) -> dict[str, Path | None]:
    """The input files: the log, the plan and the explicit segments."""
    return {"log": options.log.path, "plan": options.plan, "segments": options.segments}


MATRIX: Job[MatrixOptions, MatrixInputs, AlignmentResult] = Job(
    "matrix", MatrixOptions, read_matrix, compute_matrix, matrix_input_files,
    "alignment matrix M and A = M^-1 from a rate-table log and its plan")


@fields_signature(MatrixOptions)
def matrix(*, progress: Progress | None = None, **fields: Any) -> AlignmentResult:
    """The alignment of a gyro from a rate-table log and its plan, as ``imu-align matrix`` computes it.

    Parameters
    ----------
    progress : callable, optional
        Called with the samples done.
    **fields
        The fields of :class:`MatrixOptions`: ``log`` (a path, or a :class:`~align.io.source.LogSource`),
        ``plan`` (a path), and optionally ``method``, ``segments``, ``gyro_range`` (rad/s), ``min_dwell`` (s), ...

    Returns
    -------
    AlignmentResult
        ``M``, ``A = M^-1`` (3, 3), ``bias`` (3,) rad/s, their 1-sigma, the checks, with its provenance.

    Examples
    --------
    A session simulated with a known ``M``, aligned:

    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from align.alignment.plan import Plan
    >>> from align.alignment.simulate import SessionSpec, simulate_session
    >>> from align.io import write_csv
    >>> from align.model import SensorModel
    >>> from align.units import DEG
    >>> plan = Plan.standard_rate(100 * DEG)
    >>> truth = SensorModel(np.array([[1.002, 0.003, -0.002], [-0.004, 0.998, 0.001], [0.002, -0.001, 1.001]]),
    ...                     np.array([0.01, -0.02, 0.005]))
    >>> t, g, _ = simulate_session(plan, truth, SessionSpec(noise_density=0.0), seed=1)
    >>> folder = Path(tempfile.mkdtemp())
    >>> write_csv(folder / "session.csv", ["time", "gyro_x", "gyro_y", "gyro_z"], np.column_stack([t, g / DEG]))
    >>> _ = (folder / "plan.toml").write_text(plan.to_toml())
    >>> r = matrix(log=folder / "session.csv", plan=folder / "plan.toml")
    >>> bool(np.abs(r.M - truth.M).max() < 1e-4), r.provenance.job
    (True, 'matrix')
    """
    return MATRIX.run(MatrixOptions(**fields), progress=progress)
