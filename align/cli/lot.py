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
    json_out: opt.OptInput("--json", "The statistics as JSON (versioned; SI, each figure's unit stated): Cpk and "
                           "why, control limits and run-rule signals, outliers, yield.", "LOT.json") = None,
    trend: opt.Choice("--trend", ("order", "time"), "Trend over the lot's order (per unit) or time (per day).")
    = "order",
) -> None:
    """Statistics of a lot (each unit's latest run): count, mean, spread, Cpk, yield, outliers, trend.

    Exit status 4 when a unit failed, gave an error or is outside the spec (listed under "units not passing").
    """
    from align.cli.paths import check_outputs, outputs

    check_outputs([table, spec], report=report, json=json_out)
    from pathlib import Path

    from align.errors import CheckFailed, InputError
    from align.present.lot import lot_report_html, lot_summary
    from align.production import latest_rows, lot_statistics, read_spec, read_table
    from align.production.lotjson import lot_json
    from align.production.stats import figures_needed
    from align.production.table import META
    from align.production.thermal_groups import lot_groups

    if not Path(table).exists():  # the store is a folder of parts (or, before release 0.3, one file)
        raise InputError("file not found; give OUT/results.parquet of imu-align batch", str(table))
    limits = read_spec(spec) if spec is not None else None
    figures = figures_needed(limits)
    rows = latest_rows(read_table(table, [n for n, _ in META] + figures), figures)  # only the columns looked at
    stats = lot_statistics(rows, limits, opt.value(trend))
    thermal = lot_groups(rows, Path(table).parent)
    with outputs() as staged:
        if report is not None:
            staged.write_text(report, lot_report_html(stats, str(table), thermal))
        if json_out is not None:
            staged.write_text(json_out, lot_json(stats, str(table), thermal))
    typer.echo(lot_summary(stats, str(table)))
    if thermal:
        from align.present.lot import thermal_lines

        typer.echo("\nunits grouped by thermal profile:\n" + "\n".join(f"  {c}" for c in thermal_lines(thermal)))
    bad = stats.count - stats.passed
    if bad:
        raise CheckFailed(f"{bad} of {stats.count} units do not pass (listed above)", str(table))


COMMANDS = {"lot": lot}
