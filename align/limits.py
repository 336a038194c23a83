"""Limits: what each figure of merit must meet, read from TOML with its units (parsed here, at the edge), and the verdicts.

One limits file serves every calibration and alignment job (``--limits``), the report, the batch and the lot
(``lot --spec`` reads the same file)::

    phi_xy = { abs_max = "0.1 deg" }            # |phi_xy| <= 0.1 deg
    "phi_*" = { abs_max = "0.1 deg", guard = "0.01 deg" }   # every cross-axis angle; WARN within 0.01 deg of it
    scale_x = { min = 0.995, max = 1.005 }      # plain numbers for ratios
    "scale_*" = { abs_max = "0.5 %", sigma_max = "0.1 %" }  # |scale - 1| <= 0.5 %; NOT USABLE when its 1-sigma > 0.1 %
    arw_x = { max = "0.3 deg/sqrt(h)" }         # an angular unit: applies to gyroscopes
    bias_x = { abs_max = "0.05 m/s^2" }         # an acceleration: applies to accelerometers

    [magnetometer]                              # limits for one sensor only
    heading_error = { max = "1 deg" }

A limit of a figure whose unit depends on the sensor (bias, noise terms) applies to the sensors
whose figure has the limit's dimension; one of another dimension is refused. A figure is shown
in the unit its limit is written in. A scale limit written in % or ppm bounds the deviation from 1
(``abs_max = "0.5 %"``: ``0.995 <= scale <= 1.005``); a scale limit whose range excludes 1 is refused.
Two keys limiting one figure of one sensor (``phi_xy`` and ``"phi_*"``) are refused, naming both.
``coverage``, ``spread`` and ``heading_error`` apply to magnetometers only.

``part = "ADIS16485"`` (a part of :mod:`align.parts`) adds its datasheet's figures as limits of the gyroscope for
the figures the file does not limit: ``|delta_*|`` within the axis-to-axis misalignment, ``arw_*`` within the angle
random walk (or the rate noise density, numerically N in deg/sqrt(s)).

Beside the bounds: ``sigma_max`` (the largest 1-sigma with which the figure is usable: a scale's relative, in
% or ppm), ``guard`` (the guard band inside a bound: a quantity, or ``"k sigma"`` of the figure's own 1-sigma;
default ``"2 sigma"``, ISO 14253-1: a value closer to a bound than its expanded uncertainty does not show
conformance and is WARN).

:func:`judge` gives each :class:`~align.merit.Figure` its verdict (see :mod:`align.merit`). Without a limits
file, :data:`DEFAULT_LIMITS` judges whether a calibration determined its figures well enough to be used at all
(1-sigma of every angle within 1 deg, of every scale within 1 %, of a gyro bias within 0.5 deg/s, an
accelerometer's within 0.1 m/s^2, a magnetometer's within 5 uT): stated in every output that uses them.

Public names
------------
Limit, Limits, Spec, read_limits, read_spec, limits_from_text, judge, failures, DEFAULT_LIMITS, DEFAULT_TEXT, SENSORS
"""

from __future__ import annotations

import fnmatch
import math
import re
from dataclasses import dataclass, replace
from pathlib import Path

from align.errors import InputError, literal
from align.io.files import read_toml
from align.keyfigures import FIGURES, KIND, shown_unit, si_unit
from align.units import parse_unit, to_unit

#: the sensors a row may be of, and a spec table may be named after
SENSORS = ("gyroscope", "accelerometer", "magnetometer")
_BOUNDS = ("min", "max", "abs_max")
#: the keys of a figure's table beside its bounds
_OTHERS = ("sigma_max", "guard")
#: the guard band when a limit states none: this many of the figure's own 1-sigma (ISO 14253-1's k = 2)
GUARD_SIGMAS = 2.0
#: figures only a magnetometer calibration gives
MAGNETOMETER_ONLY = ("coverage", "spread", "heading_error", "field")
_NUMBER = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*)$")


@dataclass(frozen=True)
class Limit:
    """One figure's limits for one sensor (``""``: a figure whose unit is the same for every sensor).

    Attributes
    ----------
    figure : str
    sensor : str
    low, high : float or None
        SI; None where open.
    unit : str
        The unit the spec wrote it in (the figure is shown in it).
    symmetric : bool
        Written as ``abs_max`` (``|x| <= high``).
    key : str
        The key of the file that set it (``"phi_*"``).
    offset : float
        1 for a scale limit written as a deviation from 1 (in % or ppm), else 0.
    sigma_max : float or None
        The largest 1-sigma with which the figure is usable (SI; relative to the value for a scale written in %
        or ppm); None: not judged.
    guard : float or None
        The guard band inside a bound, SI; None: ``guard_sigmas`` of the figure's own 1-sigma.
    guard_sigmas : float
        The guard band in the figure's 1-sigma when ``guard`` is None.
    """

    figure: str
    sensor: str
    low: float | None
    high: float | None
    unit: str
    symmetric: bool = False
    key: str = ""
    offset: float = 0.0
    sigma_max: float | None = None
    guard: float | None = None
    guard_sigmas: float = GUARD_SIGMAS

    @property
    def bounded(self) -> bool:
        """Whether it bounds the value (not only its 1-sigma)."""
        return self.low is not None or self.high is not None

    def applies(self, sensor: str | None) -> bool:
        """True for a row of ``sensor``."""
        return self.sensor == "" or self.sensor == sensor

    def ok(self, value: float) -> bool:
        """True when ``value`` (SI, finite) lies within the limits (bounds included)."""
        return (self.low is None or value >= self.low) and (self.high is None or value <= self.high)

    def shown(self, value: float) -> float:
        """``value`` (SI) in the limit's unit."""
        return float(to_unit(value - self.offset, self.unit)) if self.unit != "1" else float(value - self.offset)

    def describe(self) -> str:
        """``|phi_xy| <= 0.1 deg``, ``0.995 <= scale_x <= 1.005``, ``arw_x <= 0.3 deg/sqrt(h)``,
        ``sigma(phi_xy) <= 1 deg``."""
        u = "" if self.unit == "1" else f" {self.unit}"
        name = f"{self.figure} - 1" if self.offset else self.figure
        low, high = self.low, self.high
        parts = []
        if self.symmetric and high is not None:
            parts.append(f"|{name}| <= {self.shown(high):g}{u}")
        elif low is not None and high is not None:
            parts.append(f"{self.shown(low):g} <= {name} <= {self.shown(high):g}{u}")
        elif high is not None:
            parts.append(f"{name} <= {self.shown(high):g}{u}")
        elif low is not None:
            parts.append(f"{name} >= {self.shown(low):g}{u}")
        if self.sigma_max is not None:
            parts.append(f"sigma({self.figure}) <= {self.shown_sigma(self.sigma_max):g}{u}")
        return ", ".join(parts)

    def shown_sigma(self, sigma: float) -> float:
        """A 1-sigma (SI; relative for a scale written in % or ppm) in the limit's unit."""
        return float(to_unit(sigma, self.unit)) if self.unit != "1" else float(sigma)


@dataclass(frozen=True)
class Limits:
    """The limits of a limits file, in the file's order (``path``: the file, or ``"default limits"``).

    ``limits`` bound values (what the lot's statistics judge); ``usability`` bound only a 1-sigma.
    """

    path: str
    limits: tuple[Limit, ...]
    usability: tuple[Limit, ...] = ()

    def limits_for(self, figure: str, sensor: str | None) -> list[Limit]:
        """The limits that bound ``figure``'s value in a row of ``sensor``."""
        return [lim for lim in self.limits if lim.figure == figure and lim.applies(sensor)]

    def usability_for(self, figure: str, sensor: str | None) -> list[Limit]:
        """The limits of ``figure``'s 1-sigma for ``sensor`` (a bounded limit with ``sigma_max`` too)."""
        return [lim for lim in (*self.limits, *self.usability)
                if lim.figure == figure and lim.applies(sensor) and lim.sigma_max is not None]


#: the old name of :class:`Limits` (a lot's spec)
Spec = Limits


def read_limits(path: str | Path) -> Limits:
    """Read a limits TOML (module docstring).

    Raises
    ------
    InputError
        An unknown figure, key or sensor table; a bound that is not a quantity or of the wrong dimension;
        ``min`` above ``max``; naming the file and the key.
    """
    return limits_from_dict(read_toml(path), str(path))


#: the old name of :func:`read_limits`
read_spec = read_limits


def limits_from_text(text: str, where: str) -> Limits:
    """The limits of TOML ``text`` (:data:`DEFAULT_TEXT`), ``where`` naming it in messages."""
    import tomllib

    return limits_from_dict(tomllib.loads(text), where)


def limits_from_dict(data: dict, where: str) -> Limits:
    """The limits of a parsed limits table (:func:`read_limits`)."""
    limits: list[Limit] = []
    data = dict(data)
    part = data.pop("part", None)
    for key, value in data.items():
        if key in SENSORS:
            if not isinstance(value, dict):
                raise InputError(f"{key}: give a table of limits ([{key}])", where)
            for k, v in value.items():
                limits += _limits(k, v, key, f"{key}.{k}", where)
        else:
            limits += _limits(key, value, None, key, where)
    if part is not None:
        limits += _part_limits(part, limits, where)
    if not limits:
        raise InputError("states no limit; give e.g. phi_xy = { abs_max = \"0.1 deg\" }", where)
    seen: dict[tuple[str, str], Limit] = {}
    for lim in limits:
        for s in SENSORS if lim.sensor == "" else (lim.sensor,):
            other = seen.get((lim.figure, s))
            if other is not None and other.key != lim.key:
                raise InputError(f"{literal(other.key)} and {literal(lim.key)} both limit {lim.figure}"
                                 + (f" of the {s}" if lim.sensor or other.sensor else "")
                                 + "; give each figure one limit (remove one key or narrow its pattern)", where)
            seen[(lim.figure, s)] = lim
    return Limits(where, tuple(lim for lim in limits if lim.bounded), tuple(lim for lim in limits if not lim.bounded))


def _figures(pattern: str, key: str, where: str) -> list[str]:
    found = [f for f in FIGURES if fnmatch.fnmatchcase(f, pattern)]
    if not found:
        import difflib

        close = difflib.get_close_matches(pattern, FIGURES, n=1)
        hint = f" (did you mean {close[0]}?)" if close else ""
        raise InputError(f"{literal(key)}: no figure is named so{hint}; the figures are scale_x, phi_xy, delta_xy, "
                         "rotation_x, bias_x, arw_x, bi_x, rrw_x, M_xy, field, coverage, heading_error, spread "
                         "(x, y, z each)", where)
    return found


def _bound(text, figure: str, key: str, name: str, where: str) -> tuple[float, str, tuple]:
    """(number, unit text, dimension) of one bound as written."""
    if isinstance(text, bool) or not isinstance(text, (int, float, str)):
        raise InputError(f"{literal(key)}.{name}: give a number or a quantity such as '0.1 deg'", where)
    if isinstance(text, str):
        m = _NUMBER.match(text)
        if not m:
            raise InputError(f"{literal(key)}.{name}: '{literal(text)}' does not start with a number", where)
        number, unit = float(m.group(1)), m.group(2).strip() or "1"
    else:
        number, unit = float(text), "1"
    if not math.isfinite(number):
        raise InputError(f"{literal(key)}.{name}: not a finite number", where)
    u = parse_unit(unit, None, f"{where}: {key}.{name}")
    return number * u.factor, unit, u.dim


def _limits(pattern: str, value, sensor: str | None, key: str, where: str) -> list[Limit]:
    if not isinstance(value, dict) or not value:
        raise InputError(f"{literal(key)}: give its limits as a table, e.g. {{ min = ..., max = ... }} or "
                         "{ abs_max = ... }", where)
    if sensor is None and not any(fnmatch.fnmatchcase(f, pattern) for f in FIGURES):
        import difflib

        close = difflib.get_close_matches(pattern, list(SENSORS), n=1, cutoff=0.4)
        if close or not set(value) & {*_BOUNDS, *_OTHERS}:
            raise InputError(f"{literal(key)}: neither a figure nor a sensor table"
                             + (f" (did you mean {close[0]}?)" if close else "") + f"; the sensor tables are "
                             f"{', '.join(SENSORS)}", where)
    for name in value:
        if name not in (*_BOUNDS, *_OTHERS):
            raise InputError(f"{literal(key)}: unknown bound '{literal(name)}'; use min, max or abs_max (and "
                             "sigma_max, guard)", where)
    if not set(value) & {*_BOUNDS, "sigma_max"}:
        raise InputError(f"{literal(key)}: give a bound (min, max, abs_max) or sigma_max", where)
    others = {n: value[n] for n in _OTHERS if n in value}
    value = {n: v for n, v in value.items() if n in _BOUNDS}
    if "abs_max" in value and ("min" in value or "max" in value):
        raise InputError(f"{literal(key)}: give abs_max, or min and/or max, not both", where)
    out = []
    for figure in _figures(pattern, key, where):
        bounds = {n: _bound(v, figure, key, n, where) for n, v in value.items()}
        sigma = _bound(others["sigma_max"], figure, key, "sigma_max", where) if "sigma_max" in others else None
        guard, guard_sigmas = _guard(others.get("guard"), figure, key, where)
        if figure.startswith("scale_") and len({v[1].strip() in ("%", "ppm") for v in bounds.values()}) > 1:
            raise InputError(f"{literal(key)}: give both bounds in % (a deviation from 1) or both as ratios", where)
        written = [*bounds.values(), *([sigma] if sigma else []), *([guard] if guard else [])]
        dims = {b[2] for b in written}
        if len(dims) > 1:
            raise InputError(f"{literal(key)}: its bounds are of different dimensions; write them in one unit", where)
        dim = dims.pop()
        unit = written[0][1]
        sensors: list[str]
        if figure in MAGNETOMETER_ONLY:
            sensors = ["magnetometer"] if sensor in (None, "magnetometer") else []
        elif sensor:
            sensors = [sensor]
        else:
            sensors = [""] if KIND[figure] in ("1", "angle", "time") else list(SENSORS)
        matching = [s for s in sensors if (si := si_unit(figure, s)) and parse_unit(si).dim == dim]
        if not matching:
            wanted = sorted({f"'{shown_unit(figure, s)}'" for s in sensors if si_unit(figure, s)})
            raise InputError(f"{literal(key)}: '{literal(unit)}' is not a unit of {figure}"
                             + (f" for the {sensor}" if sensor else "")
                             + (f"; write it like {' or '.join(wanted)}" if wanted else ""), where)
        low, high, symmetric = _low_high(bounds, key, where)
        offset = 0.0
        if figure.startswith("scale_") and bounds:
            if unit.strip() in ("%", "ppm"):  # a deviation from 1
                offset = 1.0
                low, high = (None if low is None else 1.0 + low), (None if high is None else 1.0 + high)
            elif not ((low is None or low <= 1.0) and (high is None or high >= 1.0)):
                raise InputError(f"{literal(key)}: its range excludes 1, and a scale is near 1; write e.g. "
                                 "{ min = 0.995, max = 1.005 } or { abs_max = \"0.5 %\" } (a deviation from 1)", where)
        out += [Limit(figure, s, low, high, unit, symmetric, key, offset, None if sigma is None else sigma[0],
                      None if guard is None else guard[0], guard_sigmas) for s in matching]
    return out


def _low_high(bounds: dict, key: str, where: str) -> tuple[float | None, float | None, bool]:
    """(low, high, symmetric) of a figure's bounds as written, SI."""
    if "abs_max" in bounds:
        high = bounds["abs_max"][0]
        if high < 0:
            raise InputError(f"{literal(key)}.abs_max: must be >= 0", where)
        return -high, high, True
    low, high = (bounds["min"][0] if "min" in bounds else None), (bounds["max"][0] if "max" in bounds else None)
    if low is not None and high is not None and low > high:
        raise InputError(f"{literal(key)}: min is above max", where)
    return low, high, False


def _guard(text, figure: str, key: str, where: str) -> tuple[tuple | None, float]:
    """A guard band as written: a quantity (``"0.01 deg"``) or ``"k sigma"`` -> (bound or None, k)."""
    if text is None:
        return None, GUARD_SIGMAS
    m = re.fullmatch(r"\s*([0-9.]+)\s*sigma\s*", text) if isinstance(text, str) else None
    if m:
        return None, float(m.group(1))
    bound = _bound(text, figure, key, "guard", where)
    if bound[0] < 0:
        raise InputError(f"{literal(key)}.guard: must be >= 0 (a quantity, or '2 sigma')", where)
    return bound, GUARD_SIGMAS


#: a datasheet figure (:mod:`align.parts`) -> the gyro's key figures it limits and the bound, as ``part = "NAME"``
#: writes them
#: (a datasheet's "bias instability" is the Allan floor, 0.664 B, not the fit's B: it limits nothing here)
_PART_FIGURES = (("axis_to_axis", "angle", "delta_*", "abs_max"), ("arw", "angle_random_walk", "arw_?", "max"),
                 ("noise_density", "angle_random_walk", "arw_?", "max"))


def _part_limits(name, written: list[Limit], where: str) -> list[Limit]:
    """The limits a part's datasheet gives (``part = "ADIS16405"``): the gyro's non-orthogonality within its
    axis-to-axis misalignment, its N within its angle random walk (or noise density); only for the figures the
    file does not limit itself."""
    from align.parts import get_part

    if not isinstance(name, str):
        raise InputError("part: give a part's name as a string, e.g. part = \"ADIS16405\"", where)
    part = get_part(name, f"{where}: part")
    out: list[Limit] = []
    for field, dim, pattern, bound in _PART_FIGURES:
        fig = getattr(part, field)
        if fig is None:
            continue
        part.si(field, dim)  # refuses a figure of the wrong dimension, naming the part
        key = f"part {part.name}: {field}"
        taken = {lim.figure for lim in (*written, *out) if lim.bounded and lim.sensor in ("", "gyroscope")}
        out += [replace(lim, key=key) for lim in _limits(pattern, {bound: fig.value}, "gyroscope", key, where)
                if lim.figure not in taken]
    return out

