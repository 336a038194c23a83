"""``imu-align export``: results in the formats other programs load (Kalibr, OpenVINS, VINS-Fusion, PX4, ArduPilot,
C, CSV, imucal).

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
from align.cli.parsers import POSITIVE, Domain, hertz, number, quantity
from align.cli.parts import PartsFile
from align.cli.paths import check_outputs, outputs

#: the exports that take noise figures (the options --inflate, --rate-hz, --predict-hz, --part, --floor-tau are theirs)
NOISE_EXPORTS = ("kalibr", "openvins", "vins", "px4", "ardupilot")
#: where --inflate may lie: 1 (none) up to 1000
INFLATE = Domain(">= 1 and <= 1000 (1: the figures as measured)", low=1.0, high=1000.0, open_low=False)


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
    saying what to give, and one whose ``A`` is not ``M^-1`` one naming the field."""
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


def _unused(to: str, name: str | None, rostopic: str | None, noise: dict) -> None:
    """Each option only where it means something: refused elsewhere, not ignored."""
    from align.errors import InputError

    if name is not None and to != "c":
        raise InputError(f"names the C arrays; --to {to} has none: leave it out (or give --to c)", "{name}")
    if rostopic is not None and to not in ("kalibr", "openvins"):
        raise InputError(f"is the IMU's ROS topic of Kalibr and OpenVINS; --to {to} has none: leave it out (or give "
                         "--to kalibr or --to openvins)", "{rostopic}")
    for field, given in noise.items():
        if given is not None and to not in NOISE_EXPORTS:
            raise InputError(f"is for the noise figures of --to {', '.join(NOISE_EXPORTS)}; --to {to} has none: "
                             "leave it out", "{" + field + "}")
    if noise["rate_hz"] is not None and to in ("px4", "ardupilot"):
        raise InputError(f"is the IMU's sample rate; --to {to} converts with the EKF's prediction rate: give it with "
                         "--predict-hz", "{rate_hz}")
    if noise["predict_hz"] is not None and to not in ("px4", "ardupilot"):
        raise InputError(f"is the prediction rate of PX4's and ArduPilot's EKF; --to {to} has none: leave it out (the "
                         "IMU's rate: --rate-hz)", "{predict_hz}")
    if noise["floor_tau"] is not None and noise["part"] is None:
        raise InputError("bounds the datasheet's random walk of --part; give --part too, or leave it out",
                         "{floor_tau}")
    if noise["parts"] is not None and noise["part"] is None:
        raise InputError("adds parts for --part to look up; give --part too, or leave it out", "{parts}")


def export(
    results: Annotated[list[Path], typer.Argument(metavar="RESULT.json...", show_default=False, help=(
        "Result file(s) of imu-align (--json). kalibr takes an allan result per sensor and an alignment or "
        "calibration together; openvins, vins, px4 and ardupilot an allan result per sensor; the others one "
        "result."))],
    to: opt.Choice("--to", ("kalibr", "openvins", "vins", "px4", "ardupilot", "c", "csv", "imucal"), (
        "kalibr: Kalibr's imu.yaml (noise from allan; scale-misalignment intrinsics from matrix/calibrate); "
        "openvins: OpenVINS's kalibr_imu_chain.yaml; vins: VINS-Fusion's acc_n, gyr_n, acc_w, gyr_w, g_norm; px4: "
        "EKF2 noise parameters (QGroundControl .params); ardupilot: EKF3 noise parameters (.parm); each states the "
        "conversion it applies (docs: noise-figures). c: C header (alignment, calibration, magnetometer); csv: the "
        "Allan curve, or M, A and the angles; imucal: imucal's JSON (a calibration with accelerometer and "
        "gyroscope).")),
    out: opt.OptInput("--out", "Write the export here (default: print it).", "FILE") = None,
    name: Annotated[str | None, typer.Option("--name", parser=_c_name, metavar="PREFIX", help=(
        "C header: prefix of the arrays (default IMU_ALIGN, IMU_CAL or IMU_MAG)."))] = None,
    rostopic: Annotated[str | None, typer.Option("--rostopic", parser=_rostopic, metavar="TOPIC", help=(
        "kalibr, openvins: the IMU's ROS topic (default /imu0)."))] = None,
    inflate: Annotated[float | None, typer.Option("--inflate", parser=number(INFLATE, "2"), metavar="FACTOR", help=(
        "Noise exports: multiply every noise value by FACTOR (a margin for vibration, temperature and model "
        "errors a rest record leaves out), stated in the file. Default 1: the figures as measured."))] = None,
    rate_hz: opt.RateHz("kalibr, openvins, vins: the IMU's sample rate the consumer runs at (update_rate, and f of "
                        "VINS-Fusion's per-sample values). Default: the Allan record's.") = None,
    predict_hz: Annotated[float | None, typer.Option("--predict-hz", parser=hertz, metavar="HZ", help=(
        "px4, ardupilot: the EKF's prediction rate f of the per-step values (default 100 Hz, PX4's EKF2_PREDICT_US "
        "of 10000 us; 83.3 Hz, EKF3's 12 ms step), Hz."))] = None,
    part: Annotated[str | None, typer.Option("--part", metavar="NAME", help=(
        "Noise exports: the gyroscope's figures from this part's datasheet (see 'imu-align parts') instead of an "
        "allan result."))] = None,
    parts: PartsFile = None,
    floor_tau: Annotated[float | None, typer.Option("--floor-tau", parser=quantity("time", POSITIVE, "100 s"),
                                                    metavar="TAU", help=(
        "With --part: the averaging time of the datasheet's Allan floor (e.g. '100 s'); bounds the random walk "
        "K <= B sqrt(3/TAU) from its bias instability B, written as an upper bound."))] = None,
) -> None:
    """A result in the format another program loads, stating its convention, frame, units, conversions and the tool
    version."""
    check_outputs([*results, parts], results=results, out=out)  # nor a data file a result names (its inputs)
    noise = {"inflate": inflate, "rate_hz": rate_hz, "predict_hz": predict_hz, "part": part, "parts": parts,
             "floor_tau": floor_tau}
    _unused(value(to), name, rostopic, noise)
    from align.present.exportable import export as export_result

    found = None
    if part is not None:
        from align.cli.parts import parts_table
        from align.parts import get_part

        found = get_part(part, "{part}", parts_table(parts))
    done = export_result([(_load(p), str(p)) for p in results], value(to), name, rostopic or "/imu0",
                         1.0 if inflate is None else inflate, rate_hz if predict_hz is None else predict_hz, found,
                         floor_tau)
    if out is None:
        typer.echo(done.text, nl=False)
        return
    with outputs() as staged:
        staged.write_text(out, done.text)
    typer.echo(f"wrote {out}: {value(to)} export of {', '.join(p.name for p in results)}"
               + (f" and the datasheet of {found.name}" if found is not None else ""))
    for line in done.summary:
        typer.echo(line)


COMMANDS: dict = {"export": export}
