"""Allowable misalignment: how large each element may be before a manoeuvre's limit is reached.

Each of the nine elements of ``M`` (Eq 5-10) is raised alone until some output
of the manoeuvre reaches its limit: by Example 2's closed forms
``phi_max = asin(E / Theta)`` and ``psi_max = acos(1 - E / Theta)`` (Eq 11-13)
where they apply, otherwise by root finding on attitude propagation
(:mod:`align.sensitivity.attitude`). The smallest is the binding element; the
cone is the largest rigid mounting rotation, in any direction, that meets every
limit. :func:`check_margins` sets a predicted budget against the allowance.

Results: :class:`Allowable` (``imu-align.allowable``) and :class:`MarginTable`
(``imu-align.check``), both registered with :mod:`align.results`.

Public names
------------
Allowable, allowable, Margin, margins, MarginTable, check_margins
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from align import CONVENTION
from align.errors import InputError
from align.results import Result
from align.sensitivity.attitude import closed_form_errors, output_errors
from align.sensitivity.manoeuvre import Manoeuvre
from align.sensitivity.symbolic import ELEMENTS, matrix_from_angles
from align.units import DEG
from align.values import Value

ALLOWABLE_CONVENTION = CONVENTION + "; M_ii = cos(psi_i), M_ij = sin(phi_ij) (Eq 5-10)"


def _deg(v: float) -> float | None:
    """rad -> deg for a file; ``inf`` (unconstrained) as None."""
    return None if not math.isfinite(v) else v / DEG


def _rad(v: float | None) -> float:
    """deg from a file -> rad; None (unconstrained) as ``inf``."""
    return math.inf if v is None else float(v) * DEG


class Allowable(Result, format="imu-align.allowable", convention=ALLOWABLE_CONVENTION):
    """Allowable misalignment per element of a manoeuvre.

    Attributes
    ----------
    allowable : dict
        Element (:data:`~align.sensitivity.symbolic.ELEMENTS`) -> largest size
        alone, rad; ``inf`` where no limit is ever reached.
    method : dict
        Element -> "closed form" or "numeric (attitude propagation)".
    binding : str
        The element with the smallest allowance.
    binding_value : float
        Its allowance, rad.
    cone : float
        Largest rigid mounting rotation in any direction meeting every limit, rad.
    cone_direction : ndarray, shape (3,)
        Unit axis of the tightest such rotation.
    agreement : dict
        Closed form against attitude propagation at the binding element, deg
        (the ``agreement`` of the file).
    manoeuvre : Manoeuvre
    inputs : dict
        Where the inputs came from (set with ``replace(inputs=...)``).
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

    def to_dict(self) -> dict:
        """The versioned JSON form, angles in deg (``None`` for unconstrained)."""
        return {
            **self.envelope({"angles": "deg"}),
            "manoeuvre": self.manoeuvre.description,
            "limits_deg": {k: v / DEG for k, v in self.manoeuvre.limits.items()},
            "allowable_deg": {k: _deg(v) for k, v in self.allowable.items()},
            "method": dict(self.method),
            "binding": self.binding,
            "binding_deg": self.binding_value / DEG,
            "cone_deg": self.cone / DEG,
            "cone_worst_direction": self.cone_direction.tolist(),
            "agreement": self.agreement,
            "manoeuvre_detail": self.manoeuvre.to_dict(),
            "inputs": dict(self.inputs),
        }

    @classmethod
    def from_dict(cls, d: dict, where: str = "result") -> Allowable:
        """Read the form written by :meth:`to_dict`.

        A file without ``manoeuvre_detail`` (written before it existed) gives a
        manoeuvre with its description and limits but no increments.
        """
        cls.check_envelope(d, where)
        try:
            if "manoeuvre_detail" in d:
                man = Manoeuvre.from_dict(d["manoeuvre_detail"], f"{where}: manoeuvre_detail")
            else:
                man = Manoeuvre(np.empty((0, 3)), {k: _rad(v) for k, v in d["limits_deg"].items()},
                                description=str(d["manoeuvre"]))
            return cls(
                allowable={k: _rad(v) for k, v in d["allowable_deg"].items()},
                method=dict(d["method"]), binding=str(d["binding"]), binding_value=_rad(d["binding_deg"]),
                cone=_rad(d["cone_deg"]), cone_direction=np.array(d["cone_worst_direction"], float).reshape(3),
                agreement=dict(d["agreement"]), manoeuvre=man, inputs=dict(d.get("inputs", {})),
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
    attitude propagation, both signs, up to 90 deg (``inf`` when never
    reached).

    Parameters
    ----------
    man : Manoeuvre
    directions : int
        Points on a sphere searched for the cone (the largest rigid mounting
        rotation, in any direction, that meets every limit).

    Returns
    -------
    Allowable
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
    return Allowable(allow, method, binding, allow[binding], cone, direction, agreement, man)


def _cone(man: Manoeuvre, n: int) -> tuple[float, np.ndarray]:
    """Largest rotation angle of a rigid mounting rotation, in any direction, meeting every limit.

    The root along each of ``n`` directions (a Fibonacci sphere) is found by
    Brent's method, then the worst direction is refined by Nelder-Mead.
    """
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
        "element": element, "element_deg": _deg(value),
        "closed_form_deg": dict(zip("xyz", (closed / DEG).tolist())),
        "propagated_deg": {a: float(prop[a][-1] / DEG) for a in "xyz"},
        "note": ("one fixed-axis rotation: Eq 11-13 is exact" if man.fixed_axis else
                 "rotations about changing axes do not integrate as Eq 11-13; the propagated values are the truth"),
    }


@dataclass(frozen=True, eq=False)
class Margin(Value):
    """One element of the budget-versus-allowance check.

    Attributes
    ----------
    element : str
    predicted : float
        The budget's figure for the element, rad.
    allowed : float
        The allowance, rad (``inf``: unconstrained).
    """

    element: str
    predicted: float
    allowed: float

    @property
    def margin(self) -> float:
        """``allowed - predicted``, rad."""
        return self.allowed - self.predicted

    @property
    def ok(self) -> bool:
        return self.predicted <= self.allowed


def margins(predicted: dict, allow: Allowable) -> list[Margin]:
    """Element by element: the predicted misalignment (rad) against the allowable one."""
    missing = [e for e in ELEMENTS if e not in predicted]
    if missing:
        raise ValueError(f"no prediction for {missing}")
    return [Margin(e, float(predicted[e]), float(allow.allowable[e])) for e in ELEMENTS]


class MarginTable(Result, format="imu-align.check", convention=CONVENTION):
    """The budget against the allowance, element by element (iterates over its rows).

    Attributes
    ----------
    basis : str
        Which budget figure was compared ("rss" or "worst").
    rows : tuple of Margin
        One per element, in :data:`~align.sensitivity.symbolic.ELEMENTS` order.
    inputs : dict
    """

    basis: str
    rows: tuple[Margin, ...]
    inputs: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "rows", tuple(self.rows))
        super().__post_init__()

    def __iter__(self):
        return iter(self.rows)

    def __len__(self) -> int:
        return len(self.rows)

    @property
    def passed(self) -> bool:
        """Every element within its allowance."""
        return all(r.ok for r in self.rows)

    @property
    def failed(self) -> list[str]:
        """The elements over their allowance."""
        return [r.element for r in self.rows if not r.ok]

    def to_dict(self) -> dict:
        """The versioned JSON form, angles in deg (``None`` for unconstrained)."""
        return {
            **self.envelope({"angles": "deg"}),
            "basis": self.basis, "pass": self.passed,
            "elements": [{"element": r.element, "predicted_deg": r.predicted / DEG, "allowed_deg": _deg(r.allowed),
                          "margin_deg": _deg(r.margin), "pass": r.ok} for r in self.rows],
            "inputs": dict(self.inputs),
        }

    @classmethod
    def from_dict(cls, d: dict, where: str = "result") -> MarginTable:
        """Read the form written by :meth:`to_dict`."""
        cls.check_envelope(d, where)
        try:
            rows = tuple(Margin(str(r["element"]), _rad(r["predicted_deg"]), _rad(r["allowed_deg"]))
                         for r in d["elements"])
            return cls(str(d["basis"]), rows, dict(d.get("inputs", {})))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"malformed check result ({exc!r}); regenerate it with imu-align check", where) from None


def check_margins(budget_elements: dict, allow: Allowable, basis: str) -> MarginTable:
    """The predicted budget against the allowance, element by element.

    Parameters
    ----------
    budget_elements : dict
        Element -> predicted size, rad (``mechanics.budget.Budget.elements(basis)``).
    allow : Allowable
    basis : str
        The budget figure the prediction is ("rss" or "worst"), recorded in the table.

    Returns
    -------
    MarginTable
    """
    return MarginTable(basis, tuple(margins(budget_elements, allow)))
