"""``--mounting``: the nominal mounting of an IMU in the system, as a signed axis list or a rotation.

``'+y,-x,+z'`` (the system axis each gyro x, y, z points along) or ``'30 deg about +z'``; used by
``simulate session`` and ``calibrate gyro``.

Public names
------------
MountingOption, parse_mounting_option
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

_MOUNTING_ADVICE = ("give the system axis of gyros x, y, z, e.g. '+y,-x,+z', or a rotation, e.g. '30 deg about +z' "
                    "or '30 deg about 1,1,0'")
_SIGNED_AXIS = re.compile(r"^[+-]?[xyz]$")


@dataclass(frozen=True)
class MountingOption:
    """A parsed ``--mounting``: the nominal mounting ``N`` (rows: each gyro's axis in the system frame).

    Attributes
    ----------
    rows : tuple of 3 tuples of 3 float
    text : str
        As typed.
    """

    rows: tuple[tuple[float, float, float], ...]
    text: str


def _unit_axis(text: str) -> tuple[float, float, float]:
    """``'+z'`` or ``'1,1,0'`` (commas or spaces) -> a unit vector; ValueError otherwise."""
    t = text.strip().lower()
    if _SIGNED_AXIS.match(t):
        v = [0.0, 0.0, 0.0]
        v["xyz".index(t[-1])] = -1.0 if t.startswith("-") else 1.0
        return v[0], v[1], v[2]
    parts = [p for p in re.split(r"[\s,]+", t.strip("()[] ")) if p]
    try:
        v = [float(p) for p in parts]
    except ValueError:
        raise ValueError(_MOUNTING_ADVICE) from None
    norm = math.sqrt(sum(x * x for x in v)) if len(v) == 3 else 0.0
    if not (math.isfinite(norm) and norm > 0):
        raise ValueError(f"the axis must be +x ... -z or three numbers not all 0; {_MOUNTING_ADVICE}")
    return v[0] / norm, v[1] / norm, v[2] / norm


def _rotation_rows(angle: float, axis: tuple[float, float, float]) -> tuple[tuple[float, float, float], ...]:
    """``N = Rot(axis, angle)^T`` (:func:`align.alignment.simulate.mounting_from_rotation`) as rows."""
    from align.alignment.simulate import mounting_from_rotation

    rows = mounting_from_rotation(angle, axis)
    return tuple((float(r[0]), float(r[1]), float(r[2])) for r in rows)


def parse_mounting_option(text: str) -> MountingOption:
    """``'+y,-x,+z'`` (the system axis of gyros x, y, z) or ``'<angle> about <axis>'`` (``'30 deg about +z'``,
    ``'30 deg about 1,1,0'``: the IMU turned by the angle about the axis) -> :class:`MountingOption`."""
    if isinstance(text, MountingOption):
        return text
    raw = str(text).strip()
    head, about, tail = raw.partition(" about ")
    if about:
        from align.errors import AlignError
        from align.units import parse_quantity

        try:
            angle = parse_quantity(head, "angle")
        except AlignError:
            raise ValueError(f"'{head.strip()}' is not an angle; {_MOUNTING_ADVICE}") from None
        if not math.isfinite(angle):
            raise ValueError(_MOUNTING_ADVICE)
        return MountingOption(_rotation_rows(angle, _unit_axis(tail)), raw)
    parts = [p for p in re.split(r"[\s,]+", raw.strip("()[] ")) if p]
    if len(parts) != 3 or not all(_SIGNED_AXIS.match(p.lower()) for p in parts):
        raise ValueError(_MOUNTING_ADVICE)
    rows = tuple(_unit_axis(p) for p in parts)
    if sorted(p.lower().lstrip("+-") for p in parts) != ["x", "y", "z"]:
        raise ValueError(f"'{raw}': two gyros along one system axis; each gyro needs its own axis")
    det = (rows[0][0] * (rows[1][1] * rows[2][2] - rows[1][2] * rows[2][1])
           - rows[0][1] * (rows[1][0] * rows[2][2] - rows[1][2] * rows[2][0])
           + rows[0][2] * (rows[1][0] * rows[2][1] - rows[1][1] * rows[2][0]))
    if det < 0:
        raise ValueError(f"'{raw}' is a mirrored (left-handed) set: a mounting turns the gyros, it cannot mirror "
                         "them; check the signs")
    return MountingOption(rows, raw)
