"""``imu-align export``: results in the formats other programs load (Kalibr, C, CSV, imucal).

Public names
------------
export, COMMANDS
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Annotated

import typer

from align.cli import options as opt
from align.cli.options import value
from align.cli.paths import check_outputs, outputs


def _rostopic(text: str) -> str:
    """A ROS topic name: letters, digits, ``_``, ``/`` and ``~``."""
    if not re.fullmatch(r"[~/]?[A-Za-z][A-Za-z0-9_/]*", text):
        raise typer.BadParameter(f"'{text}' is not a ROS topic name; e.g. /imu0")
    return text


def _c_name(text: str) -> str:
    """A C identifier."""
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", text):
        raise typer.BadParameter(f"'{text}' is not a C identifier (letters, digits and _); e.g. IMU_CAL")
    return text


#: what a file that is not a result gets told
NOT_A_RESULT = ("not a result file: give a JSON written by an imu-align command's --json (matrix, calibrate, allan, "
                "calibrate mag)")


def _load(path: Path):
    """The result in ``path``; a file that is not one (not JSON, not UTF-8, no imu-align format) gets one line
    saying what to give."""
    from align.errors import InputError
    from align.io import read_json
    from align.results import result_from_dict

    try:
        d = read_json(path)
    except InputError as exc:
        if exc.message.startswith(("not valid JSON", "not UTF-8", "holds NUL", "is empty", "expected a JSON")):
            raise InputError(NOT_A_RESULT, str(path)) from None
        raise  # missing, a folder, unreadable: said as it is
    if not isinstance(d.get("format"), str) or not d["format"].startswith("imu-align."):
        raise InputError(NOT_A_RESULT, str(path))
    return result_from_dict(d, str(path))


def _unused(to: str, name: str | None, rostopic: str | None) -> None:
    """``--name`` only for ``--to c``, ``--rostopic`` only for ``--to kalibr``: refused elsewhere, not ignored."""
    from align.errors import InputError

    if name is not None and to != "c":
        raise InputError(f"names the C arrays; --to {to} has none: leave it out (or give --to c)", "{name}")
    if rostopic is not None and to != "kalibr":
        raise InputError(f"is Kalibr's ROS topic; --to {to} has none: leave it out (or give --to kalibr)", "{rostopic}")


def export(
    results: Annotated[list[Path], typer.Argument(metavar="RESULT.json...", show_default=False, help=(
        "Result file(s) of imu-align (--json). kalibr takes an allan result per sensor and an alignment or "
        "calibration together; the others take one result."))],
    to: opt.Choice("--to", ("kalibr", "c", "csv", "imucal"), "kalibr: Kalibr's imu.yaml (noise from allan; "
                   "scale-misalignment intrinsics from matrix/calibrate); c: C header (alignment, calibration, "
                   "magnetometer); csv: the Allan curve, or M, A and the angles; imucal: imucal's JSON (a calibration "
                   "with accelerometer and gyroscope)."),
    out: opt.OptInput("--out", "Write the export here (default: print it).", "FILE") = None,
    name: Annotated[str | None, typer.Option("--name", parser=_c_name, metavar="PREFIX", help=(
        "C header: prefix of the arrays (default IMU_ALIGN, IMU_CAL or IMU_MAG)."))] = None,
    rostopic: Annotated[str | None, typer.Option("--rostopic", parser=_rostopic, metavar="TOPIC", help=(
        "kalibr: the IMU's ROS topic (default /imu0)."))] = None,
) -> None:
    """A result in the format another program loads, stating its convention, frame, units and the tool version."""
    check_outputs(results, results=results, out=out)  # nor a data file a result names (its record of the inputs)
    _unused(value(to), name, rostopic)
    from align.present.exportable import export_text

    text = export_text([(_load(p), str(p)) for p in results], value(to), name, rostopic or "/imu0")
    if out is None:
        typer.echo(text, nl=False)
        return
    with outputs() as staged:
        staged.write_text(out, text)
    typer.echo(f"wrote {out}: {value(to)} export of {', '.join(p.name for p in results)}")


COMMANDS: dict = {"export": export}
