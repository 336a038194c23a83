"""``imu-align check``: the mounting budget against the allowance (:data:`align.sensitivity.jobs.CHECK`).

Public names
------------
check, check_options, check_files, COMMANDS
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from align.cli import options as opt
from align.cli.allowable import Manoeuvre
from align.cli.budget import Mount
from align.cli.options import value
from align.cli.parts import PartsFile, parts_fields, parts_file
from align.cli.paths import check_outputs, data_files, write_run


def check_options(*, mount: Path, manoeuvre: Path, basis: Any = "rss", parts: Path | None = None, **_: Any):
    """The :class:`align.sensitivity.jobs.CheckOptions` of ``imu-align check``'s parameters."""
    from align.sensitivity.jobs import CheckOptions

    return CheckOptions(mount=mount, manoeuvre=manoeuvre, basis=value(basis), **parts_fields(parts))


def check_files(result, inputs, params: dict) -> list[tuple[Path, bytes | str]]:
    """No file beside the JSON result."""
    return []


def check(
    mount: Mount,
    manoeuvre: Manoeuvre,
    basis: opt.Choice("--basis", ("rss", "worst"), "Budget figure to compare: rss (the source's method) or worst.") = "rss",
    json_out: opt.JsonOut = None,
    parts: PartsFile = None,
) -> None:
    """The mounting budget against the allowance; exit status 4 when an element fails."""
    params = dict(locals())
    check_outputs([mount, manoeuvre, parts_file(parts)[0], *data_files(mount, manoeuvre)], json_out=json_out)
    from align.errors import CheckFailed
    from align.present.presets import preset_lines
    from align.present.text import margin_summary
    from align.sensitivity.jobs import CHECK

    table, inputs = CHECK.run_with_inputs(check_options(**params))
    write_run(json_out, table)
    typer.echo(margin_summary(table.rows, table.basis))
    shown = preset_lines(inputs)
    if shown:
        typer.echo("\n" + "\n".join(shown))
    if not table.passed:
        raise CheckFailed(f"the budget ({table.basis}) exceeds the allowance for {', '.join(table.failed)}")


COMMANDS = {"check": check}
