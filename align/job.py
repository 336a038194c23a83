"""A job: one command's unit of work, as a library call.

Every command of ``imu-align`` is one :class:`Job`: a frozen options value (every field typed,
in SI, with its default: the one place defaults live) and ``run(options) -> Result``, which reads
its inputs through the one log reader (:mod:`align.io.source`), checks them, computes, and stamps
the result with its :class:`~align.provenance.Provenance` (input files with size and hash, the
options, the tool version). The command line parses words into the options, calls ``run`` and
renders the result; the report and the batch call the same ``run``; so does a notebook::

    from align.api import jobs, MatrixOptions
    result = jobs["matrix"].run(MatrixOptions(log=..., plan=...))

A job is two steps, so that a caller that also draws the readings (``--plot``) reads them once:
``read(options) -> inputs`` (files -> checked inputs, a job's own frozen type) and
``compute(inputs, options, progress) -> result``. ``run`` is the two in turn.

Every options value is checked before a job reads anything (:func:`check_options`): a field typed as a
number takes a finite number (a quantity string such as ``"2 s"`` where the field states its unit with
:func:`quantity`), within the domain the field states; a flag takes True or False; a whole number a whole
number. One :class:`~align.errors.InputError` names the field (``{min_dwell}``) and what to give.

Public names
------------
Job, Progress, fields_signature, check_options, quantity, judged, read_limits_of
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Generic, TypeVar

from align.provenance import Provenance, start_hashing
from align.results import Result

__all__ = ["Job", "Progress", "fields_signature", "check_options", "quantity", "judged", "read_limits_of"]

#: ``progress(n)``: n more units of work done (samples read, runs made); the library never draws it
Progress = Callable[[int], None]

O = TypeVar("O")  # noqa: E741  (the options type)
I = TypeVar("I")  # noqa: E741  (the checked inputs)
R = TypeVar("R", bound=Result)


@dataclass(frozen=True)
class Job(Generic[O, I, R]):
    """One command's unit of work.

    Attributes
    ----------
    name : str
        The command that runs it (``"matrix"``, ``"calibrate accel"``).
    options : type
        Its frozen, keyword-only options type.
    read : callable
        ``read(options) -> inputs``: the input files read through the one log reader and checked;
        raises :class:`~align.errors.InputError` naming the file, field or option.
    compute : callable
        ``compute(inputs, options, progress) -> Result``; ``progress`` may be None.
    files : callable
        ``files(options) -> {role: path or None}``: the input files the result depends on (its
        provenance, and the batch's content hash).
    summary : str
        One line: what the job does.
    """

    name: str
    options: type[O]
    read: Callable[[O], I]
    compute: Callable[[I, O, Progress | None], R]
    files: Callable[[O], Mapping[str, Path | str | None]]
    summary: str = ""

    def stamp(self, result: R, options: O, limits: Any = None) -> R:
        """``result`` with the provenance of this job run with ``options``, and its figures of merit judged
        (:func:`judged`) against ``limits`` (the options' ``limits`` file, read; None: the default limits)."""
        files = dict(self.files(options))
        if getattr(options, "limits", None) is not None:
            files.setdefault("limits", options.limits)  # type: ignore[attr-defined]
        return result.replace(provenance=Provenance.of(self.name, files, options),
                              verdicts=judged(result, self.name, limits))

    def run(self, options: O, *, progress: Progress | None = None) -> R:
        """Read, check and compute: the job's result with its provenance.

        Parameters
        ----------
        options : the job's options type
        progress : callable, optional
            Called with the units of work done as they are done.

        Returns
        -------
        Result
            The job's result type, its ``provenance`` set.
        """
        if not isinstance(options, self.options):
            raise TypeError(f"{self.name} takes {self.options.__name__}, not {type(options).__name__}")
        return self.run_with_inputs(options, progress=progress)[0]

    def run_with_inputs(self, options: O, *, progress: Progress | None = None) -> tuple[R, I]:
        """As :meth:`run`, and the checked inputs too (for a caller that also draws them). The input files'
        SHA-256 is computed in the background while the job computes (:func:`align.provenance.start_hashing`)."""
        options = check_options(options)
        limits = read_limits_of(options)  # before the log: a bad limits file costs no computation
        inputs = self.read_hashing(options)
        return self.stamp(self.compute(inputs, options, progress), options, limits), inputs

    def read_hashing(self, options: O) -> I:
        """``self.read(options)``, the input files' SHA-256 started first in the background
        (:func:`align.provenance.start_hashing`): a long log is hashed beside its decoding and the computation,
        and :meth:`stamp` takes the digest when it is done."""
        start_hashing([p for p in self.files(options).values() if p is not None])
        return self.read(options)


def read_limits_of(options: Any) -> Any:
    """The limits file an options value names in its ``limits`` field, read (:func:`align.limits.read_limits`), over
    the options' own tolerances (``tolerance_limits()``, a limits table, when the options type has them); None when
    there are neither.

    Raises
    ------
    InputError
        A limits file that cannot be read, naming it.
    """
    path = getattr(options, "limits", None)
    own = options.tolerance_limits() if hasattr(options, "tolerance_limits") else {}
    if path is None and not own:
        return None
    from align.io.files import read_toml
    from align.limits import limits_from_dict

    if path is None:
        return limits_from_dict(own, "the tolerances")
    data = read_toml(path)  # the file's limits over the options' own (a tolerance the file also states: the file's)
    return limits_from_dict({**{k: v for k, v in own.items() if k not in data}, **data}, str(path))


def judged(result: Result, test: str, limits: Any = None) -> tuple:
    """``result``'s figures of merit (:meth:`~align.results.Result.figures_of_merit`) judged against ``limits`` (an
    :class:`align.limits.Limits`) with the default limits (:func:`align.judge.judge`), each naming ``test`` as the
    test it came from."""
    import dataclasses

    figures = result.figures_of_merit()
    if not figures:
        return ()
    from align.judge import judge

    return judge((dataclasses.replace(f, test=f.test or test) for f in figures), limits)


def describe(job: Job[Any, Any, Any]) -> str:
    """``name: summary`` of a job, for listings."""
    return f"{job.name}: {job.summary}" if job.summary else job.name


F = TypeVar("F", bound=Callable[..., Any])


def fields_signature(options: type) -> Callable[[F], F]:
    """Give a job's keyword-only call (``def matrix(*, progress=None, **fields)``) the signature of its options:
    ``help()``, ``inspect.signature`` and an editor then list every field with its default.

    The call's own keyword parameters come first; each field of the frozen ``options`` dataclass that the call
    does not name follows, keyword-only, with its default (``dataclasses.MISSING``: required).
    """
    import dataclasses
    import inspect

    def decorate(fn: F) -> F:
        own = [p for p in inspect.signature(fn).parameters.values() if p.kind is not inspect.Parameter.VAR_KEYWORD]
        named = {p.name for p in own}
        extra = []
        for f in dataclasses.fields(options):
            if f.name in named or not f.init:
                continue
            default = (f.default if f.default is not dataclasses.MISSING
                       else f.default_factory() if f.default_factory is not dataclasses.MISSING  # type: ignore[misc]
                       else inspect.Parameter.empty)
            extra.append(inspect.Parameter(f.name, inspect.Parameter.KEYWORD_ONLY, default=default))  # types: the options' docs
        required = [p for p in extra if p.default is inspect.Parameter.empty]
        optional = [p for p in extra if p.default is not inspect.Parameter.empty]
        fn.__signature__ = inspect.signature(fn).replace(parameters=[*own, *required, *optional])  # type: ignore[attr-defined]
        return fn

    return decorate



#: the SI unit a dimension's quantity is held in, for messages
SI_UNITS = {"angle": "rad", "angular_rate": "rad/s", "length": "m", "time": "s", "frequency": "Hz",
            "acceleration": "m/s^2", "dimensionless": ""}


def quantity(default: Any, dimension: str, *, gt: float | None = None, ge: float | None = None,
             lt: float | None = None, le: float | None = None) -> Any:
    """An options field holding a quantity in SI: its ``dimension`` (a key of :data:`align.units.DIMENSIONS`:
    ``"time"``, ``"angular_rate"``, ``"dimensionless"``) and its domain in SI, read by :func:`check_options` (a
    string such as ``"2 s"`` is parsed into it).

    Examples
    --------
    >>> from dataclasses import dataclass
    >>> @dataclass(frozen=True, kw_only=True)
    ... class Opts:
    ...     dwell: float = quantity(1.0, "time", gt=0)
    >>> check_options(Opts(dwell="1500 ms")).dwell
    1.5
    """
    import dataclasses

    return dataclasses.field(default=default, metadata={"dimension": dimension, "gt": gt, "ge": ge, "lt": lt,
                                                        "le": le})


def _kinds(hint: Any) -> set[Any]:
    import typing

    args = typing.get_args(hint)
    return set(args) if typing.get_origin(hint) in (typing.Union, getattr(__import__("types"), "UnionType", None)) \
        else {hint}


def check_options(options: Any) -> Any:
    """``options`` checked field by field (module docstring); quantity strings parsed into SI.

    Returns
    -------
    The same options, or a copy with the parsed quantities.

    Raises
    ------
    InputError
        Naming the field (``{name}``) and what to give.
    """
    import dataclasses
    import math
    import numbers
    import typing

    from align.errors import InputError
    from align.units import parse_quantity

    cls = type(options)  # resolved where it was defined (a package may show it as its own: cls.__module__)
    hints = typing.get_type_hints(cls, globalns=getattr(cls.__init__, "__globals__", None))
    parsed: dict[str, Any] = {}
    for f in dataclasses.fields(options):
        value, kinds, meta, where = getattr(options, f.name), _kinds(hints.get(f.name)), f.metadata, "{" + f.name + "}"
        if value is None and type(None) in kinds:
            continue
        dim = meta.get("dimension")
        unit = SI_UNITS.get(dim, dim) if dim else None
        if float in kinds and isinstance(value, str) and dim is not None:
            value = parsed[f.name] = parse_quantity(value, dim, where)
        if float in kinds and not isinstance(value, str):
            if isinstance(value, bool) or not isinstance(value, numbers.Real):
                raise InputError(f"{value!r} is not a number; give one" + (f" in {unit}" if unit else ""), where)
            if not math.isfinite(value):
                raise InputError(f"{value!r} is not a finite number; give one" + (f" in {unit}" if unit else ""),
                                 where)
            for key, ok, word in (("gt", lambda v, b: v > b, ">"), ("ge", lambda v, b: v >= b, ">="),
                                  ("lt", lambda v, b: v < b, "<"), ("le", lambda v, b: v <= b, "<=")):
                bound = meta.get(key)
                if bound is not None and not ok(value, bound):
                    raise InputError(f"{value:g} is out of range; give a value {word} {bound:g}"
                                     + (f" ({unit})" if unit else ""), where)
        elif float in kinds and isinstance(value, str):
            raise InputError(f"'{value}' is not a number; give a number" + (f" in {unit}" if unit else ""), where)
        elif bool in kinds and float not in kinds and not isinstance(value, bool):
            raise InputError(f"{value!r} is not True or False", where)
        elif int in kinds and float not in kinds and bool not in kinds and (
                isinstance(value, bool) or not isinstance(value, numbers.Integral)):
            raise InputError(f"{value!r} is not a whole number; give one", where)
    return dataclasses.replace(options, **parsed) if parsed else options
