"""Estimators of ``[M | b]`` from rate-table segments.

Every segment is one linear observation of all three gyros, ``y_k = [M | b] phi_k`` (SI units;
built by :mod:`align.alignment.observe`).

:func:`fit_lsq` is the general weighted least squares over any set of segments (any axes, rates,
lengths); :func:`fit_rate_pairs` (Eq 28-30) and :func:`fit_angle_pairs` (Eq 31) are the closed
forms of the source, which it reproduces on their designs; :func:`two_axis` is the orthogonal
shortcut (Eq 35-36).

Each estimate is linear, ``x = L y`` (Eq E1), and its covariance is propagated through ``L`` (Eq E2): the
noise inside the segments and, when the observations carry the bias-drift model
(:class:`~align.alignment.biasdrift.DriftObservation`, from :func:`~align.alignment.biasdrift.with_drift`), the
bias change between the segments (Eq D2), and without a latitude the Earth rate segments share (Eq O3 of
:mod:`~align.alignment.observe`), both also in :func:`fit_lsq`'s weights (generalised least squares, Eq E4);
the bias is then the session bias, the mean of ``b(t)`` over the
samples of the segments used. When the residuals scatter more than the model predicts (Eq E3) the
covariance is inflated by the ratio.

Public names
------------
Fit, condition_number, fit_lsq, fit_rate_pairs, fit_angle_pairs, alignment_sigma
(the two-axis shortcut, Eq 35-36, is in :mod:`align.alignment.twoaxis`)
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from align.alignment.biasdrift import DriftObservation
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

    Each gyro ``i`` is fitted separately: minimise ``sum_k (y_ki - phi_k . x_i)^2 / var_ki``; when the
    observations carry the bias drift or a shared, unmodelled Earth rate (no latitude), generalised least squares
    on the whole error covariance ``S = diag(noise) + D C G C^T D + E`` (Eq E4, :func:`_error_cov`:
    ``W = S^-1``), so that segments whose biases move together (neighbours under a drift, segments sharing the
    Earth rate along one table axis) are not weighted as if independent. The
    covariance is that of ``x = L y``, ``L = (Phi^T W Phi)^-1 Phi^T W`` (Eq E1-E2; ``(Phi^T W Phi)^-1`` without
    drift), inflated by ``chi2 / E[chi2]`` when that exceeds 1 (Eq E3; ``E[chi2] = dof`` without drift: the
    scatter between segments is larger than the noise and drift inside them); a stated relative table
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
        :class:`~align.alignment.biasdrift.DriftObservation` s also carry the bias drift (Eq D2-D3).
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
    errors = _errors(obs)
    for i in range(3):
        wts = 1.0 / var[:, i]
        whiten = None if equal_weights else _whitening(_error_cov(phi, errors, i))
        if whiten is None:
            whiten = np.diag(np.sqrt(wts))
        a = whiten @ phi[:, active]
        b = whiten @ y[:, i]
        sol, *_ = np.linalg.lstsq(a, b, rcond=None)
        x[i, active] = sol
        resid[:, i] = y[:, i] - phi[:, active] @ sol
        chi2[i] = float(np.sum(resid[:, i] ** 2 * wts))
        if equal_weights:
            inflate = chi2[i] / dof if dof > 0 else np.nan
            cov[i][sub] = np.linalg.inv(a.T @ a) * inflate
        else:
            lmap = np.linalg.solve(a.T @ a, a.T @ whiten)  # x = L y (Eq E1)
            cov[i][sub] = _propagate(lmap, phi, active, var[:, i], resid[:, i], dof, errors, i)
    m = x[:, :3]
    if rate_accuracy:
        for i in range(3):
            cov[i, :3, :3] += np.diag(np.nan_to_num(m[i] * rate_accuracy) ** 2)
    sig = np.sqrt(np.einsum("ijj->ij", cov))
    return Fit(m, x[:, 3], sig[:, :3], sig[:, 3], cov, resid, dof, chi2, condition_number(phi[:, active]), method)


def _whitening(cov: np.ndarray | None) -> np.ndarray | None:
    """``W`` (k, k) with ``W^T W = cov^-1`` (the inverse Cholesky factor), or None for None."""
    if cov is None:
        return None
    scale = np.sqrt(np.diag(cov))
    chol = np.linalg.cholesky(cov / np.outer(scale, scale) + 1e-12 * np.eye(len(scale)))
    return np.linalg.solve(chol, np.diag(1.0 / scale))


def _pairs(obs: list[Observation], plan: Plan, kind: str) -> dict[int, tuple[Observation, Observation]]:
    """For each axis, the observation with positive and negative turn (Eq 28, 31)."""
    found: dict[int, dict[int, Observation]] = {}
    for o in obs:
        if o.segment.kind != kind:
            continue
        assert o.segment.step is not None  # a rate or angle segment is a plan step
        step = plan.steps[o.segment.step]
        found.setdefault(step.axis, {})[int(np.sign(step.turn * step.sign))] = o
    pairs = {a: (d[1], d[-1]) for a, d in found.items() if 1 in d and -1 in d}
    missing = [axis_name(a) for a in range(3) if a not in pairs]
    if missing:
        raise TestError(f"the {kind} method needs one +{kind} and one -{kind} step about each axis; "
                        f"none complete about {', '.join(missing)} (set {{method=lsq}})")
    return pairs


def fit_rate_pairs(obs: list[Observation], plan: Plan) -> Fit:
    """Eq 28-30: ``M_ij = (g_i(+) - g_i(-)) / (w(+) - w(-))``, ``b = mean of (g(+) + g(-)) / 2``.

    With the table turning at ``+w`` and ``-w`` this is the source's ``(g(+) - g(-)) / (2 w)``; the
    bias is the average over the three pairs of the pairwise bias, assuming equal rates. The
    uncertainty is that of the linear map ``x = L y`` (:func:`_propagate`): the noise of the two dwells
    and, for :class:`~align.alignment.biasdrift.DriftObservation` s, the bias change between them (Eq D2),
    inflated by the scatter of the residuals (the pairwise biases) beyond what that predicts.

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
        ``M`` (3, 3), dimensionless, ``b`` (3,), rad/s, their covariance, ``chi2`` of the residuals.
    """
    pairs = _pairs(obs, plan, "rate")
    where = {id(o): k for k, o in enumerate(obs)}
    lmap = np.zeros((4, len(obs)))
    m = np.empty((3, 3))
    biases = []
    for a, (p, n) in pairs.items():
        span = p.phi[a] - n.phi[a]
        m[:, a] = (p.y - n.y) / span
        wp, wn = p.phi[a], n.phi[a]
        biases.append((p.y * wn - n.y * wp) / (wn - wp))
        lmap[a, where[id(p)]], lmap[a, where[id(n)]] = 1.0 / span, -1.0 / span
        lmap[3, where[id(p)]] += wn / (wn - wp) / len(pairs)
        lmap[3, where[id(n)]] -= wp / (wn - wp) / len(pairs)
    bias = np.mean(biases, axis=0)
    return _closed_form_fit(obs, m, bias, lmap, "rate")


def fit_angle_pairs(obs: list[Observation], plan: Plan) -> Fit:
    """Eq 31: ``M_ij = (Theta_i(+) - Theta_i(-)) / (theta(+) - theta(-))``.

    The bias cancels when both turns last equally long; otherwise the static periods' mean bias is removed
    first and reported (with no static period, the pairwise bias assuming equal durations is reported).
    The uncertainty is that of the linear map ``x = L y`` (:func:`_propagate`): the turns' noise, the
    static bias' own error times ``T(+) - T(-)`` and, for :class:`~align.alignment.biasdrift.DriftObservation` s,
    the bias change between the turns and the static periods times ``T`` (Eq D2), inflated by the
    scatter of the residuals beyond what that predicts.

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
        ``M`` (3, 3), dimensionless, ``b`` (3,), rad/s (sigma NaN without a static period); ``chi2`` of the residuals.
    """
    pairs = _pairs(obs, plan, "angle")
    where = {id(o): k for k, o in enumerate(obs)}
    lmap = np.zeros((4, len(obs)))
    statics = [o for o in obs if o.segment.kind == "static"]
    if statics:
        w = np.array([o.duration for o in statics])
        bias = np.average([o.y for o in statics], axis=0, weights=w)
        bias_row = np.zeros(len(obs))
        bias_row[[where[id(o)] for o in statics]] = w / w.sum()
        lmap[3] = bias_row
    else:
        bias = None
    m = np.empty((3, 3))
    pair_bias = []
    for a, (p, n) in pairs.items():
        span = p.phi[a] - n.phi[a]
        yp, yn = p.y, n.y
        if bias is not None:
            yp, yn = yp - bias * p.duration, yn - bias * n.duration
            lmap[a] -= (p.duration - n.duration) / span * lmap[3]
        else:
            pair_bias.append((p.y + n.y) / (p.duration + n.duration))
            lmap[3, [where[id(p)], where[id(n)]]] += 1.0 / (p.duration + n.duration) / len(pairs)
        m[:, a] = (yp - yn) / span
        lmap[a, where[id(p)]] += 1.0 / span
        lmap[a, where[id(n)]] -= 1.0 / span
    fit = _closed_form_fit(obs, m, np.mean(pair_bias, axis=0) if bias is None else bias, lmap, "angle")
    if statics:
        return fit
    cov = fit.cov.copy()
    cov[:, 3, :], cov[:, :, 3] = np.nan, np.nan
    return replace(fit, cov=cov, sigma_bias=np.full(3, np.nan))


def _closed_form_fit(obs: list[Observation], m: np.ndarray, bias: np.ndarray, lmap: np.ndarray, method: str) -> Fit:
    """A closed form's :class:`Fit`: residuals, ``chi2`` and the covariance of ``x = L y``, ``lmap`` (4, k)."""
    phi, y, var = _design(obs)
    resid = y - phi @ np.hstack([m, bias[:, None]]).T
    dof = len(obs) - 4
    errors = _errors(obs)
    cov = np.array([_propagate(lmap, phi, np.arange(4), var[:, i], resid[:, i], dof, errors, i) for i in range(3)])
    sig = np.sqrt(np.einsum("ijj->ij", cov))
    chi2 = np.sum(resid**2 / var, axis=0)
    return Fit(m, bias, sig[:, :3], sig[:, 3], cov, resid, dof, chi2, condition_number(phi), method)


def _errors(obs: list[Observation]) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None, np.ndarray | None]:
    """The observations' noise variances (k, 3); when they carry a drift model (all
    :class:`~align.alignment.biasdrift.DriftObservation`), its generalised covariance ``G`` (3, k, k) of the
    segments' mean biases (Eq D2) and the session weights ``tau`` (k,), ``T_k / sum T``; when some carry a
    shared, unmodelled Earth term (:mod:`~align.alignment.observe`, Eq O3), its covariance ``E`` (3, k, k)."""
    shared = [o.earth for o in obs]
    earth = None
    if any(e is not None for e in shared):
        b = np.array([np.zeros((3, 3)) if e is None else np.asarray(e, float) for e in shared])  # (k, 3, 3)
        earth = np.einsum("kim,lim->ikl", b, b)
    drifted = [o for o in obs if isinstance(o, DriftObservation)]
    if obs and len(drifted) == len(obs):
        spans = np.array([o.span for o in drifted])
        durations = spans[:, 1] - spans[:, 0]
        return (np.array([o.noise_var for o in drifted]), drifted[0].drift.covariance(spans), durations / durations.sum(),
                earth)
    return np.array([o.var for o in obs]), None, None, earth


def _error_cov(phi: np.ndarray, errors: tuple, i: int) -> np.ndarray | None:
    """Covariance (k, k) of gyro ``i``'s observation errors about ``[M | b] phi`` with ``b`` the session bias (Eq E4):
    ``diag(noise) + D C G C^T D + E`` (``D = diag(phi_3)``, ``C = I - 1 tau^T``; ``G`` Eq D2, ``E`` Eq O3), or None
    when it is the diagonal the weights already hold (no drift, no shared Earth term)."""
    noise, g, tau, earth = errors
    if (g is None or not np.any(g[i])) and earth is None:
        return None
    cov = np.diag(noise[:, i])
    if g is not None and np.any(g[i]):
        c = (np.eye(len(tau)) - tau[None, :]) * phi[:, 3][:, None]
        part = c @ g[i] @ c.T
        cov = cov + (part + part.T) / 2
    if earth is not None:
        cov = cov + earth[i]
    return cov


def _propagate(lmap: np.ndarray, phi: np.ndarray, active: np.ndarray, var: np.ndarray, resid: np.ndarray, dof: int,
               errors: tuple, i: int) -> np.ndarray:
    """Covariance of one gyro's ``x = L y`` (Eq E1-E3), inflated by the residuals' excess scatter.

    The error of ``x`` is ``L n + A bbar`` with ``n`` the noise inside the segments and ``bbar`` their mean
    biases, ``A = L diag(phi_3)`` minus the session weights ``tau`` in the bias row (the bias is reported about
    the session bias ``sum tau_k bbar_k``; every row of ``A`` then sums to zero, as Eq D2 needs):
    ``cov = L N L^T + A G A^T`` (E2). The residuals ``r = (I - Phi L) y`` have the expected weighted sum of
    squares ``E = sum_k R_kk / var_k`` with ``R`` likewise (E3; ``E = dof`` for weighted least squares without
    drift); when ``dof > 0``, ``cov`` is multiplied by ``max(1, chi2 / E)``.

    Parameters
    ----------
    lmap : ndarray, shape (p, k)
        ``L``: the estimate of the active parameters (the bias last) from the observations.
    phi : ndarray, shape (k, 4)
        The design; ``phi[:, active]`` (k, p).
    active : ndarray of int, shape (p,)
    var, resid : ndarray, shape (k,)
        The weights' variances and the residuals of this gyro.
    dof : int
    errors : tuple
        From :func:`_errors`.
    i : int
        The gyro.

    Returns
    -------
    ndarray, shape (p, p)
    """
    noise, g, tau, earth = errors
    proj = np.eye(len(var)) - phi[:, active] @ lmap
    cov = (lmap * noise[:, i]) @ lmap.T
    r_var = np.einsum("kj,j,kj->k", proj, noise[:, i], proj)
    if g is not None:
        a = lmap * phi[:, 3]
        a[-1] -= tau
        cov = cov + a @ g[i] @ a.T
        pa = proj * phi[:, 3]
        r_var = r_var + np.einsum("kj,jl,kl->k", pa, g[i], pa)
    if earth is not None:  # the Earth rate the segments share (Eq O3)
        cov = cov + lmap @ earth[i] @ lmap.T
        r_var = r_var + np.einsum("kj,jl,kl->k", proj, earth[i], proj)
    expect = float(np.sum(r_var / var))
    if dof > 0 and expect > 0:
        cov = cov * max(1.0, float(np.sum(resid**2 / var)) / expect)
    return cov


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
