"""``imu-align budget``: the mounting-misalignment budget of a mount (:data:`mechanics.jobs.BUDGET`).

Public names
------------
budget, budget_options, budget_files, Mount, MOUNT_HELP, COMMANDS
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from align.cli import options as opt
from align.cli.parts import PartsFile, parts_fields, parts_file
from align.cli.paths import check_outputs, data_files, write_run
from align.cli.progress import progress

MOUNT_HELP = "Mount description TOML: [imu], [package], [ledges] or [baseplate], [screws]."
Mount = opt.Arg(MOUNT_HELP, "MOUNT")


def budget_options(*, mount: Path, monte_carlo: int = 0, seed: int = 0, parts: Path | None = None, **_: Any):
    """The :class:`mechanics.jobs.BudgetOptions` of ``imu-align budget``'s parameters (output options ignored)."""
    from mechanics.jobs import BudgetOptions

    return BudgetOptions(mount=mount, monte_carlo=monte_carlo, seed=seed, **parts_fields(parts))


def budget_files(result, inputs, params: dict) -> list[tuple[Path, bytes | str]]:
    """The pictures ``--plot``, ``--picture`` and ``--glb`` ask for (all drawn before anything is written)."""
    import mechanics

    out: list[tuple[Path, bytes | str]] = []
    exaggerate = params.get("exaggerate", 30.0)
    if params.get("plot") is not None:
        out.append((params["plot"], mechanics.histogram_png(result)))
    if params.get("picture") is not None:
        out.append((params["picture"], mechanics.assembly_png(result.mount, exaggerate)))
    if params.get("glb") is not None:
        out.append((params["glb"], mechanics.assembly_glb(result.mount, exaggerate)))
    return out


def budget(
    mount: Mount,
    monte_carlo: opt.MonteCarlo() = 0,
    seed: opt.Seed = 0,
    json_out: opt.JsonOut = None,
    plot: opt.OptInput("--plot", "PNG histogram of the Monte Carlo (needs --monte-carlo).", "FILE.png") = None,
    picture: opt.OptInput("--picture", "PNG of the assembly, tilt exaggerated.", "FILE.png") = None,
    glb: opt.OptInput("--glb", "GLB of the assembly, tilt exaggerated.", "FILE.glb") = None,
    exaggerate: opt.Number("--exaggerate", "Angle exaggeration of --picture and --glb (> 0, at most 10000).",
                           opt.Domain("> 0 and <= 10000", low=0.0, high=1e4), "30", "FACTOR") = 30.0,
    parts: PartsFile = None,
) -> None:
    """Mounting-misalignment budget: source formulas, worst case and Monte Carlo."""
    params = dict(locals())
    from align.errors import InputError

    if plot is not None and monte_carlo == 0:
        raise InputError("the histogram needs {monte_carlo}", "{plot}")
    check_outputs([mount, parts_file(parts)[0], *data_files(mount=mount)], json_out=json_out, plot=plot,
                  picture=picture, glb=glb)
    from align.present.text import budget_summary
    from mechanics.jobs import BUDGET

    opts = budget_options(**params)
    with progress(monte_carlo, "Monte Carlo") as tick:
        result = BUDGET.run(opts, progress=tick)
    write_run(json_out, result, budget_files(result, None, params))  # all or none: every picture drawn first
    typer.echo(budget_summary(result))


COMMANDS = {"budget": budget}
