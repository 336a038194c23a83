"""Units: the one place where unit strings become SI numbers.

Quantities enter the program as strings with an explicit unit ("100 deg/s",
"0.2 mm", "0.3 deg/sqrt(h)", "15 deg/h") and leave it the same way; inside,
everything is SI with angles in radians. Angle is kept as a dimension of its own
so that a length given where an angle is expected is caught.

Public names
------------
parse_unit, parse_quantity, parse_scale, to_unit, format_quantity, unit_mixup_hint, Unit, DIMENSIONS, SHOWN_IN,
COUNT_EXAMPLES, TEMPERATURE_UNITS, temperature_offset, DEG, DEG_S, DEG_H, ARCSEC, MM, HOUR, STANDARD_GRAVITY
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache
from typing import TYPE_CHECKING, overload

from align.errors import UnitError, literal

if TYPE_CHECKING:  # numpy only for the hints: the command line's --help imports no numerical library
    import numpy as np

#: one degree in radians
DEG = math.pi / 180.0
#: one degree per second in rad/s
DEG_S = DEG
#: one degree per hour in rad/s
DEG_H = DEG / 3600.0
#: one arc second in radians
ARCSEC = DEG / 3600.0
#: one millimetre in metres
MM = 1e-3
#: one hour in seconds
HOUR = 3600.0
#: standard gravity in m/s^2 (the unit "g")
STANDARD_GRAVITY = 9.80665

_BASES = ("m", "s", "rad", "T", "count")


@dataclass(frozen=True)
class Unit:
    """A unit: a factor to SI and a dimension (exponents of m, s, rad, T, count).

    Units multiply, divide and take rational powers (``deg/sqrt(h)``); angle is
    a dimension of its own (reference section 1: radians inside, degrees at the
    edges).

    Attributes
    ----------
    factor : float
        One of this unit in SI (angles in rad), e.g. ``pi / 180`` for ``deg/s``.
    dim : tuple of Fraction, length 5
        Exponents of m, s, rad, T and count.
    """

    factor: float
    dim: tuple[Fraction, ...]

    def __mul__(self, other: Unit) -> Unit:
        return Unit(self.factor * other.factor, tuple(a + b for a, b in zip(self.dim, other.dim)))

    def __truediv__(self, other: Unit) -> Unit:
        return Unit(self.factor / other.factor, tuple(a - b for a, b in zip(self.dim, other.dim)))

    def __pow__(self, p: Fraction) -> Unit:
        return Unit(self.factor ** float(p), tuple(a * p for a in self.dim))


def _u(factor: float, **exps: int | Fraction) -> Unit:
    return Unit(factor, tuple(Fraction(exps.get(b, 0)) for b in _BASES))


_ONE = _u(1.0)
_PREFIXES = {"n": 1e-9, "u": 1e-6, "µ": 1e-6, "m": 1e-3, "k": 1e3}
_ATOMS: dict[str, Unit] = {
    "m": _u(1.0, m=1), "in": _u(0.0254, m=1), "inch": _u(0.0254, m=1),
    "s": _u(1.0, s=1), "sec": _u(1.0, s=1), "min": _u(60.0, s=1),
    "h": _u(3600.0, s=1), "hr": _u(3600.0, s=1), "hour": _u(3600.0, s=1),
    "Hz": _u(1.0, s=-1),
    "rad": _u(1.0, rad=1), "deg": _u(DEG, rad=1), "°": _u(DEG, rad=1),
    "arcmin": _u(DEG / 60.0, rad=1), "arcsec": _u(ARCSEC, rad=1),
    "rev": _u(2 * math.pi, rad=1),
    "dps": _u(DEG, rad=1, s=-1), "rpm": _u(2 * math.pi / 60.0, rad=1, s=-1),
    "g": _u(STANDARD_GRAVITY, m=1, s=-2),
    "T": _u(1.0, T=1), "gauss": _u(1e-4, T=1), "G": _u(1e-4, T=1),
    "count": _u(1.0, count=1), "counts": _u(1.0, count=1), "LSB": _u(1.0, count=1),
    "%": _u(1e-2), "ppm": _u(1e-6), "1": _ONE,
}
_PREFIXABLE = {"m", "s", "rad", "deg", "dps", "g", "T", "G", "gauss", "Hz"}

#: named dimensions a caller can ask for
DIMENSIONS: dict[str, tuple[Unit, str]] = {
    "angle": (_u(1, rad=1), "an angle, e.g. '1 deg'"),
    "angular_rate": (_u(1, rad=1, s=-1), "an angular rate, e.g. '100 deg/s'"),
    "length": (_u(1, m=1), "a length, e.g. '0.2 mm'"),
    "time": (_u(1, s=1), "a time, e.g. '30 s'"),
    "frequency": (_u(1, s=-1), "a frequency, e.g. '100 Hz'"),
    "acceleration": (_u(1, m=1, s=-2), "an acceleration, e.g. '9.81 m/s^2'"),
    "magnetic_field": (_u(1, T=1), "a magnetic field, e.g. '50 uT'"),
    "angle_random_walk": (_u(1, rad=1, s=Fraction(-1, 2)), "an angle random walk, e.g. '0.3 deg/sqrt(h)'"),
    "rate_random_walk": (_u(1, rad=1, s=Fraction(-3, 2)), "a rate random walk, e.g. '3 deg/h/sqrt(h)'"),
    "velocity_random_walk": (_u(1, m=1, s=Fraction(-3, 2)), "a velocity random walk, e.g. '0.05 m/s/sqrt(h)'"),
    "dimensionless": (_ONE, "a plain number or ratio, e.g. '0.1 %'"),
    "counts": (_u(1, count=1), "raw counts"),
}

_TOKEN = re.compile(r"\s*(sqrt\(|\*\*|[*/^()]|[-+]?\d+(?:\.\d+)?|[A-Za-zµ°%][A-Za-z0-9µ°_]*|%)")


def _atom(name: str) -> Unit:
    if name in _ATOMS:
        return _ATOMS[name]
    if len(name) > 1 and name[0] in _PREFIXES and name[1:] in _PREFIXABLE:
        base = _ATOMS[name[1:]]
        return Unit(base.factor * _PREFIXES[name[0]], base.dim)
    raise ValueError(f"unknown unit '{name}'")


class _Parser:
    """Recursive-descent parser: expr := term (('*'|'/') term)*; term := atom ('^' num)?"""

    def __init__(self, text: str) -> None:
        pos, toks = 0, []
        text = text.strip()
        while pos < len(text):
            m = _TOKEN.match(text, pos)
            if not m or m.end() == pos:
                raise ValueError(f"cannot read '{text[pos:]}'")
            toks.append(m.group(1))
            pos = m.end()
        self.toks, self.i = toks, 0

    def peek(self) -> str | None:
        return self.toks[self.i] if self.i < len(self.toks) else None

    def take(self) -> str:
        tok = self.peek()
        if tok is None:
            raise ValueError("unit ends too early")
        self.i += 1
        return tok

    def expr(self) -> Unit:
        unit = self.term()
        while self.peek() in ("*", "/"):
            op = self.take()
            rhs = self.term()
            unit = unit * rhs if op == "*" else unit / rhs
        return unit

    def term(self) -> Unit:
        tok = self.take()
        if tok == "sqrt(":
            unit = self.expr() ** Fraction(1, 2)
            if self.take() != ")":
                raise ValueError("missing ')'")
        elif tok == "(":
            unit = self.expr()
            if self.take() != ")":
                raise ValueError("missing ')'")
        else:
            unit = _atom(tok)
        if self.peek() in ("^", "**"):
            self.take()
            unit = unit ** Fraction(self.take())
        return unit


@lru_cache(maxsize=256)
def parse_unit(text: str, expect: str | None = None, where: str | None = None) -> Unit:
    """Parse a unit string such as ``"deg/s"`` or ``"deg/h/sqrt(h)"``.

    Parameters
    ----------
    text : str
        The unit. ``"dps"``, ``"mdps"``, ``"rad/s"``, ``"deg/sqrt(h)"``, ``"m/s^2"``,
        ``"uT"``, ``"%"`` and the like.
    expect : str, optional
        A key of :data:`DIMENSIONS`; the unit must have that dimension.
    where : str, optional
        Name of the file field or option, for the error message.

    Returns
    -------
    Unit
        Its factor to SI (angles in radians) and its dimension.
    """
    try:
        parser = _Parser(text)
        unit = parser.expr() if parser.toks else _ONE
        if parser.peek() is not None:
            raise ValueError(f"unexpected '{parser.peek()}'")
    except (ValueError, ZeroDivisionError, IndexError) as exc:
        raise UnitError(f"cannot read unit '{literal(text)}' ({literal(exc)})", where) from None
    if expect is not None:
        want, example = DIMENSIONS[expect]
        if unit.dim != want.dim:
            raise UnitError(f"'{literal(text)}' is not {example}", where)
    return unit


_NUMBER = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*)$")


def parse_quantity(text: str | float | int, expect: str, where: str | None = None) -> float:
    """Parse ``"<number> <unit>"`` into an SI float.

    Parameters
    ----------
    text : str, float or int
        For example ``"100 deg/s"``, ``"-360 deg"``, ``"0.3 deg/sqrt(h)"``.
        A bare number (string or not) is accepted only for ``expect="dimensionless"``.
    expect : str
        A key of :data:`DIMENSIONS`.
    where : str, optional
        Name of the field, for the error message.

    Returns
    -------
    float
        The value in SI units (radians for angles).
    """
    if isinstance(text, bool) or not isinstance(text, (str, int, float)):
        raise UnitError(f"expected a quantity string such as {DIMENSIONS[expect][1]!s}, got {literal(repr(text))}", where)
    if not isinstance(text, str):
        if expect != "dimensionless":
            raise UnitError(f"{literal(repr(text))} has no unit; write {DIMENSIONS[expect][1]}", where)
        if not math.isfinite(text):
            raise UnitError(f"{literal(repr(text))} is not a finite number", where)
        return float(text)
    m = _NUMBER.match(text)
    if not m:
        raise UnitError(f"'{literal(text)}' does not start with a number; write {DIMENSIONS[expect][1]}", where)
    value, unit_text = float(m.group(1)), m.group(2).strip()
    if not unit_text and expect != "dimensionless":
        raise UnitError(f"'{literal(text)}' has no unit; write {DIMENSIONS[expect][1]}", where)
    if not math.isfinite(value):
        raise UnitError(f"'{literal(text)}' is not a finite number", where)
    return value * parse_unit(unit_text, expect, where).factor


#: the unit readings of a dimension are shown in when they were given as a count size
SHOWN_IN = {"magnetic_field": "uT", "angular_rate": "deg/s", "acceleration": "m/s^2"}
#: per dimension of :data:`SHOWN_IN`: a count size, the same as a datasheet sensitivity, and the part and range
#: they belong to (for messages that ask for one)
COUNT_EXAMPLES = {"angular_rate": ("0.0076336 deg/s", "131 LSB/(deg/s)", "an MPU-6050 at +/-250 deg/s"),
                  "acceleration": ("0.061035 mg", "16384 LSB/g", "an MPU-6050 at +/-2 g"),
                  "magnetic_field": ("0.92 mG", "1090 LSB/gauss", "an HMC5883L at +/-1.3 gauss")}


def parse_scale(text: str, expect: str, where: str | None = None) -> tuple[float, str]:
    """The unit of raw readings: a unit of ``expect``, ``counts``, or the size of one count.

    Parameters
    ----------
    text : str
        ``"uT"``, ``"gauss"``, ``"deg/s"``; ``"counts"`` (readings kept in counts); the size of one
        count: ``"0.92 mG"``, ``"0.0076336 deg/s"`` (one count is that much) or ``"0.0076336 deg/s/LSB"``;
        or a datasheet sensitivity, counts per unit: ``"131 LSB/(deg/s)"``, ``"16384 LSB/g"`` (one count
        is 1/131 deg/s, 1/16384 g).
    expect : str
        A key of :data:`DIMENSIONS` with an entry in :data:`SHOWN_IN`.
    where : str, optional
        The input concerned, for the error message.

    Returns
    -------
    factor : float
        Multiplies a reading into SI (or counts): the count size in SI, ``1 / (sensitivity in SI)``.
    shown : str
        The unit the scaled readings are shown and written in: ``text`` for a unit or ``counts``,
        :data:`SHOWN_IN` of the dimension for a count size or sensitivity.

    Raises
    ------
    UnitError
        Another dimension, or a count size or sensitivity that is not a finite number > 0.
    """
    want, example = DIMENSIONS[expect]
    count = DIMENSIONS["counts"][0].dim
    m = _NUMBER.match(text)
    if m is None:
        unit = parse_unit(text, where=where)
        if unit.dim not in (want.dim, count):
            raise UnitError(f"'{literal(text)}' is not {example}, 'counts' or the size of one count", where)
        return unit.factor, text
    value, unit = float(m.group(1)), parse_unit(m.group(2).strip(), where=where)
    per_count = tuple(a - b for a, b in zip(want.dim, count))
    if unit.dim in (want.dim, per_count):   # '0.0076336 deg/s', '0.0076336 deg/s/LSB': one count is that much
        size = value * unit.factor
    elif unit.dim == tuple(-d for d in per_count):   # '131 LSB/(deg/s)': counts per unit
        size = 1.0 / (value * unit.factor) if value else math.inf
    else:
        size_example, sensitivity_example, _ = COUNT_EXAMPLES[expect]
        raise UnitError(f"'{literal(text)}' is neither the size of one count ({example.split(', e.g. ')[0]}, e.g. "
                        f"'{size_example}') nor counts per unit (e.g. '{sensitivity_example}')", where)
    if not (math.isfinite(size) and size > 0):
        raise UnitError(f"'{literal(text)}': the size of one count must be a finite number > 0", where)
    return size, SHOWN_IN[expect]


@overload
def to_unit(value_si: float, unit: str) -> float: ...
@overload
def to_unit(value_si: np.ndarray, unit: str) -> np.ndarray: ...
@overload
def to_unit(value_si: float | np.ndarray, unit: str) -> float | np.ndarray: ...
def to_unit(value_si: float | np.ndarray, unit: str) -> float | np.ndarray:
    """Convert an SI value to ``unit`` (the inverse of :func:`parse_quantity`).

    Parameters
    ----------
    value_si : float or ndarray, any shape
        Value in SI units (rad, rad/s, m, s, m/s^2, T, ...).
    unit : str
        Target unit, e.g. ``"deg/s"`` or ``"deg/h"``; any unit :func:`parse_unit` reads.

    Returns
    -------
    float or ndarray, same shape as ``value_si``
        ``value_si`` divided by the unit's factor to SI. The dimension is not
        checked.
    """
    return value_si / parse_unit(unit).factor


def format_quantity(value_si: float, unit: str, digits: int = 6) -> str:
    """Format an SI value as ``"<number> <unit>"``, the form the parser reads back.

    Parameters
    ----------
    value_si : float
        Value in SI units (rad, rad/s, m, ...).
    unit : str
        Unit to show it in, e.g. ``"deg/s"``.
    digits : int
        Significant digits (``%g`` formatting).

    Returns
    -------
    str
        For example ``"100 deg/s"``.
    """
    return f"{to_unit(value_si, unit):.{digits}g} {unit}"


_MIXUPS = ((180 / math.pi, "the log looks like deg/s read as rad/s: set {gyro_units=deg/s}"),
           (math.pi / 180, "the log looks like rad/s read as deg/s: set {gyro_units=rad/s}"),
           (1e3, "mdps read as deg/s? set {gyro_units=mdps}"),
           (1e-3, "deg/s read as mdps? set {gyro_units=deg/s}"))


def unit_mixup_hint(ratio: float) -> str | None:
    """A message when measured and planned rates differ by a unit factor.

    The factors are 180/pi (deg/s read as rad/s), pi/180, 1000 (mdps read as
    deg/s) and 1/1000, each within 10 %.

    Parameters
    ----------
    ratio : float
        Measured rate (or angle) over the planned one, dimensionless.

    Returns
    -------
    str or None
        The message, naming the likely mix-up and the fix as a ``{gyro_units=...}``
        placeholder; None when the ratio is near no unit factor.
    """
    for factor, hint in _MIXUPS:
        if abs(ratio / factor - 1) < 0.1:
            return f"measured rates are {ratio:.4g}x the plan's: {hint}"
    return None


#: temperature units a log may state (an affine scale, so not a unit of :func:`parse_unit`): name -> (scale, offset)
#: taking a reading to degrees Celsius, ``C = scale * x + offset``
TEMPERATURE_UNITS = {"degC": (1.0, 0.0), "C": (1.0, 0.0), "°C": (1.0, 0.0), "celsius": (1.0, 0.0),
                     "K": (1.0, -273.15), "kelvin": (1.0, -273.15),
                     "degF": (5.0 / 9.0, -32.0 * 5.0 / 9.0), "F": (5.0 / 9.0, -32.0 * 5.0 / 9.0)}


def temperature_offset(text: str, where: str | None = None) -> tuple[float, float]:
    """The scale and offset that take a temperature reading in ``text`` to degrees Celsius.

    Temperature stays in degrees Celsius inside (the unit every datasheet and firmware states
    its temperature coefficients in), ``C = scale * x + offset``.

    Parameters
    ----------
    text : str
        ``"degC"`` (or ``"C"``), ``"K"``, ``"degF"``.
    where : str, optional
        The input that gave it, for messages.

    Returns
    -------
    scale, offset : float

    Raises
    ------
    UnitError
        For any other text.

    Examples
    --------
    >>> temperature_offset("K")
    (1.0, -273.15)
    """
    key = text.strip() if isinstance(text, str) else text
    if key not in TEMPERATURE_UNITS:
        raise UnitError(f"'{literal(str(text))}' is not a temperature unit; give degC, K or degF", where)
    return TEMPERATURE_UNITS[key]
