"""The rate-table test plan: the steps in the order they were run.

A step turns the table about one system axis, either at a constant signed
rate (``rate``, Eq 19-30) or through a signed angle (``angle``, Eq 31).
``axis = "-y"`` means the system's -y axis points along the table's spin axis;
a positive rate or angle is a right-handed turn about that axis.

The geometry (frames in :mod:`align.alignment.geometry`): ``[test] table_axis`` is the direction of the
table's positive spin axis in the local level frame (``"up"`` by default, or ``"down"``, ``"north"``,
``"south"``, ``"east"``, ``"west"``); ``[test] rest = ["north", "west", "up"]`` says where system x, y, z
point when the table is at rest before a step. Both may be overridden in a ``[[step]]`` (a fixture
re-mounted between axes). ``[mounting]`` states the IMU's nominal mounting in the system
(``axes = ["+y", "-x", "+z"]`` or ``matrix = [[...], [...], [...]]``).

Public names
------------
Step, Plan, parse_axis, axis_name, check_turn, PLAN_KEYS, TEST_KEYS, STEP_KEYS, MAX_RATE_DEG_S, MAX_ANGLE_DEG
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from align.alignment.geometry import direction, mounting_axes, parse_mounting, rest_matrix
from align.errors import InputError, literal
from align.io.keys import check_keys, table, tables
from align.units import DEG, DEG_S, format_quantity, parse_quantity

_AXIS_INDEX = {"x": 0, "y": 1, "z": 2}


def parse_axis(text: str, where: str | None = None) -> tuple[int, int]:
    """``"+x"``, ``"-z"``, ``"y"`` -> (index 0..2, sign +1/-1)."""
    t = str(text).strip().lower()
    sign = -1 if t.startswith("-") else 1
    name = t.lstrip("+-")
    if name not in _AXIS_INDEX:
        raise InputError(f"axis '{literal(text)}' is not one of +x, -x, +y, -y, +z, -z", where)
    return _AXIS_INDEX[name], sign


def axis_name(index: int, sign: int = 1) -> str:
    return ("+" if sign > 0 else "-") + "xyz"[index]


@dataclass(frozen=True)
class Step:
    """One table step.

    Attributes
    ----------
    axis : int
        System axis index (0, 1, 2).
    sign : int
        +1 or -1: which way that axis points along the table spin axis.
    rate : float or None
        Signed table rate, rad/s (rate steps).
    angle : float or None
        Signed table angle, rad (angle steps).
    table_axis : str
        Direction of the table's positive spin axis in the local level frame (``"up"``, ``"east"``, ...).
    rest : tuple of 3 str, or None
        Where system x, y, z point at rest before the step (ENU directions); None when not stated.
    """

    axis: int
    sign: int
    rate: float | None = None
    angle: float | None = None
    table_axis: str = "up"
    rest: tuple[str, str, str] | None = None

    @property
    def table_vector(self) -> np.ndarray:
        """The table's positive spin axis, unit vector in the local level frame (ENU)."""
        return direction(self.table_axis, "step")

    @property
    def rest_matrix(self) -> np.ndarray | None:
        """``C`` (3, 3), system axes (columns) in ENU at rest before the step, or None when not stated."""
        return None if self.rest is None else rest_matrix(list(self.rest), "step")

    @property
    def kind(self) -> str:
        return "rate" if self.rate is not None else "angle"

    @property
    def unit_axis(self) -> np.ndarray:
        """Signed unit vector of the table spin axis in the system frame."""
        u = np.zeros(3)
        u[self.axis] = self.sign
        return u

    @property
    def turn(self) -> float:
        """The signed table rate (rate step, rad/s) or angle (angle step, rad): a step holds exactly one."""
        value = self.rate if self.rate is not None else self.angle
        assert value is not None, "a step turns the table by a rate or an angle"
        return value

    @property
    def label(self) -> str:
        if self.rate is not None:
            return f"{axis_name(self.axis, self.sign)} at {format_quantity(self.rate, 'deg/s', 5)}"
        return f"{axis_name(self.axis, self.sign)} through {format_quantity(self.turn, 'deg', 5)}"


@dataclass(frozen=True)
class Plan:
    """A rate-table test plan.

    Attributes
    ----------
    steps : tuple of Step
    latitude : float or None
        Test-site latitude, rad; set to correct the Earth rate along the table axis.
    rate_accuracy : float
        Relative table-rate accuracy (1 sigma), added to the uncertainty of ``M``.
    angle_accuracy : float
        Table angle accuracy (1 sigma), rad, for angle steps.
    mounting : tuple of tuples, or None
        The declared nominal mounting ``N`` (rows: each gyro's nominal axis in the system frame), or None.
    table_axis : str
        The session's table axis (each step holds its own, which may differ).
    rest : tuple of 3 str, or None
        The session's rest orientation (each step holds its own).
    """

    steps: tuple[Step, ...]
    latitude: float | None = None
    rate_accuracy: float = 0.0
    angle_accuracy: float = 0.0
    mounting: tuple[tuple[float, float, float], ...] | None = None
    table_axis: str = "up"
    rest: tuple[str, str, str] | None = None

    @property
    def nominal(self) -> np.ndarray | None:
        """The declared nominal mounting ``N`` (3, 3), or None."""
        return None if self.mounting is None else np.array(self.mounting, float)

    @property
    def kind(self) -> str:
        kinds = {s.kind for s in self.steps}
        return kinds.pop() if len(kinds) == 1 else "mixed"

    def axes_turned(self) -> set[int]:
        return {s.axis for s in self.steps}

    @classmethod
    def from_dict(cls, data: dict, where: str = "plan") -> Plan:
        """Build a plan from the parsed TOML (see module docstring).

        Every table is checked for unknown keys (:data:`PLAN_KEYS`, :data:`TEST_KEYS`,
        :data:`STEP_KEYS`, ``[mounting]``); every value for its domain (a step turns the table: a
        finite, non-zero rate or angle; ``|latitude| <= 90 deg``; accuracies finite,
        not negative, ``rate_accuracy`` under 100 %; at rest, the step's axis points along the table axis).
        """
        check_keys(data, PLAN_KEYS, where)
        raw = tables(data, "step", where)
        if not raw:
            raise InputError("no [[step]] tables: list the table steps in the order they were run", where)
        test = table(data, "test", where)
        check_keys(test, TEST_KEYS, f"{where}: [test]")
        table_axis = _table_axis(test, "up", f"{where}: test.table_axis")
        rest = _rest(test, None, f"{where}: test.rest")
        steps = tuple(_step(item, f"{where}: step {k}", table_axis, rest) for k, item in enumerate(raw, start=1))
        mounting = None
        if "mounting" in data:
            n = parse_mounting(table(data, "mounting", where), f"{where}: mounting")
            mounting = tuple((float(row[0]), float(row[1]), float(row[2])) for row in n)
        lat = test.get("latitude")
        latitude = None if lat is None else parse_quantity(lat, "angle", f"{where}: test.latitude")
        if latitude is not None and abs(latitude) > np.pi / 2:
            raise InputError("latitude must lie within +/-90 deg", f"{where}: test.latitude")
        rate_acc = _accuracy(test, "rate_accuracy", "dimensionless", "0 %", where)
        if rate_acc >= 1:
            raise InputError(f"{format_quantity(rate_acc, '%', 4)} is not a table-rate accuracy: it must be under "
                             "100 % (e.g. \"0.01 %\")", f"{where}: test.rate_accuracy")
        angle_acc = _accuracy(test, "angle_accuracy", "angle", "0 deg", where)
        return cls(steps, latitude, rate_acc, angle_acc, mounting, table_axis, rest)

    def to_toml(self) -> str:
        """The plan as TOML text that :meth:`from_dict` reads back."""
        lines = []
        nominal = self.nominal
        if self.mounting is not None and nominal is not None:
            axes = mounting_axes(nominal)
            lines.append("[mounting]")
            if axes is not None:
                lines.append("axes = [" + ", ".join(f'"{a}"' for a in axes) + "]")
            else:
                lines.append("matrix = [" + ", ".join("[" + ", ".join(repr(float(v)) for v in row) + "]"
                                                      for row in self.mounting) + "]")
            lines.append("")
        lines.append("[test]")
        if self.latitude is not None:
            lines.append(f'latitude = "{format_quantity(self.latitude, "deg", 10)}"')
        lines.append(f'rate_accuracy = "{format_quantity(self.rate_accuracy, "%", 10)}"')
        lines.append(f'angle_accuracy = "{format_quantity(self.angle_accuracy, "deg", 10)}"')
        lines.append(f'table_axis = "{self.table_axis}"')
        if self.rest is not None:
            lines.append("rest = [" + ", ".join(f'"{d}"' for d in self.rest) + "]")
        lines.append("")
        for s in self.steps:
            lines.append("[[step]]")
            lines.append(f'axis = "{axis_name(s.axis, s.sign)}"')
            if s.rate is not None:
                lines.append(f'rate = "{format_quantity(s.rate, "deg/s", 12)}"')
            else:
                lines.append(f'angle = "{format_quantity(s.turn, "deg", 12)}"')
            if s.table_axis != self.table_axis:
                lines.append(f'table_axis = "{s.table_axis}"')
            if s.rest is not None and s.rest != self.rest:
                lines.append("rest = [" + ", ".join(f'"{d}"' for d in s.rest) + "]")
            lines.append("")
        return "\n".join(lines)

    @classmethod
    def standard_rate(cls, rate: float, latitude: float | None = None) -> Plan:
        """The six-dwell +/- rate plan about x, y, z (Eq 28-30); ``rate`` in rad/s (refused when zero or beyond a table)."""
        check_turn(rate, "rate", "{rate}")
        steps = tuple(Step(a, 1, rate=r) for a in range(3) for r in (rate, -rate))
        return cls(steps, latitude)

    @classmethod
    def standard_angle(cls, angle: float) -> Plan:
        """Six turns, +/- ``angle`` (rad) about x, y, z (Eq 31); refused when zero or beyond a table."""
        check_turn(angle, "angle", "{angle}")
        steps = tuple(Step(a, 1, angle=t) for a in range(3) for t in (angle, -angle))
        return cls(steps)


#: the keys of a plan file, of its [test] table and of each [[step]]
PLAN_KEYS = ("test", "step", "mounting")
TEST_KEYS = ("latitude", "rate_accuracy", "angle_accuracy", "table_axis", "rest")
STEP_KEYS = ("axis", "rate", "angle", "table_axis", "rest")
#: the largest table rate (deg/s) and turn (deg) a step may ask for: beyond, the number or unit is wrong
MAX_RATE_DEG_S, MAX_ANGLE_DEG = 1e5, 1e5


def _table_axis(source: dict, default: str, where: str) -> str:
    """The table-axis direction of ``[test]`` or a step (a direction name, lower case)."""
    if "table_axis" not in source:
        return default
    direction(source["table_axis"], where)
    return str(source["table_axis"]).strip().lower()


def _rest(source: dict, default: tuple[str, str, str] | None, where: str) -> tuple[str, str, str] | None:
    """The rest orientation of ``[test]`` or a step: three directions, checked (perpendicular, right-handed)."""
    if "rest" not in source:
        return default
    rest_matrix(source["rest"], where)
    x, y, z = (str(d).strip().lower() for d in source["rest"])
    return x, y, z


def _step(item: dict, here: str, table_axis: str = "up", rest: tuple[str, str, str] | None = None) -> Step:
    """One ``[[step]]`` table; ``here`` names it ("plan.toml: step 3"); ``table_axis`` and ``rest`` the session's."""
    check_keys(item, STEP_KEYS, here)
    if "axis" not in item:
        raise InputError("missing 'axis' (e.g. axis = \"+x\")", here)
    axis, sign = parse_axis(item["axis"], here)
    has_rate, has_angle = "rate" in item, "angle" in item
    if has_rate == has_angle:
        raise InputError("give exactly one of 'rate' (e.g. \"100 deg/s\") or 'angle' (e.g. \"-360 deg\")", here)
    table_axis = _table_axis(item, table_axis, f"{here}.table_axis")
    rest = _rest(item, rest, f"{here}.rest")
    if rest is not None and rest_matrix(list(rest), here)[:, axis] @ direction(table_axis, here) * sign < 0.5:
        raise InputError(f"at rest system {axis_name(axis, sign)} points {_pointing(rest, axis, sign)}, not along the "
                         f"table axis ({table_axis}): the step's axis must point along the table's spin axis; check "
                         "'rest', 'table_axis' or 'axis'", here)
    if has_rate:
        rate = check_turn(parse_quantity(item["rate"], "angular_rate", f"{here}.rate"), "rate", f"{here}.rate")
        return Step(axis, sign, rate=rate, table_axis=table_axis, rest=rest)
    angle = check_turn(parse_quantity(item["angle"], "angle", f"{here}.angle"), "angle", f"{here}.angle")
    return Step(axis, sign, angle=angle, table_axis=table_axis, rest=rest)


_OPPOSITE = {"east": "west", "west": "east", "north": "south", "south": "north", "up": "down", "down": "up"}


def _pointing(rest: tuple[str, str, str], axis: int, sign: int) -> str:
    return rest[axis] if sign > 0 else _OPPOSITE[rest[axis]]


def check_turn(value: float, kind: str, where: str) -> float:
    """``value`` (rad/s for ``kind="rate"``, rad for ``"angle"``) when a table can turn by it.

    A step must turn the table (non-zero) within what a rate table does (at most
    :data:`MAX_RATE_DEG_S` deg/s or :data:`MAX_ANGLE_DEG` deg); ``where`` names
    the field ("plan.toml: step 3.rate") or the input (``"{rate}"``).
    """
    if not math.isfinite(value):
        raise InputError(f"{kind} is {value}, not a finite number", where)
    if value == 0:
        raise InputError(f"{kind} is zero; a step must turn the table", where)
    unit, most = ("deg/s", MAX_RATE_DEG_S * DEG_S) if kind == "rate" else ("deg", MAX_ANGLE_DEG * DEG)
    if not abs(value) <= most:
        raise InputError(f"{format_quantity(value, unit, 4)} is beyond any rate table (at most "
                         f"{format_quantity(most, unit, 6)}); check the number and its unit", where)
    return value


def _accuracy(test: dict, key: str, expect: str, default: str, where: str) -> float:
    """A finite, non-negative accuracy of ``[test]``."""
    value = parse_quantity(test.get(key, default), expect, f"{where}: test.{key}")
    if not math.isfinite(value) or value < 0:
        raise InputError(f"must be a finite accuracy, zero or more; got {literal(repr(test[key]))}", f"{where}: test.{key}")
    return value
