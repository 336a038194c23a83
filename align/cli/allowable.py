"""``imu-align allowable``: what a manoeuvre allows (:data:`align.sensitivity.jobs.ALLOWABLE`).

Public names
------------
allowable, allowable_options, allowable_files, Manoeuvre, MANOEUVRE_HELP, COMMANDS
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from align.cli import options as opt
from align.cli.options import value
from align.cli.paths import check_outputs, data_files, write_run

MANOEUVRE_HELP = "Manoeuvre TOML: [[rotation]] tables with axis and angle (or a [series]), and [limits]."
Manoeuvre = opt.Arg(MANOEUVRE_HELP, "MANOEUVRE")


def allowable_options(*, manoeuvre: Path, **_: Any):
    """The :class:`align.sensitivity.jobs.AllowableOptions` of ``imu-align allowable``'s parameters."""
    from align.sensitivity.jobs import AllowableOptions

    return AllowableOptions(manoeuvre=manoeuvre)


def allowable_files(result, inputs, params: dict) -> list[tuple[Path, bytes | str]]:
    """No file beside the JSON result."""
    return []


def allowable(
    manoeuvre: Manoeuvre,
    json_out: opt.JsonOut = None,
    symbolic: opt.Choice("--symbolic", ("pretty", "latex"), "Also print the sympy response and sensitivity.") = None,
) -> None:
    """Allowable misalignment per element for a manoeuvre, the binding element and the cone."""
    params = dict(locals())
    check_outputs([manoeuvre, *data_files(manoeuvre=manoeuvre)], json_out=json_out)
    from align.present.text import allowable_summary
    from align.sensitivity import symbolic_text
    from align.sensitivity.jobs import ALLOWABLE, AllowableInputs, read_manoeuvre

    opts = allowable_options(**params)
    inputs = AllowableInputs(read_manoeuvre(opts.manoeuvre))  # read first: a bad file says so before the algebra
    if symbolic is not None:
        typer.echo(symbolic_text(value(symbolic)) + "\n")
    result = ALLOWABLE.stamp(ALLOWABLE.compute(inputs, opts, None), opts)
    write_run(json_out, result)
    typer.echo(allowable_summary(result))


COMMANDS = {"allowable": allowable}
