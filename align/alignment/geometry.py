"""Geometry of a rate-table session: the local level frame, the table axis, rest orientations, the mounting.

Frames
------
* local level frame: east, north, up (ENU); the table's spin axis and the system axes at rest are
  named by directions of it (``"up"``, ``"north"``, ...);
* system frame: the axes the plan's steps name (``+x``, ``-y``, ...);
* gyro frame: the sensitive axes, rows of ``M`` (``g = M w + b``).

The *nominal mounting* ``N`` (3, 3) holds, in its rows, each gyro's nominal sensitive axis in the
system frame, so that an ideal IMU reads ``g = N w``; it is a rotation (``det N = +1``). ``M N^T``
is then the misalignment relative to the nominal mounting (near the identity).

Public names
------------
DIRECTIONS, direction, rest_matrix, parse_mounting, mounting_axes, mounting_label, is_signed_permutation,
SIGNED_PERMUTATIONS, MOUNTING_KEYS
"""

from __future__ import annotations

import itertools

import numpy as np

from align.errors import InputError, literal
from align.io.keys import check_keys
from align.model import nearest_rotation

#: unit vectors of the local level frame (east, north, up)
DIRECTIONS = {"east": (1.0, 0.0, 0.0), "west": (-1.0, 0.0, 0.0), "north": (0.0, 1.0, 0.0),
              "south": (0.0, -1.0, 0.0), "up": (0.0, 0.0, 1.0), "down": (0.0, 0.0, -1.0)}

#: the keys of a plan's ``[mounting]`` table (one of the two)
MOUNTING_KEYS = ("axes", "matrix")

_AXES = {"+x": (0, 1), "x": (0, 1), "-x": (0, -1), "+y": (1, 1), "y": (1, 1), "-y": (1, -1),
         "+z": (2, 1), "z": (2, 1), "-z": (2, -1)}


def direction(name: object, where: str) -> np.ndarray:
    """The unit vector (ENU) of a direction name (``"up"``, ``"east"``, ...), refused naming ``where``."""
    key = str(name).strip().lower()
    if key not in DIRECTIONS:
        raise InputError(f"'{literal(str(name))}' is not a direction; use one of {', '.join(DIRECTIONS)}", where)
    return np.array(DIRECTIONS[key])


def rest_matrix(names: object, where: str) -> np.ndarray:
    """Where the system axes point at rest, as the matrix ``C`` (3, 3) whose columns are the system x, y, z axes in
    ENU (``w_local = C w_system``).

    ``names`` is a list of three directions (``["north", "west", "up"]``: system x points north, ...); they must be
    perpendicular and right-handed.
    """
    if not isinstance(names, (list, tuple)) or len(names) != 3:
        raise InputError(f"must list where system x, y and z point, e.g. [\"north\", \"west\", \"up\"]; got "
                         f"{literal(repr(names))}", where)
    c = np.column_stack([direction(n, where) for n in names])
    if abs(np.linalg.det(c)) < 0.5:
        raise InputError(f"{literal(', '.join(map(str, names)))}: two system axes point the same way or opposite; give "
                         "three perpendicular directions", where)
    if np.linalg.det(c) < 0:
        raise InputError(f"{literal(', '.join(map(str, names)))} is a left-handed set (x cross y must point along z); "
                         "check the directions", where)
    return c


def _axes_matrix(axes: object, where: str) -> np.ndarray:
    if not isinstance(axes, (list, tuple)) or len(axes) != 3:
        raise InputError(f"must list the system axis of gyros x, y and z, e.g. [\"+y\", \"-x\", \"+z\"]; got "
                         f"{literal(repr(axes))}", where)
    n = np.zeros((3, 3))
    for i, text in enumerate(axes):
        key = str(text).strip().lower()
        if key not in _AXES:
            raise InputError(f"'{literal(str(text))}' is not one of +x, -x, +y, -y, +z, -z", where)
        col, sign = _AXES[key]
        n[i, col] = sign
    if abs(np.linalg.det(n)) < 0.5:
        raise InputError(f"{literal(', '.join(map(str, axes)))}: two gyros along one system axis; each gyro needs its "
                         "own axis", where)
    return n


def parse_mounting(table: dict, where: str) -> np.ndarray:
    """The nominal mounting ``N`` (3, 3) of a plan's ``[mounting]`` table (see the module docstring).

    ``axes = ["+y", "-x", "+z"]``: the system axis each gyro (x, y, z in order) points along; or
    ``matrix = [[...], [...], [...]]``: each gyro's nominal axis as a unit vector (rows) in the system frame,
    orthonormal within 5e-3 (then made exactly orthonormal). A mirrored set (``det = -1``) is refused.
    """
    check_keys(table, MOUNTING_KEYS, where)
    if ("axes" in table) == ("matrix" in table):
        raise InputError("give exactly one of 'axes' (e.g. [\"+y\", \"-x\", \"+z\"]) or 'matrix' (rows: each gyro's "
                         "axis in the system frame)", where)
    if "axes" in table:
        n = _axes_matrix(table["axes"], f"{where}.axes")
        here = f"{where}.axes"
    else:
        here = f"{where}.matrix"
        parsed: np.ndarray | None
        try:
            parsed = np.array(table["matrix"], dtype=float)
        except (TypeError, ValueError):
            parsed = None
        if parsed is None or parsed.shape != (3, 3) or not np.isfinite(parsed).all():
            raise InputError("must be three rows of three numbers, e.g. [[0.866, 0.5, 0], [-0.5, 0.866, 0], [0, 0, 1]]",
                             here)
        n = parsed
        off = float(np.abs(n @ n.T - np.eye(3)).max())
        if off > 5e-3:  # rounded entries (0.866, 0.5) pass; the nearest rotation is then used
            raise InputError(f"the rows are not perpendicular unit vectors (N N^T differs from the identity by {off:.2g}); "
                             "give each gyro's nominal axis as a unit vector", here)
    if np.linalg.det(n) < 0:
        raise InputError("a mirrored (left-handed) set: a mounting turns the gyros, it cannot mirror them; check the "
                         "signs", here)
    return nearest_rotation(n)


def is_signed_permutation(n: np.ndarray, tol: float = 1e-9) -> bool:
    """Whether every row of ``n`` is a signed system axis (a mounting of 90/180 deg turns)."""
    return bool(np.all(np.abs(np.abs(n).max(axis=1) - 1) < tol) and np.allclose(np.abs(n).sum(axis=1), 1, atol=tol))


#: the 24 proper rotations that map system axes onto system axes (det +1), identity first
SIGNED_PERMUTATIONS = tuple(
    m for m in (
        np.eye(3)[list(p)] * np.array(s)[:, None]
        for p in itertools.permutations(range(3)) for s in itertools.product((1, -1), repeat=3)
    ) if np.linalg.det(m) > 0
)


def mounting_axes(n: np.ndarray) -> list[str] | None:
    """``["+y", "-x", "+z"]`` for a signed-permutation mounting (the form ``[mounting] axes`` reads), else None."""
    if not is_signed_permutation(n, 1e-6):
        return None
    out = []
    for row in n:
        j = int(np.argmax(np.abs(row)))
        out.append(("+" if row[j] > 0 else "-") + "xyz"[j])
    return out


def mounting_label(n: np.ndarray) -> str:
    """``"gyro x along system +y, gyro y along -x, gyro z along +z"``, or the rows' vectors for another rotation."""
    axes = mounting_axes(n)
    if axes is None:
        rows = "; ".join(f"gyro {'xyz'[i]} along ({', '.join(f'{v:+.4f}' for v in n[i])})" for i in range(3))
        return rows + " in the system frame"
    return ", ".join(f"gyro {g} along {'system ' if k == 0 else ''}{a}" for k, (g, a) in enumerate(zip("xyz", axes)))
