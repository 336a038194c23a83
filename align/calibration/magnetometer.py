"""Magnetometer hard- and soft-iron calibration from tumbling data (seed 004), with gates.

Hard iron ``h`` (an offset) and soft iron turn the sphere ``|m| = F`` of the
field into an ellipsoid; the calibration maps it back:
``m_cal = W (m_raw - h)`` with ``W`` symmetric positive definite (``soft_iron``).

Steps: centre and scale the data (conditioning only); fit the ellipsoid
algebraically (Li and Griffiths 2004, ellipsoid-specific: ``4J - I^2 = 1``), or a
sphere, or an axis-aligned ellipsoid; refine ``h`` and ``W`` geometrically
(``sum (|W (m - h)| - F)^2``, Levenberg-Marquardt) to a known field strength or
to the fitted one (``det W = 1`` scale). Gates refuse, with a clear message,
data that cannot give a trustworthy answer: too few samples, planar or clustered
captures (the hard iron's 1-sigma from the refinement exceeds 2 % of the field),
a quadric that is not an ellipsoid, a reflected solution.

Public names
------------
MagCalibration, calibrate_magnetometer, alignment_to_gravity, misalignment_from_axes_down, MODELS
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align import __version__
from align.io import check_finite
from align.errors import InputError, TestError
from align.units import DEG, to_unit

MODELS = ("sphere", "diagonal", "symmetric")
CONVENTION = "m_cal = soft_iron (m_raw - hard_iron)"


@dataclass(frozen=True)
class MagCalibration:
    """A magnetometer calibration (field quantities in SI, tesla, or raw counts)."""

    hard_iron: np.ndarray
    soft_iron: np.ndarray
    field: float
    model: str
    units: str
    sigma_hard_iron: np.ndarray
    spread_before: float
    spread_after: float
    coverage: float
    heading_error: float
    dip: float | None
    notes: tuple = ()
    misalignment: np.ndarray | None = None

    def correct(self, raw: np.ndarray) -> np.ndarray:
        return (np.asarray(raw) - self.hard_iron) @ self.soft_iron.T

    def to_dict(self) -> dict:
        u = self.units
        d = {
            "format": "imu-align.magnetometer", "version": 1, "generator": f"imu-align {__version__}",
            "sensor": "magnetometer", "convention": CONVENTION, "model": self.model,
            "units": {"hard_iron": u, "field": u, "soft_iron": "1", "angles": "deg"},
            "hard_iron": to_unit(self.hard_iron, u).tolist(), "soft_iron": self.soft_iron.tolist(),
            "field": float(to_unit(self.field, u)),
            "uncertainty": {"level": "1 sigma", "hard_iron": to_unit(self.sigma_hard_iron, u).tolist()},
            "quality": {"field_spread_before": self.spread_before, "field_spread_after": self.spread_after,
                        "spread_is": "std(|m|) / mean(|m|)", "coverage": self.coverage,
                        "coverage_is": "smallest eigenvalue of mean(u u^T) of the calibrated directions (1/3 for a full sphere)",
                        "predicted_heading_error_deg": self.heading_error / DEG,
                        "dip_deg": None if self.dip is None else self.dip / DEG},
            "notes": list(self.notes),
        }
        if self.misalignment is not None:
            d["misalignment"] = self.misalignment.tolist()
            d["misalignment_convention"] = "m_body = misalignment m_cal"
        return d

    @classmethod
    def from_dict(cls, d: dict, where: str = "magnetometer") -> "MagCalibration":
        from align.units import parse_unit

        try:
            u = d["units"]["hard_iron"]
            f = parse_unit(u).factor
            q = d["quality"]
            mis = d.get("misalignment")
            return cls(np.array(d["hard_iron"], float) * f, np.array(d["soft_iron"], float).reshape(3, 3),
                       float(d["field"]) * f, d["model"], u, np.array(d["uncertainty"]["hard_iron"], float) * f,
                       q["field_spread_before"], q["field_spread_after"], q["coverage"],
                       q["predicted_heading_error_deg"] * DEG, None if q["dip_deg"] is None else q["dip_deg"] * DEG,
                       tuple(d.get("notes", [])), None if mis is None else np.array(mis, float))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"malformed magnetometer calibration ({exc!r})", where) from None


def _li_griffiths(x: np.ndarray) -> np.ndarray:
    """Ellipsoid-specific algebraic fit (Li and Griffiths 2004): the 10 quadric coefficients.

    ``a x^2 + b y^2 + c z^2 + 2f yz + 2g xz + 2h xy + 2p x + 2q y + 2r z + d = 0``
    subject to ``4J - I^2 = 1`` (``I = a + b + c``, ``J = ab + bc + ca - f^2 - g^2 - h^2``),
    solved as a generalised eigenproblem.
    """
    X, Y, Z = x.T
    D = np.column_stack([X * X, Y * Y, Z * Z, 2 * Y * Z, 2 * X * Z, 2 * X * Y, 2 * X, 2 * Y, 2 * Z, np.ones(len(x))])
    S = D.T @ D
    S11, S12, S22 = S[:6, :6], S[:6, 6:], S[6:, 6:]
    k = 4.0
    C1 = np.zeros((6, 6))
    C1[:3, :3] = k / 2 - 1
    np.fill_diagonal(C1[:3, :3], -1.0)
    C1[3:, 3:] = -k * np.eye(3)
    try:
        tmp = S11 - S12 @ np.linalg.solve(S22, S12.T)
        w, v = np.linalg.eig(np.linalg.solve(C1, tmp))
    except np.linalg.LinAlgError:
        raise TestError("the capture is degenerate (no ellipsoid through it): rotate the device through all orientations",
                        "magnetometer") from None
    w, v = np.real(w), np.real(v)
    pos = np.flatnonzero(w > -1e-9 * np.max(np.abs(w)))  # noise-free data put the answer at w = 0
    if len(pos) == 0:
        raise TestError("no ellipsoid fits these samples (the fitted quadric is not an ellipsoid)", "magnetometer")
    v1 = v[:, pos[np.argmax(w[pos])]]
    v2 = -np.linalg.solve(S22, S12.T @ v1)
    return np.concatenate([v1, v2])


def _quadric_to_ellipsoid(coef: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centre ``c`` and shape ``Q`` (positive definite) with ``(x - c)^T Q (x - c) = 1``."""
    a, b, c, f, g, h, p, q, r, d = coef
    Q = np.array([[a, h, g], [h, b, f], [g, f, c]])
    centre = -np.linalg.solve(Q, np.array([p, q, r]))
    s = centre @ Q @ centre - d
    Q = Q / s
    if not np.all(np.linalg.eigvalsh(Q) > 0):
        raise TestError("the fitted quadric is not an ellipsoid (non-positive axis): the data do not show "
                        "an iron-distorted field; check the columns and the capture", "magnetometer")
    return centre, Q


def _sqrtm_spd(q: np.ndarray) -> np.ndarray:
    w, v = np.linalg.eigh(q)
    return (v * np.sqrt(w)) @ v.T


def _initial(x: np.ndarray, model: str) -> tuple[np.ndarray, np.ndarray]:
    """Algebraic fit on normalised data: centre and ``W`` with ``|W (x - c)| ~ 1``."""
    if model == "sphere":
        A = np.column_stack([2 * x, np.ones(len(x))])
        sol, *_ = np.linalg.lstsq(A, np.sum(x * x, axis=1), rcond=None)
        centre = sol[:3]
        radius = np.sqrt(sol[3] + centre @ centre)
        return centre, np.eye(3) / radius
    if model == "diagonal":
        A = np.column_stack([x * x, 2 * x, np.ones(len(x))])
        sol, *_ = np.linalg.lstsq(A[:, :6], -A[:, 6], rcond=None)
        coef = np.array([sol[0], sol[1], sol[2], 0, 0, 0, sol[3], sol[4], sol[5], 1.0])
    else:
        coef = _li_griffiths(x)
    centre, Q = _quadric_to_ellipsoid(coef)
    return centre, _sqrtm_spd(Q)


def _pack(w: np.ndarray, model: str) -> np.ndarray:
    if model == "sphere":
        return np.array([w[0, 0]])
    if model == "diagonal":
        return np.diag(w).copy()
    return w[np.triu_indices(3)]


def _unpack(p: np.ndarray, model: str) -> np.ndarray:
    if model == "sphere":
        return np.eye(3) * p[0]
    if model == "diagonal":
        return np.diag(p)
    w = np.zeros((3, 3))
    w[np.triu_indices(3)] = p
    return w + np.triu(w, 1).T


def calibrate_magnetometer(m: np.ndarray, units: str = "uT", field: float | None = None, model: str = "symmetric",
                           acc: np.ndarray | None = None, dip: float | None = None,
                           max_hard_iron_sigma: float = 0.02) -> MagCalibration:
    """Hard and soft iron from a tumbling capture (see module docstring).

    Parameters
    ----------
    m : ndarray, shape (n, 3)
        Raw readings, SI (tesla) or counts.
    field : float, optional
        Known field strength (same unit as ``m``); otherwise the fitted one (``det W = 1``).
    model : {"sphere", "diagonal", "symmetric"}
    acc : ndarray, shape (n, 3), optional
        Simultaneous accelerometer readings: give the dip angle for the heading-error prediction.
    dip : float, optional
        Magnetic dip (rad) when no accelerometer is given; default 60 deg, said in the notes.
    max_hard_iron_sigma : float
        Refuse when the hard iron's 1-sigma exceeds this fraction of the field.
    """
    from scipy.optimize import least_squares

    if model not in MODELS:
        raise InputError(f"unknown model '{model}'; choose {', '.join(MODELS)}", "--model")
    m = np.asarray(m, float)
    check_finite(m, "magnetometer")
    n_par = {"sphere": 4, "diagonal": 6, "symmetric": 9}[model]
    if len(m) < 3 * n_par:
        raise InputError(f"only {len(m)} samples; the {model} model needs at least {3 * n_par}", "magnetometer")
    # centre and scale (conditioning only; the hard iron comes from the fit, not from the sample mean)
    c0 = 0.5 * (m.min(axis=0) + m.max(axis=0))
    s0 = float(np.sqrt(np.mean(np.sum((m - c0) ** 2, axis=1))))
    if not s0 > 0:
        raise TestError("all samples are equal: the sensor did not move", "magnetometer")
    x = (m - c0) / s0
    sv = np.linalg.svd(x - x.mean(axis=0), compute_uv=False)
    if sv[2] < 0.15 * sv[0]:
        raise TestError(f"planar or near-level capture: the samples barely leave a plane (thickness {sv[2] / sv[0]:.2f} of "
                        "their width); tilt the device through all orientations (a figure-eight in every direction)",
                        "magnetometer")
    centre, w = _initial(x, model)
    target = None if field is None else field / s0
    p0 = np.concatenate([centre, _pack(w, model)])

    def resid(p):
        wm = _unpack(p[3:], model)
        r = np.linalg.norm((x - p[:3]) @ wm.T, axis=1)
        return r - (1.0 if target is None else target)

    # the centre may move at most 0.3 data radii from the algebraic fit: on partial coverage the
    # unconstrained geometric cost slides toward ever larger ellipsoids
    lo, hi = np.full(len(p0), -np.inf), np.full(len(p0), np.inf)
    lo[:3], hi[:3] = centre - 0.3, centre + 0.3
    sol = least_squares(resid, p0, method="trf", bounds=(lo, hi), x_scale="jac")
    if np.any(np.isclose(sol.x[:3], lo[:3]) | np.isclose(sol.x[:3], hi[:3])):
        raise TestError("coverage too small: the fit runs away along the poorly covered direction (the geometric "
                        "refinement reached its bound); rotate the device through more orientations", "magnetometer")
    notes_refine = "geometric refinement (trust region) from the algebraic Li-Griffiths fit"
    centre, w = sol.x[:3], _unpack(sol.x[3:], model)
    if target is None:  # the fitted field: scale W to unit determinant, |m_cal| is then the field
        det = np.linalg.det(w)
        if not det > 0:
            raise TestError("the fit came out reflected or singular (det <= 0)", "magnetometer")
        scale = det ** (1 / 3)
        w = w / scale
        f_fit = 1.0 / scale
    else:
        f_fit = target
    if not np.all(np.linalg.eigvalsh(w) > 0) or np.linalg.det(w) <= 0:
        raise TestError("the soft-iron matrix is not positive definite (a reflected or degenerate solution); "
                        "the capture does not determine it", "magnetometer")
    dof = max(len(x) - len(sol.x), 1)
    r_final = resid(sol.x)
    cov = np.linalg.pinv(sol.jac.T @ sol.jac) * float(np.sum(r_final**2)) / dof
    sig_c = np.sqrt(np.diag(cov)[:3]) * s0
    hard = c0 + centre * s0
    field_si = f_fit * s0
    cal = (m - hard) @ w.T
    norms = np.linalg.norm(cal, axis=1)
    u = cal / norms[:, None]
    coverage = float(np.linalg.eigvalsh(u.T @ u / len(u))[0])
    size = min(field_si, s0)  # a runaway fit inflates the fitted field; the data's own radius does not
    if np.max(sig_c) > max_hard_iron_sigma * size or coverage < 0.05:
        raise TestError(f"coverage too small: the hard iron is uncertain by {to_unit(np.max(sig_c), units):.3g} {units} "
                        f"(limit {100 * max_hard_iron_sigma:g} % of the field) and the calibrated directions cover "
                        f"{coverage:.3f} (0.333 for a full sphere); rotate the device through more orientations",
                        "magnetometer")
    raw_norm = np.linalg.norm(m, axis=1)
    notes = [f"{model} model, {len(m)} samples; " + ("field fixed at the value given" if field is not None else
                                                      "field fitted (soft iron scaled to unit determinant)"), notes_refine]
    if acc is not None:
        a = np.asarray(acc, float)
        cosang = np.sum(u * a, axis=1) / np.linalg.norm(a, axis=1)
        dip = float(np.arcsin(np.clip(np.median(cosang), -1, 1)))
        notes.append(f"dip {np.degrees(dip):.2f} deg from the accelerometer (median angle between field and gravity)")
    elif dip is None:
        dip = 60 * DEG
        notes.append("dip not measured: heading error predicted for 60 deg (mid latitudes); give accelerometer data for the real one")
    horizontal = field_si * np.cos(dip)
    heading = float(np.arctan2(np.std(norms - field_si), horizontal))
    notes.append("predicted heading error: the residual field-magnitude scatter seen across the horizontal field (1 sigma)")
    return MagCalibration(hard, w * 1.0, field_si, model, units, sig_c, float(np.std(raw_norm) / np.mean(raw_norm)),
                          float(np.std(norms) / np.mean(norms)), coverage, heading, dip, tuple(notes))


def misalignment_from_axes_down(down: dict) -> np.ndarray:
    """Seed 004: rows are the normalised mean calibrated field with the x, y, z axes pointing down in turn."""
    rows = [np.asarray(down[a], float) for a in "xyz"]
    return np.array([r / np.linalg.norm(r) for r in rows])


def alignment_to_gravity(m_cal: np.ndarray, acc: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Rotation ``R`` (mag frame to accelerometer frame) making the field-gravity angle constant.

    Minimises the scatter of ``asin(a_hat . R m_hat)`` (the dip) over a tumbling
    capture; returns ``R``, the dip (rad) and the remaining scatter (rad).
    """
    from scipy.optimize import least_squares
    from scipy.spatial.transform import Rotation

    mh = m_cal / np.linalg.norm(m_cal, axis=1, keepdims=True)
    ah = acc / np.linalg.norm(acc, axis=1, keepdims=True)

    def resid(p):
        r = Rotation.from_rotvec(p[:3]).as_matrix()
        return np.arcsin(np.clip(np.sum(ah * (mh @ r.T), axis=1), -1, 1)) - p[3]

    p0 = np.array([0.0, 0.0, 0.0, float(np.median(np.arcsin(np.clip(np.sum(ah * mh, axis=1), -1, 1))))])
    sol = least_squares(resid, p0)
    return Rotation.from_rotvec(sol.x[:3]).as_matrix(), float(sol.x[3]), float(np.std(sol.fun))
