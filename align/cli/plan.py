"""``imu-align plan``: averaging time per table step for an alignment goal (Example 3), and the whole plan.

The command parses its options into :class:`align.noise.jobs.PlanOptions` (:func:`plan_options`, which the
batch uses too) and runs :data:`align.noise.jobs.PLAN`.

Public names
------------
plan, plan_options
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from align.cli import options as opt
from align.cli.allan import Accuracy, NoiseRatio
from align.cli.options import ACCURACY, NONNEGATIVE, NONZERO, PAUSE, POSITIVE
from align.cli.parts import ENV, PartsFile, parts_file
from align.cli.paths import check_outputs, outputs

Rate = "Table rate, e.g. '100 deg/s'"


def _si(value: float | str | None, expect: str, field: str) -> float | None:
    """A quantity as typed (checked when parsed) or already in SI."""
    if value is None or not isinstance(value, str):
        return value
    from align.units import parse_quantity

    return parse_quantity(value, expect, "{" + field + "}")


def _required(value: float | str | None, expect: str, field: str) -> float:
    """A quantity the plan cannot do without (a manifest row may leave it out)."""
    si = _si(value, expect, field)
    if si is None:
        from align.errors import InputError

        raise InputError("is required", "{" + field + "}")
    return float(si)


def plan_options(rate: float | str | None = None, accuracy: float | str | None = None, noise_ratio: float = 10.0,
                 arw: str | float | None = None, bias_instability: str | float | None = None,
                 rate_random_walk: str | float | None = None, imu: str | None = None,
                 allan_json: Path | None = None, turn_angle: float | str = "360 deg", settle: float | str = "2 s",
                 steps: int = 6, parts: Path | None = None, **_: Any):
    """The ``plan`` job's options from the command's parameters (Python names, as typer delivers them).

    The parts file is ``parts``, else the one the environment names (:data:`align.cli.parts.ENV`).
    Output options and unknown keys are ignored.

    Returns
    -------
    PlanOptions
    """
    from align.noise.jobs import PlanOptions

    return PlanOptions(
        rate=_required(rate, "angular_rate", "rate"), accuracy=_required(accuracy, "angle", "accuracy"),
        noise_ratio=noise_ratio,
        arw=_si(arw, "angle_random_walk", "arw"), bias_instability=_si(bias_instability, "angular_rate",
                                                                       "bias_instability"),
        rate_random_walk=_si(rate_random_walk, "rate_random_walk", "rate_random_walk"), imu=imu,
        allan=allan_json, parts=parts_file(parts)[0], turn_angle=_required(turn_angle, "angle", "turn_angle"),
        settle=_required(settle, "time", "settle"), steps=steps)


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
    params = dict(locals())
    from align.errors import AlignError, InputError
    from align.noise.jobs import PLAN
    from align.present.text import plan_summary

    path, note = parts_file(parts)
    check_outputs([allan_json, path], json_out=json_out)
    options = plan_options(**params)
    try:
        result = PLAN.run(options)
    except AlignError as exc:  # a parts file named by the environment: say so
        if note is None or path is None or str(path) not in str(exc.where or ""):
            raise
        raise InputError(f"{exc.message} (the parts file {note}; fix it or unset {ENV})", exc.where) from None
    with outputs() as out:
        if json_out is not None:
            out.write_json(json_out, result)
    typer.echo(plan_summary(result))


COMMANDS = {"plan": plan}
