"""Results: one envelope, one registry, one loader.

Every result imu-align writes is a JSON object whose first keys are the
envelope::

    {"format": "imu-align.alignment", "version": 1, "generator": "imu-align 0.2.0",
     "convention": "g = M w + b; ...", "units": {...}, ...body...}

A result type is a :class:`Result` subclass that names its format, version and
convention in its class statement, writes itself with :meth:`Result.to_dict`
(through :meth:`Result.envelope`) and reads itself back with
:meth:`Result.from_dict` (which first calls :meth:`Result.check_envelope`).
:func:`load_result` picks the type from the file's ``format`` and refuses an
unknown format, a missing version or a newer one with one clear line, as
imucal's ``load_calibration_info`` does; :func:`save_result` writes any result
atomically. A new result type adds one line to :data:`KNOWN`.

Public names
------------
Result, Correction, KNOWN, register, envelope, file_unit, load_result, result_from_dict, save_result
"""

from __future__ import annotations

import importlib
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, Protocol, Self, TypeVar, dataclass_transform, overload

import numpy as np

from align import __version__
from align.errors import InputError
from align.io.files import read_json, write_json
from align.io.keys import check_keys
from align.merit import Figure
from align.plausible import check_usable_model
from align.provenance import Provenance
from align.units import parse_unit
from align.values import Value

#: every result format -> the module that defines (and registers) its type
KNOWN: dict[str, str] = {
    "imu-align.alignment": "align.alignment.result",
    "imu-align.truth": "align.alignment.simulate",
    "imu-align.corrected": "align.alignment.corrected",
    "imu-align.calibration": "align.calibration.results",
    "imu-align.magnetometer": "align.calibration.magnetometer",
    "imu-align.allan": "align.noise.analysis",
    "imu-align.plan": "align.noise.planner",
    "imu-align.allowable": "align.sensitivity.allowable",
    "imu-align.check": "align.sensitivity.margins",
    "imu-align.budget": "mechanics.budget",
    "imu-align.drift": "align.navigation.result",
    "imu-align.thermal": "align.calibration.thermal.result",
    "imu-align.thermal-matrix": "align.calibration.thermal.matrix_t",
    "imu-align.positions": "align.calibration.jobs.positions",
    "imu-align.warmup": "align.noise.warmup",
    "imu-align.repeatability": "align.noise.repeatability",
    "imu-align.verification": "align.alignment.jobs.verify_job",
}

_TYPES: dict[str, type[Result]] = {}
#: the first keys of every result file
ENVELOPE_KEYS = ("format", "version", "generator", "convention", "units", "provenance", "figures_of_merit")


class Correction(Protocol):
    """What corrects a log: the sensor it is for, the unit of its readings, and the correction.

    Attributes
    ----------
    sensor : str
        ``"gyroscope"``, ``"accelerometer"`` or ``"magnetometer"``.
    units : str
        Unit of the readings in the result's file (the default unit of the log).
    """

    # read-only: a result states them as a property or a (frozen) field
    @property
    def sensor(self) -> str: ...

    @property
    def units(self) -> str: ...

    def correct(self, raw: np.ndarray) -> np.ndarray:
        """Corrected readings (n, 3), SI, from raw readings (n, 3), SI."""


def register(cls: type[Result]) -> type[Result]:
    """Make ``cls`` the type :func:`load_result` returns for ``cls.FORMAT`` (done for every Result subclass)."""
    if cls.FORMAT not in KNOWN:
        raise ValueError(f"{cls.FORMAT} is not listed in align.results.KNOWN")
    _TYPES[cls.FORMAT] = cls
    return cls


def file_unit(d: dict[str, Any], key: str, expect: str | None, where: str) -> tuple[str, float]:
    """The unit a result file states for ``key`` (``d["units"][key]``) and its factor to SI.

    Raises KeyError when the file states none (the caller reports a malformed file).
    """
    unit = d["units"][key]
    return unit, parse_unit(unit, expect, f"{where}: units.{key}").factor


def envelope(format: str, version: int, convention: str, units: dict[str, Any] | None = None) -> dict[str, Any]:
    """The first keys of every result file: format, version, generator, convention, units."""
    return {"format": format, "version": version, "generator": f"imu-align {__version__}",
            "convention": convention, "units": dict(units or {})}


@dataclass_transform(frozen_default=True, eq_default=False)
class Result(Value):
    """Base of every result type: a frozen value (see :class:`~align.values.Value`) that is a file.

    A subclass names its file format in its class statement and is made a frozen
    dataclass and registered for :func:`load_result` there::

        class AlignmentResult(Result, format="imu-align.alignment", convention=CONVENTION):
            method: str
            M: np.ndarray
            ...

    It implements ``to_dict`` (starting with :meth:`envelope`) and ``from_dict``
    (starting with :meth:`check_envelope`), so that ``from_dict(to_dict(r)) == r``.
    """

    FORMAT: ClassVar[str]
    VERSION: ClassVar[int] = 1
    CONVENTION: ClassVar[str]

    #: what the result was computed from (:class:`align.provenance.Provenance`), stamped by the job that made it
    #: (:meth:`align.job.Job.run`); None for a result made by a library function alone. A keyword-only
    #: field of every result type, written in the envelope and not compared by ``==``.
    provenance: Provenance | None
    #: its figures of merit (:meth:`figures_of_merit`) judged against limits (:func:`align.judge.judge`), stamped by the
    #: job that made it;
    #: () before (a library function's result). Written in the envelope as ``figures_of_merit``; not compared by ``==``.
    verdicts: tuple[Figure, ...]

    def __init_subclass__(cls, format: str, convention: str, version: int = 1, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        cls.FORMAT, cls.VERSION, cls.CONVENTION = format, version, convention
        if "provenance" not in getattr(cls, "__dataclass_fields__", {}):
            cls.__annotations__ = {**cls.__dict__.get("__annotations__", {}), "provenance": "Provenance | None"}
            cls.provenance = field(default=None, kw_only=True, compare=False)  # type: ignore[assignment]
        if "verdicts" not in getattr(cls, "__dataclass_fields__", {}):
            cls.__annotations__ = {**cls.__dict__.get("__annotations__", {}), "verdicts": "tuple[Figure, ...]"}
            cls.verdicts = field(default=(), kw_only=True, compare=False)  # type: ignore[assignment]
        dataclass(frozen=True, eq=False)(cls)
        register(cls)

    def envelope(self, units: dict[str, Any] | None = None) -> dict[str, Any]:
        """The envelope of this result (see :func:`envelope`), with its provenance when it has one."""
        d = envelope(self.FORMAT, self.VERSION, self.CONVENTION, units)
        if self.provenance is not None:
            d["provenance"] = self.provenance.to_dict()
        if self.verdicts:
            d["figures_of_merit"] = [f.to_dict() for f in self.verdicts]
        return d

    def figures_of_merit(self) -> tuple[Figure, ...]:
        """Its figures of merit, not yet judged (:class:`align.merit.Figure`); () for a result that gives none."""
        return ()

    @classmethod
    def check_envelope(cls, d: Any, where: str = "result", keys: Iterable[str] | None = None) -> None:
        """Refuse a dictionary that is not this type's format, or a newer version of it, and (with
        ``keys``, the body's keys) one holding a key neither the envelope nor the body knows."""
        if not isinstance(d, dict):
            raise InputError("expected a JSON object", where)
        if d.get("format") != cls.FORMAT:
            raise InputError(f"not an {cls.FORMAT} result (format {d.get('format')!r})", where)
        version = d.get("version")
        if not isinstance(version, int) or isinstance(version, bool) or version < 1:
            raise InputError(f"{cls.FORMAT} result without a valid version ({version!r}); regenerate it", where)
        if version > cls.VERSION:
            raise InputError(f"{cls.FORMAT} version {version} is newer than this imu-align {__version__} reads "
                             f"(up to {cls.VERSION}); upgrade imu-align", where)
        if keys is not None:
            check_keys(d, [*ENVELOPE_KEYS, *keys], where)

    def correction(self, sensor: str | None = None, where: str = "result") -> Correction:
        """What corrects a log of ``sensor`` (the only sensor when None); results that correct nothing refuse.

        A result that corrects a log checks its matrix first (finite, invertible, ``det > 0``:
        :func:`align.plausible.check_usable_model`), naming ``where`` (the file).
        """
        raise InputError(f"holds an {self.FORMAT} result, which corrects no log; give an alignment or a calibration", where)

    def _only_sensor(self, held: str, sensor: str | None, where: str, matrix: str = "M") -> Self:
        """``self`` when ``sensor`` is None or ``held`` (for results of one sensor), its ``matrix`` checked usable.

        Raises
        ------
        InputError, TestError, HandednessError
            Another sensor asked for; the matrix not finite, singular or ``det <= 0``
            (:func:`align.plausible.check_usable_model`): no log is corrected with it.
        """
        if sensor is not None and sensor != held:
            raise InputError(f"holds a {held} result, no {sensor} calibration; choose another {{sensor}}", where)
        check_usable_model(getattr(self, matrix), where, matrix)
        return self

    def to_dict(self) -> dict[str, Any]:  # pragma: no cover - every subclass implements it
        raise NotImplementedError

    @classmethod
    def from_dict(cls, d: dict[str, Any], where: str = "result") -> Result:  # pragma: no cover
        """The result a file's dictionary holds.

        Parameters
        ----------
        d : dict
            A result file's JSON object.
        where : str
            The file's name, for messages.

        Raises
        ------
        InputError
            Another format, a newer version, or a malformed body.
        """
        raise NotImplementedError


def _type_of(fmt: Any, where: str) -> type[Result]:
    if fmt not in KNOWN:
        known = ", ".join(KNOWN)
        raise InputError(f"not an imu-align result (format {fmt!r}); expected one of: {known}", where)
    if fmt not in _TYPES:
        importlib.import_module(KNOWN[fmt])
    return _TYPES[fmt]


def result_from_dict(d: Any, where: str = "result") -> Result:
    """The result a dictionary holds, of the type its ``format`` names."""
    if not isinstance(d, dict):
        raise InputError("expected a JSON object", where)
    result = _type_of(d.get("format"), where).from_dict(d, where)
    if d.get("provenance") is not None and result.provenance is None:
        result = result.replace(provenance=Provenance.from_dict(d["provenance"], f"{where}: provenance"))
    if d.get("figures_of_merit") and not result.verdicts:
        result = result.replace(verdicts=_figures(d["figures_of_merit"], f"{where}: figures_of_merit"))
    return result


def _figures(items: Any, where: str) -> tuple[Figure, ...]:
    """The judged figures an envelope holds (:meth:`align.merit.Figure.to_dict`)."""
    if not isinstance(items, list) or not all(isinstance(x, dict) for x in items):
        raise InputError("expected a list of figures (objects with name, sensor, value, ...)", where)
    try:
        return tuple(Figure.from_dict(x) for x in items)
    except (TypeError, ValueError) as exc:
        raise InputError(f"a figure cannot be read ({exc}); regenerate the file", where) from None


_R = TypeVar("_R", bound="Result")
_R2 = TypeVar("_R2", bound="Result")


@overload
def load_result(path: str | Path, expect: None = None) -> Result: ...
@overload
def load_result(path: str | Path, expect: tuple[type[_R]]) -> _R: ...
@overload
def load_result(path: str | Path, expect: tuple[type[_R], type[_R2]]) -> _R | _R2: ...
@overload
def load_result(path: str | Path, expect: tuple[type[Result], ...]) -> Result: ...


def load_result(path: str | Path, expect: tuple[type[Result], ...] | None = None) -> Result:
    """Read any imu-align result file and return its type.

    Parameters
    ----------
    path : str or Path
        A JSON file written by :func:`save_result` (or any ``--json`` output).
    expect : tuple of Result types, optional
        Refuse a result of any other type (naming the expected ones).

    Returns
    -------
    Result
    """
    d = read_json(path)
    result = result_from_dict(d, str(path))
    if expect is not None and not isinstance(result, expect):
        names = " or ".join(t.FORMAT for t in expect)
        raise InputError(f"holds an {result.FORMAT} result; expected {names}", str(path))
    return result


def save_result(path: str | Path, result: Result) -> None:
    """Write a result atomically as indented JSON (NaN as null)."""
    write_json(path, result.to_dict())
