"""The jobs a batch may run, and each unit's options checked and made into the single command's words.

A manifest's options are checked against the job's own command when the manifest is read (the click
command typer builds, :func:`align.cli._click_app`): an unknown option, one the batch gives itself,
a value missing, or a word that is no option is one :class:`~align.errors.InputError` naming the
manifest's row. Options naming files are resolved against the manifest's folder, and the input
files among them enter the unit's content hash: every option typed ``Path`` (found from the
command's type hints) and the files of ``--axis-down x=FILE,y=FILE,z=FILE``.

Public names
------------
JOBS, RESERVED, OUTPUT_OPTIONS, check_options
"""

from __future__ import annotations

import difflib
from pathlib import Path
from typing import Annotated

from align.errors import InputError, literal

#: job -> (the option its manifest ``plan`` column is given as, whether it needs one)
JOBS: dict[str, tuple[str | None, str]] = {
    "matrix": ("--plan", "required"),
    "calibrate ferraris": ("--sections", "required"),
    "calibrate accel": ("--positions", "optional"),
    "calibrate mag": (None, "none"),
    "calibrate gyro": (None, "none"),
    "allan": (None, "none"),
}
#: options the batch gives every unit itself
RESERVED = ("--json", "--help", "--version")
#: options naming files a command writes (not inputs: they do not enter the content hash)
OUTPUT_OPTIONS = ("--c-header", "--plot", "--imucal-json", "--json")
#: str options whose value names input files, with how to find them: option -> parser of the value
FILE_LISTS = ("--axis-down",)


def _jobs() -> dict[str, str]:
    """The jobs this installation has, each with its use of the plan column."""
    from align.cli import COMMANDS

    have = {name if not subs else f"{name} {s}" for name, subs in COMMANDS.items() for s in (subs or (None,))}
    return {job: use for job, (_, use) in JOBS.items() if job in have}


def _command(job: str):
    from align.cli import alignment, calibrate, noise

    words = job.split()
    return calibrate.COMMANDS[words[1]] if words[0] == "calibrate" else {**alignment.COMMANDS, **noise.COMMANDS}[words[0]]


def _click(job: str):
    from align.cli import _click_app

    command = _click_app()
    for word in job.split():
        command = command.commands[word]
    return command


def _path_options(job: str) -> set[str]:
    """The options of ``job`` whose value is a file (``--segments``, ``--plot``): resolved against the manifest."""
    import typing

    found: set[str] = set()
    for hint in typing.get_type_hints(_command(job), include_extras=True).values():
        if typing.get_origin(hint) is not Annotated:
            continue
        base, *meta = typing.get_args(hint)
        if Path in (typing.get_args(base) or (base,)):
            for m in meta:  # typer.Option("--plot", ...) in Annotated: the flag is its first argument, "default"
                names = [getattr(m, "default", None), *(getattr(m, "param_decls", ()) or ())]
                found |= {d for d in names if isinstance(d, str) and d.startswith("--")}
    return found


def check_options(unit, where: str) -> None:
    """Check a unit's options against its job's command: known names, a value where one is needed, no
    positional words, none of :data:`RESERVED`; ``--axis-down``'s text parsed.

    Raises
    ------
    InputError
        Naming the manifest ``where``, the unit's row and column options.
    """
    def bad(what: str) -> InputError:
        return InputError(f"{unit.row}, column options: {what}", where)

    params = [p for p in _click(unit.job).params if getattr(p, "param_type_name", "") == "option"]
    flags = {o for p in params if getattr(p, "is_flag", False) for o in (*p.opts, *p.secondary_opts)}
    names = {o for p in params for o in (*p.opts, *p.secondary_opts)}
    plan_flag = JOBS[unit.job][0]
    words, i = unit.options, 0
    while i < len(words):
        word = words[i]
        name, eq, text = word.partition("=")
        if not word.startswith("-") or word == "-":
            raise bad(f"'{literal(word)}' is not an option of {unit.job} (a second log or a stray value?); "
                      "give one log per row, in column log")
        if name in RESERVED:
            raise bad(f"{name} is the batch's own (each unit's result goes to OUT/units/SERIAL.JOB.json); remove it")
        if name not in names:
            close = difflib.get_close_matches(name, sorted(names), n=1)
            raise bad(f"{unit.job} has no option {literal(name)}" + (f" (did you mean {close[0]}?)" if close else "")
                      + f"; see imu-align {unit.job} --help")
        if plan_flag is not None and name == plan_flag:
            raise bad(f"{name} is given in column plan; remove it from the options")
        if name in flags:
            i += 1
            continue
        if not eq and i + 1 >= len(words):
            raise bad(f"{name} needs a value")
        value = text if eq else words[i + 1]
        if name in FILE_LISTS:
            _axis_down_files(value, bad)
        i += 1 if eq else 2


def _axis_down_files(text: str, bad) -> list[tuple[str, str]]:
    """``--axis-down``'s (axis, FILE) items (sample ranges left out); a malformed text as ``bad``."""
    from align.calibration.axisdown import parse_axis_down

    try:
        parsed = parse_axis_down(text)
    except InputError as exc:
        raise bad(f"--axis-down: {exc.message if hasattr(exc, 'message') else exc}") from None
    return [(a, v) for a, v in parsed.items() if isinstance(v, str)]


def _resolved(options: tuple[str, ...], files: set[str], folder: Path) -> tuple[list[str], list[Path]]:
    """The options with file values made absolute (relative to ``folder``), and the input files among them."""
    out, inputs, i = [], [], 0
    while i < len(options):
        word = options[i]
        name, eq, text = word.partition("=")
        if (name in files or name in FILE_LISTS) and (eq or i + 1 < len(options)):
            value = text if eq else options[i + 1]
            if name in FILE_LISTS:
                parts = []
                for axis, v in _axis_down_files(value, lambda what: InputError(what, "{axis_down}")):
                    path = (folder / v).resolve()
                    inputs.append(path)
                    parts.append(f"{axis}={path}")
                ranges = [item for item in value.split(",") if item.strip() and ":" in item.partition("=")[2]]
                resolved = ",".join(parts + [r.strip() for r in ranges])
            else:
                path = (folder / value).resolve()
                resolved = str(path)
                if name not in OUTPUT_OPTIONS:
                    inputs.append(path)
            out += [f"{name}={resolved}"] if eq else [name, resolved]
            i += 1 if eq else 2
            continue
        out.append(word)
        i += 1
    return out, inputs


def _task_maker(folder: Path):
    from align.production import Task

    files = {job: _path_options(job) for job in _jobs()}

    def make(unit, result: Path, run: str) -> Task:
        flag = JOBS[unit.job][0]
        options, inputs = _resolved(unit.options, files[unit.job], folder)
        args = [*unit.job.split(), str(unit.log)]
        if unit.plan is not None:
            args += [flag, str(unit.plan)]
        args += [*options, "--json", str(result.resolve())]
        return Task(unit, tuple(args), result.resolve(), (unit.log, unit.plan, *inputs), run)

    return make
