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
is a usage error naming the option and what to type (the parsers and domains
live in :mod:`align.cli.parsers`, re-exported here). Nothing here imports
numpy or the library's heavy modules.

A command that reads a log takes the logger file options :data:`SkipRows`,
:data:`Comment`, :data:`Delimiter` (text logs), :data:`TimeUnits` (a time
column), :data:`Topic` and :data:`Stamps` (a log of several streams: a ROS bag,
a ULog, a DataFlash log), and builds the library's ``LogFormat`` from them with
:func:`log_format` (and its ``LogSource`` with :func:`log_source`). A unit option
left out means the unit the file states (a ULog, a bag), else the sensor's
default (:func:`stated_default` says so in the help).

Public names
------------
FLAGS, COMMAND_FLAGS, ALIASES, spell, speller, rewrite_aliases (the spelling of fields and flags);
Domain, ANY, POSITIVE, NONNEGATIVE, NONZERO, ACCURACY, DURATION, PAUSE, TOLERANCE, DIP, MAX_RATE_HZ
(the domains of values);
hertz, quantity, checked_text, number, whole, delimiter, comment, time_units, topic, stamps, split_columns, names,
value (values at the edge);
JsonOut, Seed, MonteCarlo, RateHz, Quantity, OptQuantity, Text, Number, Whole, Choice, Columns, UnitFlag, GyroUnits,
Units, Arg, Input, OptInput, Flag, SkipRows, Comment, Delimiter, TimeColumn, TimeUnits, Topic, Stamps (typed options:
``name: Type = default``); stated_default (the help of a unit option);
log_format, log_source (the log options as the library's ``LogFormat`` and ``LogSource``)
"""

from __future__ import annotations

import enum
import shlex
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Annotated

import typer

from align.cli.parsers import (  # noqa: F401  (re-exported: the commands take them from here)
    ACCURACY,
    ANY,
    DIP,
    DURATION,
    MAX_RATE_HZ,
    NONNEGATIVE,
    NONZERO,
    PAUSE,
    POSITIVE,
    TOLERANCE,
    Domain,
    checked_text,
    comment,
    delimiter,
    hertz,
    number,
    quantity,
    stamps,
    time_units,
    topic,
    whole,
)

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
    # a logger file's format (align.io.formats.LogFormat): the default spelling, listed because every log reader
    # names them
    "skip_rows": "--skip-rows",
    "comment": "--comment",
    "delimiter": "--delimiter",
    "time_units": "--time-units",
    "topic": "--topic",
    "stamps": "--stamps",
    # positional arguments
    "log": "LOG",
    "logs": "LOG...",
    "mount": "MOUNT",
    "manoeuvre": "MANOEUVRE",
    "out_dir": "OUT_DIR",
    "paths": "LOG...",
    "results": "RESULTS",
}

#: command -> field -> flag, where a command spells a field its own way
COMMAND_FLAGS: dict[str, dict[str, str]] = {
    "report": {"log": "--log", "mount": "--mount", "manoeuvre": "--manoeuvre"},
    "matrix": {"units": "--gyro-units"},
    "simulate": {"units": "--gyro-units"},
    "simulate session": {"units": "--gyro-units"},
    "simulate poses": {"units": "--gyro-units"},
    "calibrate ferraris": {"units": "--accel-units", "columns": "--accel-columns or --gyro-columns"},
    "calibrate accel": {"units": "--accel-units"},
    "calibrate mag": {"units": "--mag-units", "columns": "--columns or --accel-columns"},
    "drift": {"manoeuvre": "--manoeuvre", "columns": "--gyro-columns or --accel-columns"},
}

#: command -> old flag -> its name today; accepted, not shown in --help
ALIASES: dict[str, dict[str, str]] = {
    "simulate session": {"--fs": "--rate-hz"},
    "simulate poses": {"--fs": "--rate-hz"},
    "simulate lot": {"--fs": "--rate-hz"},
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
    lowered = None if value is None else value.lower()
    switch = lowered in ("true", "false") and flag.startswith("--")
    if switch and lowered == "false":
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


# ---- typed options: Annotated types, the default goes in the signature ----

#: where the versioned JSON result goes
JsonOut = Annotated[Path | None, typer.Option("--json", metavar="FILE.json", help="Write the versioned JSON result here.")]
#: the temperature column of a log and its unit (calibrate thermal; apply with a thermal result)
TemperatureColumn = Annotated[str | None, typer.Option("--temperature-column", metavar="NAME", help=(
    "The temperature column (calibrate thermal: required; apply: for a thermal calibration)."))]
TemperatureUnits = Annotated[str | None, typer.Option("--temperature-units", metavar="UNIT", help=(
    "Its unit: degC, K or degF (default: the file's, else degC)."))]
#: the limits file the result's figures of merit are judged against (beside the default limits)
Limits = Annotated[Path | None, typer.Option("--limits", metavar="LIMITS.toml", help=(
    "Limits the figures of merit are judged against (per figure: min/max/abs_max, sigma_max, guard; per sensor "
    "tables). Without it, default limits judge whether each figure is determined well enough to use. A figure that "
    "FAILs or is NOT USABLE exits 4, with the files still written."))]
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
    # named at run time (one Enum per option): mypy types only functional Enums with a literal name
    kind = enum.Enum(flag.strip("-").title().replace("-", ""), {v: v for v in values}, type=str)  # type: ignore[misc]
    return Annotated[kind, typer.Option(flag, help=help)]


def Flag(flag: str, help: str):
    """An on/off switch (``--earth/--no-earth``)."""
    return Annotated[bool, typer.Option(flag, help=help)]


def Columns(help: str, flag: str = "--columns", optional: bool = False):
    """A column list: ``--columns``, ``--gyro-columns`` or ``--accel-columns`` (see :func:`names`, :func:`split_columns`)."""
    return Annotated[str | None if optional else str, typer.Option(flag, metavar="NAMES", help=help)]


def stated_default(unit: str) -> str:
    """The end of a unit option's help: what leaving it out means (``default: the unit the file states, else deg/s``)."""
    return f" Default: the unit the file states (a ULog, a bag), else {unit}."


def UnitFlag(flag: str, help: str, optional: bool = True):
    """A unit option (``--gyro-units``, ``--accel-units``, ``--mag-units``, ``--units``); the library checks it.
    None (left out): the unit the file states, else the sensor's default (say which with :func:`stated_default`)."""
    return Annotated[str | None if optional else str, typer.Option(flag, metavar="UNIT", help=help)]


def GyroUnits(help: str = "Unit of the gyro columns, e.g. deg/s, rad/s, mdps, or the size of one count: "
                          "'0.0076336 deg/s' or '131 LSB/(deg/s)'.", stated: bool = False):
    """``--gyro-units``; ``stated``: the unit of a log read (None when left out: the unit the file states, else
    deg/s; the help says so); else a unit the command writes (a default in the signature)."""
    if not stated:
        return UnitFlag("--gyro-units", help, optional=False)
    return UnitFlag("--gyro-units", help + stated_default("deg/s"))


def Units(help: str):
    """``--units``: the generic unit option, None when not given."""
    return UnitFlag("--units", help, optional=True)


# ---- a logger file's format: every command that reads a log takes these ----

#: ``--skip-rows N``: lines at the top of a text log before its header
SkipRows = Annotated[int, typer.Option("--skip-rows", parser=whole(0, 10_000_000, "4"), metavar="N", help=(
    "Lines to skip at the top of a text log, before its header (a logger's preamble)."))]
#: ``--comment CHAR``: the rest of a line after it is ignored
Comment = Annotated[str | None, typer.Option("--comment", parser=comment, metavar="CHAR", help=(
    "Comment character of a text log: the rest of a line after it is ignored, e.g. '#'."))]
#: ``--delimiter C``: the field separator of a text log
Delimiter = Annotated[str | None, typer.Option("--delimiter", parser=delimiter, metavar="C", help=(
    "Field separator of a text log: ',' (default), ';', tab, space (any run of blanks) or another character."))]
#: ``--time-column NAME``: the time column of a log (default ``time``; the first of four ``--columns`` names, as before)
TimeColumn = Annotated[str | None, typer.Option("--time-column", metavar="NAME", help=(
    "Name of the time column (default: time; not read with --rate-hz)."))]
#: ``--time-units``: the unit of the time column, detected when left out
TimeUnits = Annotated[str | None, typer.Option("--time-units", parser=time_units, metavar="UNIT", help=(
    "Unit of the time column: s, ms, us or ns (default: the unit the file states, else detected from the sample "
    "interval)."))]
#: ``--topic NAME``: the stream of a log of several (a ROS bag's topic, a ULog's topic:instance, a DataFlash message)
Topic = Annotated[str | None, typer.Option("--topic", parser=topic, metavar="TOPIC", help=(
    "The stream to read from a log of several: a ROS topic (/imu0), a ULog topic and instance (sensor_gyro:1), a "
    "DataFlash message and instance (IMU:1). Default: the log's IMU stream (with several, its reader's choice, "
    "recorded in the result); 'imu-align inspect LOG' lists them."))]
#: ``--stamps header|record``: which time a stream's samples carry
Stamps = Annotated[str | None, typer.Option("--stamps", parser=stamps, metavar="header|record", help=(
    "Time stamps of a stream that has two: header (the sensor's, default) or record (when the recorder wrote the "
    "message)."))]


def log_format(*, skip_rows: int = 0, comment: str | None = None, delimiter: str | None = None,
               time_units: str | None = None, topic: str | None = None, stamps: str | None = None):
    """The logger file options as the library's ``align.io.formats.LogFormat`` (a comment character equal to the
    delimiter is refused there, naming ``{comment}``; a topic for a log of one stream when the log is read)."""
    from align.io.formats import LogFormat

    return LogFormat(skip_rows=skip_rows, comment=comment, delimiter=delimiter, time_units=time_units, topic=topic,
                     stamps=stamps)


def log_source(path, columns: str | None = None, *, rate_hz: float | None = None, units: str | None = None,
               time_column: str | None = None, **format_fields):
    """The log options of a command as the library's ``align.io.source.LogSource``.

    ``columns`` as typed (a comma list, or None for the sensor's defaults); ``units`` None: the unit the file
    states, else the sensor's default; ``format_fields``: the keyword arguments of :func:`log_format` (``skip_rows``,
    ``comment``, ``delimiter``, ``time_units``, ``topic``, ``stamps``).
    """
    from align.io.source import LogSource

    return LogSource(path=Path(path), columns=None if columns is None else tuple(names(columns)),
                     time_column=time_column, rate_hz=rate_hz, units=units, format=log_format(**format_fields))
