"""``imu-align calibrate gyro``: accelerometer and gyro from static poses and free rotations (no rate table).

Registered with the other calibrations in :mod:`align.cli.calibrate`.

Public names
------------
gyro, rotation_table
"""

from __future__ import annotations

from typing import Annotated

import typer

from align.cli import options as opt
from align.cli.options import DURATION, POSITIVE, names, split_columns
from align.cli.paths import check_outputs, outputs
from align.cli.simulate import MountingOption, parse_mounting_option

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


def _split(text: str, rate_hz: float | None, field: str) -> tuple[str | None, list[str]]:
    """``'time,x,y,z'`` -> ``('time', [x, y, z])``; ``x,y,z`` with a sample rate."""
    from align.errors import InputError

    given = names(text)
    if len(given) != (3 if rate_hz is not None else 4):
        raise InputError("give four names time,x,y,z (three, x,y,z, with {rate_hz})", "{" + field + "}")
    return split_columns(text, rate_hz)


def _table_m(frame, where: str):
    """``M`` and its 1-sigma of the rate-table result in ``frame`` (an alignment, or a calibration file's gyroscope)."""
    from align.alignment.result import AlignmentResult
    from align.calibration import CalibrationSet
    from align.results import load_result

    got = load_result(frame, (AlignmentResult, CalibrationSet)).correction("gyroscope", where)
    return got.M, got.sigma_M


def _read(path, columns, units, time_col, rate_hz, fmt, field: str, columns_field: str, expect: str | None):
    """One sensor's log, its missing columns named with that sensor's option."""
    import align.io as fileio
    from align.errors import InputError

    try:
        return fileio.read_sensor_log(path, columns, units, time_col, rate_hz, expect=expect, log_format=fmt,
                                      counts=True, field=field)
    except InputError as exc:
        if "{columns}" not in exc.message:
            raise
        raise InputError(exc.message.replace("{columns}", "{" + columns_field + "}"), exc.where) from None


def gyro(
    log: opt.Arg("Session log: an initial static period, then 12 or more static poses reached by free rotations about "
                 "varied axes (gyro columns, and the accelerometer's unless --accel-log).", "LOG"),
    gyro_columns: opt.Columns("Gyro columns: time,x,y,z (x,y,z with --rate-hz).", "--gyro-columns") =
        "time,gyr_x,gyr_y,gyr_z",
    accel_columns: opt.Columns("Accelerometer columns: x,y,z in LOG; with --accel-log that file's time,x,y,z (x,y,z "
                               "with --rate-hz).", "--accel-columns") = "acc_x,acc_y,acc_z",
    accel_log: opt.OptInput("--accel-log", "The accelerometer in a second file with the same time stamps.",
                            "FILE") = None,
    rate_hz: opt.RateHz() = None,
    accel_units: opt.UnitFlag("--accel-units", "Accelerometer unit, 'counts' (M then in counts per m/s^2), or the "
                                               "size of one count ('16384 LSB/g').") = "m/s^2",
    gyro_units: opt.GyroUnits("Gyro unit, e.g. deg/s, 'counts' (M then in counts per rad/s), or the size of one count "
                              "('131 LSB/(deg/s)').") = "deg/s",
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
    plot: opt.OptInput("--plot", "Picture of the session calibrated: |a| over the poses, |w| over the rotations with "
                       "their turn and residual (PNG).", "SESSION.png") = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    time_units: opt.TimeUnits = None,
) -> None:
    """Gyro (and accelerometer) calibration from rotations between static poses: imu_tk's method, no rate table.

    The gyro's M is relative to the accelerometer frame (gravity gives no reference about the vertical) unless
    --frame or --mounting gives the system frame: M_system = M R (w_accelerometer frame = R w_system).
    """
    check_outputs([log, accel_log, frame], json_out=json_out, plot=plot)
    import numpy as np

    from align.calibration import CalibrationSet, StaticDetector
    from align.calibration.gyro import calibrate_gyro_session
    from align.calibration.gyroframe import in_system_frame
    from align.errors import InputError
    from align.present.text import calibration_summary
    from align.units import parse_quantity

    if frame is not None and mounting is not None:
        raise InputError("give the system frame once: a rate-table result or a mounting", "{frame}")
    fmt = opt.log_format(skip_rows, comment, delimiter, time_units)
    time_col, gcols = _split(gyro_columns, rate_hz, "gyro_columns")
    gyr = _read(log, gcols, gyro_units, time_col, rate_hz, fmt, "gyro_units", "gyro_columns", "angular_rate")
    if accel_log is None:
        if len(names(accel_columns)) != 3:
            raise InputError("give three names x,y,z of the accelerometer in the gyro's log", "{accel_columns}")
        acc = _read(log, names(accel_columns), accel_units, time_col, rate_hz, fmt, "accel_units", "accel_columns",
                    "acceleration")
    else:
        atime, acols = _split(accel_columns, rate_hz, "accel_columns")
        acc = _read(accel_log, acols, accel_units, atime, rate_hz, fmt, "accel_units", "accel_columns", "acceleration")
        step = float(np.median(np.diff(gyr.t)))
        if len(acc.t) != len(gyr.t) or np.abs(acc.t - gyr.t).max() > 0.5 * step:
            bad = min(len(acc.t), len(gyr.t))
            row = int(np.argmax(np.abs(acc.t[:bad] - gyr.t[:bad]) > 0.5 * step)) if bad else 0
            raise InputError(f"its {len(acc.t)} time stamps are not the gyro log's {len(gyr.t)} (first difference at "
                             f"row {row}); both sensors must be sampled together", str(accel_log))
    grange = None
    if gyro_range is not None:
        grange = parse_quantity(gyro_range, "counts" if gyr.shown == "counts" else "angular_rate", "{gyro_range}")
        if not grange > 0:
            raise InputError("give the full scale > 0, e.g. '250 deg/s'", "{gyro_range}")
    drop = ()
    if drop_rotations:
        try:
            drop = tuple(sorted({int(p) for p in names(drop_rotations)}))
        except ValueError:
            raise InputError("give rotation numbers, e.g. '1,5'", "{drop_rotations}") from None
    detector = StaticDetector(window, factor, init_static, min_static, gyro_factor)
    session = calibrate_gyro_session(gyr.t, acc.data, gyr.data, acc.shown, gyr.shown, gravity, detector, intervals,
                                     grange, drop, g_sensitivity, str(log),
                                     None if accel_log is None else str(accel_log))
    acc_cal, gyr_cal = session.accelerometer, session.gyroscope
    if frame is not None or mounting is not None:
        table, table_sigma = _table_m(frame, str(frame)) if frame is not None else (None, None)
        nominal = np.array(mounting.rows, float) if mounting is not None else None
        acc_cal, gyr_cal, _ = in_system_frame(acc_cal, gyr_cal, table, nominal,
                                              str(frame) if frame is not None else mounting.text, table_sigma)
    inputs = {"log": str(log), "accel_log": None if accel_log is None else str(accel_log), "gyro_columns": gyro_columns,
              "accel_columns": accel_columns, "accel_units": accel_units, "gyro_units": gyro_units,
              "intervals": intervals, "poses": [list(p) for p in session.poses], "dropped_rotations": list(drop),
              "g_sensitivity": g_sensitivity,
              "frame": None if frame is None else str(frame), "mounting": None if mounting is None else mounting.text,
              **gyr.inputs()}
    result = CalibrationSet({"accelerometer": acc_cal, "gyroscope": gyr_cal}, inputs)
    with outputs() as out:  # all or none
        if json_out is not None:
            out.write_json(json_out, result)
        if plot is not None:
            from align.present.gyroplot import gyro_session_png

            a_cal, g_cal = session.accelerometer, session.gyroscope
            force = a_cal.correct(acc.data)
            out.write_bytes(plot, gyro_session_png(gyr.t, force, g_cal.correct(gyr.data, force), list(session.poses),
                                                   list(g_cal.rotations), gravity))
    typer.echo(calibration_summary(result.sensors))
    typer.echo(rotation_table(gyr_cal.rotations))
