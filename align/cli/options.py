"""Options shared by the commands, and the one table that turns a library field into a flag.

The library names an input by its Python name (``rate_hz``, ``gyro_units``) in
a placeholder (``{rate_hz}``, ``{gyro_units=deg/s}``); :func:`spell` renders it
as the command line spells it (``--rate-hz``, ``--gyro-units deg/s``): by
default field ``foo_bar`` is flag ``--foo-bar``; :data:`FLAGS` lists the
exceptions and :data:`COMMAND_FLAGS` the few that depend on the command.
:data:`ALIASES` keeps the old spellings of renamed options working without
showing them in ``--help`` (:func:`rewrite_aliases`).

Every option a command shares with another is defined here once, typed: a
sample rate is a number of Hz or a frequency (``100``, ``'100 Hz'``), a quantity
option arrives in SI (``'1 s'`` -> 1.0), a choice is checked before the command
runs. Nothing here imports numpy or the library's heavy modules.

Public names
------------
FLAGS, COMMAND_FLAGS, ALIASES, spell, speller, rewrite_aliases (the spelling of fields and flags);
hertz, quantity, split_columns, names, value (values at the edge);
JsonOut, Seed, MonteCarlo, RateHz, Quantity, OptQuantity, Choice, Columns, UnitFlag, GyroUnits, Units, Arg, Input,
OptInput, Flag (typed options: ``name: Type = default``)
"""

from __future__ import annotations

import enum
import shlex
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Annotated

import typer

#: library field -> flag, where it is not ``--`` + the field with ``_`` as ``-``
FLAGS: dict[str, str] = {
    "json_out": "--json",
    "fs": "--rate-hz",
    "table_rate": "--rate",
    "ratio": "--noise-ratio",
    "allan_json": "--allan",
    "allan_log": "--allan",
    "allan_columns": "--columns",
    "allan_rate_hz": "--rate-hz",
    "allan_units": "--units",
    "acc_units": "--accel-units",
    "gyr_units": "--gyro-units",
    "acc_columns": "--accel-columns",
    "gyr_columns": "--gyro-columns",
    "pairwise_bias": "--bias",
    "earth_correction": "--earth",
    "window_s": "--window",
    "margin_s": "--margin",
    "dwell_s": "--dwell",
    "static_s": "--gap",
    "noise_density": "--noise",
    "taus": "--grid",
    "style": "--symbolic",
    "memory_limit": "--memory-limit-mb",
    "init_static_s": "--init-static",
    "min_duration_s": "--min-static",
    "acc": "--accel-columns",
    # positional arguments
    "log": "LOG",
    "logs": "LOG...",
    "mount": "MOUNT",
    "manoeuvre": "MANOEUVRE",
    "out_dir": "OUT_DIR",
}

#: command -> field -> flag, where a command spells a field its own way
COMMAND_FLAGS: dict[str, dict[str, str]] = {
    "report": {"log": "--log", "mount": "--mount", "manoeuvre": "--manoeuvre"},
    "calibrate ferraris": {"units": "--accel-units", "columns": "--accel-columns or --gyro-columns"},
    "calibrate accel": {"units": "--accel-units"},
    "calibrate mag": {"units": "--mag-units"},
}

#: command -> old flag -> its name today; accepted, not shown in --help
ALIASES: dict[str, dict[str, str]] = {
    "simulate": {"--fs": "--rate-hz"},
    "report": {"--allan-units": "--units", "--allan-columns": "--columns", "--allan-rate-hz": "--rate-hz"},
    "calibrate ferraris": {"--acc-units": "--accel-units", "--gyr-units": "--gyro-units",
                           "--acc-columns": "--accel-columns", "--gyr-columns": "--gyro-columns"},
    "calibrate accel": {"--units": "--accel-units"},
}


def spell(name: str, value: str | None = None, command: str | None = None) -> str:
    """A library field as the command line spells it: ``rate_hz`` -> ``--rate-hz``,
    ``(gyro_units, 'deg/s')`` -> ``--gyro-units deg/s``, ``(earth_correction, 'false')`` -> ``--no-earth``."""
    flag = COMMAND_FLAGS.get(command or "", {}).get(name) or FLAGS.get(name) or "--" + name.replace("_", "-")
    if value is None or not flag.startswith("--"):
        return flag
    if value.lower() in ("true", "false"):
        return flag if value.lower() == "true" else "--no-" + flag[2:]
    return f"{flag} {shlex.quote(value)}"


def speller(command: str | None) -> Callable[[str, str | None], str]:
    """:func:`spell` for one command (``"matrix"``, ``"calibrate accel"``), as ``AlignError.render`` takes it."""
    return partial(spell, command=command)


def rewrite_aliases(command: str | None, args: list[str]) -> list[str]:
    """``args`` with the command's old option names (``--fs``, ``--fs=200``) replaced by today's."""
    table = ALIASES.get(command or "", {})
    out: list[str] = []
    for i, arg in enumerate(args):
        if arg == "--":
            return out + args[i:]
        name, eq, value = arg.partition("=")
        out.append(table[name] + eq + value if name in table else arg)
    return out


def split_columns(text: str, rate_hz: float | None) -> tuple[str | None, list[str]]:
    """``'time,x,y,z'`` -> ``('time', [x, y, z])``; with a sample rate the last three names, no time column."""
    from align.errors import InputError

    given = names(text)
    if rate_hz is None:
        if len(given) != 4:
            raise InputError("give four names: time,x,y,z (or three with {rate_hz})", "{columns}")
        return given[0], given[1:]
    return None, given[-3:]


def names(text: str) -> list[str]:
    """``'a, b,c'`` -> ``['a', 'b', 'c']``."""
    return [c.strip() for c in text.split(",") if c.strip()]


def value(choice) -> str:
    """The string of a :func:`Choice` member (or of a plain string)."""
    return getattr(choice, "value", choice)


# ---- value parsers (a ValueError becomes a usage error naming the option) ----

def hertz(text: str | float) -> float:
    """A sample rate: a bare number of Hz (``100``) or a frequency (``'100 Hz'``, ``'2 kHz'``), in Hz."""
    if isinstance(text, (int, float)):
        return float(text)
    try:
        value = float(text)
    except ValueError:
        from align.errors import AlignError
        from align.units import parse_quantity

        try:
            value = parse_quantity(text, "frequency")
        except AlignError:
            raise ValueError(f"'{text}' is not a sample rate; give Hz, e.g. 100 or '100 Hz'") from None
    if not value > 0 or value == float("inf"):
        raise ValueError(f"'{text}' is not a positive sample rate")
    return value


def quantity(expect: str) -> Callable[[str], float]:
    """A parser of ``'<number> <unit>'`` of dimension ``expect`` (a key of ``align.units.DIMENSIONS``), to SI."""

    def parse(text: str | float) -> float:
        if isinstance(text, (int, float)):
            return float(text)
        from align.errors import AlignError
        from align.units import parse_quantity

        try:
            return parse_quantity(text, expect)
        except AlignError as exc:
            raise ValueError(exc.render()) from None

    parse.__name__ = expect
    return parse


# ---- typed options: Annotated types, the default goes in the signature ----

#: where the versioned JSON result goes
JsonOut = Annotated[Path | None, typer.Option("--json", metavar="FILE.json", help="Write the versioned JSON result here.")]
#: the random seed of a simulation or a Monte Carlo
Seed = Annotated[int, typer.Option("--seed", metavar="N", help="Random seed.")]


def Arg(help: str, metavar: str):
    """A required positional input file (``LOG``, ``MOUNT``)."""
    return Annotated[Path, typer.Argument(metavar=metavar, help=help, show_default=False)]


def Input(flag: str, help: str, metavar: str):
    """A required file given as an option (``--plan PLAN.toml``)."""
    return Annotated[Path, typer.Option(flag, metavar=metavar, help=help)]


def OptInput(flag: str, help: str, metavar: str):
    """A file given as an option that may be left out (an input, or an output checked by ``paths.check_outputs``)."""
    return Annotated[Path | None, typer.Option(flag, metavar=metavar, help=help)]


def RateHz(help: str = "Sample rate, for a log without a time column.", required: bool = False):
    """``--rate-hz``: a number of Hz or a frequency, given to the command in Hz (see :func:`hertz`)."""
    return Annotated[float if required else float | None,
                     typer.Option("--rate-hz", parser=hertz, metavar="HZ", help=f"{help} Hz, e.g. 100 or '100 Hz'.")]


def Quantity(flag: str, expect: str, help: str, metavar: str = "QUANTITY"):
    """A quantity option (``'1 s'``, ``'0.05 deg'``) given to the command in SI (see :func:`quantity`)."""
    return Annotated[float, typer.Option(flag, parser=quantity(expect), metavar=metavar, help=help)]


def OptQuantity(flag: str, expect: str, help: str, metavar: str = "QUANTITY"):
    """:func:`Quantity` that may be left out (None)."""
    return Annotated[float | None, typer.Option(flag, parser=quantity(expect), metavar=metavar, help=help)]


def MonteCarlo(help: str = "Monte Carlo draws (0: none)."):
    """``--monte-carlo N``, N >= 0."""
    return Annotated[int, typer.Option("--monte-carlo", min=0, metavar="N", help=help)]


def Choice(flag: str, values: tuple[str, ...], help: str):
    """One of ``values``, checked by the parser; the command receives an Enum member (see :func:`value`)."""
    kind = enum.Enum(flag.strip("-").title().replace("-", ""), {v: v for v in values}, type=str)
    return Annotated[kind, typer.Option(flag, help=help)]


def Flag(flag: str, help: str):
    """An on/off switch (``--earth/--no-earth``)."""
    return Annotated[bool, typer.Option(flag, help=help)]


def Columns(help: str, flag: str = "--columns", optional: bool = False):
    """A column list: ``--columns``, ``--gyro-columns`` or ``--accel-columns`` (see :func:`names`, :func:`split_columns`)."""
    return Annotated[str | None if optional else str, typer.Option(flag, metavar="NAMES", help=help)]


def UnitFlag(flag: str, help: str, optional: bool = False):
    """A unit option (``--gyro-units``, ``--accel-units``, ``--mag-units``, ``--units``); the library checks it."""
    return Annotated[str | None if optional else str, typer.Option(flag, metavar="UNIT", help=help)]


def GyroUnits(help: str = "Unit of the gyro columns, e.g. deg/s, rad/s, mdps."):
    """``--gyro-units``."""
    return UnitFlag("--gyro-units", help)


def Units(help: str):
    """``--units``: the generic unit option, None when not given."""
    return UnitFlag("--units", help, optional=True)
