"""The rate-table test plan: the steps in the order they were run.

A step turns the table about one system axis, either at a constant signed
rate (``rate``, Eq 19-30) or through a signed angle (``angle``, Eq 31).
``axis = "-y"`` means the system's -y axis points along the table's spin axis;
a positive rate or angle is a right-handed turn about that axis.

Public names
------------
Step, Plan, parse_axis, axis_name
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.errors import InputError
from align.units import format_quantity, parse_quantity

_AXIS_INDEX = {"x": 0, "y": 1, "z": 2}


def parse_axis(text: str, where: str | None = None) -> tuple[int, int]:
    """``"+x"``, ``"-z"``, ``"y"`` -> (index 0..2, sign +1/-1)."""
    t = str(text).strip().lower()
    sign = -1 if t.startswith("-") else 1
    name = t.lstrip("+-")
    if name not in _AXIS_INDEX:
        raise InputError(f"axis '{text}' is not one of +x, -x, +y, -y, +z, -z", where)
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
    """

    axis: int
    sign: int
    rate: float | None = None
    angle: float | None = None

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
    def label(self) -> str:
        if self.rate is not None:
            return f"{axis_name(self.axis, self.sign)} at {format_quantity(self.rate, 'deg/s', 5)}"
        return f"{axis_name(self.axis, self.sign)} through {format_quantity(self.angle, 'deg', 5)}"


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
    """

    steps: tuple[Step, ...]
    latitude: float | None = None
    rate_accuracy: float = 0.0
    angle_accuracy: float = 0.0

    @property
    def kind(self) -> str:
        kinds = {s.kind for s in self.steps}
        return kinds.pop() if len(kinds) == 1 else "mixed"

    def axes_turned(self) -> set[int]:
        return {s.axis for s in self.steps}

    @classmethod
    def from_dict(cls, data: dict, where: str = "plan") -> Plan:
        """Build a plan from the parsed TOML (see module docstring)."""
        raw = data.get("step")
        if not isinstance(raw, list) or not raw:
            raise InputError("no [[step]] tables: list the table steps in the order they were run", where)
        steps = []
        for k, item in enumerate(raw, start=1):
            here = f"{where}: step {k}"
            if not isinstance(item, dict) or "axis" not in item:
                raise InputError("missing 'axis' (e.g. axis = \"+x\")", here)
            axis, sign = parse_axis(item["axis"], here)
            has_rate, has_angle = "rate" in item, "angle" in item
            if has_rate == has_angle:
                raise InputError("give exactly one of 'rate' (e.g. \"100 deg/s\") or 'angle' (e.g. \"-360 deg\")", here)
            if has_rate:
                value = parse_quantity(item["rate"], "angular_rate", f"{here}.rate")
                steps.append(Step(axis, sign, rate=value))
            else:
                value = parse_quantity(item["angle"], "angle", f"{here}.angle")
                steps.append(Step(axis, sign, angle=value))
            if value == 0:
                raise InputError("rate or angle is zero; a step must turn the table", here)
        test = data.get("test", {})
        if not isinstance(test, dict):
            raise InputError("[test] must be a table", where)
        lat = test.get("latitude")
        latitude = None if lat is None else parse_quantity(lat, "angle", f"{where}: test.latitude")
        if latitude is not None and abs(latitude) > np.pi / 2:
            raise InputError("latitude must lie within +/-90 deg", f"{where}: test.latitude")
        rate_acc = parse_quantity(test.get("rate_accuracy", "0 %"), "dimensionless", f"{where}: test.rate_accuracy")
        angle_acc = parse_quantity(test.get("angle_accuracy", "0 deg"), "angle", f"{where}: test.angle_accuracy")
        if rate_acc < 0 or angle_acc < 0:
            raise InputError("accuracies must not be negative", f"{where}: test")
        return cls(tuple(steps), latitude, rate_acc, angle_acc)

    def to_toml(self) -> str:
        """The plan as TOML text that :meth:`from_dict` reads back."""
        lines = []
        if self.latitude is not None or self.rate_accuracy or self.angle_accuracy:
            lines.append("[test]")
            if self.latitude is not None:
                lines.append(f'latitude = "{format_quantity(self.latitude, "deg", 10)}"')
            lines.append(f'rate_accuracy = "{format_quantity(self.rate_accuracy, "%", 10)}"')
            lines.append(f'angle_accuracy = "{format_quantity(self.angle_accuracy, "deg", 10)}"')
            lines.append("")
        for s in self.steps:
            lines.append("[[step]]")
            lines.append(f'axis = "{axis_name(s.axis, s.sign)}"')
            if s.rate is not None:
                lines.append(f'rate = "{format_quantity(s.rate, "deg/s", 12)}"')
            else:
                lines.append(f'angle = "{format_quantity(s.angle, "deg", 12)}"')
            lines.append("")
        return "\n".join(lines)

    @classmethod
    def standard_rate(cls, rate: float, latitude: float | None = None) -> Plan:
        """The six-dwell +/- rate plan about x, y, z (Eq 28-30); ``rate`` in rad/s."""
        steps = tuple(Step(a, 1, rate=r) for a in range(3) for r in (rate, -rate))
        return cls(steps, latitude)

    @classmethod
    def standard_angle(cls, angle: float) -> Plan:
        """Six turns, +/- ``angle`` (rad) about x, y, z (Eq 31)."""
        steps = tuple(Step(a, 1, angle=t) for a in range(3) for t in (angle, -angle))
        return cls(steps)
