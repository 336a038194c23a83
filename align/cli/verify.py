"""``imu-align verify``: a gyro correction replayed on a session it was not fitted to (:data:`align.alignment.jobs.
verify_job.VERIFY`).

Public names
------------
verify, verify_options, COMMANDS
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from align.cli import options as opt
from align.cli.matrix import GYRO_COLUMNS
from align.cli.options import POSITIVE, TOLERANCE
from align.cli.paths import check_outputs, judged_outcome, write_run


def verify_options(*, result: Path, log: Path, plan: Path, sensor: Any = None, gyro_units: str | None = None,
                   columns: str | None = None, time_column: str | None = None, rate_hz: float | None = None,
                   tolerance_angle: float | None = None, tolerance_scale: float | None = None,
                   limits: Path | None = None, skip_rows: int = 0, comment: str | None = None,
                   delimiter: str | None = None, time_units: str | None = None, topic: str | None = None,
                   stamps: str | None = None, **_: Any):
    """The :class:`~align.alignment.jobs.verify_job.VerifyOptions` of ``imu-align verify``'s parameters."""
    from align.alignment.jobs.verify_job import VerifyOptions

    source = opt.log_source(log, columns, rate_hz=rate_hz, units=gyro_units, time_column=time_column,
                            skip_rows=skip_rows, comment=comment, delimiter=delimiter, time_units=time_units,
                            topic=topic, stamps=stamps)
    given = {"tolerance_angle": tolerance_angle, "tolerance_scale": tolerance_scale}
    return VerifyOptions(result=result, log=source, plan=plan, sensor=None if sensor is None else opt.value(sensor),
                         limits=limits, **{k: v for k, v in given.items() if v is not None})


def verify(
    result: opt.Arg("The alignment (matrix --json) or gyro calibration to verify.", "RESULT.json"),
    log: opt.Arg("A rate-table session it was not fitted to (read as matrix reads its log).", "LOG"),
    plan: opt.Input("--plan", "That session's plan TOML ([[step]] tables).", "PLAN.toml"),
    sensor: opt.Choice("--sensor", ("gyroscope",), "The sensor of a calibration holding several.") = None,
    tolerance_angle: opt.Quantity("--tolerance-angle", "angle", "Largest residual cross-axis misalignment.", "ANGLE",
                                  POSITIVE, "'0.05 deg'") = "0.05 deg",
    tolerance_scale: opt.Quantity("--tolerance-scale", "dimensionless", "Largest residual scale error.", "RATIO",
                                  TOLERANCE, "'0.1 %'") = "0.1 %",
    gyro_units: opt.GyroUnits(stated=True) = None,
    columns: opt.Columns(f"Gyro columns of the session, as matrix's --columns (default {GYRO_COLUMNS}).",
                         optional=True) = None,
    time_column: opt.TimeColumn = None,
    rate_hz: opt.RateHz() = None,
    json_out: opt.JsonOut = None,
    limits: opt.Limits = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    time_units: opt.TimeUnits = None,
    topic: opt.Topic = None,
    stamps: opt.Stamps = None,
) -> None:
    """Replay a gyro correction on a session it was not fitted to: the residual M, its figures and the verdict."""
    params = dict(locals())
    check_outputs([result, log, plan, limits], json_out=json_out)
    from align.alignment.jobs.verify_job import VERIFY
    from align.present.merit import verify_lines

    res = VERIFY.run(verify_options(**params))
    write_run(json_out, res)
    typer.echo("\n".join(verify_lines(res, str(result), str(log))))
    judged_outcome(res)


COMMANDS = {"verify": verify}
