"""The jobs a batch may run, and each unit's manifest row made into its job's options.

A manifest's options are checked against the job's own command when the manifest is read (the click
command typer builds, :func:`align.cli._click_app`): an unknown option, one the batch gives itself,
a value missing or malformed, or a word that is no option is one :class:`~align.errors.InputError`
naming the manifest's row. The row's words (its log, its plan column as the job's plan option, its
options) are then parsed by that command exactly as the single command parses them
(``make_context``: typer's parsers, units and domains applied), file values are resolved against
the manifest's folder, and the job's options builder (:mod:`align.cli.builders`) makes the job's
frozen options: the worker runs ``align.api.job(name).run(options)``, the single command's job by
construction. A library error while the options are built (a column list the job refuses, an
output that would overwrite an input) is the unit's failure, in the single command's words.

The input files of the unit's content hash are the job's own (``job.files(options)``: log, plan, and
every other input the options name, the ``--axis-down`` captures included).

Public names
------------
JOBS, RESERVED, OUTPUT_OPTIONS, Prepared, check_options, prepare_unit, prepare_validation, validation_unit, parse_rows,
task_maker, error_line
"""

from __future__ import annotations

import difflib
import enum
import functools
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from align.errors import AlignError, InputError, literal

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


def _plan_flag(job: str) -> str | None:
    """The option a unit's plan is given as: its job's (:data:`JOBS`), ``--plan`` for a validation run's ``verify``."""
    return "--plan" if job == "verify" else JOBS[job][0]


def validation_unit(unit):
    """A unit's validation run as a unit of job ``verify``: the validation session as its log, its plan and
    ``verify``'s options (the row's ``validation*`` columns), for :func:`check_options` and :func:`prepare_unit`."""
    from dataclasses import replace

    return replace(unit, job="verify", log=unit.validation, plan=unit.validation_plan,
                   options=unit.validation_options, validation=None, validation_plan=None, validation_options=())


def _column(unit) -> str:
    return "validation_options" if unit.job == "verify" else "options"


def _jobs() -> dict[str, str]:
    """The jobs this installation has (a command with an options builder, :mod:`align.cli.builders`), each with
    its use of the plan column."""
    from align.cli import COMMANDS
    from align.cli.builders import BUILDERS

    have = {name if not subs else f"{name} {s}" for name, subs in COMMANDS.items() for s in (subs or (None,))}
    return {job: use for job, (_, use) in JOBS.items() if job in have and job in BUILDERS}


def _click(job: str):
    from align.cli import _click_app

    command = _click_app()
    for word in job.split():
        command = command.commands[word]
    return command


def check_options(unit, where: str) -> None:
    """Check a unit's options against its job's command: known names (old spellings too, as the command takes
    them: :data:`align.cli.options.ALIASES`), a value where one is needed, no positional words, none of
    :data:`RESERVED`; ``--axis-down``'s text parsed.

    Raises
    ------
    InputError
        Naming the manifest ``where``, the unit's row and column options.
    """
    from align.cli.options import ALIASES

    def bad(what: str) -> InputError:
        return InputError(f"{unit.row}, column {_column(unit)}: {what}", where)

    aliases = ALIASES.get(unit.job, {})
    params = [p for p in _click(unit.job).params if getattr(p, "param_type_name", "") == "option"]
    flags = {o for p in params if getattr(p, "is_flag", False) for o in (*p.opts, *p.secondary_opts)}
    names = {o for p in params for o in (*p.opts, *p.secondary_opts)}
    plan_flag = _plan_flag(unit.job)
    words, i = unit.options, 0
    while i < len(words):
        word = words[i]
        name, eq, text = word.partition("=")
        name = aliases.get(name, name)
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


def _resolved(options: tuple[str, ...], folder: Path) -> list[str]:
    """The options with the files of ``--axis-down`` made absolute (relative to ``folder``); other path
    values are resolved once parsed (:func:`_absolute`)."""
    out, i = [], 0
    while i < len(options):
        word = options[i]
        name, eq, text = word.partition("=")
        if name in FILE_LISTS and (eq or i + 1 < len(options)):
            value = text if eq else options[i + 1]
            parts = [f"{axis}={(folder / v).resolve()}"
                     for axis, v in _axis_down_files(value, lambda what: InputError(what, "{axis_down}"))]
            ranges = [item for item in value.split(",") if item.strip() and ":" in item.partition("=")[2]]
            resolved = ",".join(parts + [r.strip() for r in ranges])
            out += [f"{name}={resolved}"] if eq else [name, resolved]
            i += 1 if eq else 2
            continue
        out.append(word)
        i += 1
    return out


@dataclass(frozen=True)
class Prepared:
    """A unit's manifest row made into its job's run (what its :class:`~align.production.Task` holds).

    Attributes
    ----------
    options : object or None
        The job's frozen options; None when the job refused them (``refused``).
    params : dict
        The command's parameters (plain values: choices as their text, paths absolute) when the row asks
        for extra output files (``--plot``, ``--c-header``, ``--imucal-json``): the files builder's input;
        else empty.
    inputs : tuple of Path or None
        The files of the content hash: log, plan, then the job's other input files.
    refused : (int, str) or None
        The exit status and the single command's one-line error when the options were refused.
    """

    options: Any
    params: dict = field(default_factory=dict)
    inputs: tuple[Path | None, ...] = ()
    refused: tuple[int, str] | None = None


def error_line(job: str, exc: BaseException) -> tuple[int, str]:
    """The exit status and the one line the single command ``imu-align JOB`` gives for ``exc``
    (:func:`align.cli.run`: a library error with the inputs spelled as the command's own flags)."""
    from align.cli import PROG, _internal, _known
    from align.cli.options import speller

    if isinstance(exc, AlignError):
        return exc.exit_code, f"{PROG}: error: {' '.join(exc.render(speller(job, _known(job.split()))).split())}"
    if isinstance(exc, MemoryError):
        return 1, f"{PROG}: error: out of memory; use a smaller input (or, for allan, a lower --memory-limit-mb)"
    return 1, f"{PROG}: internal error: {_internal(exc)} (set IMU_ALIGN_DEBUG=1 for details)"


@functools.cache
def _output_names(job: str) -> frozenset[str]:
    """The parameters (Python names) of ``job``'s command that name files it writes (once per job)."""
    return frozenset({p.name for p in _click(job).params if set(getattr(p, "opts", ())) & set(OUTPUT_OPTIONS)})


@functools.cache
def _path_params(job: str) -> frozenset[str]:
    """The parameters of ``job``'s command declared as paths (typer gives some click versions' values as text;
    its type hints evaluated once per job: a few milliseconds each time)."""
    import typing

    callback = _click(job).callback
    found = set()
    for name, hint in typing.get_type_hints(callback, include_extras=True).items():
        base = typing.get_args(hint)[0] if typing.get_origin(hint) is typing.Annotated else hint
        kinds = typing.get_args(base) or (base,)
        if Path in kinds or any(Path in (typing.get_args(k) or (k,)) for k in kinds):
            found.add(name)
    return frozenset(found)


def _absolute(value: Any, folder: Path, path: bool = False) -> Any:
    """A path value resolved against the manifest's ``folder`` (lists of paths too); other values as they are.
    ``path``: the parameter is a path even when the parser gave it as text."""
    if path and isinstance(value, str):
        value = Path(value)
    if path and isinstance(value, (list, tuple)) and value and all(isinstance(v, str) for v in value):
        value = type(value)(Path(v) for v in value)
    if isinstance(value, Path):
        return (folder / value).resolve()
    if isinstance(value, (list, tuple)) and value and all(isinstance(v, Path) for v in value):
        return type(value)((folder / v).resolve() for v in value)
    return value


def _plain(value: Any) -> Any:
    """A parsed value a worker can unpickle: a choice (an Enum typer makes on the fly) as its text."""
    return value.value if isinstance(value, enum.Enum) else value


def _hashed(unit, files) -> tuple[Path | None, ...]:
    """The content hash's files: the unit's log and plan, then every other file ``job.files(options)`` names."""
    first = (unit.log, unit.plan)
    rest: list[Path] = []
    for value in files.values():
        for item in value if isinstance(value, (list, tuple)) else (value,):
            item = getattr(item, "path", item)  # a LogSource
            if item is None:
                continue
            path = Path(item)
            if path not in first and path not in rest:
                rest.append(path)
    return (*first, *rest)


def _parsed(unit, folder: Path, where: str, cache: dict | None, first: tuple[Path, ...] = ()) -> dict[str, Any]:
    """The command's parameters for the unit's row, as click parses them, paths resolved against ``folder``.

    Rows of one job with the same options words differ only in their log and plan: those are parsed and resolved
    once (``cache``), the row's log and plan (resolved by the manifest's reader) put in place for each row (a
    path's value is not checked when parsed). ``first``: arguments before the log (a validation run's ``verify``
    takes the result it replays first).
    """
    from align.cli import _usage_message
    from align.cli.options import rewrite_aliases

    command = _click(unit.job)
    flag = _plan_flag(unit.job)
    names = [p.name for p in command.params if getattr(p, "param_type_name", "") == "argument"]
    plan_name = next((p.name for p in command.params if flag in getattr(p, "opts", ())), None) if flag else None
    key = (unit.job, unit.options, unit.plan is None, folder)
    if cache is not None and key in cache:
        params = dict(cache[key])
    else:
        words = _resolved(unit.options, folder)  # --axis-down's files made absolute
        args = [*map(str, first), str(unit.log), *([str(flag), str(unit.plan)] if unit.plan is not None else []),
                *rewrite_aliases(unit.job, words)]
        try:
            params = dict(command.make_context(f"imu-align {unit.job}", args, resilient_parsing=False).params)
        except Exception as exc:
            if not (hasattr(exc, "exit_code") and hasattr(exc, "format_message")):  # no usage error (click's, typer's)
                raise
            what = " ".join(_usage_message(exc, unit.job.split(), args).split())
            raise InputError(f"{unit.row}, column {_column(unit)}: {what}", where) from None
        paths = _path_params(unit.job)
        params = {name: _absolute(value, folder, name in paths) for name, value in params.items()}
        if cache is not None:
            cache[key] = dict(params)
    params.update(zip(names, (*first, unit.log)))
    if plan_name is not None:
        params[plan_name] = unit.plan
    return params


def prepare_unit(unit, folder: Path, where: str, cache: dict | None = None) -> Prepared:
    """Parse a unit's row with its job's command and build the job's options (see the module docstring).

    Parameters
    ----------
    unit : Unit
        Its options already checked by :func:`check_options`.
    folder : Path
        The manifest's folder (absolute): relative paths in the options are relative to it.
    where : str
        The manifest, for messages.
    cache : dict, optional
        Rows parsed before (see :func:`parse_rows`).

    Returns
    -------
    Prepared

    Raises
    ------
    InputError
        A value the command's parser refuses, naming the manifest, the row and column options.
    """
    from align.api import job as find
    from align.cli.builders import options_builder
    from align.cli.paths import check_outputs

    params = _parsed(unit, folder, where, cache)
    outs = _output_names(unit.job)
    asked = {name: params[name] for name in outs if params.get(name) is not None}
    try:  # as the single command: its outputs checked, then its options built
        if asked:
            check_outputs([v for k, v in params.items() if isinstance(v, Path) and k not in outs], **asked)
        options = options_builder(unit.job)(**params)
        files = find(unit.job).files(options)
    except AlignError as exc:
        return Prepared(None, {}, (unit.log, unit.plan), error_line(unit.job, exc))
    return Prepared(options, {k: _plain(v) for k, v in params.items()} if asked else {}, _hashed(unit, files))


class ParseCache(dict):
    """The rows parsed, by their options words (:func:`_parsed`): the latest :attr:`SIZE` kept, so that a manifest
    whose rows differ each (``{serial}`` in their options) does not keep one parse per unit."""

    SIZE = 256

    def __setitem__(self, key, value) -> None:
        if key not in self and len(self) >= self.SIZE:
            del self[next(iter(self))]
        super().__setitem__(key, value)


def parse_rows(units: Iterable, folder: Path, where: str) -> ParseCache:
    """Every unit's row parsed by its job's command (and its validation run's by ``verify``), rows with the same
    options words once: a row the command refuses is refused before any unit runs. The parse cache
    :func:`task_maker` builds each unit's options from (a row no longer in it is parsed again)."""
    cache = ParseCache()
    for u in units:
        _parsed(u, folder, where, cache)
        if u.validation is not None:
            _parsed(validation_unit(u), folder, where, cache, (Path("result.json"),))
    return cache


def prepare_validation(unit, result: Path, folder: Path, where: str, cache: dict | None = None
                       ) -> tuple[Any, tuple[int, str] | None, tuple[Path, ...]]:
    """``verify``'s options for a unit's validation run (its ``result`` replayed on the validation session), the
    refusal of a library error while they are built, and the files the content hash covers beside the unit's."""
    from align.api import job as find
    from align.cli.builders import options_builder

    check = validation_unit(unit)
    params = _parsed(check, folder, where, cache, (result,))
    try:
        options = options_builder("verify")(**params)
        files = [p for k, p in find("verify").files(options).items() if k != "result" and p is not None]
    except AlignError as exc:
        return None, error_line("verify", exc), (check.log, check.plan)
    return options, None, tuple(Path(p) for p in files)


def task_maker(folder: Path, cache: dict | None = None, where: str | None = None) -> Callable[[Any, Path, str], Any]:
    """``make(unit, result, run) -> Task``: the unit's job and options, built as the unit is taken
    (:func:`prepare_unit`, its row's parse from ``cache``): the options of a long lot are not all held at once."""
    from align.production import Task

    cache = ParseCache() if cache is None else cache

    def make(unit, result: Path, run: str) -> Task:
        said = where or str(folder)
        got, result = prepare_unit(unit, folder, said, cache), result.resolve()
        if unit.validation is None:
            return Task(unit, result, got.inputs, run, got.options, got.params, got.refused)
        check, refused, files = prepare_validation(unit, result, folder, said, cache)
        inputs = (*got.inputs, *(f for f in files if f not in got.inputs))
        return Task(unit, result, inputs, run, got.options, got.params, got.refused, check, refused)

    return make
