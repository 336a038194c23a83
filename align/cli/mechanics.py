"""Commands of the mounting budget and the allowance: ``budget``, ``allowable``, ``check``.

Public names
------------
budget, allowable, check, COMMANDS, MOUNT_HELP, MANOEUVRE_HELP
"""

from pathlib import Path

import typer

from align.cli import options as opt
from align.cli.options import value
from align.cli.parts import PartsFile, parts_file, parts_table
from align.cli.paths import check_outputs, data_files, outputs
from align.cli.progress import progress

MOUNT_HELP = "Mount description TOML: [imu], [package], [ledges] or [baseplate], [screws]."
MANOEUVRE_HELP = "Manoeuvre TOML: [[rotation]] tables with axis and angle (or a [series]), and [limits]."
Mount = opt.Arg(MOUNT_HELP, "MOUNT")
Manoeuvre = opt.Arg(MANOEUVRE_HELP, "MANOEUVRE")


def _read_mount(path: Path, parts: Path | None = None):
    """The mount, its ``[imu] part`` looked up in the presets and the user's parts file (``--parts`` or
    the environment variable of :mod:`align.cli.parts`)."""
    from align.io import read_toml
    from mechanics import mount_from_dict

    table = parts_table(parts)
    return mount_from_dict(read_toml(path), str(path), path.parent, parts=table)


def _read_manoeuvre(path: Path):
    from align.io import read_toml
    from align.sensitivity import manoeuvre_from_dict

    return manoeuvre_from_dict(read_toml(path), str(path), path.parent)


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
    from align.errors import InputError

    if plot is not None and monte_carlo == 0:
        raise InputError("the histogram needs {monte_carlo}", "{plot}")
    check_outputs([mount, parts_file(parts)[0], *data_files(mount=mount)], json_out=json_out, plot=plot,
                  picture=picture, glb=glb)
    import mechanics
    from align.present.text import budget_summary

    m = _read_mount(mount, parts)
    result = mechanics.budget(m)
    if parts_file(parts)[0] is not None:
        result = result.replace(inputs={**result.inputs, "parts": str(parts_file(parts)[0])})
    if monte_carlo:
        with progress(monte_carlo, "Monte Carlo") as tick:
            result = result.replace(monte_carlo=mechanics.monte_carlo(m, monte_carlo, seed, progress=tick))
    with outputs() as out:  # all or none: every picture is drawn before anything is written
        if plot is not None:
            out.write_bytes(plot, mechanics.histogram_png(result))
        if picture is not None:
            out.write_bytes(picture, mechanics.assembly_png(m, exaggerate))
        if glb is not None:
            out.write_bytes(glb, mechanics.assembly_glb(m, exaggerate))
        if json_out is not None:
            out.write_json(json_out, result)
    typer.echo(budget_summary(result))


def allowable(
    manoeuvre: Manoeuvre,
    json_out: opt.JsonOut = None,
    symbolic: opt.Choice("--symbolic", ("pretty", "latex"), "Also print the sympy response and sensitivity.") = None,
) -> None:
    """Allowable misalignment per element for a manoeuvre, the binding element and the cone."""
    check_outputs([manoeuvre, *data_files(manoeuvre=manoeuvre)], json_out=json_out)
    from align.present.text import allowable_summary
    from align.sensitivity import allowable as compute
    from align.sensitivity import symbolic_text

    man = _read_manoeuvre(manoeuvre)
    if symbolic is not None:
        typer.echo(symbolic_text(value(symbolic)) + "\n")
    result = compute(man)
    with outputs() as out:
        if json_out is not None:
            out.write_json(json_out, result)
    typer.echo(allowable_summary(result))


def check(
    mount: Mount,
    manoeuvre: Manoeuvre,
    basis: opt.Choice("--basis", ("rss", "worst"), "Budget figure to compare: rss (the source's method) or worst.") = "rss",
    json_out: opt.JsonOut = None,
    parts: PartsFile = None,
) -> None:
    """The mounting budget against the allowance; exit status 4 when an element fails."""
    check_outputs([mount, manoeuvre, parts_file(parts)[0], *data_files(mount, manoeuvre)], json_out=json_out)
    import mechanics
    from align.errors import CheckFailed
    from align.present.presets import preset_lines
    from align.present.text import margin_summary
    from align.sensitivity import allowable as compute
    from align.sensitivity import check_margins

    b = mechanics.budget(_read_mount(mount, parts))
    allow = compute(_read_manoeuvre(manoeuvre))
    table = check_margins(b.elements(value(basis)), allow, value(basis))
    table = table.replace(inputs={"mount": str(mount), "manoeuvre": str(manoeuvre), "part": b.mount.part,
                                  "preset": b.mount.preset})
    with outputs() as out:
        if json_out is not None:
            out.write_json(json_out, table)
    typer.echo(margin_summary(table.rows, table.basis))
    shown = preset_lines(b)
    if shown:
        typer.echo("\n" + "\n".join(shown))
    if not table.passed:
        raise CheckFailed(f"the budget ({table.basis}) exceeds the allowance for {', '.join(table.failed)}")


COMMANDS = {"budget": budget, "allowable": allowable, "check": check}
