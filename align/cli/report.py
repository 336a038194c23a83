"""``imu-align report``: one self-contained HTML page from any subset of inputs and results
(:func:`align.present.story.make_report`, which runs the same jobs as the commands).

Public names
------------
report, COMMANDS
"""

from pathlib import Path
from typing import Annotated, Any

import typer

from align.cli import options as opt
from align.cli.allan import NoiseRatio, grid_value
from align.cli.allowable import MANOEUVRE_HELP
from align.cli.budget import MOUNT_HELP
from align.cli.options import ACCURACY, POSITIVE
from align.cli.parts import LazyParts, PartsFile, parts_file
from align.cli.paths import check_outputs, data_files, outputs
from align.cli.progress import progress


def _when() -> str:
    """The report's date: now, local time to the minute; ``SOURCE_DATE_EPOCH`` (seconds, UTC) when set, for
    reproducible reports."""
    import os
    from datetime import UTC, datetime

    epoch = os.environ.get("SOURCE_DATE_EPOCH", "").strip()
    if epoch.isdigit():
        return datetime.fromtimestamp(int(epoch), UTC).strftime("%Y-%m-%d %H:%M UTC")
    return datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z").strip()


Repeated = Annotated[list[Path] | None, typer.Option("--calibration", metavar="RESULT.json", help=(
    "A calibration result (calibrate accel, ferraris, gyro or mag --json); repeat for several."))]
Drift = Annotated[list[Path] | None, typer.Option("--drift", metavar="RESULT.json", help=(
    "A navigation result (drift --json) whose error growth the report shows; repeat for several."))]


#: the rate-table log's sample rate: matrix spells it --rate-hz, which the report gives to the static record (--allan)
LogRate = Annotated[float | None, typer.Option("--log-rate-hz", parser=opt.hertz, metavar="HZ", help=(
    "Sample rate of the rate-table log (--log), when it has no time column (matrix's --rate-hz; --rate-hz here is "
    "the static record's). Hz, e.g. 200 or '200 Hz'."))]


def _label(flag: str, help: str, metavar: str = "TEXT"):
    return Annotated[str | None, typer.Option(flag, metavar=metavar, help=help)]


def _flags() -> frozenset[str]:
    """The report's option names, so that a note names only flags the report has (others in words)."""
    import inspect

    known: set[str] = set()
    for p in inspect.signature(report).parameters.values():
        for meta in getattr(p.annotation, "__metadata__", ()):
            first = getattr(meta, "default", None)  # typer takes a str first argument in Annotated as a name
            for decl in [first] + list(getattr(meta, "param_decls", None) or ()):
                if isinstance(decl, str) and decl.startswith("-"):
                    known.update(decl.split("/"))
    return frozenset(known)


def report(
    out: opt.Input("--out", "The HTML report to write.", "REPORT.html"),
    mount: opt.OptInput("--mount", MOUNT_HELP, "MOUNT.toml") = None,
    manoeuvre: opt.OptInput("--manoeuvre", MANOEUVRE_HELP + " With --mount: the budget is checked against it; with "
                            "an alignment: the measured misalignment is.", "MANOEUVRE.toml") = None,
    log: opt.OptInput("--log", "Rate-table log for the alignment, with --plan (its columns: --gyro-columns).",
                      "LOG") = None,
    plan: opt.OptInput("--plan", "Its test plan TOML ([[step]] tables).", "PLAN.toml") = None,
    alignment: opt.OptInput("--alignment", "An alignment result (matrix --json) instead of --log and --plan.",
                            "RESULT.json") = None,
    allan_log: opt.OptInput("--allan", "Static recording, or an Allan result (allan --json), for the noise figures and "
                            "the test plan.", "STATIC") = None,
    calibration: Repeated = None,
    drift: Drift = None,
    title: _label("--title", "Title of the report (default by what it reports: 'IMU alignment report', 'IMU "
                  "calibration report'...).") = None,
    serial: _label("--serial", "Serial number of the unit tested.") = None,
    operator: _label("--operator", "Who ran the test.") = None,
    test_id: _label("--test-id", "Identifier of the test (a work order, a run number).") = None,
    columns: opt.Columns("Columns of the static recording (--allan), as allan's --columns: x,y,z (default "
                         "gyro_x,gyro_y,gyro_z, old names accepted), or time,x,y,z.", optional=True) = None,
    rate_hz: opt.RateHz("Sample rate of the static recording, when it has no time column.") = None,
    time_column: opt.TimeColumn = None,
    units: opt.UnitFlag("--units", "Unit of the static recording (--allan), as allan's --units: an angular rate or an "
                        "acceleration (deg/s, m/s^2, g), or the size of one count ('131 LSB/(deg/s)', "
                        "'16384 LSB/g')." + opt.stated_default("deg/s")) = None,
    grid: Annotated[str, typer.Option("--grid", parser=grid_value, metavar="GRID", help=(
        "Static recording's tau grid, as allan's: dense | octave | decade | explicit taus '0.01,0.1,1' (s)."))] = "dense",
    per_decade: opt.Whole("--per-decade", "Points per decade of the dense grid (1 to 1000), as allan's.", 1, 1000,
                          "10") = 10,
    modified: opt.Flag("--modified/--no-modified", "Also the modified Allan deviation of the static recording.") = False,
    noise_ratio: NoiseRatio = 10.0,
    memory_limit_mb: opt.Number("--memory-limit-mb", "Static recording: phase kept in memory up to this size (MB); "
                                "beyond it, a temporary file (as allan's).", POSITIVE, "2000", "MB") = 2000.0,
    gyro_units: opt.GyroUnits("Unit of the rate-table log (--log); without --log and --alignment, of the static "
                              "recording (--allan), as allan's --gyro-units.", stated=True) = None,
    gyro_columns: opt.Columns("Columns of the rate-table log (--log): time,x,y,z (x,y,z with --log-rate-hz). Default "
                              "time,gyro_x,gyro_y,gyro_z; for --alignment, the columns the result records.",
                              "--gyro-columns", optional=True) = None,
    log_rate_hz: LogRate = None,
    log_time_column: Annotated[str | None, typer.Option("--log-time-column", metavar="NAME", help=(
        "Name of the rate-table log's time column (matrix's --time-column; default: time; not read with "
        "--log-rate-hz). --time-column here is the static record's."))] = None,
    rate: opt.Text("--rate", "angular_rate", "Table rate for the plan.", "RATE", POSITIVE, "'100 deg/s'",
                   optional=False) = "100 deg/s",
    accuracy: opt.Text("--accuracy", "angle", "Alignment goal for the plan.", "ANGLE", ACCURACY, "'0.1 deg'",
                       optional=False) = "0.1 deg",
    monte_carlo: opt.MonteCarlo("Monte Carlo draws of the budget.") = 100_000,
    basis: opt.Choice("--basis", ("rss", "worst"), "Budget figure checked against the allowance (as check's "
                      "--basis): rss (the source's method) or worst.") = "rss",
    seed: opt.Seed = 0,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    time_units: opt.TimeUnits = None,
    topic: opt.Topic = None,
    stamps: opt.Stamps = None,
    parts: PartsFile = None,
    limits: opt.Limits = None,
) -> None:
    """One self-contained HTML report from any subset of results: budget, allowance, alignment, noise, calibrations.

    A summary comes first: every check, its verdict and the number behind it. The measured misalignment is
    propagated through the manoeuvre and judged with a guard band of 2 sigma (PASS, WARN within 2 sigma of a
    limit, FAIL). Every result's figures of merit are judged against --limits and the default limits (NOT USABLE
    when not determined well enough to use). The exit status is 4 when a check fails; the report is written first. With a measured
    alignment the measurement governs: the mounting budget against the allowance is then a design check, shown
    with its verdict, that fails nothing.
    """
    from align.errors import CheckFailed, InputError

    if (log is None) != (plan is None):
        raise InputError("give {log} and {plan} together", "{log}" if log is None else "{plan}")
    calibrations, drifts = list(calibration or []), list(drift or [])
    check_outputs([mount, manoeuvre, log, plan, alignment, allan_log, *calibrations, *drifts, parts_file(parts)[0], limits,
                   *data_files(mount, manoeuvre)], out=out,
                  results=[alignment, *calibrations, *drifts,
                           allan_log if allan_log is not None and allan_log.suffix.lower() == ".json" else None])
    from align.present.story import make_report

    header = {"serial number": serial, "operator": operator, "test": test_id, "date": _when()}
    allan_opts = None
    if allan_log is not None and allan_log.suffix.lower() != ".json":  # a static record: as `allan REC` reads it
        from align.cli.allan import allan_options

        if log is None and alignment is None and gyro_units is not None:  # no rate-table log: as `allan --gyro-units`
            if units is not None:
                raise InputError("give the static recording's unit once: {units} or {gyro_units} (without {log}, "
                                 "--gyro-units is the recording's, as allan's)", "{gyro_units}")
            units = gyro_units
        allan_opts = allan_options(logs=[allan_log], columns=columns, rate_hz=rate_hz, units=units,
                                   time_column=time_column, grid=grid, per_decade=per_decade, modified=modified,
                                   rate=rate, accuracy=accuracy, noise_ratio=noise_ratio,
                                   memory_limit_mb=memory_limit_mb, skip_rows=skip_rows, comment=comment,
                                   delimiter=delimiter, time_units=time_units, topic=topic, stamps=stamps)
    fmt: dict[str, Any] = dict(skip_rows=skip_rows, comment=comment, delimiter=delimiter, time_units=time_units,
                               topic=topic, stamps=stamps)
    given = any(v not in (0, None) for v in fmt.values())  # else: what a result recorded
    with progress(monte_carlo if mount is not None else 0, "Monte Carlo") as tick:
        done = make_report(
            mount, manoeuvre, log=log, plan=plan, allan=allan_log, allan_columns=columns, allan_rate_hz=rate_hz,
            allan_units=units, gyro_units=gyro_units, table_rate=rate, accuracy=accuracy, monte_carlo=monte_carlo,
            basis=opt.value(basis), noise_ratio=noise_ratio, allan_options=allan_opts, log_time_column=log_time_column,
            seed=seed, progress=tick, log_format=opt.log_format(**fmt) if given else None, alignment=alignment,
            calibrations=calibrations, drift=drifts, title=title, header=header,
            parts=LazyParts(parts) if mount is not None else None, log_columns=gyro_columns, log_rate_hz=log_rate_hz,
            spell=opt.speller("report", _flags()), limits=limits)
    with outputs() as staged:
        staged.write_text(out, done.page)
    typer.echo(done.text + f"\nreport: {out}")
    if done.failed:  # as 'check': the report is written, then the failure is the exit status
        raise CheckFailed("; ".join(f"{v.check} failed ({v.number})" for v in done.failed))


COMMANDS = {"report": report}
