"""``imu-align lot``: the statistics of a lot from the batch's results table.

Public names
------------
lot, COMMANDS
"""

from __future__ import annotations

import typer

from align.cli import options as opt


def lot(
    table: opt.Arg("The lot's table (results.parquet of imu-align batch).", "TABLE.parquet"),
    spec: opt.OptInput("--spec", "Limits per figure (TOML): phi_xy = { abs_max = \"0.1 deg\" }, scale_x = { min = "
                       "0.995, max = 1.005 }, arw_x = { max = \"0.3 deg/sqrt(h)\" }; tables [gyroscope], "
                       "[accelerometer], [magnetometer] for one sensor.", "SPEC.toml") = None,
    report: opt.OptInput("--report", "HTML report: failing units first, histograms with the limits, control "
                         "charts.", "LOT.html") = None,
    trend: opt.Choice("--trend", ("order", "time"), "Trend over the lot's order (per unit) or time (per day).")
    = "order",
) -> None:
    """Statistics of a lot (each unit's latest run): count, mean, spread, Cpk, yield, outliers, trend.

    Exit status 4 when a unit failed, gave an error or is outside the spec (listed first).
    """
    from align.cli.paths import check_outputs, outputs

    check_outputs([table, spec], report=report)
    from align.errors import CheckFailed
    from align.io import existing_file
    from align.present.lot import lot_report_html, lot_summary
    from align.production import latest_rows, lot_statistics, read_spec, read_table
    from align.production.stats import figures_needed

    limits = read_spec(spec) if spec is not None else None
    rows = latest_rows(read_table(existing_file(table)), figures_needed(limits))
    stats = lot_statistics(rows, limits, opt.value(trend))
    with outputs() as staged:
        if report is not None:
            staged.write_text(report, lot_report_html(stats, str(table)))
    typer.echo(lot_summary(stats, str(table)))
    bad = stats.count - stats.passed
    if bad:
        raise CheckFailed(f"{bad} of {stats.count} units do not pass (listed first)", str(table))


COMMANDS = {"lot": lot}
