"""Estimators of ``[M | b]`` from rate-table segments.

Every segment is one linear observation of all three gyros, ``y_k = [M | b] phi_k`` (SI units;
built by :mod:`align.alignment.observe`).

:func:`fit_lsq` is the general weighted least squares over any set of segments (any axes, rates,
lengths); :func:`fit_rate_pairs` (Eq 28-30) and :func:`fit_angle_pairs` (Eq 31) are the closed
forms of the source, which it reproduces on their designs; :func:`two_axis` is the orthogonal
shortcut (Eq 35-36).

Public names
------------
Fit, condition_number, fit_lsq, fit_rate_pairs, fit_angle_pairs, alignment_sigma
(the two-axis shortcut, Eq 35-36, is in :mod:`align.alignment.twoaxis`)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.alignment.observe import Observation
from align.alignment.plan import Plan, axis_name
from align.errors import TestError
from align.values import Value


@dataclass(frozen=True, eq=False)
class Fit(Value):
    """Estimated ``M`` and ``b`` with their 1-sigma uncertainties.

    Attributes
    ----------
    M, sigma_M : ndarray, shape (3, 3)
        ``M`` of ``g = M w + b`` (Eq 14-15) and its 1-sigma, dimensionless; columns never turned about NaN.
    bias, sigma_bias : ndarray, shape (3,)
        rad/s (m/s^2 for an accelerometer fit).
    cov : ndarray, shape (3, 4, 4)
        Covariance of each row ``[M_i1, M_i2, M_i3, b_i]``.
    residuals : ndarray, shape (k, 3)
        ``y - [M | b] phi`` per observation, rad/s for dwells, rad for turns.
    dof : int
        Observations minus parameters, per gyro.
    chi2 : ndarray, shape (3,)
        Weighted residual sum of squares per gyro.
    condition_number : float
        Of the column-normalised design matrix.
    method : str
        The estimator: ``"lsq"``, ``"two-axis"``, ``"ols"``, ``"rate"`` or ``"angle"``.
    """

    M: np.ndarray
    bias: np.ndarray
    sigma_M: np.ndarray
    sigma_bias: np.ndarray
    cov: np.ndarray
    residuals: np.ndarray
    dof: int
    chi2: np.ndarray
    condition_number: float
    method: str


def _design(obs: list[Observation]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``phi`` (k, 4), ``y`` (k, 3) and ``var`` (k, 3) of the observations, stacked."""
    return np.array([o.phi for o in obs]), np.array([o.y for o in obs]), np.array([o.var for o in obs])


def condition_number(phi: np.ndarray) -> float:
    """Condition number of the design with each column scaled to unit norm (which removes its units).

    Parameters
    ----------
    phi : ndarray, shape (k, p)
        The stacked regressors ``phi_k`` (rad/s, rad, s or 1).

    Returns
    -------
    float
        Largest over smallest singular value; ``inf`` when rank-deficient.
    """
    norms = np.linalg.norm(phi, axis=0)
    norms[norms == 0] = 1.0
    s = np.linalg.svd(phi / norms, compute_uv=False)
    return float(s[0] / s[-1]) if s[-1] > 0 else float("inf")


def fit_lsq(obs: list[Observation], rate_accuracy: float = 0.0, method: str = "lsq", equal_weights: bool = False) -> Fit:
    """General weighted least squares for ``[M | b]`` (extends Eq 28-31).

    Each gyro ``i`` is fitted separately: minimise ``sum_k (y_ki - phi_k . x_i)^2 / var_ki``. The
    covariance is ``(Phi^T W Phi)^-1``, inflated by ``chi2 / dof`` when that exceeds 1 (the scatter
    between segments is larger than the noise inside them, e.g. bias drift); a stated relative table
    accuracy (rate, or angle over the turn) adds ``(M_ij rate_accuracy)^2``.
    Columns of ``M`` for axes never turned about are left NaN (the two-axis shortcut fills them).
    With ``equal_weights`` it is ordinary least squares, ``K = Y X^T (X X^T)^-1`` (reference
    section 5), and the covariance is scaled by the residual variance ``chi2 / dof`` alone. Raises
    TestError when the segments do not determine the turned columns and ``b``.

    Parameters
    ----------
    obs : list of Observation, length k
        From :func:`observe`: ``y`` (3,) a mean reading (rad/s; m/s^2 for an accelerometer)
        or a turn's integrated reading (rad); ``phi`` (4,) ``[w u; 1]``, ``[0; 1]`` or
        ``[theta u; T]``; ``var`` (3,) the variance of ``y``. Static periods or +/- pairs fix ``b``.
    rate_accuracy : float
        Relative table accuracy (rate, or angle over the turn), dimensionless; 0 adds nothing.
    method : str
        The label recorded in :attr:`Fit.method` (``"lsq"``, ``"two-axis"``, ``"ols"``).
    equal_weights : bool
        Ordinary instead of weighted least squares (``var`` ignored).

    Returns
    -------
    Fit
        ``M`` (3, 3), dimensionless, ``b`` (3,), rad/s (m/s^2), their covariance, residuals (k, 3), ``chi2``.
    """
    phi, y, var = _design(obs)
    if equal_weights:
        var = np.ones_like(var)
    k = len(obs)
    active = np.flatnonzero(np.linalg.norm(phi, axis=0) > 0)
    if np.linalg.matrix_rank(phi[:, active] / np.linalg.norm(phi[:, active], axis=0)) < len(active) or 3 not in active:
        raise TestError("the segments do not determine M and the bias together: "
                        "turn about each axis and add +/- pairs or static periods")
    x, cov = np.full((3, 4), np.nan), np.full((3, 4, 4), np.nan)
    chi2, resid = np.empty(3), np.empty((k, 3))
    dof = k - len(active)
    sub = np.ix_(active, active)
    for i in range(3):
        wts = 1.0 / var[:, i]
        a = phi[:, active] * np.sqrt(wts)[:, None]
        b = y[:, i] * np.sqrt(wts)
        sol, *_ = np.linalg.lstsq(a, b, rcond=None)
        x[i, active] = sol
        resid[:, i] = y[:, i] - phi[:, active] @ sol
        chi2[i] = float(np.sum(resid[:, i] ** 2 * wts))
        if equal_weights:
            inflate = chi2[i] / dof if dof > 0 else np.nan
        else:
            inflate = max(1.0, chi2[i] / dof) if dof > 0 else 1.0
        cov[i][sub] = np.linalg.inv(a.T @ a) * inflate
    m = x[:, :3]
    if rate_accuracy:
        for i in range(3):
            cov[i, :3, :3] += np.diag(np.nan_to_num(m[i] * rate_accuracy) ** 2)
    sig = np.sqrt(np.einsum("ijj->ij", cov))
    return Fit(m, x[:, 3], sig[:, :3], sig[:, 3], cov, resid, dof, chi2, condition_number(phi[:, active]), method)


def _pairs(obs: list[Observation], plan: Plan, kind: str) -> dict[int, tuple[Observation, Observation]]:
    """For each axis, the observation with positive and negative turn (Eq 28, 31)."""
    found: dict[int, dict[int, Observation]] = {}
    for o in obs:
        if o.segment.kind != kind:
            continue
        step = plan.steps[o.segment.step]
        value = step.rate if kind == "rate" else step.angle
        found.setdefault(step.axis, {})[int(np.sign(value * step.sign))] = o
    pairs = {a: (d[1], d[-1]) for a, d in found.items() if 1 in d and -1 in d}
    missing = [axis_name(a) for a in range(3) if a not in pairs]
    if missing:
        raise TestError(f"the {kind} method needs one +{kind} and one -{kind} step about each axis; "
                        f"none complete about {', '.join(missing)} (set {{method=lsq}})")
    return pairs


def fit_rate_pairs(obs: list[Observation], plan: Plan) -> Fit:
    """Eq 28-30: ``M_ij = (g_i(+) - g_i(-)) / (w(+) - w(-))``, ``b = mean of (g(+) + g(-)) / 2``.

    With the table turning at ``+w`` and ``-w`` this is the source's ``(g(+) - g(-)) / (2 w)``; the
    bias is the average over the three pairs of the pairwise bias, assuming equal rates.

    Parameters
    ----------
    obs : list of Observation
        Constant-rate dwells (:func:`observe`): ``y`` (3,) the mean gyro reading, rad/s;
        ``phi`` (4,) ``[w u; 1]``, table rate ``w`` in rad/s; ``var`` (3,), (rad/s)^2. The last
        ``+w`` and ``-w`` dwell about each axis are used (TestError when one is missing).
    plan : Plan
        The plan the segments' steps refer to (axis, sign and rate of each step).

    Returns
    -------
    Fit
        ``M`` (3, 3), dimensionless, ``b`` (3,), rad/s, 1-sigma from the dwells' noise; ``chi2`` NaN.
    """
    pairs = _pairs(obs, plan, "rate")
    m, var_m = np.empty((3, 3)), np.empty((3, 3))
    biases, var_b = [], []
    for a, (p, n) in pairs.items():
        span = p.phi[a] - n.phi[a]
        m[:, a] = (p.y - n.y) / span
        var_m[:, a] = (p.var + n.var) / span**2
        wp, wn = p.phi[a], n.phi[a]
        biases.append((p.y * wn - n.y * wp) / (wn - wp))
        var_b.append((p.var * wn**2 + n.var * wp**2) / (wn - wp) ** 2)
    bias = np.mean(biases, axis=0)
    sigma_b = np.sqrt(np.sum(var_b, axis=0)) / 3.0
    return _closed_form_fit(obs, m, bias, np.sqrt(var_m), sigma_b, "rate")


def fit_angle_pairs(obs: list[Observation], plan: Plan) -> Fit:
    """Eq 31: ``M_ij = (Theta_i(+) - Theta_i(-)) / (theta(+) - theta(-))``.

    The bias cancels when both turns last equally long; otherwise the static periods' mean bias is removed
    first and reported (with no static period, the pairwise bias assuming equal durations is reported).

    Parameters
    ----------
    obs : list of Observation
        Turns and static periods (:func:`observe`): for a turn ``y`` (3,) is the integrated
        reading ``Theta_i``, rad, and ``phi`` (4,) ``[theta u; T]`` (table angle, rad; duration, s);
        for a static period ``y`` is the mean reading, rad/s. The last ``+theta`` and ``-theta``
        turn about each axis are used (TestError when one is missing).
    plan : Plan
        The plan the segments' steps refer to (axis, sign and angle of each step).

    Returns
    -------
    Fit
        ``M`` (3, 3), dimensionless, ``b`` (3,), rad/s (sigma NaN without a static period); ``chi2`` NaN.
    """
    pairs = _pairs(obs, plan, "angle")
    statics = [o for o in obs if o.segment.kind == "static"]
    if statics:
        w = np.array([o.duration for o in statics])
        bias = np.average([o.y for o in statics], axis=0, weights=w)
        sigma_b = np.sqrt(np.sum([o.var * wi**2 for o, wi in zip(statics, w)], axis=0)) / w.sum()
    else:
        bias, sigma_b = None, None
    m, var_m = np.empty((3, 3)), np.empty((3, 3))
    pair_bias = []
    for a, (p, n) in pairs.items():
        span = p.phi[a] - n.phi[a]
        yp, yn = p.y, n.y
        if bias is not None:
            yp, yn = yp - bias * p.duration, yn - bias * n.duration
        else:
            pair_bias.append((p.y + n.y) / (p.duration + n.duration))
        m[:, a] = (yp - yn) / span
        var_m[:, a] = (p.var + n.var) / span**2
    if bias is None:
        bias = np.mean(pair_bias, axis=0)
        sigma_b = np.full(3, np.nan)
    return _closed_form_fit(obs, m, bias, np.sqrt(var_m), sigma_b, "angle")


def _closed_form_fit(obs, m, bias, sigma_m, sigma_b, method) -> Fit:
    phi, y, _ = _design(obs)
    resid = y - phi @ np.hstack([m, bias[:, None]]).T
    cov = np.zeros((3, 4, 4))
    for i in range(3):
        cov[i] = np.diag(np.append(sigma_m[i], sigma_b[i]) ** 2)
    return Fit(m, bias, sigma_m, sigma_b, cov, resid, len(obs) - 4, np.full(3, np.nan), condition_number(phi), method)


def alignment_sigma(m: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """1-sigma of ``A = M^-1`` (Eq 14-15) by first-order propagation ``dA = -A dM A``.

    Parameters
    ----------
    m : ndarray, shape (3, 3)
        The estimated ``M``, dimensionless.
    cov : ndarray, shape (3, 4, 4)
        Covariance of each (independent) row ``[M_i1, M_i2, M_i3, b_i]``; only the ``M`` block is used.

    Returns
    -------
    ndarray, shape (3, 3)
        1-sigma of each element of ``A``, dimensionless.
    """
    a = np.linalg.inv(m)
    var = np.zeros((3, 3))
    for i in range(3):
        # dA_kl = -sum_j A_ki dM_ij A_jl  ->  gradient over row i: g_j = A_ki A_jl
        grad = np.einsum("k,jl->klj", a[:, i], a)
        var += np.einsum("klj,jm,klm->kl", grad, cov[i, :3, :3], grad)
    return np.sqrt(var)
