"""``imu-align matrix``: the alignment matrix M and A = M^-1 from a rate-table log (:data:`align.alignment.jobs.MATRIX`).

Public names
------------
matrix, matrix_options, matrix_files, GYRO_COLUMNS, COMMANDS
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from align.cli import options as opt
from align.cli.options import DURATION, PAUSE, POSITIVE, TOLERANCE, value
from align.cli.paths import check_outputs, judged_outcome, write_run
from align.vocab import Sensor

#: the columns ``matrix`` reads by default, time first (the old spelling of ``--columns``, still accepted)
GYRO_COLUMNS = ",".join(("time", *Sensor.GYROSCOPE.columns))

Log = opt.Arg("Gyro log: .csv, .csv.gz, .npy, .parquet, or a log of several streams (a ROS bag, a ULog, a DataFlash "
              "log: --topic; 'imu-align inspect LOG' lists them).", "LOG")


def matrix_options(*, log: Path, plan: Path, method: Any = "auto", gyro_units: str | None = None,
                   columns: str | None = None, time_column: str | None = None, rate_hz: float | None = None,
                   segments: Path | None = None, gyro_range: float | None = None, min_dwell: float | None = None,
                   window: float | None = None, margin: float | None = None, static_threshold: float | None = None,
                   rate_tolerance: float | None = None, scale_tolerance: float | None = None,
                   axis_to_axis: float | None = None, scale_spec: float | None = None, two_axis_variant: Any = None,
                   earth: bool | None = None, skip_rows: int = 0, comment: str | None = None,
                   delimiter: str | None = None, time_units: str | None = None, topic: str | None = None,
                   stamps: str | None = None, limits: Path | None = None, **_: Any):
    """The :class:`align.alignment.jobs.MatrixOptions` of ``imu-align matrix``'s parameters (SI, as the options
    parse them; output options and unknown keys ignored; a parameter left None keeps the job's default)."""
    from align.alignment.jobs import MatrixOptions

    variant = None if two_axis_variant is None else value(two_axis_variant)
    given: dict[str, Any] = {
        "method": value(method), "two_axis_variant": variant, "segments": segments, "gyro_range": gyro_range,
        "min_dwell": min_dwell, "window": window, "margin": margin, "static_threshold": static_threshold,
        "rate_tolerance": rate_tolerance, "scale_tolerance": scale_tolerance, "axis_to_axis": axis_to_axis,
        "scale_spec": scale_spec, "earth": earth}
    source = opt.log_source(log, columns, rate_hz=rate_hz, units=gyro_units, time_column=time_column,
                            skip_rows=skip_rows, comment=comment, delimiter=delimiter, time_units=time_units, topic=topic,
                            stamps=stamps)
    return MatrixOptions(limits=limits, log=source, plan=plan, **{k: v for k, v in given.items() if v is not None})


def matrix_files(result, inputs, params: dict) -> list[tuple[Path, bytes | str]]:
    """The C header ``--c-header`` and the segmentation picture ``--plot`` ask for (drawn before anything is
    written); ``inputs``: the job's checked inputs (the picture needs the log), or None without ``--plot``."""
    out: list[tuple[Path, bytes | str]] = []
    if params.get("c_header") is not None:
        out.append((params["c_header"], result.as_c_header(f"imu-align alignment from {Path(params['log']).name}")))
    if params.get("plot") is not None:
        from align.present.plots import segmentation_plot_png

        out.append((params["plot"], segmentation_plot_png(inputs.log.t, inputs.log.data, result, result.units)))
    return out


def matrix(
    log: Log,
    plan: opt.Input("--plan", "Test plan TOML: [[step]] tables (axis, rate or angle), optional [mounting] and [test] "
                    "(latitude, table_axis, rest).", "PLAN.toml"),
    method: opt.Choice("--method", ("auto", "rate", "angle", "lsq", "two-axis"),
                   "Estimator; auto: lsq for three turned axes, two-axis for two.") = "auto",
    gyro_units: opt.GyroUnits(stated=True) = None,
    columns: opt.Columns("Gyro columns: x,y,z (with --time-column, default time), or time,x,y,z (time first); "
                         f"default {GYRO_COLUMNS}.", optional=True) = None,
    time_column: opt.TimeColumn = None,
    rate_hz: opt.RateHz() = None,
    segments: opt.OptInput("--segments", "Explicit segments JSON {name: {start, end}} instead of automatic.",
                       "SEGMENTS.json") = None,
    json_out: opt.JsonOut = None,
    limits: opt.Limits = None,
    c_header: opt.OptInput("--c-header", "Write A and the bias as a C header here.", "FILE.h") = None,
    gyro_range: opt.OptQuantity("--gyro-range", "angular_rate", "Gyro full scale, e.g. '2000 deg/s': flags saturation.",
                            "RATE", POSITIVE, "'2000 deg/s'") = None,
    min_dwell: opt.Quantity("--min-dwell", "time", "Shortest acceptable step.", "TIME", DURATION, "'1 s'") = "1 s",
    window: opt.Quantity("--window", "time", "Moving-mean window of the segmentation.", "TIME", DURATION,
                         "'0.1 s'") = "0.1 s",
    margin: opt.Quantity("--margin", "time", "Trimmed from each end of a dwell beyond the ramp.", "TIME", PAUSE,
                         "'0.1 s'") = "0.1 s",
    static_threshold: opt.Quantity("--static-threshold", "angular_rate",
                               "Static periods lie within this of the quietest one (angle plans).", "RATE", POSITIVE,
                                   "'1 deg/s'") = "1 deg/s",
    rate_tolerance: opt.Quantity("--rate-tolerance", "dimensionless", "Largest difference of a measured turn from the plan.",
                             "RATIO", TOLERANCE, "'10 %'") = "10 %",
    scale_tolerance: opt.Quantity("--scale-tolerance", "dimensionless", "Scale factors must lie within 1 +/- this.",
                              "RATIO", TOLERANCE, "'5 %'") = "5 %",
    axis_to_axis: opt.Quantity("--axis-to-axis", "angle", "Axis-to-axis spec for the two-axis shortcut's error.",
                           "ANGLE", POSITIVE, "'0.05 deg'") = "0.05 deg",
    scale_spec: opt.Quantity("--scale-spec", "dimensionless", "Scale-factor spec (1 sigma) of the gyro the two-axis "
                             "shortcut cannot measure: its assumed scale's uncertainty.", "RATIO", TOLERANCE,
                             "'1 %'") = "1 %",
    two_axis_variant: opt.Choice("--two-axis-variant", ("procrustes", "cross"),
                             "Two-axis shortcut: procrustes, or cross (the source's Eq 36).") = "procrustes",
    earth: opt.Flag("--earth/--no-earth", "Model the Earth rate, as far as the plan's table geometry allows, when it "
                    "gives a latitude.") = True,
    plot: opt.OptInput("--plot", "Picture of the segmentation: steps, static periods, ramps and motions left out (PNG).",
                       "SEGMENTS.png") = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    time_units: opt.TimeUnits = None,
    topic: opt.Topic = None,
    stamps: opt.Stamps = None,
) -> None:
    """Alignment matrix M and A = M^-1 from rate-table data."""
    params = dict(locals())
    check_outputs([log, plan, segments, limits], json_out=json_out, c_header=c_header, plot=plot)
    from align.alignment.jobs import MATRIX
    from align.present.text import alignment_summary

    result, inputs = MATRIX.run_with_inputs(matrix_options(**params))
    write_run(json_out, result, matrix_files(result, inputs, params))  # all or none: the picture drawn first
    typer.echo(alignment_summary(result))
    judged_outcome(result)


COMMANDS = {"matrix": matrix}
