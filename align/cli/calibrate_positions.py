"""``imu-align calibrate positions``: gyro bias (and where observable scale, misalignment and g-sensitivity) with
Earth rate, and the accelerometer from gravity, over indexed static positions on a table pointed north (seed 000's
six-, twelve- and twenty-four-position methods); the work is the library job
:data:`align.calibration.jobs.positions.POSITIONS`.

Also ``simulate_positions``, the command ``imu-align simulate positions`` (a rehearsal of the test with known truth).

Public names
------------
positions, positions_options, simulate_positions
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from align.cli import options as opt
from align.cli.options import ANY, DURATION, NONNEGATIVE, POSITIVE
from align.cli.paths import check_outputs, judged_outcome, write_run

if TYPE_CHECKING:
    from align.calibration.jobs.positions import PositionsOptions


def positions_options(*, log: Path, positions: Path, gyro_columns: str | None = None,
                      accel_columns: str | None = None, accel_log: Path | None = None, time_column: str | None = None,
                      rate_hz: float | None = None, gyro_units: str | None = None, accel_units: str | None = None,
                      latitude: float | None = None, gravity: float | None = None, g_sensitivity: bool = True,
                      gyro_scale: bool = True,
                      window: float = 1.0, factor: float = 6.0, init_static: float | None = None,
                      min_static: float = 1.0, max_rate: float = math.radians(0.5), frame: Path | None = None,
                      limits: Path | None = None, skip_rows: int = 0, comment: str | None = None,
                      delimiter: str | None = None, time_units: str | None = None, topic: str | None = None,
                      stamps: str | None = None, **_: Any) -> PositionsOptions:
    """The job's options from the command's parameters (Python names; output options and unknown keys ignored)."""
    from align.calibration.jobs.positions import PositionsOptions

    fmt = dict(skip_rows=skip_rows, comment=comment, delimiter=delimiter, time_units=time_units, topic=topic,
               stamps=stamps)
    gyro = opt.log_source(log, gyro_columns, rate_hz=rate_hz, units=gyro_units, time_column=time_column, **fmt)
    accel = None
    if accel_log is not None or accel_columns is not None or accel_units is not None:
        accel = opt.log_source(accel_log if accel_log is not None else log, accel_columns, rate_hz=rate_hz,
                               units=accel_units, time_column=time_column if accel_log is not None else None, **fmt)
    return PositionsOptions(log=gyro, accel=accel, positions=positions, latitude=latitude, gravity=gravity,
                            g_sensitivity=g_sensitivity, gyro_scale=gyro_scale, window_s=window, factor=factor,
                            init_static_s=init_static, min_static_s=min_static, max_rate=max_rate, frame=frame, limits=limits)


def positions(
    log: opt.Arg("Session log: the static positions in order, separated by table moves (gyro columns, and the "
                 "accelerometer's unless --accel-log).", "LOG"),
    positions: opt.Input("--positions", "Positions TOML: latitude, gravity, and scheme = 'six' | 'twelve' | "
                         "'twenty-four', or [[position]] tables (up and north axes, or roll/pitch/yaw to "
                         "north-east-down; start/end samples or none: detected).", "POSITIONS.toml"),
    gyro_columns: opt.Columns("Gyro columns x,y,z (default gyro_x,gyro_y,gyro_z); four names time,x,y,z name the time "
                              "column first.", "--gyro-columns", optional=True) = None,
    accel_columns: opt.Columns("Accelerometer columns x,y,z (default acc_x,acc_y,acc_z).", "--accel-columns",
                               optional=True) = None,
    accel_log: opt.OptInput("--accel-log", "The accelerometer in a second file with the same time stamps.",
                            "FILE") = None,
    time_column: opt.TimeColumn = None,
    rate_hz: opt.RateHz() = None,
    gyro_units: opt.GyroUnits("Gyro unit, e.g. deg/s, rad/s, mdps.", stated=True) = None,
    accel_units: opt.UnitFlag("--accel-units", "Accelerometer unit (an acceleration)." + opt.stated_default("m/s^2"))
        = None,
    latitude: opt.OptQuantity("--latitude", "angle", "Geodetic latitude of the table (default: the positions "
                              "file's).", "ANGLE", ANY, "'45 deg'") = None,
    gravity: opt.OptQuantity("--gravity", "acceleration", "Local gravity (default: the positions file's, else "
                             "9.80665 m/s^2).", "ACCEL", POSITIVE, "'9.81 m/s^2'") = None,
    g_sensitivity: opt.Flag("--g-sensitivity/--no-g-sensitivity", "Model the gyro's g-sensitivity K_ga (gyro = M w + "
                            "K_ga f + b); --no-g-sensitivity assumes it zero.") = True,
    gyro_scale: opt.Flag("--gyro-scale/--no-gyro-scale", "Estimate the gyro's M from Earth rate where the positions "
                         "make it observable (weakly, for most gyros: 15 deg/h); --no-gyro-scale takes it as the "
                         "identity and estimates only the bias and K_ga.") = True,
    window: opt.Quantity("--window", "time", "Variance window of the static detector.", "TIME", DURATION, "'1 s'") = "1 s",
    factor: opt.Number("--factor", "Static threshold: this many times the quiet variance (> 0).", POSITIVE, "6",
                       "FACTOR") = 6.0,
    init_static: opt.OptQuantity("--init-static", "time", "Initial static period for the threshold, e.g. '50 s'.",
                                 "TIME", DURATION, "'50 s'") = None,
    min_static: opt.Quantity("--min-static", "time", "Shortest static position.", "TIME", DURATION, "'1 s'") = "1 s",
    max_rate: opt.Quantity("--max-rate", "angular_rate", "Largest mean gyro rate of a static sample (a turn about the "
                           "vertical leaves the accelerometer still).", "RATE", POSITIVE, "'0.5 deg/s'") = "0.5 deg/s",
    frame: opt.OptInput("--frame", "A rate-table result of the same gyro (alignment or calibration JSON): its M is "
                        "taken as known and only the gyro's bias and K_ga are estimated.", "RESULT.json") = None,
    json_out: opt.JsonOut = None,
    limits: opt.Limits = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    time_units: opt.TimeUnits = None,
    topic: opt.Topic = None,
    stamps: opt.Stamps = None,
) -> None:
    """Multi-position static calibration with Earth rate: gyro bias (scale and g-sensitivity where the positions make
    them observable; the others reported as not observable), accelerometer bias, scale and misalignment."""
    params = dict(locals())
    check_outputs([log, positions, accel_log, frame, limits], json_out=json_out)
    from align.calibration.jobs.positions import POSITIONS

    result, _ = POSITIONS.run_with_inputs(positions_options(**params))
    write_run(json_out, result)
    from align.present.text import positions_summary

    typer.echo(positions_summary(result))
    judged_outcome(result)


def simulate_positions(
    out_dir: opt.Arg("Folder for positions.csv, positions.toml and truth.json (created if missing).", "OUT_DIR"),
    scheme: opt.Choice("--scheme", ("six", "twelve", "twenty-four"), "The standard positions (seed 000).") = "twelve",
    latitude: opt.Quantity("--latitude", "angle", "Latitude of the table.", "ANGLE", ANY, "'45 deg'") = "45 deg",
    rate_hz: opt.RateHz("Sample rate.") = "100 Hz",
    dwell: opt.Quantity("--dwell", "time", "Time held in each position.", "TIME", DURATION, "'60 s'") = "60 s",
    move: opt.Quantity("--move", "time", "Length of each table move.", "TIME", DURATION, "'10 s'") = "10 s",
    noise: opt.Quantity("--noise", "angle_random_walk", "Gyro angle random walk (white rate noise).", "ARW",
                        NONNEGATIVE, "'0.05 deg/sqrt(h)'") = "0.05 deg/sqrt(h)",
    accel_noise: opt.Quantity("--accel-noise", "velocity_random_walk", "Accelerometer white noise.", "VRW",
                              NONNEGATIVE, "'0.001 m/s^2/sqrt(Hz)'") = "0.001 m/s^2/sqrt(Hz)",
    seed: opt.Seed = 0,
    force: Annotated[bool, typer.Option("--force", help="Replace the files the folder already holds.")] = False,
) -> None:
    """Simulate indexed static positions on a table pointed north, with Earth rate (for calibrate positions):
    positions.csv (time, gyro deg/s, accel m/s^2), positions.toml and truth.json."""
    from align.calibration.jobs.positions import rehearsal
    from align.cli.paths import outputs
    from align.cli.simulate import refuse_replacing
    from align.errors import InputError

    if abs(latitude) > math.pi / 2:
        raise InputError("give a latitude within -90..90 deg", "{latitude}")
    names = ("positions.csv", "positions.toml", "truth.json")
    check_outputs([], folder=("out_dir", out_dir, names))
    refuse_replacing("out_dir", out_dir, names, force)
    columns, table, text, truth = rehearsal(opt.value(scheme), latitude, seed, rate_hz, dwell, move, noise, accel_noise)
    with outputs() as out:
        out.folder(out_dir)
        out.write_csv(out_dir / names[0], columns, table)
        out.write_text(out_dir / names[1], text)
        out.write_json(out_dir / names[2], truth)
    typer.echo(f"wrote {out_dir}/positions.csv ({len(table)} rows, {len(truth['positions'])} positions), "
               "positions.toml and truth.json")
