"""``imu-align drift``: what the residual errors cost (attitude, velocity and position error growth).

Public names
------------
drift, COMMANDS
"""

from pathlib import Path
from typing import Annotated

import typer

from align.cli import options as opt
from align.cli.options import DURATION, NONNEGATIVE, POSITIVE, Domain, hertz
from align.cli.parts import PartsFile, parts_file, parts_table
from align.cli.paths import check_outputs, data_files, outputs
from align.cli.progress import progress

_DEG = 3.141592653589793 / 180
LATITUDE = Domain("within -90 deg and 90 deg", low=-90 * _DEG, high=90 * _DEG, open_low=False)
MAX_RUNS = 1_000_000


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


def drift(
    duration: opt.Quantity("--duration", "time", "Mission length, e.g. '10 min' or '600 s'.", "TIME", DURATION,
                           "'10 min'"),
    allan: Annotated[list[Path] | None, typer.Option("--allan", metavar="RESULT.json", help=(
        "Allan result (imu-align allan --json) of the gyros or the accelerometers: their noise terms (N, B, K, R) "
        "and, with several runs, the bias repeatability. Give it twice for both sensors."))] = None,
    alignment: opt.OptInput("--alignment", "Alignment or calibration result: its 1-sigma of M and bias are the residual "
                            "scale, misalignment and bias.", "RESULT.json") = None,
    budget: opt.OptInput("--budget", "Mount TOML: its budget's per-axis misalignment, uncompensated (instead of "
                         "--alignment).", "MOUNT.toml") = None,
    imu: Annotated[str | None, typer.Option("--imu", metavar="PART", help=(
        "A datasheet preset (see 'imu-align parts'), e.g. ADIS16485: the gyro noise (ARW, bias instability) when no "
        "gyro --allan is given."))] = None,
    parts: PartsFile = None,
    manoeuvre: opt.OptInput("--manoeuvre", "Manoeuvre TOML of allowable/check ([[rotation]] or [series]); "
                            "static mission when left out.", "FILE.toml") = None,
    runs: opt.Whole("--runs", "Monte Carlo runs (2 to 1,000,000).", 2, MAX_RUNS, "1000") = 1000,
    rate_hz: opt.RateHz("Sensor sample rate of the mission.", required=True) = 100.0,
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
    seed: opt.Seed = 0,
    json_out: opt.JsonOut = None,
    plot: opt.OptInput("--plot", "PNG of the error growth: mean, 1- and 3-sigma envelopes, closed forms.",
                       "FILE.png") = None,
) -> None:
    """Attitude, velocity and position error growth from the residual sensor errors over a mission."""
    from align.errors import InputError

    if alignment is not None and budget is not None:
        raise InputError("give {alignment} (residuals after an alignment) or {budget} (no alignment), not both",
                         "{budget}")
    allan = list(allan or [])
    check_outputs([*allan, alignment, budget, manoeuvre, parts_file(parts)[0], *data_files(budget, manoeuvre)],
                  json_out=json_out, plot=plot)
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
        where={"allan": [str(p) for p in allan], "correction": str(alignment), "budget": str(budget)})
    settings = dict(heading=heading, latitude=latitude, earth_rate=earth_rate)
    if manoeuvre is None:
        mission = static_mission(duration, rate_hz, **settings)
    else:
        mission = manoeuvre_mission(read_toml(manoeuvre), str(manoeuvre), manoeuvre.parent, duration, rate_hz,
                                    turn_rate, **settings)
    inputs = {k: v for k, v in {"allan": [str(p) for p in allan] or None, "alignment": alignment and str(alignment),
                                "budget": budget and str(budget), "imu": part and part.name,
                                "manoeuvre": manoeuvre and str(manoeuvre)}.items() if v}
    with progress(runs, "Monte Carlo") as tick:
        result = compute(mission, errors, runs, seed, nav_rate, inputs=inputs, progress=tick)
    with outputs() as out:
        if plot is not None:
            out.write_bytes(plot, drift_plot_png(result))
        if json_out is not None:
            out.write_json(json_out, result)
    typer.echo(drift_summary(result))


COMMANDS = {"drift": drift}
