"""``imu-align calibrate``: Ferraris sessions, accelerometer positions, magnetometer ellipsoid.

Public names
------------
app, ferraris, accel, mag, COMMANDS
"""

from typing import Annotated

import typer

from align.cli import options as opt
from align.cli.options import DIP, DURATION, NONZERO, POSITIVE, names, split_columns, value
from align.cli.paths import check_outputs, outputs

Gravity = "Local gravity"


def ferraris(
    log: opt.Arg("Session log (CSV) with accelerometer and gyro columns.", "LOG"),
    sections: opt.Input("--sections", "imucal section list JSON: x_p ... z_a, x_rot, y_rot, z_rot.", "SECTIONS.json"),
    rate_hz: opt.RateHz("Sample rate.", required=True),
    turn_angle: opt.Quantity("--turn-angle", "angle", "Signed angle of each turn about the axis pointing up.",
                         "ANGLE", NONZERO, "'-360 deg'") = "-360 deg",
    gravity: opt.Quantity("--gravity", "acceleration", Gravity + ".", "ACCEL", POSITIVE, "'9.81 m/s^2'") = "9.80665 m/s^2",
    accel_columns: opt.Columns("Accelerometer columns.", "--accel-columns") = "acc_x,acc_y,acc_z",
    gyro_columns: opt.Columns("Gyro columns.", "--gyro-columns") = "gyr_x,gyr_y,gyr_z",
    accel_units: opt.UnitFlag("--accel-units", "Accelerometer unit, or the size of one count ('16384 LSB/g').") = "m/s^2",
    gyro_units: opt.GyroUnits("Gyro unit.") = "deg/s",
    bias: opt.Choice("--bias", ("pairwise", "lsq"), "Accelerometer bias: pairwise (Ferraris, tilt-robust) or lsq.") = "pairwise",
    g_sensitivity: opt.Flag("--g-sensitivity/--no-g-sensitivity",
                        "Estimate the gyro's g-sensitivity from the static faces.") = True,
    json_out: opt.JsonOut = None,
    imucal_json: opt.OptInput("--imucal-json", "Also write the result as imucal's JSON.", "FILE.json") = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
) -> None:
    """A Ferraris session (six static faces and a turn about each axis), as imucal records it."""
    check_outputs([log, sections], json_out=json_out, imucal_json=imucal_json)
    import align.io as fileio
    from align.calibration import CalibrationSet, sections_from_dict
    from align.calibration import ferraris as compute
    from align.present.text import calibration_summary

    fmt = opt.log_format(skip_rows, comment, delimiter)
    acc = fileio.read_sensor_log(log, names(accel_columns), accel_units, None, rate_hz, expect="acceleration",
                                 log_format=fmt, field="accel_units")
    gyr = fileio.read_sensor_log(log, names(gyro_columns), gyro_units, None, rate_hz, log_format=fmt)
    ranges = sections_from_dict(fileio.read_json(sections), str(sections))
    acc_cal, gyr_cal = compute(acc.data, gyr.data, rate_hz, ranges, turn_angle, gravity, acc.shown, gyr.shown,
                               pairwise_bias=value(bias) == "pairwise", g_sensitivity=g_sensitivity, where=str(log))
    result = CalibrationSet({"accelerometer": acc_cal, "gyroscope": gyr_cal},
                            {"log": str(log), "sections": str(sections), "accel_units": accel_units,
                             "gyro_units": gyro_units, **fmt.to_dict()})
    with outputs() as out:  # all or none
        if json_out is not None:
            out.write_json(json_out, result)
        if imucal_json is not None:
            out.write_json(imucal_json, result.as_imucal())
    typer.echo(calibration_summary(result.sensors))


def accel(
    log: opt.Arg("Accelerometer log: static positions separated by moves.", "LOG"),
    positions: opt.OptInput("--positions", "Positions TOML ([[position]] tables: up, start/end, holdout); without it the "
                        "orientations are unknown and |a| = g is fitted.", "POSITIONS.toml") = None,
    columns: opt.Columns("Columns: time,x,y,z (x,y,z with --rate-hz).") = "time,acc_x,acc_y,acc_z",
    rate_hz: opt.RateHz() = None,
    accel_units: opt.UnitFlag("--accel-units", "Unit of the readings (an acceleration), 'counts', or the "
                                                "size of one count: '16384 LSB/g'.") = "m/s^2",
    gravity: opt.Text("--gravity", "acceleration", Gravity + " (default 9.80665 m/s^2, or the positions file's gravity).",
                      "ACCEL", POSITIVE, "'9.81 m/s^2'") = None,
    window: opt.Quantity("--window", "time", "Variance window of the static detector.", "TIME", DURATION, "'1 s'") = "1 s",
    factor: opt.Number("--factor", "Static threshold: this many times the quiet variance (> 0).", POSITIVE, "6",
                       "FACTOR") = 6.0,
    init_static: opt.OptQuantity("--init-static", "time", "Initial static period for the threshold (imu_tk), e.g. '50 s'.",
                             "TIME", DURATION, "'50 s'") = None,
    min_static: opt.Quantity("--min-static", "time", "Shortest static interval.", "TIME", DURATION, "'1 s'") = "1 s",
    json_out: opt.JsonOut = None,
    plot: opt.OptInput("--plot", "Picture of the static intervals (PNG).", "OUT.png") = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    time_units: opt.TimeUnits = None,
) -> None:
    """Accelerometer multi-position calibration (known orientations, or |a| = g over many attitudes)."""
    check_outputs([log, positions], json_out=json_out, plot=plot)
    import align.io as fileio
    from align.calibration import CalibrationSet, StaticDetector, calibrate_accel_log
    from align.present.text import calibration_summary
    from align.units import parse_quantity

    time_col, cols = split_columns(columns, rate_hz)
    fmt = opt.log_format(skip_rows, comment, delimiter, time_units)
    got = fileio.read_sensor_log(log, cols, accel_units, time_col, rate_hz, expect="acceleration", log_format=fmt,
                                 counts=True)  # an accelerometer may be calibrated in its counts
    spec = fileio.read_toml(positions) if positions is not None else None
    g = None if gravity is None else parse_quantity(gravity, "acceleration", "{gravity}")
    detector = StaticDetector(window, factor, init_static, min_static)
    cal = calibrate_accel_log(got.t, got.data, spec, got.shown, g, detector, str(log), str(positions))
    # how the log was read and the detector set: what the report needs to draw the session again
    result = CalibrationSet({"accelerometer": cal}, {
        "log": str(log), "positions": None if positions is None else str(positions), "accel_units": accel_units,
        "columns": columns, "rate_hz": rate_hz, "detector": {"window_s": window, "factor": factor,
                                                             "init_static_s": init_static, "min_static_s": min_static},
        **got.inputs()})
    with outputs() as out:
        if json_out is not None:
            out.write_json(json_out, result)
        if plot is not None:
            from align.calibration.accel import session_intervals
            from align.present.calplots import accel_statics_png

            used = session_intervals(got.t, got.data, spec, detector, str(positions))
            out.write_bytes(plot, accel_statics_png(got.t, got.data, used, got.shown))
    typer.echo(calibration_summary(result.sensors))


def mag(
    log: opt.Arg("Magnetometer capture while tumbling the device (CSV or blank-separated text).", "LOG"),
    columns: opt.Columns("Magnetometer columns (col0,col1,... for a file without header).") = "mag_x,mag_y,mag_z",
    mag_units: opt.UnitFlag("--mag-units", "Unit: uT, nT, gauss, mG, 'counts', or the size of one count, e.g. "
                        "'0.92 mG'.") = "uT",
    field: Annotated[str | None, typer.Option("--field", metavar="FIELD", help=(
        "Known field strength to refine to, e.g. '48.5 uT'."))] = None,
    model: opt.Choice("--model", ("sphere", "diagonal", "symmetric"), "Soft-iron model.") = "symmetric",
    accel_columns: opt.Columns("Simultaneous accelerometer columns (dip angle, alignment to gravity).", "--accel-columns",
                           optional=True) = None,
    dip: opt.OptQuantity("--dip", "angle", "Magnetic dip for the heading-error prediction when no accelerometer "
                         "(-90 to 90 deg).", "ANGLE", DIP, "'60 deg'") = None,
    axis_down: Annotated[str | None, typer.Option("--axis-down", metavar="x=FILE,y=FILE,z=FILE", help=(
        "Misalignment to the body axes from turns with each axis pointing down (seed 004): the device turned on a "
        "flat surface through a full turn with x, then y, then z down; each a file with the same columns, or samples "
        "of LOG as START:STOP (counted from 0, STOP exclusive; left out of the ellipsoid fit), e.g. "
        "'x=100:900,y=1000:1800,z=2000:2800'."))] = None,
    plot: opt.OptInput("--plot", "Picture of the capture before and after, and the heading error (PNG).",
                       "OUT.png") = None,
    json_out: opt.JsonOut = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
) -> None:
    """Magnetometer hard and soft iron (ellipsoid fit with coverage gates), and the misalignment from axis-down turns."""
    from align.calibration.axisdown import parse_axis_down

    spec = None if axis_down is None else parse_axis_down(axis_down)
    files = [v for v in (spec or {}).values() if isinstance(v, str)]
    check_outputs([log, *files], json_out=json_out, plot=plot)
    import align.io as fileio
    from align.calibration import calibrate_magnetometer, with_gravity_alignment
    from align.calibration.axisdown import axis_down_captures, with_axis_down
    from align.errors import InputError
    from align.io.logs import check_readings
    from align.present.text import magnetometer_summary
    from align.units import parse_quantity, parse_scale

    fmt = opt.log_format(skip_rows, comment, delimiter)
    scale, shown = parse_scale(mag_units, "magnetic_field", "{mag_units}")
    wanted = names(columns) + (names(accel_columns) if accel_columns else [])
    _, data = fileio.read_columns(log, wanted, log_format=fmt)
    check_readings(data, str(log))
    def read(path):  # an axis-down capture file: the log's columns, checked as the log is
        got = fileio.read_columns(path, wanted, log_format=fmt)[1]
        check_readings(got, str(path))
        return got

    captures, tumble = {}, data
    if spec is not None:
        captures, tumble = axis_down_captures(spec, data, str(log), read)
    m = tumble[:, :3] * scale
    acc = tumble[:, 3:6] if accel_columns else None
    f = None if field is None else parse_quantity(field, "counts" if shown == "counts" else "magnetic_field", "{field}")
    if f is not None and not f > 0:
        raise InputError("give a field strength > 0, e.g. '48.5 uT'", "{field}")
    cal = calibrate_magnetometer(m, shown, f, value(model), acc, dip, where=str(log))
    if spec is not None:
        cal = with_axis_down(cal, {a: c[0][:, :3] * scale for a, c in captures.items()},
                             {a: c[0][:, 3:6] for a, c in captures.items()} if accel_columns else None,
                             {a: c[1] for a, c in captures.items()})
    elif acc is not None:
        cal = with_gravity_alignment(cal, m, acc)
    cal = cal.replace(inputs={"log": str(log), "columns": columns, "mag_units": mag_units, **fmt.to_dict(),
                              **({"axis_down": axis_down} if axis_down is not None else {})})
    with outputs() as out:
        if json_out is not None:
            out.write_json(json_out, cal)
        if plot is not None:
            from align.present.calplots import magnetometer_png

            out.write_bytes(plot, magnetometer_png(m, cal))
    typer.echo(magnetometer_summary(cal))


from align.cli.gyrocal import gyro  # noqa: E402  (the command lives in its own module)

COMMANDS = {"ferraris": ferraris, "accel": accel, "mag": mag, "gyro": gyro}

app = typer.Typer(help="Sensor calibration: Ferraris sessions, accelerometer positions, magnetometer ellipsoid, gyro "
                       "without a rate table.",
                  add_completion=False, rich_markup_mode=None, pretty_exceptions_enable=False)
for _name, _command in COMMANDS.items():
    app.command(_name)(_command)
