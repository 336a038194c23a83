"""The ``imu-align`` command line: a thin layer over the library.

Each command parses its options (units and domains at this edge), checks its
output paths, calls the library, and stages its files as it computes them; they
are committed together at its end, so a failed run writes nothing (all or none,
:class:`align.io.outputs.Outputs`). Every failure is one line on stderr and an
exit status:

* a usage mistake (unknown command or option, missing argument, a value of the
  wrong type or outside its domain): ``imu-align CMD: what is wrong; usage: ...;
  see imu-align CMD --help``, status 2;
* a library error: ``imu-align: error: `` + the error with its inputs spelled as
  the command's own flags, or in words for an input the command has no option
  for (:func:`align.cli.options.spell`), status 2 (input), 3 (test) or 4 (check);
* Ctrl-C: ``imu-align: interrupted; nothing was written``, status 130; a closed
  pipe (``| head``): quiet, status 1;
* anything else: ``imu-align: internal error: ...``, status 1 (``IMU_ALIGN_DEBUG=1``
  shows the traceback, and the warnings that are otherwise never shown).

Modules
-------
options    shared option types and their domains, the field -> flag table, old spellings
paths      output checks before the work, the run's all-or-none outputs
progress   the progress bar of long jobs
alignment  matrix, apply
verify     verify (a gyro correction replayed on a session it was not fitted to)
simulate   simulate session | poses | lot | thermal | positions | warmup | turn-ons
mechanics  budget, allowable, check
noise      allan, plan
bias       warmup, repeatability (the bias settling from turn-on; turn-on to turn-on repeatability)
parts      parts
navigation drift
story      report, demo
exports    export
batch      batch
lot        lot
calibrate  calibrate ferraris | accel | mag | gyro | thermal | positions | thermal-matrix
inspect    inspect (what a log holds, before any job)
"""

from __future__ import annotations

import difflib
import functools
import os
import sys
from typing import Annotated, Protocol, cast

import typer

from align import __version__
from align.cli import (
    alignment,
    batch,
    bias,
    calibrate,
    exports,
    inspect,
    lot,
    mechanics,
    navigation,
    noise,
    parts,
    simulate,
    story,
    verify,
)
from align.cli.options import rewrite_aliases, speller

PROG = "imu-align"

app = typer.Typer(
    add_completion=False,
    rich_markup_mode=None,
    pretty_exceptions_enable=False,
    help="MEMS IMU mounting-misalignment analysis and electronic alignment.\n\n"
    "Convention everywhere: g = M w + b, w = A (g - b), A = M^-1; rows of M are gyros.",
)


def _show_version(shown: bool) -> None:
    if shown:
        typer.echo(f"{PROG} {__version__}")
        raise typer.Exit(0)


@app.callback()
def _root(
    version: Annotated[bool, typer.Option("--version", is_eager=True, callback=_show_version,
                                          help="Print the version and exit.")] = False,
) -> None:
    # the app's help is the Typer's own; this callback only adds --version
    pass


_MODULES = (alignment, verify, mechanics, parts, noise, bias, navigation, story, exports, batch, lot, inspect)
for _module in _MODULES:
    for _name, _command in _module.COMMANDS.items():
        app.command(_name)(_command)
app.add_typer(simulate.app, name="simulate")
app.add_typer(calibrate.app, name="calibrate")

#: command -> its subcommands (empty: a command)
COMMANDS: dict[str, tuple[str, ...]] = {
    **{name: () for m in _MODULES for name in m.COMMANDS},
    "simulate": tuple(simulate.COMMANDS),
    "calibrate": tuple(calibrate.COMMANDS),
}


def _command_path(args: list[str]) -> tuple[list[str], str | None]:
    """The command words at the start of ``args`` (``['calibrate', 'mag']``), and a usage error, if any."""
    first = next((i for i, a in enumerate(args) if not a.startswith("-")), None)
    if first is None:  # no command: only the top-level options (--help, --version), or nothing
        return [], None if args else "missing command"
    name = args[first]
    if name not in COMMANDS:
        return [], _unknown("command", name, list(COMMANDS))
    subs = COMMANDS[name]
    if not subs:
        return [name], None
    sub = args[first + 1] if first + 1 < len(args) else None
    if sub is None or sub.startswith("-"):
        return [name], None if "--help" in args else "missing command"
    if sub not in subs:
        return [name], _unknown("command", sub, list(subs))
    return [name, sub], None


def _unknown(kind: str, name: str, known: list[str]) -> str:
    close = difflib.get_close_matches(name, known, n=3, cutoff=0.5)
    return f"unknown {kind} {name}" + (f" (did you mean {' or '.join(close)}?)" if close else "")


@functools.lru_cache(maxsize=1)
def _click_app():
    """The click command typer builds from ``app``, built once per process (typer rebuilds it on every
    call: half of a short command's time, and a batch runs one command per unit)."""
    return typer.main.get_command(app)


def _params(path: list[str]) -> list:
    """The parameters of the command at ``path``, as typer builds them (``typer.main.get_command``)."""
    command = _click_app()
    for word in path:
        command = getattr(command, "commands", {}).get(word)
    return list(getattr(command, "params", []))


def _usage(path: list[str]) -> str:
    """``usage: imu-align matrix LOG --plan PLAN.toml [options]``: the command and what it requires."""
    if not path:
        return f"usage: {PROG} COMMAND [options]; commands: {', '.join(COMMANDS)}"
    if COMMANDS.get(path[0]) and len(path) == 1:
        return f"usage: {PROG} {path[0]} {'|'.join(COMMANDS[path[0]])} [options]"
    words = [PROG, *path]
    for p in _params(path):
        if not getattr(p, "required", False) or getattr(p, "hidden", False):
            continue
        shown = getattr(p, "metavar", None) or (getattr(p, "name", "") or "").upper()
        if getattr(p, "param_type_name", "") == "option":
            shown = f"{p.opts[0]} {shown}"
        words.append(shown)
    return "usage: " + " ".join(words + ["[options]"])


def _flag(param) -> str:
    if getattr(param, "param_type_name", "") == "argument":
        return getattr(param, "metavar", None) or param.name.upper()
    opts = getattr(param, "opts", None) or [getattr(param, "name", "?")]
    return max(opts, key=len)


def _given(param, args: list[str]) -> str | None:
    """The value the user gave an option (``--flag VALUE`` or ``--flag=VALUE``), if it can be found."""
    opts = getattr(param, "opts", [])
    for i, arg in enumerate(args):
        name, eq, text = arg.partition("=")
        if name in opts:
            return text if eq else (args[i + 1] if i + 1 < len(args) else None)
    return None


class _UsageError(Protocol):
    """What click's and typer's usage errors (both copies) offer that is read here."""

    def format_message(self) -> str: ...


def _usage_message(exc: Exception, path: list[str], args: list[str]) -> str:
    """What a usage error says, from the exception's public attributes (click's or typer's own copy)."""
    kinds = {c.__name__ for c in type(exc).__mro__}
    param = getattr(exc, "param", None)
    if "MissingParameter" in kinds and param is not None:
        kind = "argument" if getattr(param, "param_type_name", "") == "argument" else "option"
        return f"missing {kind} {_flag(param)}"
    option = getattr(exc, "option_name", None)
    if "NoSuchOption" in kinds and option:
        known = [o for p in _params(path) if not getattr(p, "hidden", False)
                 for o in getattr(p, "opts", []) + getattr(p, "secondary_opts", []) if o.startswith("--")]
        return _unknown("option", option, known + ["--help"])
    text = (getattr(exc, "message", None) or cast(_UsageError, exc).format_message()).strip()
    text = text.removeprefix("Value error, ").rstrip(".")
    if "BadParameter" in kinds and param is not None:
        given = _given(param, args)
        cause = exc.__cause__ or exc.__context__  # typer < 0.27 keeps the parser's reason only there
        bare = given is None and " " not in text  # the value itself (typer < 0.27 from a parser called directly)
        if (not text or text == given or bare) and isinstance(cause, ValueError) and str(cause):
            text = " ".join(str(cause).split()).removeprefix("Value error, ").rstrip(".")
        if given is None or repr(given) in text:
            return f"invalid value for {_flag(param)}: {text}"
        return f"invalid value {given!r} for {_flag(param)}" + ("" if text == given else f": {text}")
    return text[:1].lower() + text[1:]


def _fail(path: list[str], what: str) -> int:
    where = " ".join([PROG, *path])
    _say(f"{where}: {what}; {_usage(path)}; see {where} --help")
    return 2


def _known(path: list[str]) -> frozenset[str] | None:
    """The options (``--json``, ``--no-earth``) and argument names (``LOG``) of the command at ``path``."""
    if not path:
        return None
    known: set[str] = set()
    for p in _params(path):
        if getattr(p, "param_type_name", "") == "argument":
            known.add(_flag(p))
        else:
            known.update(getattr(p, "opts", []) + getattr(p, "secondary_opts", []))
    return frozenset(known)


#: what Ctrl-C leaves behind, per command (default: nothing)
_INTERRUPTED = {"batch": "interrupted; the units done are kept (results.parquet, units/): run the same command "
                         "again to finish the rest"}


def _interrupted(args: list[str]) -> str:
    path, _ = _command_path(args)
    return f"{PROG}: " + _INTERRUPTED.get(" ".join(path), "interrupted; nothing was written")


def _internal(exc: BaseException) -> str:
    """One line for an unexpected exception: its type and its first 300 characters."""
    text = " ".join(f"{type(exc).__name__}: {exc}".split())
    return text if len(text) <= 300 else text[:297] + "..."


def _quiet_pipe() -> int:
    """stdout's reader went away (``| head``): point stdout at /dev/null so that exiting flushes nothing."""
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    except (OSError, ValueError):
        pass
    return 1


def run(args: list[str]) -> int:
    """Run ``imu-align ARGS`` and return the exit status; every failure is one line on stderr.

    Warnings (numpy's ``invalid value encountered``, ...) never reach the terminal: a result
    that cannot be trusted is refused by the library's checks instead; ``IMU_ALIGN_DEBUG=1``
    shows them (and the traceback of an unexpected error).
    """
    import warnings

    debug = bool(os.environ.get("IMU_ALIGN_DEBUG"))
    try:
        with warnings.catch_warnings():
            if not debug:
                warnings.simplefilter("ignore")
            return _run(args, debug)
    except KeyboardInterrupt:
        _say(_interrupted(args))
        return 130
    except BrokenPipeError:
        return _quiet_pipe()


def _say(line: str) -> None:
    try:
        typer.echo(line, err=True)
    except (OSError, ValueError):
        pass


def _run(args: list[str], debug: bool) -> int:
    from align.errors import AlignError

    args = simulate.old_spelling(args)  # today's `simulate DIR [--kind poses | --lot N]`
    path, problem = _command_path(args)
    if problem:
        return _fail(path, problem)
    command = " ".join(path) or None
    args = rewrite_aliases(command, args)
    try:
        code = _click_app()(args=args, prog_name=PROG, standalone_mode=False)
    except AlignError as exc:
        _say(f"{PROG}: error: {' '.join(exc.render(speller(command, _known(path))).split())}")  # one line, always
        return exc.exit_code
    except BrokenPipeError:
        return _quiet_pipe()
    except Exception as exc:
        if hasattr(exc, "exit_code") and hasattr(exc, "format_message"):  # a usage error (click's or typer's)
            if getattr(exc, "exit_code", 2) != 2:
                _say(f"{PROG}: error: {' '.join(exc.format_message().split())}")
                return exc.exit_code
            return _fail(path, " ".join(_usage_message(exc, path, args).split()))
        if isinstance(exc, typer.Abort):  # click's answer to Ctrl-C
            _say(_interrupted(args))
            return 130
        if debug:
            raise
        if isinstance(exc, MemoryError):
            _say(f"{PROG}: error: out of memory; use a smaller input (or, for allan, a lower --memory-limit-mb)")
            return 1
        _say(f"{PROG}: internal error: {_internal(exc)} (set IMU_ALIGN_DEBUG=1 for details)")
        return 1
    if code == 130:  # typer's answer to Ctrl-C (KeyboardInterrupt inside a command), said in no words
        _say(_interrupted(args))
    return code if isinstance(code, int) else 0


def main(argv: list[str] | None = None) -> None:
    """Entry point of the ``imu-align`` console script and ``python -m align.cli``."""
    sys.exit(run(list(sys.argv[1:] if argv is None else argv)))
