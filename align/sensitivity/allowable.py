"""Allowable misalignment: how large each element may be before a manoeuvre's limit is reached.

Each of the nine elements of ``M`` (Eq 5-10) is raised alone until some output
of the manoeuvre reaches its limit: by Example 2's closed forms
``phi_max = asin(E / Theta)`` and ``psi_max = acos(1 - E / Theta)`` (Eq 11-13)
where they apply, otherwise by root finding on attitude propagation
(:mod:`align.sensitivity.propagation`). The smallest is the binding element; the
cone is the largest rigid mounting rotation, in any direction, that meets every
limit.

Result: :class:`Allowable` (``imu-align.allowable``), registered with
:mod:`align.results`; an allowable file keeps a ``[series]`` manoeuvre as a
summary without its samples.

Public names
------------
Allowable, allowable, deg_for_file, rad_from_file (the budget against it: :mod:`align.sensitivity.margins`)
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import field

import numpy as np

from align import CONVENTION
from align.errors import InputError
from align.results import Result
from align.sensitivity.manoeuvre import Manoeuvre
from align.sensitivity.propagation import closed_form_errors, output_errors
from align.sensitivity.symbolic import ELEMENTS, matrix_from_angles
from align.units import DEG

ALLOWABLE_CONVENTION = CONVENTION + "; M_ii = cos(psi_i), M_ij = sin(phi_ij) (Eq 5-10)"


def deg_for_file(v: float) -> float | None:
    """rad -> deg for a file; ``inf`` (unconstrained) as None."""
    return None if not math.isfinite(v) else v / DEG


def rad_from_file(v: float | None) -> float:
    """deg from a file -> rad; None (unconstrained) as ``inf``."""
    return math.inf if v is None else float(v) * DEG


def _series_summary(man: Manoeuvre) -> dict | None:
    """What an allowable file keeps of a ``[series]`` in place of its samples; None for ``[[rotation]]`` steps.

    ``samples`` (one more than the ``increments`` integrated between them), ``increments_sum_deg``
    (3,) and ``increments_sha256`` (rad, little-endian float64, row by row), which identifies the series.
    """
    if man.segments or len(man.increments) == 0:
        return None
    inc = np.ascontiguousarray(man.increments, dtype="<f8")
    return {"samples": len(inc) + 1, "increments": len(inc), "increments_sum_deg": (inc.sum(axis=0) / DEG).tolist(),
            "increments_sha256": hashlib.sha256(inc.tobytes()).hexdigest()}


class Allowable(Result, format="imu-align.allowable", convention=ALLOWABLE_CONVENTION):
    """Allowable misalignment per element of a manoeuvre.

    Attributes
    ----------
    allowable : dict
        Element (:data:`~align.sensitivity.symbolic.ELEMENTS`) -> largest size alone, rad (``inf``: never limited).
    method : dict
        Element -> "closed form" or "numeric (attitude propagation)".
    binding, binding_value : str, float
        The element with the smallest allowance, and that allowance, rad.
    cone, cone_direction : float, ndarray of shape (3,)
        Largest rigid mounting rotation, in any direction, meeting every limit, rad; the tightest one's unit axis.
    agreement : dict
        Closed form against attitude propagation at the binding element, deg (the file's ``agreement``).
    manoeuvre : Manoeuvre
        Its limits, rad; a ``[series]`` read back from a file has no increments (re-read its file to recompute).
    inputs : dict
        Where the inputs came from (set with ``replace(inputs=...)``).
    series : dict or None
        For a ``[series]``, the summary the file keeps in place of its samples (``samples``, ``increments``,
        ``increments_sum_deg``, ``increments_sha256``); None for ``[[rotation]]`` steps.
    """

    allowable: dict
    method: dict
    binding: str
    binding_value: float
    cone: float
    cone_direction: np.ndarray
    agreement: dict
    manoeuvre: Manoeuvre
    inputs: dict = field(default_factory=dict)
    series: dict | None = None

    def to_dict(self) -> dict:
        """The versioned JSON form, angles in deg (``None`` for unconstrained).

        Returns
        -------
        dict
            ``manoeuvre_detail`` is ``Manoeuvre.to_dict``; for a ``[series]``, ``series`` replaces ``increments_deg``.
        """
        return {
            **self.envelope({"angles": "deg"}),
            "manoeuvre": self.manoeuvre.description,
            "limits_deg": {k: v / DEG for k, v in self.manoeuvre.limits.items()},
            "allowable_deg": {k: deg_for_file(v) for k, v in self.allowable.items()},
            "method": dict(self.method), "binding": self.binding, "binding_deg": self.binding_value / DEG,
            "cone_deg": self.cone / DEG, "cone_worst_direction": self.cone_direction.tolist(),
            "agreement": self.agreement, "manoeuvre_detail": self._manoeuvre_detail(), "inputs": dict(self.inputs),
        }

    def _manoeuvre_detail(self) -> dict:
        """The manoeuvre's dictionary; a ``[series]`` summarised, its samples left out."""
        summary = self.series if self.series is not None else _series_summary(self.manoeuvre)
        if summary is None:
            return self.manoeuvre.to_dict()
        detail = self.manoeuvre.replace(increments=np.empty((0, 3))).to_dict()   # not the samples, even as a list
        return {**{k: v for k, v in detail.items() if k != "increments_deg"}, "series": dict(summary)}

    @classmethod
    def from_dict(cls, d: dict, where: str = "result") -> Allowable:
        """Read the form written by :meth:`to_dict` (InputError for another format, a newer version, a bad body).

        A ``[series]`` (summary in :attr:`series`) or an older file without ``manoeuvre_detail`` has no increments.

        Parameters
        ----------
        d : dict
            The parsed JSON.
        where : str
            Names the file in error messages.

        Returns
        -------
        Allowable
        """
        cls.check_envelope(d, where)
        try:
            detail = d.get("manoeuvre_detail")
            series = None if detail is None or detail.get("series") is None else dict(detail["series"])
            if detail is not None:   # a [series] without its samples: no increments
                man = Manoeuvre.from_dict(detail if series is None else {**detail, "increments_deg": []},
                                          f"{where}: manoeuvre_detail")
            else:
                man = Manoeuvre(np.empty((0, 3)), {k: rad_from_file(v) for k, v in d["limits_deg"].items()},
                                description=str(d["manoeuvre"]))
            return cls(
                allowable={k: rad_from_file(v) for k, v in d["allowable_deg"].items()},
                method=dict(d["method"]), binding=str(d["binding"]), binding_value=rad_from_file(d["binding_deg"]),
                cone=rad_from_file(d["cone_deg"]), cone_direction=np.array(d["cone_worst_direction"], float).reshape(3),
                agreement=dict(d["agreement"]), manoeuvre=man, inputs=dict(d.get("inputs", {})), series=series,
            )
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise InputError(f"malformed allowable result ({exc!r}); regenerate it with imu-align allowable",
                             where) from None


def _worst_ratio(man: Manoeuvre, m: np.ndarray) -> float:
    errs = output_errors(man, m)
    return max(errs[k] / man.limits[k] for k in man.limits)


def _closed_form(man: Manoeuvre, element: str) -> float | None:
    """Example 2's closed forms for one rotation about one axis and per-gyro limits (else None)."""
    if not man.fixed_axis or not set(man.limits) <= {"x", "y", "z"}:
        return None
    axis, theta = man.segments[0]
    theta = abs(theta)
    if theta >= np.pi:
        return None
    gyro, about = element[4], element[-1]          # psi_z: gyro z about z; phi_yz: gyro y about z
    if about != axis or gyro not in man.limits:
        return np.inf
    e = man.limits[gyro]
    if element.startswith("phi"):
        return float(np.arcsin(e / theta)) if e < theta else np.inf          # phi_max = asin(E / Theta)
    return float(np.arccos(1 - e / theta)) if e < theta else np.inf          # psi_max = acos(1 - E / Theta)


def allowable(man: Manoeuvre, directions: int = 200) -> Allowable:
    """Allowable size of each misalignment element alone, the binding one and the cone.

    Each element is raised alone (others zero) until some limit is reached:
    the closed forms ``asin(E / Theta)`` and ``acos(1 - E / Theta)`` (Example 2,
    from Eq 11-13) where they apply, otherwise numeric root finding (Brent) on
    attitude propagation, both signs, up to 90 deg (``inf`` when never reached).

    Parameters
    ----------
    man : Manoeuvre
        Body-frame increments (n, 3), rad, and the limits on its outputs (output name -> rad).
    directions : int
        Points on a sphere searched for the cone (the largest rigid mounting
        rotation, in any direction, that meets every limit).

    Returns
    -------
    Allowable
        Per element the allowance (rad) and how it was found; the binding element, the cone (rad).

    Examples
    --------
    The reference's Example 2 (a 30 deg heading change about z, y and z outputs within 1 deg each):
    ``phi_yz <= asin(1/30)`` binds, ``psi_z <= acos(29/30)``.

    >>> from align.sensitivity.manoeuvre import Manoeuvre
    >>> from align.units import DEG
    >>> man = Manoeuvre([[0, 0, 30 * DEG]], {"y": 1 * DEG, "z": 1 * DEG}, fixed_axis=True,
    ...                 segments=[("z", 30 * DEG)])
    >>> a = allowable(man, directions=50)
    >>> a.binding, round(a.binding_value / DEG, 4), round(a.allowable["psi_z"] / DEG, 3)
    ('phi_yz', 1.9102, 14.835)
    """
    from scipy.optimize import brentq

    limit = np.pi / 2
    allow, method = {}, {}
    for k, name in enumerate(ELEMENTS):
        cf = _closed_form(man, name)
        if cf is not None:
            allow[name], method[name] = cf, "closed form"
            continue
        best = np.inf
        for sign in (1.0, -1.0):
            def f(x, k=k, sign=sign):
                v = np.zeros(9)
                v[k] = sign * x
                return _worst_ratio(man, matrix_from_angles(v)) - 1.0
            if f(limit) > 0:
                best = min(best, brentq(f, 0.0, limit, xtol=1e-12))
        allow[name], method[name] = best, "numeric (attitude propagation)"
    binding = min(ELEMENTS, key=lambda e: allow[e])
    cone, direction = _cone(man, directions)
    agreement = _agreement(man, binding, allow[binding])
    return Allowable(allow, method, binding, allow[binding], cone, direction, agreement, man, series=_series_summary(man))


def _cone(man: Manoeuvre, n: int) -> tuple[float, np.ndarray]:
    """Largest rigid mounting rotation meeting every limit: Brent's root along each of ``n`` directions
    (a Fibonacci sphere), the worst direction then refined by Nelder-Mead."""
    from scipy.optimize import brentq, minimize
    from scipy.spatial.transform import Rotation

    top = np.pi / 2

    def root(d: np.ndarray, cap: float) -> float:
        d = d / np.linalg.norm(d)
        f = lambda x: _worst_ratio(man, Rotation.from_rotvec(d * x).as_matrix().T) - 1.0  # noqa: E731
        return brentq(f, 0.0, cap, xtol=1e-12) if f(cap) > 0 else cap

    i = np.arange(n) + 0.5
    polar, azim = np.arccos(1 - 2 * i / n), np.pi * (1 + 5**0.5) * i
    dirs = np.column_stack([np.cos(azim) * np.sin(polar), np.sin(azim) * np.sin(polar), np.cos(polar)])
    best, worst = top, dirs[0]
    for d in dirs:
        r = root(d, best)          # only directions tighter than the best so far need a root
        if r < best:
            best, worst = r, d
    if best >= top:
        return top, worst
    refined = minimize(lambda v: root(worst + v, top), np.zeros(3), method="Nelder-Mead",
                       options={"xatol": 1e-6, "fatol": 1e-12, "initial_simplex": np.eye(4, 3) * 0.05})
    if refined.fun < best:
        best, worst = float(refined.fun), (worst + refined.x) / np.linalg.norm(worst + refined.x)
    return best, worst


def _agreement(man: Manoeuvre, element: str, value: float) -> dict:
    """Closed form (Eq 11-13, summed over steps) against attitude propagation at the binding element."""
    v = {e: 0.0 for e in ELEMENTS}
    if np.isfinite(value):
        v[element] = value
    m = matrix_from_angles(v)
    closed = closed_form_errors(man, m)
    prop = output_errors(man, m, history=True)
    return {
        "element": element, "element_deg": deg_for_file(value),
        "closed_form_deg": dict(zip("xyz", (closed / DEG).tolist())),
        "propagated_deg": {a: float(prop[a][-1] / DEG) for a in "xyz"},
        "note": ("one fixed-axis rotation: Eq 11-13 is exact" if man.fixed_axis else
                 "rotations about changing axes do not integrate as Eq 11-13; the propagated values are the truth"),
    }
