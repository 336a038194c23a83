"""Manoeuvres: the rotations a requirement is stated for, and the limits on its outputs.

A manoeuvre is read from TOML (see README): a list of fixed-axis rotations
``[[rotation]] axis, angle`` or a ``[series]`` rate file, and ``[limits]``, the
largest error allowed on each limited output (see
:data:`~align.sensitivity.symbolic.OUTPUTS`). Inside it is a sequence of
body-frame rotation increments (rotation vectors, rad).

Public names
------------
Manoeuvre, manoeuvre_from_dict, manoeuvre_inputs, MANOEUVRE_KEYS, ROTATION_KEYS, SERIES_KEYS
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from align.errors import InputError, literal
from align.io.keys import check_keys, file_name, referenced_file, table, tables
from align.sensitivity.symbolic import AXIS_INDEX, OUTPUTS
from align.units import DEG, parse_quantity, parse_unit
from align.values import Value


@dataclass(frozen=True, eq=False)
class Manoeuvre(Value):
    """A manoeuvre: body-frame rotation increments and the limits on outputs.

    Attributes
    ----------
    increments : ndarray, shape (n, 3)
        True body-frame rotation vector of each step (a fixed-axis rotation is
        one step), rad.
    limits : dict
        Output name -> largest allowed error, rad.
    fixed_axis : bool
        True when the manoeuvre is one rotation about one coordinate axis (the
        closed forms of Example 2 apply).
    description : str
    segments : tuple of (str, float)
        The ``[[rotation]]`` steps as (axis, signed angle in rad); empty for a
        rate series.
    """

    increments: np.ndarray
    limits: dict
    fixed_axis: bool = False
    description: str = ""
    segments: tuple = field(default_factory=tuple)

    def __post_init__(self) -> None:
        object.__setattr__(self, "increments", np.asarray(self.increments, dtype=float).reshape(-1, 3))
        object.__setattr__(self, "segments", tuple((str(a), float(v)) for a, v in self.segments))
        super().__post_init__()

    def to_dict(self) -> dict:
        """The manoeuvre in degrees (the ``manoeuvre_detail`` of an allowable result)."""
        return {
            "description": self.description,
            "limits_deg": {k: v / DEG for k, v in self.limits.items()},
            "fixed_axis": self.fixed_axis,
            "segments": [{"axis": a, "angle_deg": v / DEG} for a, v in self.segments],
            "increments_deg": (self.increments / DEG).tolist(),
        }

    @classmethod
    def from_dict(cls, d: dict, where: str = "manoeuvre") -> Manoeuvre:
        """Read the form written by :meth:`to_dict`."""
        try:
            return cls(np.array(d["increments_deg"], dtype=float).reshape(-1, 3) * DEG,
                       {k: float(v) * DEG for k, v in d["limits_deg"].items()}, bool(d["fixed_axis"]),
                       str(d.get("description", "")),
                       tuple((s["axis"], float(s["angle_deg"]) * DEG) for s in d.get("segments", [])))
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise InputError(f"malformed manoeuvre ({literal(repr(exc))})", where) from None


#: the tables of a manoeuvre file and the keys of each (``[limits]``: the outputs, see ``OUTPUTS``)
MANOEUVRE_KEYS = ("rotation", "series", "limits")
ROTATION_KEYS = ("axis", "angle")
SERIES_KEYS = ("file", "columns", "units", "time_units")
#: the largest turn (deg) one [[rotation]] may give: beyond, the number or its unit is wrong
MAX_ANGLE_DEG = 1e5


def _limits(data: dict, where: str) -> dict:
    limits_t = table(data, "limits", where)
    if not limits_t:
        raise InputError("missing [limits]: the largest allowed error of each gyro (x, y, z) or output angle", where)
    check_keys(limits_t, OUTPUTS, f"{where}: [limits]")
    limits = {}
    for name, value in limits_t.items():
        limits[name] = parse_quantity(value, "angle", f"{where}: limits.{name}")
        if not limits[name] > 0:
            raise InputError("a limit must be positive", f"{where}: limits.{name}")
    return limits


def manoeuvre_from_dict(data: dict, where: str = "manoeuvre", base_dir: str | Path | None = None) -> Manoeuvre:
    """Read a manoeuvre (``[[rotation]]`` list or ``[series]`` rate file, and ``[limits]``).

    Unknown tables and keys are refused (:data:`MANOEUVRE_KEYS`, :data:`ROTATION_KEYS`,
    :data:`SERIES_KEYS`, the outputs in ``[limits]``); a rotation's angle must be
    non-zero, a limit positive, the series' ``units`` an angular rate.

    Parameters
    ----------
    data : dict
        Parsed TOML.
    where : str
        Names the source in errors (the file).
    base_dir : str or Path, optional
        Folder a relative ``series.file`` is read from.

    Returns
    -------
    Manoeuvre
    """
    check_keys(data, MANOEUVRE_KEYS, where)
    limits = _limits(data, where)
    rotations, series = tables(data, "rotation", where), table(data, "series", where)
    if rotations and series:
        raise InputError("give [[rotation]] steps or a [series], not both", where)
    if series:
        return _series(series, limits, where, base_dir)
    if not rotations:
        raise InputError("no [[rotation]] (axis, angle) and no [series]: nothing to analyse", where)
    inc, segs = [], []
    for k, r in enumerate(rotations, start=1):
        here = f"{where}: rotation {k}"
        check_keys(r, ROTATION_KEYS, here)
        if "axis" not in r or "angle" not in r:
            raise InputError("needs axis (x, y or z) and angle", here)
        axis = str(r["axis"]).strip().lower()
        sign = -1.0 if axis.startswith("-") else 1.0
        if axis.lstrip("+-") not in AXIS_INDEX:
            raise InputError(f"axis '{literal(r['axis'])}' is not x, y or z", f"{here}.axis")
        angle = parse_quantity(r["angle"], "angle", f"{here}.angle")
        if angle == 0:
            raise InputError("angle is zero", f"{here}.angle")
        if abs(angle) > MAX_ANGLE_DEG * DEG:
            raise InputError(f"{angle / DEG:.4g} deg is beyond any manoeuvre (at most {MAX_ANGLE_DEG:g} deg); "
                             "check the number and its unit", f"{here}.angle")
        u = np.zeros(3)
        u[AXIS_INDEX[axis.lstrip('+-')]] = sign
        inc.append(angle * u)
        segs.append((axis.lstrip("+-"), sign * angle))
    fixed = len(inc) == 1
    desc = "; ".join(f"{a} {v / DEG:+g} deg" for a, v in segs)
    return Manoeuvre(np.array(inc), limits, fixed, desc, tuple(segs))


def manoeuvre_inputs(data: dict, base_dir: str | Path | None = None) -> list[Path]:
    """The data files a manoeuvre file reads (its ``[series]`` file), resolved as the reader resolves them.

    For output checks before any work: an output must not overwrite one of these.
    Nothing is validated here (an unusable file is refused by :func:`manoeuvre_from_dict`).
    """
    return [p for p in [referenced_file(data, "series", "file", base_dir)] if p is not None]


def _series_columns(series: dict, where: str) -> list[str]:
    """``columns`` of ``[series]``: "time,wx,wy,wz" or a list of four names."""
    raw = series.get("columns", "time,wx,wy,wz")
    if isinstance(raw, str):
        cols = [c.strip() for c in raw.split(",")]
    elif isinstance(raw, list) and all(isinstance(c, str) for c in raw):
        cols = [c.strip() for c in raw]
    else:
        cols = []
    if len(cols) != 4 or not all(cols):
        raise InputError(f"columns must name time and three rates (e.g. \"time,wx,wy,wz\"), got {literal(repr(raw))}",
                         f"{where}: series.columns")
    return cols


def _series(series: dict, limits: dict, where: str, base_dir) -> Manoeuvre:
    """A ``[series]`` of body rates, integrated by the trapezoid rule into increments."""
    from align.io import LogFormat, check_log, check_time, read_log

    check_keys(series, SERIES_KEYS, f"{where}: [series]")
    path = file_name(series, "file", f"{where}: series.file", "rates.csv", base_dir)
    cols = _series_columns(series, where)
    units = series.get("units", "deg/s")
    if not isinstance(units, str):
        raise InputError(f"expected a unit string (units = \"rad/s\"), got {literal(repr(units))}", f"{where}: series.units")
    parse_unit(units, "angular_rate", f"{where}: series.units")
    time_units = series.get("time_units", "s")  # stated, not detected: a slow trajectory is no IMU log
    if time_units not in ("s", "ms", "us", "ns"):
        raise InputError(f"expected one of s, ms, us, ns, got {literal(repr(time_units))}", f"{where}: series.time_units")
    t, w = read_log(path, cols[1:], units, cols[0], log_format=LogFormat(time_units=time_units))
    check_log(t, w, str(path), min_rows=2)
    check_time(t, str(path), gap=1.5)
    inc = 0.5 * (w[1:] + w[:-1]) * np.diff(t)[:, None]   # trapezoid increments
    return Manoeuvre(inc, limits, False, f"rate series {path.name}: {len(t)} samples, {t[-1] - t[0]:.4g} s")
