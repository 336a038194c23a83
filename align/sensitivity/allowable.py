"""Sensitivity: what misalignment does to a manoeuvre, and how much a requirement allows.

The response of misaligned gyros to a rotation ``w`` is ``g = M w`` with ``M``
written in angles (Eq 5-10)::

    g_x = w_x cos(psi_x) + w_y sin(phi_xy) + w_z sin(phi_xz)     (and likewise y, z)

and for a rotation about a fixed axis the integrated outputs obey the same
matrix, ``theta_G = M theta`` (Eq 11-13). sympy derives the response and its
Jacobian with respect to each angle (:func:`symbolic`); numbers come from the
lambdified forms. Manoeuvres that are sequences or rate time series are
propagated as attitude (quaternions, scipy's convention) with the true and the
misaligned rates, and compared.

Outputs a requirement can limit: ``x``, ``y``, ``z`` (each gyro's integrated
angle: the rotation vector of the attitude the gyros report minus the true one;
for a fixed-axis rotation exactly ``(M - I) theta``, Eq 11-13) and ``azimuth``,
``elevation``, ``roll`` (Z-Y-X Euler angles of the reported attitude minus the true).

Public names
------------
ELEMENTS, OUTPUTS, symbolic, symbolic_text, matrix_from_angles, response,
sensitivity, Manoeuvre, manoeuvre_from_dict, output_errors, closed_form_errors, Allowable,
allowable, Margin, margins
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from align.errors import InputError
from align.units import DEG, parse_quantity

ELEMENTS = ("psi_x", "psi_y", "psi_z", "phi_xy", "phi_xz", "phi_yx", "phi_yz", "phi_zx", "phi_zy")
OUTPUTS = ("x", "y", "z", "azimuth", "elevation", "roll")
_AX = {"x": 0, "y": 1, "z": 2}


@dataclass(frozen=True)
class Symbolic:
    """The sympy model: ``M`` in angles, ``g = M w``, ``theta_G = M theta`` and the Jacobians."""

    angles: tuple
    w: object
    theta: object
    M: object
    g: object
    theta_G: object
    jacobian: object


@lru_cache(maxsize=1)
def symbolic() -> Symbolic:
    """Derive Eq 5-13 and their sensitivities with sympy (cached)."""
    import sympy as sp

    ang = sp.symbols(" ".join(ELEMENTS), real=True)
    a = dict(zip(ELEMENTS, ang))
    w = sp.Matrix(sp.symbols("omega_x omega_y omega_z", real=True))
    th = sp.Matrix(sp.symbols("theta_x theta_y theta_z", real=True))
    m = sp.Matrix(3, 3, lambda i, j: sp.cos(a[f"psi_{'xyz'[i]}"]) if i == j else sp.sin(a[f"phi_{'xyz'[i]}{'xyz'[j]}"]))
    g = m * w
    return Symbolic(ang, w, th, m, g, m * th, g.jacobian(sp.Matrix(ang)))


def symbolic_text(style: str = "pretty") -> str:
    """Eq 5-10, Eq 11-13 and the sensitivity matrix as text (``pretty``) or LaTeX (``latex``)."""
    import sympy as sp

    s = symbolic()
    show = (lambda e: sp.latex(e)) if style == "latex" else (lambda e: sp.pretty(e, use_unicode=False))
    if style not in ("pretty", "latex"):
        raise InputError("choose pretty or latex", "--symbolic")
    return "\n\n".join([
        "Gyro response g = M w (Eq 5-10):", show(sp.Eq(sp.Symbol("g"), s.g, evaluate=False)),
        "Integrated, fixed-axis rotation theta_G = M theta (Eq 11-13):", show(sp.Eq(sp.Symbol("theta_G"), s.theta_G, evaluate=False)),
        f"Sensitivity d g / d ({', '.join(ELEMENTS)}):", show(s.jacobian),
    ])


@lru_cache(maxsize=1)
def _lambdified():
    import sympy as sp

    s = symbolic()
    m_fn = sp.lambdify([s.angles], s.M, "numpy")
    j_fn = sp.lambdify([s.angles, list(s.w)], s.jacobian, "numpy")
    return m_fn, j_fn


def _angle_vector(angles) -> np.ndarray:
    if isinstance(angles, dict):
        unknown = set(angles) - set(ELEMENTS)
        if unknown:
            raise InputError(f"unknown element(s) {', '.join(sorted(unknown))}; elements are {', '.join(ELEMENTS)}")
        return np.array([float(angles.get(e, 0.0)) for e in ELEMENTS])
    return np.asarray(angles, dtype=float).reshape(9)


def matrix_from_angles(angles) -> np.ndarray:
    """``M`` of Eq 5-10 from the nine angles (rad), via the lambdified sympy form."""
    return np.array(_lambdified()[0](tuple(_angle_vector(angles))), dtype=float)


def response(w, angles) -> np.ndarray:
    """Gyro outputs ``g = M w`` (Eq 5-10); ``w`` of shape (3,) or (n, 3)."""
    return np.asarray(w, float) @ matrix_from_angles(angles).T


def sensitivity(w, angles) -> np.ndarray:
    """Jacobian ``d g / d angles``, shape (3, 9), at rate ``w`` (3,) (lambdified sympy)."""
    return np.array(_lambdified()[1](tuple(_angle_vector(angles)), list(np.asarray(w, float))), dtype=float)


# --- attitude propagation ---------------------------------------------------------------

def _qmul(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product of scalar-last quaternions (scipy's convention), arrays (..., 4)."""
    px, py, pz, pw = np.moveaxis(p, -1, 0)
    qx, qy, qz, qw = np.moveaxis(q, -1, 0)
    return np.stack([pw * qx + px * qw + py * qz - pz * qy,
                     pw * qy - px * qz + py * qw + pz * qx,
                     pw * qz + px * qy - py * qx + pz * qw,
                     pw * qw - px * qx - py * qy - pz * qz], axis=-1)


def _attitudes(increments: np.ndarray) -> np.ndarray:
    """Attitude after each body-frame increment (rotation vectors (n, 3)): R_k = R_(k-1) exp(dtheta_k).

    An inclusive prefix product by doubling (log2 n vectorised steps), scalar-last quaternions.
    """
    from scipy.spatial.transform import Rotation

    q = Rotation.from_rotvec(increments).as_quat()
    step = 1
    while step < len(q):
        q = np.concatenate([q[:step], _qmul(q[:-step], q[step:])])
        step *= 2
    return q


@dataclass(frozen=True)
class Manoeuvre:
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
    """

    increments: np.ndarray
    limits: dict
    fixed_axis: bool = False
    description: str = ""
    segments: tuple = field(default_factory=tuple)


def manoeuvre_from_dict(data: dict, where: str = "manoeuvre", base_dir=None) -> Manoeuvre:
    """Read a manoeuvre (``[[rotation]]`` list or ``[series]`` rate file, and ``[limits]``)."""
    limits_t = data.get("limits")
    if not isinstance(limits_t, dict) or not limits_t:
        raise InputError("missing [limits]: the largest allowed error of each gyro (x, y, z) or output angle", where)
    limits = {}
    for name, value in limits_t.items():
        if name not in OUTPUTS:
            raise InputError(f"unknown output '{name}'; use {', '.join(OUTPUTS)}", f"{where}: limits.{name}")
        limits[name] = parse_quantity(value, "angle", f"{where}: limits.{name}")
        if not limits[name] > 0:
            raise InputError("a limit must be positive", f"{where}: limits.{name}")
    rotations, series = data.get("rotation"), data.get("series")
    if rotations and series:
        raise InputError("give [[rotation]] steps or a [series], not both", where)
    if series:
        return _series(series, limits, where, base_dir)
    if not isinstance(rotations, list) or not rotations:
        raise InputError("no [[rotation]] (axis, angle) and no [series]: nothing to analyse", where)
    inc, segs = [], []
    for k, r in enumerate(rotations, start=1):
        here = f"{where}: rotation {k}"
        if not isinstance(r, dict) or "axis" not in r or "angle" not in r:
            raise InputError("needs axis (x, y or z) and angle", here)
        axis = str(r["axis"]).strip().lower()
        sign = -1.0 if axis.startswith("-") else 1.0
        if axis.lstrip("+-") not in _AX:
            raise InputError(f"axis '{r['axis']}' is not x, y or z", f"{here}.axis")
        angle = parse_quantity(r["angle"], "angle", f"{here}.angle")
        if angle == 0:
            raise InputError("angle is zero", f"{here}.angle")
        u = np.zeros(3)
        u[_AX[axis.lstrip('+-')]] = sign
        inc.append(angle * u)
        segs.append((axis.lstrip("+-"), sign * angle))
    fixed = len(inc) == 1
    desc = "; ".join(f"{a} {v / DEG:+g} deg" for a, v in segs)
    return Manoeuvre(np.array(inc), limits, fixed, desc, tuple(segs))


def _series(series: dict, limits: dict, where: str, base_dir) -> Manoeuvre:
    from pathlib import Path

    from align.io import read_log
    from align.io import check_log, check_time

    if "file" not in series:
        raise InputError("missing file = \"rates.csv\"", f"{where}: series.file")
    path = Path(series["file"])
    if base_dir is not None and not path.is_absolute():
        path = Path(base_dir) / path
    cols = [c.strip() for c in str(series.get("columns", "time,wx,wy,wz")).split(",")]
    if len(cols) != 4:
        raise InputError("columns must name time and three rates", f"{where}: series.columns")
    t, w = read_log(path, cols[1:], str(series.get("units", "deg/s")), cols[0])
    check_log(t, w, str(path), min_rows=2)
    check_time(t, str(path), gap=1.5)
    inc = 0.5 * (w[1:] + w[:-1]) * np.diff(t)[:, None]   # trapezoid increments
    return Manoeuvre(inc, limits, False, f"rate series {path.name}: {len(t)} samples, {t[-1] - t[0]:.4g} s")


def _euler(q: np.ndarray) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return Rotation.from_quat(q).as_euler("ZYX")             # azimuth, elevation, roll


def output_errors(man: Manoeuvre, m: np.ndarray, history: bool = False) -> dict:
    """Largest |error| (rad) of every limited output over the manoeuvre, by attitude propagation.

    With ``history`` the full time histories are returned instead (arrays (n,)).
    """
    from scipy.spatial.transform import Rotation

    q_true = _attitudes(man.increments)
    q_meas = _attitudes(man.increments @ np.asarray(m).T)
    out = {}
    need = set(man.limits) if not history else set(OUTPUTS)
    if need & {"x", "y", "z"}:
        d = Rotation.from_quat(q_meas).as_rotvec() - Rotation.from_quat(q_true).as_rotvec()
        for name in ("x", "y", "z"):
            out[name] = d[:, _AX[name]]
    if need & {"azimuth", "elevation", "roll"}:
        e = _euler(q_meas) - _euler(q_true)
        e = (e + np.pi) % (2 * np.pi) - np.pi
        for k, name in enumerate(("azimuth", "elevation", "roll")):
            out[name] = e[:, k]
    if history:
        return out
    return {name: float(np.max(np.abs(out[name]))) for name in man.limits}


def closed_form_errors(man: Manoeuvre, m: np.ndarray) -> np.ndarray:
    """Eq 11-13 applied step by step and summed: ``sum_k (M - I) theta_k`` per gyro (rad)."""
    return (man.increments @ (np.asarray(m) - np.eye(3)).T).sum(axis=0)


@dataclass(frozen=True)
class Allowable:
    """Allowable misalignment per element (rad; ``inf`` where no requirement is affected)."""

    allowable: dict
    method: dict
    binding: str
    binding_value: float
    cone: float
    cone_direction: np.ndarray
    agreement: dict
    manoeuvre: Manoeuvre

    def to_dict(self) -> dict:
        from align import CONVENTION, __version__

        return {
            "format": "imu-align.allowable", "version": 1, "generator": f"imu-align {__version__}",
            "convention": CONVENTION + "; M_ii = cos(psi_i), M_ij = sin(phi_ij) (Eq 5-10)",
            "units": {"angles": "deg"},
            "manoeuvre": self.manoeuvre.description,
            "limits_deg": {k: v / DEG for k, v in self.manoeuvre.limits.items()},
            "allowable_deg": {k: (None if not np.isfinite(v) else v / DEG) for k, v in self.allowable.items()},
            "method": self.method,
            "binding": self.binding,
            "binding_deg": self.binding_value / DEG,
            "cone_deg": self.cone / DEG,
            "cone_worst_direction": self.cone_direction.tolist(),
            "agreement": self.agreement,
        }


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
    the closed forms ``asin(E / Theta)`` and ``acos(1 - E / Theta)`` where they
    apply, otherwise numeric root finding (Brent) on attitude propagation,
    both signs, up to 90 deg (``inf`` when never reached). The cone is the
    largest rigid mounting rotation, in any direction (``directions`` points on
    a sphere), that meets every limit.
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
        "element": element, "element_deg": (value / DEG) if np.isfinite(value) else None,
        "closed_form_deg": dict(zip("xyz", (closed / DEG).tolist())),
        "propagated_deg": {a: float(prop[a][-1] / DEG) for a in "xyz"},
        "note": ("one fixed-axis rotation: Eq 11-13 is exact" if man.fixed_axis else
                 "rotations about changing axes do not integrate as Eq 11-13; the propagated values are the truth"),
    }


@dataclass(frozen=True)
class Margin:
    """One element of the budget-versus-allowance check (rad; allowed ``inf`` = unconstrained)."""

    element: str
    predicted: float
    allowed: float

    @property
    def margin(self) -> float:
        return self.allowed - self.predicted

    @property
    def ok(self) -> bool:
        return self.predicted <= self.allowed


def margins(predicted: dict, allow: Allowable) -> list[Margin]:
    """Element by element: the predicted misalignment against the allowable one."""
    missing = [e for e in ELEMENTS if e not in predicted]
    if missing:
        raise ValueError(f"no prediction for {missing}")
    return [Margin(e, float(predicted[e]), float(allow.allowable[e])) for e in ELEMENTS]
