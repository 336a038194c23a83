"""Commands that tell the whole story: ``report`` (one HTML page) and ``demo`` (on bundled inputs).

Public names
------------
report, demo, COMMANDS
"""

from pathlib import Path

import typer

from align.cli import options as opt
from align.cli.mechanics import MANOEUVRE_HELP, MOUNT_HELP
from align.cli.options import ACCURACY, POSITIVE
from align.cli.paths import check_outputs, data_files, outputs
from align.cli.progress import progress

#: the files ``demo`` writes into its folder
DEMO_FILES = ("mount.toml", "manoeuvre.toml", "static.npy", "session.csv", "plan.toml", "budget.json",
              "allowable.json", "check.json", "allan.json", "plan.json", "alignment.json", "truth.json", "report.html")


def report(
    mount: opt.Input("--mount", MOUNT_HELP, "MOUNT.toml"),
    manoeuvre: opt.Input("--manoeuvre", MANOEUVRE_HELP, "MANOEUVRE.toml"),
    out: opt.Input("--out", "The HTML report to write.", "REPORT.html"),
    log: opt.OptInput("--log", "Rate-table log (time,gyro_x,gyro_y,gyro_z) for the alignment, with --plan.", "LOG") = None,
    plan: opt.OptInput("--plan", "Its test plan TOML ([[step]] tables).", "PLAN.toml") = None,
    allan_log: opt.OptInput("--allan", "Static recording for the Allan deviation and the test plan.", "STATIC") = None,
    columns: opt.Columns("Columns of the static recording (--allan).") = "gyro_x,gyro_y,gyro_z",
    rate_hz: opt.RateHz("Sample rate of the static recording, when it has no time column.") = None,
    units: opt.UnitFlag("--units", "Unit of the static recording (an angular rate).") = "deg/s",
    gyro_units: opt.GyroUnits("Unit of the rate-table log (--log).") = "deg/s",
    rate: opt.Text("--rate", "angular_rate", "Table rate for the plan.", "RATE", POSITIVE, "'100 deg/s'",
                   optional=False) = "100 deg/s",
    accuracy: opt.Text("--accuracy", "angle", "Alignment goal for the plan.", "ANGLE", ACCURACY, "'0.1 deg'",
                       optional=False) = "0.1 deg",
    monte_carlo: opt.MonteCarlo("Monte Carlo draws of the budget.") = 100_000,
    seed: opt.Seed = 0,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    time_units: opt.TimeUnits = None,
) -> None:
    """One self-contained HTML report: budget, allowance, noise plan and alignment."""
    from align.errors import InputError

    if (log is None) != (plan is None):
        raise InputError("give {log} and {plan} together", "{log}" if log is None else "{plan}")
    check_outputs([mount, manoeuvre, log, plan, allan_log, *data_files(mount, manoeuvre)], out=out)
    from align.present.story import build_report

    with progress(monte_carlo, "Monte Carlo") as tick:
        page, summary, _ = build_report(
            mount, manoeuvre, log=log, plan=plan, allan=allan_log, allan_columns=columns, allan_rate_hz=rate_hz,
            allan_units=units, gyro_units=gyro_units, table_rate=rate, accuracy=accuracy, monte_carlo=monte_carlo,
            seed=seed, progress=tick, log_format=opt.log_format(skip_rows, comment, delimiter, time_units))
    with outputs() as staged:
        staged.write_text(out, page)
    typer.echo(summary + f"\nreport: {out}")


def demo(
    out: opt.OptInput("--out", "Folder for the inputs, results and report (created if missing).", "FOLDER") = Path(
        "imu-align-demo"),
) -> None:
    """The whole story on bundled inputs (Examples 1-3, simulated records): summary and report."""
    check_outputs(folder=("out", out, DEMO_FILES))
    from align.present.story import run_demo

    # all or none: the inputs are staged and read back, the results and the report staged beside them,
    # and only then are all the files (and the folder, if new) put in place
    with outputs() as staged, progress(100_000, "Monte Carlo") as tick:
        staged.folder(out)
        page, summary, results = run_demo(out, staged, progress=tick)
        for name, result in results.items():
            staged.write_json(out / f"{name}.json", result)
        staged.write_text(out / "report.html", page)
    typer.echo("imu-align demo (inputs: the reference's Examples 1-3, a simulated static record and rate-table session)\n"
               + summary + f"\nwrote {out}/report.html and the JSON results beside it")


COMMANDS = {"report": report, "demo": demo}
