"""``imu-align calibrate gyro``: accelerometer and gyro from static poses and free rotations (no rate table); the
work is the library job :data:`align.calibration.jobs.GYRO`.

Public names
------------
gyro, gyro_options, gyro_files, rotation_table, Mounting
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from align.cli import options as opt
from align.cli.mounting import MountingOption, parse_mounting_option
from align.cli.options import DURATION, POSITIVE, names
from align.cli.paths import check_outputs, judged_outcome, write_run

if TYPE_CHECKING:
    from align.calibration.jobs import GyroInputs, GyroOptions
    from align.calibration.results import CalibrationSet

#: ``--mounting`` of ``calibrate gyro`` (no plan here: none unless given)
Mounting = Annotated[MountingOption | None, typer.Option(
    "--mounting", parser=parse_mounting_option, metavar="MOUNTING",
    help="Nominal mounting of the IMU, for the system frame: the system axis of the accelerometer's (and gyros') x, "
         "y, z ('+y,-x,+z'), or a rotation ('30 deg about +z', '30 deg about 1,1,0'). Default: none (the "
         "accelerometer frame).")]


def rotation_table(rows) -> str:
    """The per-rotation lines: times, turn, axis, residual; ``rows`` the calibration's rotation table
    (:attr:`align.calibration.results.Calibration.rotations`, what the file holds)."""
    lines = ["rotations (residual: angle between the predicted and the measured gravity direction at the next pose):",
             "  rotation  poses      t [s]          turn [deg]  axis (accelerometer frame)  residual [deg]"]
    for r in rows:
        k, (t0, t1) = r["rotation"], r["t_s"]
        axis = " ".join(f"{v:+.2f}" for v in r["axis"])
        left = "" if r["used"] else "  (left out: a check)"
        lines.append(f"  {k:>8}  {k:>2}->{k + 1:<3}  {t0:7.1f}-{t1:<7.1f}  {r['turn_deg']:9.1f}   {axis:<26}  "
                     f"{r['residual_deg']:9.3f}{left}")
    used = [r for r in rows if r["used"]]
    if used:
        big = max(used, key=lambda r: r["residual_deg"])
        lines.append(f"  largest residual: rotation {big['rotation']}, {big['residual_deg']:.3g} deg")
    return "\n".join(lines)


def gyro_options(*, log: Path, gyro_columns: str | None = None, accel_columns: str | None = None,
                 accel_log: Path | None = None, time_column: str | None = None, rate_hz: float | None = None,
                 accel_units: str | None = None, gyro_units: str | None = None, gravity: float = 9.80665,
                 window: float = 1.0, factor: float = 6.0, gyro_factor: float = 1000.0,
                 init_static: float | None = None, min_static: float = 1.0, intervals: str | None = None,
                 gyro_range: str | float | None = None, drop_rotations: str | None = None,
                 g_sensitivity: bool = False, frame: Path | None = None,
                 mounting: MountingOption | str | None = None, skip_rows: int = 0, comment: str | None = None,
                 delimiter: str | None = None, time_units: str | None = None, topic: str | None = None,
                 stamps: str | None = None, limits: Path | None = None, **_: Any) -> GyroOptions:
    """The job's options from the command's parameters (Python names; output options and unknown keys ignored).

    Returns
    -------
    GyroOptions
    """
    from align.calibration.jobs import GyroOptions
    from align.errors import InputError
    from align.io.logs import sensor_scale
    from align.units import parse_quantity

    fmt = dict(skip_rows=skip_rows, comment=comment, delimiter=delimiter, time_units=time_units, topic=topic,
               stamps=stamps)
    gyro = opt.log_source(log, gyro_columns, rate_hz=rate_hz, units=gyro_units, time_column=time_column, **fmt)
    accel = opt.log_source(accel_log if accel_log is not None else log, accel_columns, rate_hz=rate_hz,
                           units=accel_units, time_column=time_column if accel_log is not None else None, **fmt)
    grange: float | None
    if isinstance(gyro_range, str):
        shown = sensor_scale(gyro_units or "deg/s", "angular_rate", "gyro_units", counts=True)[1]
        grange = parse_quantity(gyro_range, "counts" if shown == "counts" else "angular_rate", "{gyro_range}")
    else:
        grange = gyro_range
    drop: tuple[int, ...] = ()
    if drop_rotations:
        try:
            drop = tuple(sorted({int(p) for p in names(drop_rotations)}))
        except ValueError:
            raise InputError("give rotation numbers, e.g. '1,5'", "{drop_rotations}") from None
    if isinstance(mounting, str):
        try:
            mounting = parse_mounting_option(mounting)
        except ValueError as exc:
            raise InputError(str(exc), "{mounting}") from None
    return GyroOptions(limits=limits,
                       log=gyro, accel=accel, gravity=gravity, window_s=window, factor=factor, gyro_factor=gyro_factor,
                       init_static_s=init_static, min_static_s=min_static, intervals=intervals, gyro_range=grange,
                       drop_rotations=drop, g_sensitivity=g_sensitivity, frame=frame,
                       mounting=None if mounting is None else mounting.rows,
                       mounting_text=None if mounting is None else mounting.text)


def gyro_files(result: CalibrationSet, inputs: GyroInputs, params: dict[str, Any]) -> list[tuple[Path, bytes | str]]:
    """The picture ``--plot`` asks for (beside the ``--json`` result): the session as calibrated, before any turn
    into the system frame."""
    plot = params.get("plot")
    if plot is None:
        return []
    from align.present.gyroplot import gyro_session_png

    session = inputs.session["session"]
    a_cal, g_cal = session.accelerometer, session.gyroscope
    force = a_cal.correct(inputs.acc.data)
    gravity = float(params.get("gravity") or 9.80665)
    return [(Path(plot), gyro_session_png(inputs.gyr.t, force, g_cal.correct(inputs.gyr.data, force),
                                          list(session.poses), list(g_cal.rotations), gravity))]


def gyro(
    log: opt.Arg("Session log: an initial static period, then 12 or more static poses reached by free rotations about "
                 "varied axes (gyro columns, and the accelerometer's unless --accel-log).", "LOG"),
    gyro_columns: opt.Columns("Gyro columns x,y,z (default gyro_x,gyro_y,gyro_z, or gyr_x,... / gx,... when the file "
                              "has those); four names time,x,y,z name the time column first.", "--gyro-columns",
                              optional=True) = None,
    accel_columns: opt.Columns("Accelerometer columns x,y,z in LOG, or in --accel-log (four names: that file's time "
                               "column first); default acc_x,acc_y,acc_z (or accel_x,... / ax,...).", "--accel-columns",
                               optional=True) = None,
    accel_log: opt.OptInput("--accel-log", "The accelerometer in a second file with the same time stamps.",
                            "FILE") = None,
    time_column: opt.TimeColumn = None,
    rate_hz: opt.RateHz() = None,
    accel_units: opt.UnitFlag("--accel-units", "Accelerometer unit, 'counts' (M then in counts per m/s^2), or the "
                              "size of one count ('16384 LSB/g')." + opt.stated_default("m/s^2")) = None,
    gyro_units: opt.GyroUnits("Gyro unit, e.g. deg/s, 'counts' (M then in counts per rad/s), or the size of one count "
                              "('131 LSB/(deg/s)').", stated=True) = None,
    gravity: opt.Quantity("--gravity", "acceleration", "Local gravity.", "ACCEL", POSITIVE, "'9.81 m/s^2'") =
        "9.80665 m/s^2",
    window: opt.Quantity("--window", "time", "Variance window of the static detector.", "TIME", DURATION, "'1 s'") = "1 s",
    factor: opt.Number("--factor", "Static threshold: this many times the variance of the initial static period "
                       "(imu_tk's T_init).", POSITIVE, "6", "FACTOR") = 6.0,
    gyro_factor: opt.Number("--gyro-factor", "Static threshold of the gyro: this many times its variance over the "
                            "initial static period (a pose held by hand wobbles it ~100x).", POSITIVE, "1000",
                            "FACTOR") = 1000.0,
    init_static: opt.OptQuantity("--init-static", "time", "Length of the initial static period (gyro bias, static "
                                 "threshold); default: detected.", "TIME", DURATION, "'50 s'") = None,
    min_static: opt.Quantity("--min-static", "time", "Shortest static pose.", "TIME", DURATION, "'1 s'") = "1 s",
    intervals: Annotated[str | None, typer.Option("--intervals", metavar="RANGES", help=(
        "The static poses as sample ranges start:end (end exclusive), e.g. '150:3613,4297:4354,...', the first the "
        "initial static period; default: detected."))] = None,
    gyro_range: Annotated[str | None, typer.Option("--gyro-range", metavar="RATE", help=(
        "The gyro's full scale ('250 deg/s'; in counts with --gyro-units counts): rotations with samples at it are "
        "refused. Default: flat tops at the record's extremes count as saturated."))] = None,
    drop_rotations: Annotated[str | None, typer.Option("--drop-rotations", metavar="LIST", help=(
        "Rotations left out of the fit (numbers from 1, e.g. '1,5'), e.g. saturated ones; reported as checks."))] = None,
    g_sensitivity: opt.Flag("--g-sensitivity/--no-g-sensitivity", "Model the gyro's g-sensitivity K_ga (raw = M w + "
                            "K_ga f + b): bias and K_ga from every pose's mean, removed before integrating. Default: "
                            "imu_tk's model, the bias from the initial static period.") = False,
    frame: opt.OptInput("--frame", "A rate-table result of the same gyro (alignment or calibration JSON): both sensors "
                        "are turned into its system frame, M = M_c R with R nearest to M_c^-1 M_table.",
                        "RESULT.json") = None,
    mounting: Mounting = None,
    json_out: opt.JsonOut = None,
    limits: opt.Limits = None,
    plot: opt.OptInput("--plot", "Picture of the session calibrated: |a| over the poses, |w| over the rotations with "
                       "their turn and residual (PNG).", "SESSION.png") = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    time_units: opt.TimeUnits = None,
    topic: opt.Topic = None,
    stamps: opt.Stamps = None,
) -> None:
    """Gyro (and accelerometer) calibration from rotations between static poses: imu_tk's method, no rate table.

    The gyro's M is relative to the accelerometer frame (gravity gives no reference about the vertical) unless
    --frame or --mounting gives the system frame: M_system = M R (w_accelerometer frame = R w_system).
    """
    params = dict(locals())
    check_outputs([log, accel_log, frame, limits], json_out=json_out, plot=plot)
    from align.calibration.jobs import GYRO
    from align.present.text import calibration_summary

    result, inputs = GYRO.run_with_inputs(gyro_options(**params))
    write_run(json_out, result, gyro_files(result, inputs, params))  # all or none
    typer.echo(calibration_summary(result.sensors))
    typer.echo(rotation_table(result.sensor("gyroscope").rotations))
    judged_outcome(result)
