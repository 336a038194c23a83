"""``imu-align drift``: what the residual errors cost (attitude, velocity and position error growth), through
:data:`align.navigation.jobs.DRIFT`.

Public names
------------
drift, drift_options, drift_files, COMMANDS
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from align.cli import options as opt
from align.cli.options import DIP, DURATION, NONNEGATIVE, POSITIVE, hertz, names
from align.cli.parts import PartsFile, parts_fields, parts_file
from align.cli.paths import check_outputs, data_files, write_run
from align.cli.progress import progress

#: a latitude is an angle from -90 deg to 90 deg, as a dip angle is
LATITUDE = DIP
MAX_RUNS = 1_000_000


def _trajectory_source(trajectory: Path, gyro_columns: str | None, time_column: str | None, rate_hz: float | None,
                       gyro_units: str | None, **fmt: Any):
    """The trajectory's gyro columns as a LogSource, by the one column convention: its time column (``time``,
    ``--time-column``, or the first of four names) is read, unless ``--rate-hz`` is given with three names and no
    ``--time-column`` (a log without time); a log with neither is refused naming both options."""
    given = None if gyro_columns is None else names(gyro_columns)
    at_rate = rate_hz is not None and given is not None and len(given) == 3 and time_column is None
    return opt.log_source(trajectory, gyro_columns, rate_hz=rate_hz if at_rate else None, units=gyro_units,
                          time_column=time_column, **fmt)


def drift_options(*, duration: float | None = None, allan: list[Path] | None = None, alignment: Path | None = None,
                  budget: Path | None = None, mount_error: Any = "attitude", imu: str | None = None,
                  parts: Path | None = None, manoeuvre: Path | None = None, trajectory: Path | None = None,
                  gyro_columns: str | None = None, accel_columns: str | None = None, time_column: str | None = None,
                  gyro_units: str | None = None, accel_units: str | None = None, runs: int = 1000,
                  rate_hz: float | None = None,
                  nav_rate: float | None = None, turn_rate: float | None = None, heading: float = 0.0,
                  latitude: float | None = None, earth_rate: bool = False, gyro_bias: float | None = None,
                  accel_bias: float | None = None, flicker_span: int = 8, seed: int = 0, skip_rows: int = 0,
                  comment: str | None = None, delimiter: str | None = None, time_units: str | None = None,
                  topic: str | None = None, stamps: str | None = None, **_: Any):
    """The :class:`align.navigation.jobs.DriftOptions` of ``imu-align drift``'s parameters (output options
    ignored)."""
    from align.navigation.jobs import DriftOptions

    source = None if trajectory is None else _trajectory_source(
        trajectory, gyro_columns, time_column, rate_hz, gyro_units, skip_rows=skip_rows, comment=comment,
        delimiter=delimiter, time_units=time_units, topic=topic, stamps=stamps)
    more: dict[str, Any] = {k: v for k, v in {"turn_rate": turn_rate, "latitude": latitude}.items() if v is not None}
    return DriftOptions(
        duration=duration, allan=tuple(allan or ()), alignment=alignment, budget=budget,
        mount_error=opt.value(mount_error), imu=imu, manoeuvre=manoeuvre, trajectory=source,
        accel_columns=None if accel_columns is None else tuple(names(accel_columns)), accel_units=accel_units,
        runs=runs, rate_hz=100.0 if rate_hz is None else rate_hz, nav_rate=nav_rate, heading=heading,
        earth_rate=earth_rate, gyro_bias=gyro_bias, accel_bias=accel_bias, flicker_span=flicker_span, seed=seed,
        **more, **parts_fields(parts))


def drift_files(result, inputs, params: dict) -> list[tuple[Path, bytes | str]]:
    """The picture ``--plot`` asks for."""
    if params.get("plot") is None:
        return []
    from align.present.navigation import drift_plot_png

    return [(params["plot"], drift_plot_png(result))]


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
    gyro_columns: opt.Columns("Gyro columns of --trajectory: x,y,z (read at --rate-hz, unless --time-column names "
                              "the time column), or time,x,y,z. Default gyro_x,gyro_y,gyro_z with the time column "
                              "time (gyr_x,gyr_y,gyr_z accepted).", "--gyro-columns", optional=True) = None,
    accel_columns: opt.Columns("Accelerometer columns of --trajectory: x,y,z (default acc_x,acc_y,acc_z).",
                               "--accel-columns", optional=True) = None,
    time_column: opt.TimeColumn = None,
    gyro_units: opt.GyroUnits("Gyro unit of --trajectory, e.g. deg/s or rad/s.", stated=True) = None,
    accel_units: opt.UnitFlag("--accel-units", "Accelerometer unit of --trajectory, e.g. m/s^2 or g."
                              + opt.stated_default("m/s^2")) = None,
    runs: opt.Whole("--runs", "Monte Carlo runs (2 to 1,000,000).", 2, MAX_RUNS, "1000") = 1000,
    rate_hz: opt.RateHz("Sensor sample rate of the mission (default 100 Hz), or of a --trajectory without a time "
                        "column.") = None,
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
    topic: opt.Topic = None,
    stamps: opt.Stamps = None,
) -> None:
    """Attitude, velocity and position error growth from the residual sensor errors over a mission."""
    params = dict(locals())
    opts = drift_options(**params)
    check_outputs([*opts.allan, alignment, budget, manoeuvre, trajectory, parts_file(parts)[0],
                   *data_files(budget, manoeuvre)], json_out=json_out, plot=plot)
    from align.navigation.jobs import DRIFT
    from align.present.navigation import drift_summary

    with progress(runs, "Monte Carlo") as tick:
        result = DRIFT.run(opts, progress=tick)
    write_run(json_out, result, drift_files(result, None, params))  # all or none
    typer.echo(drift_summary(result))


COMMANDS = {"drift": drift}
