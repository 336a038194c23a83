"""The positions file of an accelerometer session: its keys, its ``[[position]]`` tables, checked.

A positions file (TOML) holds an optional ``gravity`` and one ``[[position]]``
table per static position: ``up`` (``"+x"`` or a vector ``[x, y, z]`` in the
sensor frame: the axis pointing up, on which the accelerometer reads ``+g``),
optional ``name``, ``start``/``end`` (samples, end exclusive; for every
position or for none) and ``holdout`` (left out of the fit and used as a
check). Unknown keys are refused with the nearest valid one; a file without
positions is refused rather than read as "no positions" (which would switch
to the ``|a| = g`` fit).

Public names
------------
Position, parse_positions, positions_of, FILE_KEYS, POSITION_KEYS
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.alignment.plan import parse_axis
from align.errors import InputError, literal
from align.io.keys import check_keys, tables

#: the top-level keys of a positions file
FILE_KEYS = ("gravity", "position")
#: the keys of a ``[[position]]`` table
POSITION_KEYS = ("name", "up", "start", "end", "holdout")


@dataclass(frozen=True)
class Position:
    """One static position: its name, the unit vector pointing up (sensor frame, shape (3,)),
    its sample range (``start, end``, end exclusive) or None, and whether it is held out."""

    name: str
    up: np.ndarray
    samples: tuple[int, int] | None
    holdout: bool


def positions_of(spec: dict, where: str) -> list:
    """The ``[[position]]`` tables of a parsed positions file, its keys checked; never empty.

    Raises
    ------
    InputError
        An unknown top-level key, ``[position]`` written for ``[[position]]``, or no positions at all.
    """
    if not isinstance(spec, dict):
        raise InputError("a positions file holds gravity and [[position]] tables", where)
    check_keys(spec, FILE_KEYS, where)
    found = tables(spec, "position", where)
    if not found:
        raise InputError("no [[position]] tables: list the static positions (up = \"+x\", ...), or give no positions "
                         "file for the |a| = g fit over unknown attitudes", where)
    return found


def _up(up: object, where: str) -> np.ndarray:
    if isinstance(up, str):
        axis, sign = parse_axis(up, where)
        u = np.zeros(3)
        u[axis] = sign
        return u
    if isinstance(up, list) and len(up) == 3 and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in up):
        u = np.asarray(up, float)
        norm = float(np.linalg.norm(u))
        if np.all(np.isfinite(u)) and norm > 0:
            return u / norm
    raise InputError("up must be an axis ('+x') or a non-zero vector [x, y, z]", where)


def _sample(value: object, key: str, where: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise InputError(f"{key} must be a sample number (an integer >= 0), not {literal(repr(value))}", where)
    return value


def parse_positions(positions: list, where: str) -> list[Position]:
    """The ``[[position]]`` tables as :class:`Position` values.

    Parameters
    ----------
    positions : list of dict
        The tables, as read from the file.
    where : str
        The positions file, for errors.

    Raises
    ------
    InputError
        No positions, an unknown key (the nearest valid key named), a bad ``up``, a
        ``start`` without ``end``, ranges for some positions only, two positions of one name.
    """
    if not isinstance(positions, list) or not positions:
        raise InputError("no [[position]] tables", where)
    out: list[Position] = []
    for k, p in enumerate(positions, start=1):
        at = f"{where}: position {k}"
        if not isinstance(p, dict):
            raise InputError("each position must be a [[position]] table", at)
        check_keys(p, POSITION_KEYS, at)
        name = p.get("name", f"position {k}")
        if not isinstance(name, str) or not name.strip():
            raise InputError("name must be a non-empty text", at)
        if any(q.name == name for q in out):
            raise InputError(f"two positions are named '{literal(name)}': give each its own name", at)
        if ("start" in p) != ("end" in p):
            raise InputError("give both start and end (samples, end exclusive), or neither", at)
        samples = None
        if "start" in p:
            samples = (_sample(p["start"], "start", at), _sample(p["end"], "end", at))
            if samples[1] <= samples[0]:
                raise InputError(f"end {samples[1]} must be after start {samples[0]}", at)
        holdout = p.get("holdout", False)
        if not isinstance(holdout, bool):
            raise InputError("holdout must be true or false", at)
        out.append(Position(name, _up(p.get("up"), f"{where}: {name}.up"), samples, holdout))
    given = [q.samples is not None for q in out]
    if any(given) and not all(given):
        raise InputError("give start/end for every position or for none (automatic detection)", where)
    return out
