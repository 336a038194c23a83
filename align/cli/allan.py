"""``imu-align allan``: Allan deviation, noise-model fit and noise figures of static recordings.

The command parses its options into :class:`align.noise.jobs.AllanOptions` (:func:`allan_options`, which the
report's noise step and the batch use too), runs :data:`align.noise.jobs.ALLAN`, and writes the result
and its picture (:func:`allan_files`).

Public names
------------
allan, allan_options, allan_files, grid_value, GRIDS
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Any

import typer

from align.cli import options as opt
from align.cli.options import ACCURACY, POSITIVE
from align.cli.paths import check_outputs, judged_outcome, write_run
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


def allan_options(logs: Any = (), columns: str | None = None, rate_hz: float | None = None,
                  gyro_units: str | None = None, units: str | None = None, grid: str | list[float] = "dense",
                  per_decade: int = 10, modified: bool = False, rate: float | str | None = None,
                  accuracy: float | str | None = None, noise_ratio: float = 10.0, memory_limit_mb: float = 2000.0,
                  skip_rows: int = 0, comment: str | None = None, delimiter: str | None = None,
                  time_units: str | None = None, time_column: str | None = None, topic: str | None = None,
                  stamps: str | None = None, limits: Path | None = None, **_: Any):
    """The ``allan`` job's options from the command's parameters (Python names, as typer delivers them).

    The command, the batch and the report's noise step (``report --allan REC`` with its ``--columns``,
    ``--units``, ...) build the options with this one function, so the same words mean the same there.
    ``rate`` and ``accuracy`` may be typed quantities (``'100 deg/s'``) or SI numbers. Output options and
    unknown keys are ignored.

    Returns
    -------
    AllanOptions
    """
    from align.noise.jobs import AllanOptions
    from align.units import parse_quantity

    if isinstance(rate, str):
        rate = parse_quantity(rate, "angular_rate", "{rate}")
    if isinstance(accuracy, str):
        accuracy = parse_quantity(accuracy, "angle", "{accuracy}")
    paths = (logs,) if isinstance(logs, (str, Path)) else tuple(logs or ())
    return AllanOptions(limits=limits,
        logs=tuple(Path(p) for p in paths), columns=tuple(opt.names(columns)) if columns is not None else None,
        time_column=time_column or None, rate_hz=rate_hz, gyro_units=gyro_units, units=units,
        format=opt.log_format(skip_rows=skip_rows, comment=comment, delimiter=delimiter, time_units=time_units,
                              topic=topic, stamps=stamps),
        grid=grid if isinstance(grid, str) else tuple(grid), per_decade=per_decade, modified=modified,
        rate=rate, accuracy=accuracy, noise_ratio=noise_ratio, memory_limit=float(memory_limit_mb) * 1e6)


def allan_files(result, inputs, params: dict) -> list[tuple[Path, bytes | str]]:
    """The picture ``--plot`` asks for (drawn before anything is written), beside the JSON result."""
    plot = params.get("plot")
    if plot is None:
        return []
    from align.present.plots import allan_plot_png

    extra = (result.plan.noise_target, result.plan.averaging.tau) if result.plan else ()
    return [(Path(plot), allan_plot_png(result, *extra))]


def allan(
    logs: Annotated[list[Path], typer.Argument(metavar="LOG...", show_default=False, help=(
        "Static recordings: .csv, .csv.gz, .npy, raw float64 .bin, or a log of several streams (a ROS bag, a ULog, a "
        "DataFlash .bin: --topic); several runs are pooled (each run's curve and fit, a pooled curve fitted and "
        "planned from) and give the bias repeatability."))],
    columns: opt.Columns("Data columns (default gyro_x,gyro_y,gyro_z); four names: the time column first. A text "
                         "log's time column is 'time' (--time-column) unless --rate-hz.", optional=True) = None,
    rate_hz: opt.RateHz("Sample rate, for files without a time column (.npy always); a time column, when the "
                        "file has one, must agree.") = None,
    gyro_units: opt.GyroUnits("Unit of the data columns (an angular rate).", stated=True) = None,
    units: opt.Units("Any rate or acceleration unit instead of --gyro-units (e.g. g).") = None,
    grid: Annotated[str, typer.Option("--grid", parser=grid_value, metavar="GRID",
                                      help="dense | octave | decade | explicit taus '0.01,0.1,1' (s).")] = "dense",
    per_decade: opt.Whole("--per-decade", "Points per decade of the dense grid (1 to 1000).", 1, 1000, "10") = 10,
    modified: opt.Flag("--modified/--no-modified", "Also the modified Allan deviation.") = False,
    json_out: opt.JsonOut = None,
    limits: opt.Limits = None,
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
    time_column: opt.TimeColumn = None,
    topic: opt.Topic = None,
    stamps: opt.Stamps = None,
) -> None:
    """Allan deviation, noise-model fit and noise figures of static recordings."""
    params = dict(locals())
    from align.errors import InputError
    from align.job import read_limits_of
    from align.noise.jobs import ALLAN
    from align.present.text import allan_summary, plan_summary

    if (rate is None) != (accuracy is None):  # before any file is looked at, as before
        raise InputError("give both {rate} and {accuracy} to plan", "{rate}" if rate is None else "{accuracy}")
    check_outputs([*logs, limits], json_out=json_out, plot=plot)
    options = allan_options(**params)
    limits_read = read_limits_of(options)  # before the log: a bad limits file costs no reading
    inputs = ALLAN.read_hashing(options)
    with progress(inputs.samples, "Allan deviation (samples read)") as tick:
        result = ALLAN.stamp(ALLAN.compute(inputs, options, tick), options, limits_read)
    extra = allan_files(result, inputs, params)  # all or none: the plot is drawn before anything is written
    write_run(json_out, result, extra)  # all or none
    typer.echo(allan_summary(result))
    for note in result.notes:  # the readers' remarks (a truncated last record)
        typer.echo(f"note: {note}")
    if result.plan is not None:
        typer.echo("\n" + plan_summary(result.plan))
    judged_outcome(result)


COMMANDS = {"allan": allan}
