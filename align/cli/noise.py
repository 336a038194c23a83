"""Commands of the noise family: ``allan`` (Allan deviation and fit) and ``plan`` (averaging time).

Public names
------------
allan, plan, COMMANDS
"""

import math
from pathlib import Path
from typing import Annotated

import typer

from align.cli import options as opt
from align.cli.options import ACCURACY, NONNEGATIVE, NONZERO, PAUSE, POSITIVE, names
from align.cli.parts import PartsFile, parts_file, parts_table
from align.cli.paths import check_outputs, outputs
from align.cli.progress import progress

GRIDS = ("dense", "octave", "decade")


def grid_value(text: str) -> str | list[float]:
    """``dense``, ``octave``, ``decade`` or a comma list of taus in seconds."""
    if text in GRIDS:
        return text
    advice = "give dense, octave, decade or a comma list of taus > 0 in seconds, e.g. '0.01,0.1,1'"
    try:
        taus = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise ValueError(f"'{text}' is not a grid; {advice}") from None
    if not taus or not all(math.isfinite(t) and t > 0 for t in taus):
        raise ValueError(advice)
    return taus


NoiseRatio = opt.Number("--noise-ratio", "Plan for noise this many times below the goal (> 0).", POSITIVE, "10", "RATIO")
Accuracy = "Alignment goal, e.g. '0.1 deg'"
Rate = "Table rate, e.g. '100 deg/s'"


def allan(
    logs: Annotated[list[Path], typer.Argument(metavar="LOG...", show_default=False, help=(
        "Static recordings: .csv, .csv.gz, .npy or raw float64 .bin; several runs are pooled (each run's curve "
        "and fit, a pooled curve fitted and planned from) and give the bias repeatability."))],
    columns: opt.Columns("Data columns (a CSV's time column is 'time' unless --rate-hz).") = "gyro_x,gyro_y,gyro_z",
    rate_hz: opt.RateHz("Sample rate, for files without a time column (.npy always).") = None,
    gyro_units: opt.GyroUnits("Unit of the data columns (an angular rate).") = "deg/s",
    units: opt.Units("Any rate or acceleration unit instead of --gyro-units (e.g. g).") = None,
    grid: Annotated[str, typer.Option("--grid", parser=grid_value, metavar="GRID",
                                      help="dense | octave | decade | explicit taus '0.01,0.1,1' (s).")] = "dense",
    per_decade: opt.Whole("--per-decade", "Points per decade of the dense grid (1 to 1000).", 1, 1000, "10") = 10,
    modified: opt.Flag("--modified/--no-modified", "Also the modified Allan deviation.") = False,
    json_out: opt.JsonOut = None,
    plot: opt.OptInput("--plot", "Log-log plot with confidence band and fit (PNG).", "FILE.png") = None,
    rate: opt.OptQuantity("--rate", "angular_rate", "Table rate, to plan: draws the target and the averaging time.",
                      "RATE", POSITIVE, "'100 deg/s'") = None,
    accuracy: opt.OptQuantity("--accuracy", "angle", Accuracy + ", to plan (with --rate).", "ANGLE", ACCURACY,
                              "'0.1 deg'") = None,
    noise_ratio: NoiseRatio = 10.0,
    memory_limit_mb: opt.Number("--memory-limit-mb", "Phase kept in memory up to this size (MB); beyond it, a temporary "
                                "file.", POSITIVE, "2000", "MB") = 2000.0,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    time_units: opt.TimeUnits = None,
) -> None:
    """Allan deviation, noise-model fit and noise figures of static recordings."""
    from align.errors import InputError

    if (rate is None) != (accuracy is None):
        raise InputError("give both {rate} and {accuracy} to plan", "{rate}" if rate is None else "{accuracy}")
    check_outputs(logs, json_out=json_out, plot=plot)
    from align.noise import plan_from_allan, read_runs, run_allan
    from align.present.text import allan_summary, plan_summary

    fmt = opt.log_format(skip_rows, comment, delimiter, time_units)
    unit, scale = _allan_unit(gyro_units, units)
    channels = names(columns)
    runs, fs = read_runs(logs, channels, rate_hz, fmt, scale)
    with progress(sum(r.shape[0] for r in runs), "Allan deviation (samples read)") as tick:
        job = run_allan(runs, fs, channels, unit, grid, per_decade, modified, progress=tick,
                        memory_limit=memory_limit_mb * 1e6, where=[str(p) for p in logs])
    job = job.replace(inputs=tuple(str(p) for p in logs))
    if rate is not None:
        job = job.replace(plan=plan_from_allan(job, rate, accuracy, noise_ratio, "measured curve (worst channel)"))
    with outputs() as out:  # all or none: the plot is drawn before anything is written
        if plot is not None:
            from align.present.plots import allan_plot_png

            out.write_bytes(plot, allan_plot_png(job, *((job.plan.noise_target, job.plan.averaging.tau) if job.plan
                                                        else ())))
        if json_out is not None:
            out.write_json(json_out, job)
    typer.echo(allan_summary(job))
    if job.plan is not None:
        typer.echo("\n" + plan_summary(job.plan))


def _allan_unit(gyro_units: str, units: str | None) -> tuple[str, float]:
    """The unit the deviations are shown in, and the size of one count in it (1: the logs hold that unit).

    ``--gyro-units`` is an angular rate, ``--units`` an angular rate or an acceleration; either may be the
    size of one count (``'0.0076336 deg/s'``, ``'131 LSB/(deg/s)'``, ``'16384 LSB/g'``): the deviations are
    then shown in deg/s or m/s^2. Raw ``counts`` are refused with the advice to give the count size.
    """
    from align.errors import InputError, UnitError, literal
    from align.io import sensor_scale
    from align.units import parse_unit

    if units is None:
        factor, shown = sensor_scale(gyro_units, "angular_rate", "gyro_units")
        return shown, factor / parse_unit(shown).factor
    for expect in ("angular_rate", "acceleration"):
        try:
            factor, shown = sensor_scale(units, expect, "units")
        except UnitError as exc:
            if "raw counts" in exc.message:
                raise
            continue
        return shown, factor / parse_unit(shown).factor
    raise InputError(f"'{literal(units)}' is neither an angular rate nor an acceleration (nor the size of one count of either)",
                     "{units}")


def plan(
    rate: opt.Quantity("--rate", "angular_rate", Rate + ".", "RATE", POSITIVE, "'100 deg/s'"),
    accuracy: opt.Quantity("--accuracy", "angle", Accuracy + ".", "ANGLE", ACCURACY, "'0.1 deg'"),
    noise_ratio: NoiseRatio = 10.0,
    arw: opt.Text("--arw", "angle_random_walk", "Angle random walk, e.g. '0.3 deg/sqrt(h)'.", "ARW", POSITIVE,
                  "'0.3 deg/sqrt(h)'") = None,
    bias_instability: opt.Text("--bias-instability", "angular_rate", "Bias instability, e.g. '6 deg/h' (with --arw).",
                               "RATE", NONNEGATIVE, "'6 deg/h'") = None,
    rate_random_walk: opt.Text("--rate-random-walk", "rate_random_walk", "Rate random walk, e.g. '3 deg/h/sqrt(h)' "
                               "(with --arw).", "RRW", NONNEGATIVE, "'3 deg/h/sqrt(h)'") = None,
    imu: Annotated[str | None, typer.Option("--imu", metavar="PART", help=(
        "A datasheet preset (see 'imu-align parts'), e.g. ADIS16485; a name that is not a preset labels the "
        "figures given with --arw."))] = None,
    allan_json: opt.OptInput("--allan", "A result of 'imu-align allan --json'.", "ALLAN.json") = None,
    turn_angle: opt.Quantity("--turn-angle", "angle", "Turn of the angle method.", "ANGLE", NONZERO,
                             "'360 deg'") = "360 deg",
    settle: opt.Quantity("--settle", "time", "Settling time added to each step.", "TIME", PAUSE, "'2 s'") = "2 s",
    steps: opt.Whole("--steps", "Table steps (6: +/- about three axes).", 1, 10_000, "6") = 6,
    json_out: opt.JsonOut = None,
    parts: PartsFile = None,
) -> None:
    """Averaging time per table step for an alignment goal (Example 3), and the whole plan."""
    from align.errors import InputError
    from align.parts import find_part, get_part

    check_outputs([allan_json, parts_file(parts)[0]], json_out=json_out)
    table = parts_table(parts) if imu is not None or parts is not None else None
    preset = None if imu is None else find_part(imu, table)
    if imu is not None and preset is None and arw is None:
        try:
            get_part(imu, "{imu}", table)
        except InputError as exc:  # naming the known parts and the parts file; or the label
            raise InputError(f"{exc.message}, or give {{arw}} (and {{bias_instability}}) to use it as a label",
                             exc.where) from None
    if sum(x is not None for x in (arw, preset, allan_json)) != 1:
        raise InputError("give exactly one noise source: {arw} X [{bias_instability} Y] (with {imu} NAME, a name that "
                         "is not a preset, as its label), {imu} PART (a preset) or {allan_json} RESULT.json", "plan")
    if arw is None and (bias_instability or rate_random_walk):
        raise InputError("goes with {arw}", "{bias_instability}" if bias_instability else "{rate_random_walk}")
    from align.noise import AllanJob, make_plan, plan_from_allan, preset_model
    from align.present.text import plan_summary
    from align.results import load_result

    common = dict(turn_angle=turn_angle, steps=steps, settle=settle)
    inputs: dict = {}
    if allan_json is not None:
        job = load_result(allan_json, expect=(AllanJob,))
        result = plan_from_allan(job, rate, accuracy, noise_ratio, where=str(allan_json), **common)
    else:
        if arw is not None:
            label, curve = _model_curve(arw, bias_instability, rate_random_walk)
            if imu is not None:
                label, inputs = f"{imu.strip()} (a label, not a preset): {label}", {"imu": imu.strip()}
        else:
            label, curve = preset_model(preset)  # its N: arw, else noise_density; its B when stated
            used = ["arw" if preset.arw is not None else "noise_density", "bias_instability"]
            inputs = {"imu": preset.name, "preset": preset.provenance(used)}
        if parts_file(parts)[0] is not None and imu is not None:
            inputs["parts"] = str(parts_file(parts)[0])
        result = make_plan(rate, accuracy, noise_ratio, label, sigma=curve, **common).replace(inputs=inputs)
    with outputs() as out:
        if json_out is not None:
            out.write_json(json_out, result)
    typer.echo(plan_summary(result))


def _model_curve(arw: str, bias_instability: str | None, rate_random_walk: str | None):
    """(label, noise model) from the datasheet figures given on the command line."""
    from align.noise import model_curve
    from align.units import parse_quantity as q

    n = q(arw, "angle_random_walk", "{arw}")
    b = q(bias_instability, "angular_rate", "{bias_instability}") if bias_instability else 0.0
    k = q(rate_random_walk, "rate_random_walk", "{rate_random_walk}") if rate_random_walk else 0.0
    label = (f"model: ARW {arw}" + (f", bias instability {bias_instability}" if b else "")
             + (f", RRW {rate_random_walk}" if k else ""))
    return label, model_curve(n, b, k)


COMMANDS = {"allan": allan, "plan": plan}
