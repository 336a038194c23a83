"""``imu-align calibrate accel``: accelerometer multi-position calibration (known orientations, or ``|a| = g``
over many attitudes); the work is the library job :data:`align.calibration.jobs.ACCEL`.

Public names
------------
accel, accel_options, accel_files
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from align.cli import options as opt
from align.cli.options import DURATION, POSITIVE
from align.cli.paths import check_outputs, judged_outcome, write_run

if TYPE_CHECKING:
    from align.calibration.jobs import AccelInputs, AccelOptions
    from align.calibration.results import CalibrationSet

GRAVITY = "Local gravity"


def accel_options(*, log: Path, positions: Path | None = None, columns: str | None = None,
                  time_column: str | None = None, rate_hz: float | None = None, accel_units: str | None = None,
                  gravity: str | float | None = None, window: float = 1.0, factor: float = 6.0,
                  init_static: float | None = None, min_static: float = 1.0, skip_rows: int = 0,
                  comment: str | None = None, delimiter: str | None = None, time_units: str | None = None,
                  topic: str | None = None, stamps: str | None = None, limits: Path | None = None, **_: Any) -> AccelOptions:
    """The job's options from the command's parameters (Python names; output options and unknown keys ignored).

    Returns
    -------
    AccelOptions
    """
    from align.calibration.jobs import AccelOptions
    from align.units import parse_quantity

    g = gravity if gravity is None or isinstance(gravity, float) else parse_quantity(gravity, "acceleration",
                                                                                      "{gravity}")
    return AccelOptions(limits=limits,
                        log=opt.log_source(log, columns, rate_hz=rate_hz, units=accel_units, time_column=time_column,
                                           skip_rows=skip_rows, comment=comment, delimiter=delimiter,
                                           time_units=time_units, topic=topic, stamps=stamps),
                        positions=positions, gravity=g, window_s=window, factor=factor, init_static_s=init_static,
                        min_static_s=min_static)


def accel_files(result: CalibrationSet, inputs: AccelInputs, params: dict[str, Any]) -> list[tuple[Path, bytes | str]]:
    """The picture ``--plot`` asks for (beside the ``--json`` result)."""
    plot = params.get("plot")
    if plot is None:
        return []
    from align.calibration.accel import session_intervals
    from align.present.calplots import accel_statics_png
    from align.present.reread import stated_gravity
    from align.units import STANDARD_GRAVITY

    o = accel_options(**params)
    got = inputs.acc
    used = session_intervals(got.t, got.data, inputs.spec, o.detector, str(o.positions))
    gravity = o.gravity if o.gravity is not None else stated_gravity(inputs.spec) or STANDARD_GRAVITY
    return [(Path(plot), accel_statics_png(got.t, got.data, used, got.shown, calibration=result.sensor("accelerometer"),
                                           gravity=gravity))]


def accel(
    log: opt.Arg("Accelerometer log: static positions separated by moves.", "LOG"),
    positions: opt.OptInput("--positions", "Positions TOML ([[position]] tables: up, start/end, holdout); without it the "
                            "orientations are unknown and |a| = g is fitted.", "POSITIONS.toml") = None,
    columns: opt.Columns("Data columns x,y,z (default acc_x,acc_y,acc_z, or accel_x,... / ax,... when the file has "
                         "those); four names time,x,y,z name the time column first.", optional=True) = None,
    time_column: opt.TimeColumn = None,
    rate_hz: opt.RateHz() = None,
    accel_units: opt.UnitFlag("--accel-units", "Unit of the readings (an acceleration), 'counts', or the size of one "
                              "count: '16384 LSB/g'." + opt.stated_default("m/s^2")) = None,
    gravity: opt.Text("--gravity", "acceleration", GRAVITY + " (default 9.80665 m/s^2, or the positions file's gravity).",
                      "ACCEL", POSITIVE, "'9.81 m/s^2'") = None,
    window: opt.Quantity("--window", "time", "Variance window of the static detector.", "TIME", DURATION, "'1 s'") = "1 s",
    factor: opt.Number("--factor", "Static threshold: this many times the quiet variance (> 0).", POSITIVE, "6",
                       "FACTOR") = 6.0,
    init_static: opt.OptQuantity("--init-static", "time", "Initial static period for the threshold (imu_tk), e.g. '50 s'.",
                                 "TIME", DURATION, "'50 s'") = None,
    min_static: opt.Quantity("--min-static", "time", "Shortest static interval.", "TIME", DURATION, "'1 s'") = "1 s",
    json_out: opt.JsonOut = None,
    limits: opt.Limits = None,
    plot: opt.OptInput("--plot", "Picture of the static intervals (PNG).", "OUT.png") = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    time_units: opt.TimeUnits = None,
    topic: opt.Topic = None,
    stamps: opt.Stamps = None,
) -> None:
    """Accelerometer multi-position calibration (known orientations, or |a| = g over many attitudes)."""
    params = dict(locals())
    check_outputs([log, positions, limits], json_out=json_out, plot=plot)
    from align.calibration.jobs import ACCEL
    from align.present.text import calibration_summary

    result, inputs = ACCEL.run_with_inputs(accel_options(**params))
    write_run(json_out, result, accel_files(result, inputs, params))  # all or none
    typer.echo(calibration_summary(result.sensors))
    judged_outcome(result)
