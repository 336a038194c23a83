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
runs. Every value is checked for its domain where it is parsed (finite, and
``> 0``, ``>= 0`` or a range as the option states: :class:`Domain`); a refusal
is a usage error naming the option and what to type. Nothing here imports
numpy or the library's heavy modules.

Public names
------------
FLAGS, COMMAND_FLAGS, ALIASES, spell, speller, rewrite_aliases (the spelling of fields and flags);
Domain, ANY, POSITIVE, NONNEGATIVE, NONZERO, ACCURACY, DURATION, PAUSE, TOLERANCE, DIP, MAX_RATE_HZ
(the domains of values);
hertz, quantity, checked_text, number, whole, split_columns, names, value (values at the edge);
JsonOut, Seed, MonteCarlo, RateHz, Quantity, OptQuantity, Text, Number, Whole, Choice, Columns, UnitFlag, GyroUnits,
Units, Arg, Input, OptInput, Flag (typed options: ``name: Type = default``)
"""

from __future__ import annotations

import enum
import math
import shlex
from collections.abc import Callable
from dataclasses import dataclass
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
    "paths": "LOG...",
}

#: command -> field -> flag, where a command spells a field its own way
COMMAND_FLAGS: dict[str, dict[str, str]] = {
    "report": {"log": "--log", "mount": "--mount", "manoeuvre": "--manoeuvre"},
    "matrix": {"units": "--gyro-units"},
    "simulate": {"units": "--gyro-units"},
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


def spell(name: str, value: str | None = None, command: str | None = None,
          known: frozenset[str] | None = None) -> str:
    """A library field as the command line spells it: ``rate_hz`` -> ``--rate-hz``,
    ``(gyro_units, 'deg/s')`` -> ``--gyro-units deg/s``, ``(earth_correction, 'false')`` -> ``--no-earth``.

    With ``known`` (the options and argument names the command has), a field the command has no
    option for is spelled in words (``min_dwell`` -> ``min dwell``), never as a flag it does not take.
    """
    flag = COMMAND_FLAGS.get(command or "", {}).get(name) or FLAGS.get(name) or "--" + name.replace("_", "-")
    switch = value is not None and value.lower() in ("true", "false") and flag.startswith("--")
    if switch and value.lower() == "false":
        flag = "--no-" + flag[2:]
    if known is not None and not all(part in known for part in flag.split(" or ")):
        words = name.replace("_", " ")
        return words if value is None else f"{words} = {value}"
    if value is None or switch or not flag.startswith("--"):
        return flag
    return f"{flag} {shlex.quote(value)}"


def speller(command: str | None, known: frozenset[str] | None = None) -> Callable[[str, str | None], str]:
    """:func:`spell` for one command (``"matrix"``, ``"calibrate accel"``), as ``AlignError.render`` takes it;
    ``known``: the command's options and argument names (see :func:`spell`)."""
    return partial(spell, command=command, known=known)


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
#
# Every parser checks its value's domain where it is parsed: finite always, and the domain the
# option states (``> 0``, ``>= 0``, a range). A refusal says what to type: ``give a time > 0, e.g. '10 s'``.

_DEG = math.pi / 180.0
#: the highest sample rate accepted, Hz (a MEMS IMU samples at kHz at most)
MAX_RATE_HZ = 1e7


@dataclass(frozen=True)
class Domain:
    """Where a number may lie: above ``low`` (``open_low``: strictly), up to ``high``, or anywhere but 0.

    ``text`` is how the domain reads in a refusal (``"> 0"``, ``"within -90 deg and 90 deg"``).
    """

    text: str
    low: float | None = None
    high: float | None = None
    open_low: bool = True
    nonzero: bool = False

    def holds(self, x: float) -> bool:
        """``x`` is finite and inside the domain."""
        if not math.isfinite(x) or (self.nonzero and x == 0):
            return False
        if self.low is not None and (x <= self.low if self.open_low else x < self.low):
            return False
        return self.high is None or x <= self.high


#: any finite number
ANY = Domain("")
#: > 0
POSITIVE = Domain("> 0", low=0.0)
#: >= 0
NONNEGATIVE = Domain(">= 0", low=0.0, open_low=False)
#: any finite number but 0
NONZERO = Domain("other than 0", nonzero=True)
#: an alignment goal: (0, 90] deg
ACCURACY = Domain("> 0 and <= 90 deg", low=0.0, high=90 * _DEG)
#: a duration > 0 of at most a day (a moving window, a dwell, a static interval), s
DURATION = Domain("> 0 and <= 86400 s (a day)", low=0.0, high=86400.0)
#: a duration >= 0 of at most a day (a margin, a gap, a settling time), s
PAUSE = Domain(">= 0 and <= 86400 s (a day)", low=0.0, high=86400.0, open_low=False)
#: a relative tolerance: (0, 100 %]
TOLERANCE = Domain("> 0 and <= 100 %", low=0.0, high=1.0)
#: a magnetic dip: [-90, 90] deg
DIP = Domain("within -90 deg and 90 deg", low=-90 * _DEG, high=90 * _DEG, open_low=False)


def _give(what: str, domain: Domain, example: str) -> str:
    """``give a time > 0, e.g. '10 s'``."""
    return f"give {what}{' ' + domain.text if domain.text else ''}, e.g. {example}"


def hertz(text: str | float) -> float:
    """A sample rate: a bare number of Hz (``100``) or a frequency (``'100 Hz'``, ``'2 kHz'``), in Hz,
    above 0 and at most :data:`MAX_RATE_HZ`."""
    advice = "give a sample rate > 0 Hz and <= 1e7 Hz, e.g. 100 or '100 Hz'"
    if isinstance(text, (int, float)):
        value = float(text)
    else:
        try:
            value = float(text)
        except ValueError:
            from align.errors import AlignError
            from align.units import parse_quantity

            try:
                value = parse_quantity(text, "frequency")
            except AlignError:
                raise ValueError(advice) from None
    if not (math.isfinite(value) and 0 < value <= MAX_RATE_HZ):
        raise ValueError(advice)
    return value


def _si(text: str | float, expect: str, domain: Domain, example: str | None) -> float:
    """``text`` (``'<number> <unit>'`` of dimension ``expect``) in SI, checked against ``domain``."""
    from align.errors import AlignError
    from align.units import DIMENSIONS, parse_quantity

    what, _, default_example = DIMENSIONS[expect][1].partition(", e.g. ")
    if isinstance(text, (int, float)):
        value = float(text)
    else:
        try:
            value = parse_quantity(text, expect)
        except AlignError as exc:
            raise ValueError(exc.render()) from None
    if not domain.holds(value):
        raise ValueError(_give(what, domain, example or default_example))
    return value


def quantity(expect: str, domain: Domain = ANY, example: str | None = None) -> Callable[[str], float]:
    """A parser of ``'<number> <unit>'`` of dimension ``expect`` (a key of ``align.units.DIMENSIONS``), to SI,
    refusing a value outside ``domain`` (the refusal shows ``example``, by default the dimension's own)."""

    def parse(text: str | float) -> float:
        return _si(text, expect, domain, example)

    parse.__name__ = expect
    return parse


def checked_text(expect: str, domain: Domain = ANY, example: str | None = None) -> Callable[[str], str]:
    """Like :func:`quantity`, but the command receives the text itself (stripped), once checked
    (for options the command shows as typed, e.g. a plan's noise source)."""

    def parse(text: str) -> str:
        _si(text, expect, domain, example)
        return str(text).strip()

    parse.__name__ = expect
    return parse


def number(domain: Domain = ANY, example: str = "10") -> Callable[[str], float]:
    """A parser of a plain finite number in ``domain``."""

    def parse(text: str | float) -> float:
        try:
            value = float(text)
        except (TypeError, ValueError):
            raise ValueError(_give("a number", domain, example)) from None
        if not domain.holds(value):
            raise ValueError(_give("a number", domain, example))
        return value

    parse.__name__ = "number"
    return parse


def whole(low: int = 0, high: int | None = None, example: str = "100000") -> Callable[[str], int]:
    """A parser of a whole number ``low <= n <= high`` (``'1e5'`` is read as 100000)."""
    shown = f">= {low}" + (f" and <= {high}" if high is not None else "")

    def parse(text: str | int) -> int:
        advice = f"give a whole number {shown}, e.g. {example}"
        if isinstance(text, int):
            value = text
        else:
            try:
                value = int(str(text).strip())
            except ValueError:
                try:
                    f = float(text)
                except ValueError:
                    f = math.nan
                if not (math.isfinite(f) and f.is_integer()):
                    raise ValueError(advice) from None
                value = int(f)
        if value < low or (high is not None and value > high):
            raise ValueError(advice)
        return value

    parse.__name__ = "whole"
    return parse


# ---- typed options: Annotated types, the default goes in the signature ----

#: where the versioned JSON result goes
JsonOut = Annotated[Path | None, typer.Option("--json", metavar="FILE.json", help="Write the versioned JSON result here.")]
#: the random seed of a simulation or a Monte Carlo: a whole number >= 0
Seed = Annotated[int, typer.Option("--seed", parser=whole(0, example="0"), metavar="N", help="Random seed (>= 0).")]


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


def Quantity(flag: str, expect: str, help: str, metavar: str = "QUANTITY", domain: Domain = ANY,
             example: str | None = None):
    """A quantity option (``'1 s'``, ``'0.05 deg'``) given to the command in SI, checked against ``domain``
    (see :func:`quantity`)."""
    return Annotated[float, typer.Option(flag, parser=quantity(expect, domain, example), metavar=metavar, help=help)]


def OptQuantity(flag: str, expect: str, help: str, metavar: str = "QUANTITY", domain: Domain = ANY,
                example: str | None = None):
    """:func:`Quantity` that may be left out (None)."""
    return Annotated[float | None, typer.Option(flag, parser=quantity(expect, domain, example), metavar=metavar,
                                                help=help)]


def Text(flag: str, expect: str, help: str, metavar: str = "QUANTITY", domain: Domain = ANY, example: str | None = None,
         optional: bool = True):
    """A quantity option the command receives as typed (a string), checked like :func:`Quantity`."""
    return Annotated[str | None if optional else str, typer.Option(flag, parser=checked_text(expect, domain, example),
                                                                   metavar=metavar, help=help)]


def Number(flag: str, help: str, domain: Domain = POSITIVE, example: str = "10", metavar: str = "NUMBER"):
    """A plain number option (``--noise-ratio``, ``--exaggerate``), finite and in ``domain``."""
    return Annotated[float, typer.Option(flag, parser=number(domain, example), metavar=metavar, help=help)]


def Whole(flag: str, help: str, low: int = 0, high: int | None = None, example: str = "100000"):
    """A whole-number option (``--steps``, ``--per-decade``), ``low <= n <= high``."""
    return Annotated[int, typer.Option(flag, parser=whole(low, high, example), metavar="N", help=help)]


def MonteCarlo(help: str = "Monte Carlo draws (0: none)."):
    """``--monte-carlo N``, 0 <= N <= 1e8 (1e8 draws already take minutes and gigabytes)."""
    return Whole("--monte-carlo", help, 0, 100_000_000, "100000")


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
