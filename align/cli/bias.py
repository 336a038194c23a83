"""``imu-align warmup`` and ``imu-align repeatability``: the bias tests of the series (issue 26), modelled on
``imu-align allan`` (the same reading options); the work is the library jobs :data:`align.noise.bias_jobs.WARMUP`
and :data:`align.noise.bias_jobs.REPEATABILITY`.

Also the rehearsals with known truth: ``simulate_warmup`` (``imu-align simulate warmup``: one record from turn-on
with an exponential warm-up) and ``simulate_turn_ons`` (``imu-align simulate turn-ons``: several turn-ons with a
known bias spread), gathered in :data:`SIMULATE`.

Public names
------------
warmup, repeatability, bias_reading, warmup_summary, repeatability_summary, simulate_warmup, simulate_turn_ons,
COMMANDS, SIMULATE
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from align.cli import options as opt
from align.cli.options import DURATION, NONNEGATIVE, PAUSE, POSITIVE
from align.cli.parsers import Domain
from align.cli.paths import check_outputs, judged_outcome, write_run
from align.cli.progress import progress

if TYPE_CHECKING:
    from align.noise.repeatability import RepeatabilityResult
    from align.noise.warmup import WarmupResult

Logs = "Static records: .csv, .csv.gz, .npy, raw float64 .bin, or a log of several streams (--topic)"
Window = opt.Quantity("--window", "time", "Moving-mean window of the bias.", "TIME", POSITIVE, "'10 s'")
Final = opt.OptQuantity("--final", "time", "Final segment whose mean is the settled bias (default: the last quarter "
                        "of the record).", "TIME", POSITIVE, "'300 s'")
Band = Annotated[str | None, typer.Option("--band", metavar="SIZE", help=(
    "Half-width of the band the bias settles in, a rate or an acceleration, e.g. '0.01 deg/s' or '1 mg' (default: "
    "five times the moving mean's noise)."))]
#: a confidence level: (0, 1)
LEVEL = Domain("> 0 and < 1", low=0.0, high=1.0 - 1e-12)
Force = Annotated[bool, typer.Option("--force", help="Replace the files the folder already holds.")]


def bias_reading(columns: str | None = None, rate_hz: float | None = None, gyro_units: str | None = None,
                 units: str | None = None, time_column: str | None = None, skip_rows: int = 0,
                 comment: str | None = None, delimiter: str | None = None, time_units: str | None = None,
                 topic: str | None = None, stamps: str | None = None, window: float = 10.0,
                 final: float | None = None, band: str | None = None, limits: Path | None = None,
                 **_: Any) -> dict[str, Any]:
    """The reading and warm-up fields both jobs share, from the command's parameters (Python names)."""
    return dict(columns=tuple(opt.names(columns)) if columns is not None else None, time_column=time_column or None,
                rate_hz=rate_hz, gyro_units=gyro_units, units=units, window=window, final=final, band=band,
                limits=limits, format=opt.log_format(skip_rows=skip_rows, comment=comment, delimiter=delimiter,
                                                     time_units=time_units, topic=topic, stamps=stamps))


def _shown(value: float, sensor: str) -> str:
    from align.units import to_unit

    unit = "deg/s" if sensor == "gyroscope" else "m/s^2"
    return f"{to_unit(value, unit):.4g} {unit}"


def warmup_summary(result: WarmupResult) -> str:
    """The warm-up of each channel, and the criterion, as terminal lines."""
    lines = [f"warm-up of {result.inputs[0] if result.inputs else 'the record'} ({result.samples} samples at "
             f"{result.fs:g} Hz)"]
    for name, c in zip(result.names, result.channels):
        if c.settled:
            sigma = f" +/- {c.sigma:.3g}" if math.isfinite(c.sigma) else ""
            lines.append(f"  {name}: {c.time:.4g}{sigma} s (band +/- {_shown(c.band, result.sensor)}, settled at "
                         f"{_shown(c.value, result.sensor)})")
        else:
            lines.append(f"  {name}: {c.note}")
    lines.append(f"criterion: {result.criterion}")
    return "\n".join(lines)


def repeatability_summary(result: RepeatabilityResult) -> str:
    """The repeatability of each channel with its interval, and each record's bias, as terminal lines."""
    lines = [f"bias repeatability over {len(result.runs)} turn-ons ({100 * result.level:g} % chi-square interval):"]
    for j, name in enumerate(result.names):
        lines.append(f"  {name}: {_shown(result.value[j], result.sensor)} [{_shown(result.low[j], result.sensor)}, "
                     f"{_shown(result.high[j], result.sensor)}], mean bias {_shown(result.mean[j], result.sensor)}")
    for run in result.runs:
        stab = ", ".join("n/a" if s is None else _shown(s, result.sensor) for s in run["stability"])
        lines.append(f"  {run['input']}: warm-up {run['skip_s']:.4g} s left out; in-run stability ({result.period:g} s) "
                     f"{stab}")
    return "\n".join(lines)


def warmup(
    log: Annotated[Path, typer.Argument(metavar="LOG", show_default=False, help=Logs + ", from turn-on.")],
    columns: opt.Columns("Data columns (default gyro_x,gyro_y,gyro_z); four names: the time column first.",
                         optional=True) = None,
    rate_hz: opt.RateHz("Sample rate, for files without a time column (.npy always).") = None,
    gyro_units: opt.GyroUnits("Unit of the data columns (an angular rate).", stated=True) = None,
    units: opt.Units("Any rate or acceleration unit instead of --gyro-units (e.g. g).") = None,
    window: Window = "10 s",
    final: Final = None,
    band: Band = None,
    json_out: opt.JsonOut = None,
    limits: opt.Limits = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    time_units: opt.TimeUnits = None,
    time_column: opt.TimeColumn = None,
    topic: opt.Topic = None,
    stamps: opt.Stamps = None,
) -> None:
    """Warm-up time of a static record from turn-on: when the bias settles within a stated band."""
    params = dict(locals())
    from align.job import read_limits_of
    from align.noise.bias_jobs import WARMUP, WarmupOptions

    check_outputs([log, limits], json_out=json_out)
    options = WarmupOptions(log=log, **bias_reading(**params))
    limits_read = read_limits_of(options)
    inputs = WARMUP.read_hashing(options)
    with progress(inputs.samples, "warm-up (samples read)") as tick:
        result = WARMUP.stamp(WARMUP.compute(inputs, options, tick), options, limits_read)
    write_run(json_out, result)
    typer.echo(warmup_summary(result))
    judged_outcome(result)


def repeatability(
    logs: Annotated[list[Path], typer.Argument(metavar="LOG...", show_default=False, help=(
        Logs + "; one per turn-on of the unit, at least two."))],
    columns: opt.Columns("Data columns (default gyro_x,gyro_y,gyro_z); four names: the time column first.",
                         optional=True) = None,
    rate_hz: opt.RateHz("Sample rate, for files without a time column (.npy always).") = None,
    gyro_units: opt.GyroUnits("Unit of the data columns (an angular rate).", stated=True) = None,
    units: opt.Units("Any rate or acceleration unit instead of --gyro-units (e.g. g).") = None,
    skip: opt.OptQuantity("--skip", "time", "Warm-up left out of every record (default: each record's own warm-up, "
                          "by --window, --final, --band).", "TIME", PAUSE, "'120 s'") = None,
    period: opt.Quantity("--period", "time", "Averaging period of the in-run bias stability.", "TIME", POSITIVE,
                         "'10 s'") = "10 s",
    level: opt.Number("--level", "Confidence level of the interval, between 0 and 1.", LEVEL, "0.95",
                      "LEVEL") = 0.95,
    window: Window = "10 s",
    final: Final = None,
    band: Band = None,
    json_out: opt.JsonOut = None,
    limits: opt.Limits = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    time_units: opt.TimeUnits = None,
    time_column: opt.TimeColumn = None,
    topic: opt.Topic = None,
    stamps: opt.Stamps = None,
) -> None:
    """Bias repeatability (turn-on to turn-on) with its confidence interval, and each record's in-run stability."""
    params = dict(locals())
    from align.job import read_limits_of
    from align.noise.bias_jobs import REPEATABILITY, RepeatabilityOptions

    check_outputs([*logs, limits], json_out=json_out)
    options = RepeatabilityOptions(logs=tuple(logs), skip=skip, period=period, level=level, **bias_reading(**params))
    limits_read = read_limits_of(options)
    inputs = REPEATABILITY.read_hashing(options)
    with progress(inputs.samples, "repeatability (samples read)") as tick:
        result = REPEATABILITY.stamp(REPEATABILITY.compute(inputs, options, tick), options, limits_read)
    write_run(json_out, result)
    typer.echo(repeatability_summary(result))
    judged_outcome(result)


# ---------------------------------------------------------------------------------------------- rehearsals

Noise = opt.Quantity("--noise", "angle_random_walk", "Gyro angle random walk (white rate noise).", "ARW", NONNEGATIVE,
                     "'0.3 deg/sqrt(h)'")


def _written(out_dir: Path, names: tuple[str, ...], force: bool) -> None:
    from align.cli.simulate import refuse_replacing

    check_outputs([], folder=("out_dir", out_dir, names))
    refuse_replacing("out_dir", out_dir, names, force)


def simulate_warmup(
    out_dir: opt.Arg("Folder for warmup.csv and truth.json (created if missing).", "OUT_DIR"),
    rate_hz: opt.RateHz("Sample rate.") = "100 Hz",
    duration: opt.Quantity("--duration", "time", "Length of the record.", "TIME", DURATION, "'20 min'") = "20 min",
    tau: opt.Quantity("--tau", "time", "Time constant of the warm-up.", "TIME", POSITIVE, "'60 s'") = "60 s",
    excursion: opt.Quantity("--excursion", "angular_rate", "Bias at turn-on minus the settled bias (x; y and z get "
                            "-0.8 and 0.6 of it).", "RATE", opt.ANY, "'0.3 deg/s'") = "0.3 deg/s",
    band: opt.Quantity("--band", "angular_rate", "Band whose settling time truth.json states.", "RATE", POSITIVE,
                       "'0.01 deg/s'") = "0.01 deg/s",
    noise: Noise = "0.3 deg/sqrt(h)",
    seed: opt.Seed = 0,
    force: Force = False,
) -> None:
    """Simulate a static gyro record from turn-on with an exponential warm-up b(t) = b_end + d exp(-t/tau) plus white
    noise (for warmup): warmup.csv (time, gyro deg/s) and truth.json (the settling time into --band)."""
    import numpy as np

    from align.cli.paths import outputs
    from align.noise.warmup import settling_time
    from align.noise.warmup import simulate_warmup as simulate

    names = ("warmup.csv", "truth.json")
    _written(out_dir, names, force)
    rng = np.random.default_rng(seed)
    d = excursion * np.array([1.0, -0.8, 0.6])
    b_end = rng.normal(0.0, math.radians(0.2), 3)
    t, x = simulate(duration, rate_hz, b_end, d, tau, noise * math.sqrt(rate_hz), seed + 1)
    truth = {"model": "b(t) = b_end + d exp(-t / tau) + white noise; readings rad/s in truth, deg/s in warmup.csv",
             "tau_s": tau, "b_end_rad_s": b_end.tolist(), "d_rad_s": d.tolist(), "band_rad_s": band,
             "settling_time_s": [settling_time(v, tau, band) for v in d], "noise_rad_s_per_sample":
             noise * math.sqrt(rate_hz), "rate_hz": rate_hz, "seed": seed}
    with outputs() as out:
        out.folder(out_dir)
        out.write_csv(out_dir / names[0], ["time", "gyro_x", "gyro_y", "gyro_z"],
                      np.column_stack([t, np.degrees(x)]))
        out.write_json(out_dir / names[1], truth)
    typer.echo(f"wrote {out_dir}/warmup.csv ({len(t)} rows, {duration:g} s) and truth.json (settling into "
               f"{math.degrees(band):g} deg/s: {', '.join(f'{s:.1f}' for s in truth['settling_time_s'])} s)")


def simulate_turn_ons(
    out_dir: opt.Arg("Folder for turn_on_NN.csv and truth.json (created if missing).", "OUT_DIR"),
    count: opt.Whole("--count", "Turn-ons (records).", 2, 10_000, "10") = 10,
    rate_hz: opt.RateHz("Sample rate.") = "100 Hz",
    duration: opt.Quantity("--duration", "time", "Length of each record.", "TIME", DURATION, "'5 min'") = "5 min",
    spread: opt.Quantity("--spread", "angular_rate", "Turn-on to turn-on 1-sigma of the bias (the repeatability).",
                         "RATE", NONNEGATIVE, "'0.05 deg/s'") = "0.05 deg/s",
    noise: Noise = "0.3 deg/sqrt(h)",
    seed: opt.Seed = 0,
    force: Force = False,
) -> None:
    """Simulate several turn-ons of one gyro, each a bias drawn with a known spread plus white noise (for
    repeatability): turn_on_NN.csv (time, gyro deg/s) and truth.json."""
    import numpy as np

    from align.cli.paths import outputs
    from align.noise.repeatability import simulate_turn_ons as simulate

    names = (*(f"turn_on_{k:02d}.csv" for k in range(1, count + 1)), "truth.json")
    _written(out_dir, names, force)
    mean = np.random.default_rng(seed).normal(0.0, math.radians(0.2), 3)
    biases, records = simulate(count, duration, rate_hz, mean, spread, noise * math.sqrt(rate_hz), seed + 1)
    t = np.arange(records[0].shape[0]) / rate_hz
    truth = {"model": "each record: a bias drawn from N(mean, spread^2) per channel + white noise; rad/s",
             "mean_rad_s": mean.tolist(), "spread_rad_s": spread, "biases_rad_s": biases.tolist(),
             "sample_std_rad_s": np.std(biases, axis=0, ddof=1).tolist(), "rate_hz": rate_hz, "seed": seed}
    with outputs() as out:
        out.folder(out_dir)
        for name, rec in zip(names, records):
            out.write_csv(out_dir / name, ["time", "gyro_x", "gyro_y", "gyro_z"], np.column_stack([t, np.degrees(rec)]))
        out.write_json(out_dir / names[-1], truth)
    typer.echo(f"wrote {count} records of {duration:g} s to {out_dir} and truth.json")


COMMANDS = {"warmup": warmup, "repeatability": repeatability}
#: ``simulate``'s subcommands this module adds
SIMULATE = {"warmup": simulate_warmup, "turn-ons": simulate_turn_ons}
