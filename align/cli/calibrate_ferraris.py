"""``imu-align calibrate ferraris``: a Ferraris session (six static faces and a turn about each axis), as imucal
records it; the work is the library job :data:`align.calibration.jobs.FERRARIS`.

Public names
------------
ferraris, ferraris_options, ferraris_files
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import typer

from align.cli import options as opt
from align.cli.options import NONZERO, POSITIVE, names, value
from align.cli.paths import check_outputs, judged_outcome, write_run

if TYPE_CHECKING:
    from align.calibration.jobs import FerrarisOptions
    from align.calibration.results import CalibrationSet

GRAVITY = "Local gravity"


def ferraris_options(*, log: Path, sections: Path, rate_hz: float, turn_angle: float = -2 * 3.141592653589793,
                     gravity: float = 9.80665, accel_columns: str | None = None, gyro_columns: str | None = None,
                     accel_units: str | None = None, gyro_units: str | None = None, bias: Any = "pairwise",
                     g_sensitivity: bool = True, skip_rows: int = 0, comment: str | None = None,
                     delimiter: str | None = None, topic: str | None = None, stamps: str | None = None,
                     limits: Path | None = None, **_: Any) -> FerrarisOptions:
    """The job's options from the command's parameters (Python names; output options and unknown keys ignored).

    Returns
    -------
    FerrarisOptions
    """
    from align.calibration.jobs import FerrarisOptions
    from align.io.source import LogSource

    fmt = opt.log_format(skip_rows=skip_rows, comment=comment, delimiter=delimiter, topic=topic, stamps=stamps)
    gyro = LogSource(path=Path(log), columns=None if gyro_columns is None else tuple(names(gyro_columns)),
                     rate_hz=rate_hz, units=gyro_units, format=fmt)
    accel = LogSource(path=Path(log), columns=None if accel_columns is None else tuple(names(accel_columns)),
                      rate_hz=rate_hz, units=accel_units, format=fmt)
    return FerrarisOptions(limits=limits, log=gyro, accel=accel, sections=Path(sections), turn_angle=turn_angle, gravity=gravity,
                           bias=cast(Any, value(bias)), g_sensitivity=g_sensitivity)


def ferraris_files(result: CalibrationSet, inputs: Any, params: dict[str, Any]) -> list[tuple[Path, bytes | str]]:
    """The files ``--imucal-json`` asks for (beside the ``--json`` result)."""
    from align.io.files import to_json_value

    path = params.get("imucal_json")
    if path is None:
        return []
    return [(Path(path), json.dumps(to_json_value(result.as_imucal()), indent=2) + "\n")]


def ferraris(
    log: opt.Arg("Session log (CSV, or a stream of a log of several: --topic) with accelerometer and gyro columns.",
                 "LOG"),
    sections: opt.Input("--sections", "imucal section list JSON: x_p ... z_a, x_rot, y_rot, z_rot.", "SECTIONS.json"),
    rate_hz: opt.RateHz("Sample rate.", required=True),
    turn_angle: opt.Quantity("--turn-angle", "angle", "Signed angle of each turn about the axis pointing up.",
                             "ANGLE", NONZERO, "'-360 deg'") = "-360 deg",
    gravity: opt.Quantity("--gravity", "acceleration", GRAVITY + ".", "ACCEL", POSITIVE, "'9.81 m/s^2'") =
        "9.80665 m/s^2",
    accel_columns: opt.Columns("Accelerometer columns x,y,z (default acc_x,acc_y,acc_z, or accel_x,... / ax,... "
                               "when the file has those).", "--accel-columns", optional=True) = None,
    gyro_columns: opt.Columns("Gyro columns x,y,z (default gyro_x,gyro_y,gyro_z, or gyr_x,... / gx,... when the file "
                              "has those).", "--gyro-columns", optional=True) = None,
    accel_units: opt.UnitFlag("--accel-units", "Accelerometer unit, or the size of one count ('16384 LSB/g')."
                              + opt.stated_default("m/s^2")) = None,
    gyro_units: opt.GyroUnits("Gyro unit.", stated=True) = None,
    bias: opt.Choice("--bias", ("pairwise", "lsq"), "Accelerometer bias: pairwise (Ferraris, tilt-robust) or lsq.") = "pairwise",
    g_sensitivity: opt.Flag("--g-sensitivity/--no-g-sensitivity",
                            "Estimate the gyro's g-sensitivity from the static faces.") = True,
    json_out: opt.JsonOut = None,
    limits: opt.Limits = None,
    imucal_json: opt.OptInput("--imucal-json", "Also write the result as imucal's JSON.", "FILE.json") = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    topic: opt.Topic = None,
    stamps: opt.Stamps = None,
) -> None:
    """A Ferraris session (six static faces and a turn about each axis), as imucal records it."""
    params = dict(locals())
    check_outputs([log, sections, limits], json_out=json_out, imucal_json=imucal_json)
    from align.calibration.jobs import FERRARIS
    from align.present.text import calibration_summary

    result, inputs = FERRARIS.run_with_inputs(ferraris_options(**params))
    write_run(json_out, result, ferraris_files(result, inputs, params))  # all or none
    typer.echo(calibration_summary(result.sensors))
    judged_outcome(result)
