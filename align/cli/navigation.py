"""``imu-align drift``: what the residual errors cost (attitude, velocity and position error growth).

Public names
------------
drift, COMMANDS
"""

from pathlib import Path
from typing import Annotated

import typer

from align.cli import options as opt
from align.cli.options import DIP, DURATION, NONNEGATIVE, POSITIVE, hertz, names
from align.cli.parts import PartsFile, parts_file, parts_table
from align.cli.paths import check_outputs, data_files, outputs
from align.cli.progress import progress

#: a latitude is an angle from -90 deg to 90 deg, as a dip angle is
LATITUDE = DIP
MAX_RUNS = 1_000_000
#: the initial attitude of a recorded trajectory is levelled on its first samples, over this long (s)
LEVEL_TIME = 1.0


def _read_correction(path: Path):
    from align.alignment.result import AlignmentResult
    from align.calibration.results import CalibrationSet
    from align.results import load_result

    return load_result(path, expect=(AlignmentResult, CalibrationSet))


def _read_budget(path: Path):
    import mechanics
    from align.io import read_toml
    from mechanics import mount_from_dict

    return mechanics.budget(mount_from_dict(read_toml(path), str(path), path.parent))


def _trajectory(path: Path, gyro_columns: str, accel_columns: str, gyro_units: str, accel_units: str, rate_hz: float,
                fmt, duration: float | None, heading: float, settings: dict):
    """A recorded log as the mission's true motion: its readings from the attitude levelled on its first second."""
    import numpy as np

    from align.errors import InputError
    from align.io import read_sensor_log
    from align.navigation import level_attitude, recorded_mission

    gcols, acols = names(gyro_columns), names(accel_columns)
    if len(gcols) not in (3, 4):
        raise InputError("give four names time,x,y,z (three, x,y,z, for a log without time at {rate_hz})",
                         "{gyro_columns}")
    if len(acols) != 3:
        raise InputError("give three names x,y,z of the accelerometer in the trajectory log", "{accel_columns}")
    time_col, rate = (gcols[0], None) if len(gcols) == 4 else (None, rate_hz)
    gyr = read_sensor_log(path, gcols[-3:], gyro_units, time_col, rate, log_format=fmt, field="gyro_units")
    acc = read_sensor_log(path, acols, accel_units, time_col, rate, expect="acceleration", log_format=fmt,
                          field="accel_units")
    step = np.diff(gyr.t)
    if len(step) and (step.max() > 1.5 / gyr.rate_hz or step.min() < 0.5 / gyr.rate_hz):
        raise InputError(f"its time steps run from {step.min():.4g} to {step.max():.4g} s (gaps or repeated samples); "
                         f"the trajectory is read at one rate, {gyr.rate_hz:g} Hz: resample it", str(path))
    n = len(gyr.t)
    if duration is not None:
        n = int(round(duration * gyr.rate_hz)) + 1
        if n > len(gyr.t):
            raise InputError(f"{duration:g} s is longer than the trajectory's {(len(gyr.t) - 1) / gyr.rate_hz:g} s; "
                             "give a shorter {duration} or leave it out", "{duration}")
    first = max(1, min(n, int(round(LEVEL_TIME * gyr.rate_hz))))
    q0 = level_attitude(acc.data[:first].mean(axis=0), heading)
    return recorded_mission(gyr.data[:n], acc.data[:n], gyr.rate_hz, q0, description=(
        f"recorded trajectory {path.name}, {n:,} samples at {gyr.rate_hz:g} Hz, initial attitude levelled on its first "
        f"{first / gyr.rate_hz:g} s"), **settings)


def drift(
    duration: opt.OptQuantity("--duration", "time", "Mission length, e.g. '10 min' or '600 s' (with --trajectory: "
                              "its first part; default the whole log).", "TIME", DURATION, "'10 min'") = None,
    allan: Annotated[list[Path] | None, typer.Option("--allan", metavar="RESULT.json", help=(
        "Allan result (imu-align allan --json) of the gyros or the accelerometers: their noise terms (N, B, K, R) "
        "and, with several runs, the bias repeatability. Give it twice for both sensors."))] = None,
    alignment: opt.OptInput("--alignment", "Alignment or calibration result: its 1-sigma of M and bias are the residual "
                            "scale, misalignment and bias.", "RESULT.json") = None,
    budget: opt.OptInput("--budget", "Mount TOML: its budget's per-axis misalignment (RSS, taken as the rms angle), "
                         "uncompensated (instead of --alignment); see --mount-error.", "MOUNT.toml") = None,
    mount_error: opt.Choice("--mount-error", ("attitude", "turns"), (
        "What the budget is: 'attitude' (default) a rigid rotation of the whole IMU relative to the vehicle whose "
        "attitude starts the navigation, an initial attitude error of gyros and accelerometers alike (a tilt costs "
        "g theta t^2/2 from the start); 'turns' the attitude aligned in place by the IMU, the angles as the gyro "
        "axes' misalignment relative to that frame, which costs only when the body turns.")) = "attitude",
    imu: Annotated[str | None, typer.Option("--imu", metavar="PART", help=(
        "A datasheet preset (see 'imu-align parts'), e.g. ADIS16485: the gyro noise (ARW, bias instability) when no "
        "gyro --allan is given."))] = None,
    parts: PartsFile = None,
    manoeuvre: opt.OptInput("--manoeuvre", "Manoeuvre TOML of allowable/check ([[rotation]] or [series]); "
                            "static mission when left out.", "FILE.toml") = None,
    trajectory: opt.OptInput("--trajectory", "A recorded log as the true motion (its gyro and accelerometer readings in "
                             "--gyro-units and --accel-units; instead of --manoeuvre): what the residual errors add "
                             "along it. Its initial attitude is levelled on its first second, at --heading.",
                             "LOG") = None,
    gyro_columns: opt.Columns("Gyro columns of --trajectory: time,x,y,z (x,y,z: no time column, at --rate-hz).",
                              "--gyro-columns") = "time,gyr_x,gyr_y,gyr_z",
    accel_columns: opt.Columns("Accelerometer columns of --trajectory: x,y,z.", "--accel-columns") = "acc_x,acc_y,acc_z",
    gyro_units: opt.GyroUnits("Gyro unit of --trajectory, e.g. deg/s or rad/s.") = "deg/s",
    accel_units: opt.UnitFlag("--accel-units", "Accelerometer unit of --trajectory, e.g. m/s^2 or g.") = "m/s^2",
    runs: opt.Whole("--runs", "Monte Carlo runs (2 to 1,000,000).", 2, MAX_RUNS, "1000") = 1000,
    rate_hz: opt.RateHz("Sensor sample rate of the mission (of a --trajectory without a time column).",
                        required=True) = 100.0,
    nav_rate: Annotated[float | None, typer.Option("--nav-rate", parser=hertz, metavar="HZ", help=(
        "Navigation update rate (default 10 Hz, at most the sample rate), Hz, e.g. 10 or '10 Hz'."))] = None,
    turn_rate: opt.Quantity("--turn-rate", "angular_rate", "Mean rate of a manoeuvre's rotations.", "RATE", POSITIVE,
                            "'10 deg/s'") = "10 deg/s",
    heading: opt.Quantity("--heading", "angle", "Initial heading.", "ANGLE", example="'0 deg'") = "0 deg",
    latitude: opt.Quantity("--latitude", "angle", "Latitude (gravity; the Earth rate).", "ANGLE", LATITUDE,
                           "'45 deg'") = "45 deg",
    earth_rate: opt.Flag("--earth-rate/--no-earth-rate", "Include the Earth rate and the Coriolis term.") = False,
    gyro_bias: opt.OptQuantity("--gyro-bias", "angular_rate", "Residual gyro turn-on bias, 1 sigma (replaces any other "
                               "source).", "RATE", NONNEGATIVE, "'10 deg/h'") = None,
    accel_bias: opt.OptQuantity("--accel-bias", "acceleration", "Residual accelerometer turn-on bias, 1 sigma.",
                                "ACCEL", NONNEGATIVE, "'1 mg'") = None,
    flicker_span: opt.Whole("--flicker-span", "Bias instability (flicker) is drawn down to 1/(N T) for a mission of "
                            "length T: its low-frequency cutoff, N mission lengths (2 to 256).", 2, 256, "8") = 8,
    seed: opt.Seed = 0,
    json_out: opt.JsonOut = None,
    plot: opt.OptInput("--plot", "PNG of the error growth: mean, 1- and 3-sigma envelopes (the down channels: the runs' "
                       "percentiles), closed forms.", "FILE.png") = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    time_units: opt.TimeUnits = None,
) -> None:
    """Attitude, velocity and position error growth from the residual sensor errors over a mission."""
    from align.errors import InputError

    if alignment is not None and budget is not None:
        raise InputError("give {alignment} (residuals after an alignment) or {budget} (no alignment), not both",
                         "{budget}")
    if manoeuvre is not None and trajectory is not None:
        raise InputError("give one mission: {manoeuvre} (rotations) or {trajectory} (a recorded log), not both",
                         "{trajectory}")
    if duration is None and trajectory is None:
        raise InputError("give the mission length, e.g. '10 min'", "{duration}")
    allan = list(allan or [])
    check_outputs([*allan, alignment, budget, manoeuvre, trajectory, parts_file(parts)[0],
                   *data_files(budget, manoeuvre)], json_out=json_out, plot=plot)
    from align.io import read_toml
    from align.navigation import drift as compute
    from align.navigation import manoeuvre_mission, residual_errors, static_mission
    from align.noise import AllanJob
    from align.parts import get_part
    from align.present.navigation import drift_plot_png, drift_summary
    from align.results import load_result

    jobs = [load_result(p, expect=(AllanJob,)) for p in allan]
    part = None if imu is None else get_part(imu, "{imu}", parts_table(parts))
    errors = residual_errors(
        jobs, None if alignment is None else _read_correction(alignment),
        None if budget is None else _read_budget(budget), part, gyro_bias, accel_bias,
        where={"allan": [str(p) for p in allan], "correction": str(alignment), "budget": str(budget)},
        mount_error=opt.value(mount_error))
    settings = dict(heading=heading, latitude=latitude, earth_rate=earth_rate)
    if trajectory is not None:
        fmt = opt.log_format(skip_rows, comment, delimiter, time_units)
        mission = _trajectory(trajectory, gyro_columns, accel_columns, gyro_units, accel_units, rate_hz, fmt, duration,
                              heading, dict(latitude=latitude, earth_rate=earth_rate))
    elif manoeuvre is None:
        mission = static_mission(duration, rate_hz, **settings)
    else:
        mission = manoeuvre_mission(read_toml(manoeuvre), str(manoeuvre), manoeuvre.parent, duration, rate_hz,
                                    turn_rate, **settings)
    inputs = {k: v for k, v in {"allan": [str(p) for p in allan] or None, "alignment": alignment and str(alignment),
                                "budget": budget and str(budget), "imu": part and part.name,
                                "manoeuvre": manoeuvre and str(manoeuvre), "trajectory": trajectory and str(trajectory),
                                "mount_error": budget and opt.value(mount_error)}.items() if v}
    with progress(runs, "Monte Carlo") as tick:
        result = compute(mission, errors, runs, seed, nav_rate, inputs=inputs, progress=tick, flicker_span=flicker_span)
    with outputs() as out:
        if plot is not None:
            out.write_bytes(plot, drift_plot_png(result))
        if json_out is not None:
            out.write_json(json_out, result)
    typer.echo(drift_summary(result))


COMMANDS = {"drift": drift}
