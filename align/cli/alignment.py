"""Commands of the alignment family: ``matrix``, ``apply`` (``simulate`` is in :mod:`align.cli.simulate`).

Public names
------------
matrix, apply, GYRO_COLUMNS, SENSOR_COLUMNS, SENSOR_DIMENSIONS, COMMANDS
"""


import typer

from align.cli import options as opt
from align.cli.options import DURATION, PAUSE, POSITIVE, TOLERANCE, split_columns, value
from align.cli.paths import check_outputs, outputs

GYRO_COLUMNS = "time,gyro_x,gyro_y,gyro_z"
#: the columns ``apply`` reads by default, per sensor
SENSOR_COLUMNS = {"gyroscope": GYRO_COLUMNS, "accelerometer": "time,acc_x,acc_y,acc_z",
                  "magnetometer": "time,mag_x,mag_y,mag_z"}
#: the dimension of each sensor's readings (a key of ``align.units.DIMENSIONS``)
SENSOR_DIMENSIONS = {"gyroscope": "angular_rate", "accelerometer": "acceleration", "magnetometer": "magnetic_field"}

Log = opt.Arg("Gyro log: .csv, .csv.gz, .npy or .parquet.", "LOG")


def matrix(
    log: Log,
    plan: opt.Input("--plan", "Test plan TOML: [[step]] tables (axis, rate or angle), optional [mounting] and [test] "
                    "(latitude, table_axis, rest).", "PLAN.toml"),
    method: opt.Choice("--method", ("auto", "rate", "angle", "lsq", "two-axis"),
                   "Estimator; auto: lsq for three turned axes, two-axis for two.") = "auto",
    gyro_units: opt.GyroUnits() = "deg/s",
    columns: opt.Columns("Column names: time,x,y,z (x,y,z with --rate-hz).") = GYRO_COLUMNS,
    rate_hz: opt.RateHz() = None,
    segments: opt.OptInput("--segments", "Explicit segments JSON {name: {start, end}} instead of automatic.",
                       "SEGMENTS.json") = None,
    json_out: opt.JsonOut = None,
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
) -> None:
    """Alignment matrix M and A = M^-1 from rate-table data."""
    check_outputs([log, plan, segments], json_out=json_out, c_header=c_header, plot=plot)
    import align.io as fileio
    from align.alignment.job import AlignOptions, align
    from align.alignment.plan import Plan
    from align.alignment.segment import SegmentOptions, segments_from_ranges
    from align.present.text import alignment_summary

    time_col, cols = split_columns(columns, rate_hz)
    fmt = opt.log_format(skip_rows, comment, delimiter, time_units)
    the_plan = Plan.from_dict(fileio.read_toml(plan), str(plan))
    got = fileio.read_sensor_log(log, cols, gyro_units, time_col, rate_hz, log_format=fmt)
    t, g = got.t, got.data
    opts = AlignOptions(method=value(method), two_axis_variant=value(two_axis_variant), axis_to_axis=axis_to_axis,
                        segmentation=SegmentOptions(window_s=window, margin_s=margin, static_threshold=static_threshold),
                        min_dwell=min_dwell, rate_tolerance=rate_tolerance, scale_tolerance=scale_tolerance,
                        gyro_range=gyro_range, earth_correction=earth, scale_spec=scale_spec)
    segs = None if segments is None else segments_from_ranges(fileio.read_json(segments), the_plan, len(t), str(segments))
    result = align(t, g, the_plan, opts, segs, got.shown, str(log))
    result = result.replace(inputs={"log": str(log), "plan": str(plan), "gyro_units": gyro_units, "columns": columns,
                                    "segments": None if segments is None else str(segments), **got.inputs()},
                            notes=result.notes + tuple(filter(None, [got.time_note()])))
    with outputs() as out:  # all or none
        if json_out is not None:
            out.write_json(json_out, result)
        if c_header is not None:
            out.write_text(c_header, result.as_c_header(f"imu-align alignment from {log.name}"))
        if plot is not None:
            from align.present.plots import segmentation_plot_png

            out.write_bytes(plot, segmentation_plot_png(t, g, result, result.units))
    typer.echo(alignment_summary(result))


def apply(
    log: opt.Arg("Log to correct.", "LOG"),
    alignment: opt.Input("--alignment", "A result of 'matrix', 'calibrate ferraris', 'calibrate accel' or 'calibrate mag'.",
                     "RESULT.json"),
    out: opt.Input("--out", "Corrected CSV (same columns and units).", "OUT.csv"),
    sensor: opt.Choice("--sensor", ("accelerometer", "gyroscope", "magnetometer"),
                       "The sensor to correct, for a file holding several.") = None,
    gyro_units: opt.GyroUnits() = "deg/s",
    units: opt.Units("Unit of the columns for an accelerometer or magnetometer result (default: the result's).") = None,
    columns: opt.Columns("Column names: time,x,y,z (x,y,z with --rate-hz); default per sensor.", optional=True) = None,
    rate_hz: opt.RateHz() = None,
    plot: opt.OptInput("--plot", "Picture of the log before and after the correction (PNG).", "TRACES.png") = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    time_units: opt.TimeUnits = None,
) -> None:
    """Correct a log: gyro w = A (g - b); accelerometer M^-1 (a - b); magnetometer soft_iron (m - hard_iron)."""
    check_outputs([log, alignment], out=out, plot=plot)
    import numpy as np

    import align.io as fileio
    from align.errors import AlignError, UnitError, literal
    from align.io.formats import TIME_UNITS
    from align.plausible import check_corrected
    from align.results import load_result
    from align.units import DIMENSIONS, parse_unit

    fmt = opt.log_format(skip_rows, comment, delimiter, time_units)
    correction = load_result(alignment).correction(value(sensor), str(alignment))
    kind = correction.sensor
    if units:
        u, field = units, "units"
    elif kind == "gyroscope":
        u, field = gyro_units, "gyro_units"
    else:
        u, field = correction.units, "units"
    expect = SENSOR_DIMENSIONS[kind]
    try:
        own = parse_unit(correction.units).dim
    except AlignError:  # the size of one count ('0.92 mG'): the result holds readings of its dimension
        own = DIMENSIONS[expect][0].dim
    if own == DIMENSIONS["counts"][0].dim:
        expect = "counts"
    if kind != "gyroscope":
        try:
            given = parse_unit(u).dim
        except AlignError:  # a count size or a sensitivity ('16384 LSB/g'): read below, against the result's kind
            given = own
        if given != own:
            raise UnitError(f"'{literal(u)}' is not a unit of the {kind} data of {alignment} ({literal(correction.units)}); "
                            f"give the log's unit, e.g. {{units={correction.units}}}", "{units}")
    time_col, cols = split_columns(columns or SENSOR_COLUMNS[kind], rate_hz)
    got = fileio.read_sensor_log(log, cols, u, time_col, rate_hz, expect=expect, log_format=fmt, field=field)
    factor, _ = fileio.sensor_scale(u, expect, field)
    corrected = correction.correct(got.data)
    check_corrected(kind, corrected, got.shown, field, str(log))  # a log read in the wrong unit is refused
    names = ([time_col] if time_col else []) + cols
    t = got.t / TIME_UNITS[got.time_units] if got.time_units else got.t  # the time column as the log had it
    with outputs() as staged:  # all or none: the picture is drawn before anything is written
        staged.write_csv(out, names, np.column_stack(([t] if time_col else []) + [corrected / factor]))
        if plot is not None:
            from align.present.calplots import apply_traces_png

            staged.write_bytes(plot, apply_traces_png(got.t, got.data, corrected, got.shown))
    typer.echo(f"wrote {out}: {len(t)} rows of {kind} data corrected with {alignment} ({u})"
               + (f"; {got.time_note()}" if got.time_note() else ""))


COMMANDS = {"matrix": matrix, "apply": apply}
