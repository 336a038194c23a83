"""The gyro's ``M`` from rotations between static poses: the least-squares core (imu_tk's cost).

Between two static poses ``k`` and ``k + 1`` the body turns by ``R_k`` (the body's attitude at the
first sample of pose ``k + 1`` relative to the last sample of pose ``k``); a vector fixed in the
reference frame reads ``R_k^T v`` afterwards. Gravity is such a vector, so with the unit gravity
directions ``u_k`` measured by the calibrated accelerometer in each pose (Tedaldi, Pretto, Menegatti,
ICRA 2014)::

    r_k(M) = P_k (R_k(M)^T u_k - u_k+1)                                              (G1)

where ``R_k(M)`` integrates the corrected rates ``w = M^-1 (g - b)`` over the rotation with
:func:`align.attitude.integrate` (quaternions, fourth order) and ``P_k`` (2 x 3) projects on the
plane normal to ``u_k+1`` (the third component of G1 is second order: each rotation gives two
equations). ``M`` (9 parameters, ``g = M w + b``) minimises ``sum_k |r_k|^2`` (scipy's
Levenberg-Marquardt), started from the best ``s P`` of a scan over the scale ``s`` (readings per
rad/s: raw counts need no starting guess) and the 48 signed permutations ``P`` (a gyro turned
or mirrored relative to the accelerometer; ``det M < 0`` is then reported by the caller). The
covariance is ``s^2 (J^T J)^-1`` with the residual variance ``s^2 = sum |r_k|^2 / (2K - 9)`` over
``K`` rotations, widened by ``t_(2K-9)(0.99865) / 3`` so that 3 sigma holds its normal 99.73 % with few degrees of freedom.

Observability: column ``j`` of ``M`` is what the gyros read for a rotation about axis ``j``
(reference section 1), so its residual derivatives scale with the turn about ``j``; a sequence that
never turns about ``j`` leaves that column undetermined. The condition number of ``J`` and the
column that dominates its weakest direction say so.

Public names
------------
GyroFit, fit_gyro_matrix, direction_covariance, tangent_basis, signed_permutations, WEAK_CONDITION
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.attitude import increments, integrate_increments, quat_to_matrix

#: a condition number of the residual Jacobian above this flags the weakest column of ``M``
WEAK_CONDITION = 10.0
#: the scale scan: readings per rad/s from 1e-3 (a gyro read in krad/s) to 1e6 counts per rad/s, steps of 15 %
_SCAN = np.geomspace(1e-3, 1e6, int(np.log(1e9) / np.log(1.15)) + 1)


@dataclass(frozen=True, eq=False)
class GyroFit:
    """The least-squares solution of G1.

    Attributes
    ----------
    M, sigma_M : ndarray, shape (3, 3)
        ``g = M w + b`` in readings per rad/s, and its 1-sigma (widened for the degrees of freedom).
    residuals : ndarray, shape (K, 3)
        Per rotation: the small rotation (rad, accelerometer frame at the end pose) from the predicted to
        the measured gravity direction, ``(R_k^T u_k) x u_k+1``.
    angles : ndarray, shape (K,)
        Per rotation: the angle between the predicted and the measured gravity direction, rad.
    turns : ndarray, shape (K, 3)
        Per rotation: the rotation vector of ``R_k`` (rad, accelerometer frame at the start pose).
    column_turn : ndarray, shape (3,)
        Angle turned about each axis over the rotations used, ``sum_k int |w_j| dt`` (rad).
    dof : int
        ``2K - 9``.
    widening : float
        The factor applied to the Jacobian's 1-sigma (``t_dof(0.99865) / 3``).
    condition_number : float
        ``s_max / s_min`` of the Jacobian of G1 with respect to ``M``.
    weak_column : int
        The column of ``M`` that dominates the Jacobian's weakest direction (0, 1, 2).
    rms : float
        RMS residual angle, rad.
    ssr : float
        ``sum |r_k|^2`` over the rotations used (G1), rad^2.
    noise_ssr : float
        What the propagated noise alone would give it: ``tr((I - J J^+) C)`` (``C`` of :func:`fit_gyro_matrix`);
        ``ssr`` far above it is a model error (g-sensitivity, motion within the poses).
    """

    M: np.ndarray
    sigma_M: np.ndarray
    residuals: np.ndarray
    angles: np.ndarray
    turns: np.ndarray
    column_turn: np.ndarray
    dof: int
    widening: float
    condition_number: float
    weak_column: int
    rms: float
    ssr: float = float("nan")
    noise_ssr: float = float("nan")


def tangent_basis(u: np.ndarray) -> np.ndarray:
    """Two orthonormal vectors (2, 3) normal to the unit vector ``u`` (3,): ``P`` of G1."""
    helper = np.eye(3)[int(np.argmin(np.abs(u)))]
    e1 = np.cross(u, helper)
    e1 /= np.linalg.norm(e1)
    return np.stack([e1, np.cross(u, e1)])


class _Problem:
    """G1 for fixed data: bias-free readings over ``[lo, hi]`` and the rotation spans inside it."""

    def __init__(self, t: np.ndarray, g: np.ndarray, spans: list, dirs: np.ndarray, used: np.ndarray) -> None:
        self.lo, self.hi = spans[0][0], spans[-1][1]
        self.g = np.ascontiguousarray(g[self.lo:self.hi + 1])
        self.dt = np.diff(t[self.lo:self.hi + 1])
        self.ends = np.array([(a - self.lo, b - self.lo) for a, b in spans])
        self.dirs = dirs
        self.used = used
        self.basis = np.stack([tangent_basis(dirs[k + 1]) for k in range(len(spans))])
        self.parts = self.split(self.g)

    def split(self, g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The increments (Q4 of :mod:`align.attitude`) of the readings ``g`` taken as rates, split into their
        linear part ``S`` and coning part ``K = dt^2/12 (g_k x g_k+1)``: for ``w = A g`` (``A = M^-1``) the
        increments are ``A S_k + det(A) A^-T K_k`` (``(A u) x (A v) = det(A) A^-T (u x v)``), so one pass over
        the samples serves every ``M``."""
        coning = (self.dt * self.dt / 12.0)[:, None] * np.cross(g[:-1], g[1:])
        return increments(g, self.dt) - coning, coning

    def rotations(self, m: np.ndarray, parts: tuple | None = None) -> np.ndarray:
        """``R_k`` (K, 3, 3) for ``M = m``: one integration over ``[lo, hi]``, relative attitudes."""
        lin, coning = self.parts if parts is None else parts
        a = np.linalg.inv(m)
        q = integrate_increments(lin @ a.T + np.linalg.det(a) * (coning @ m))
        c0, c1 = quat_to_matrix(q[self.ends[:, 0]]), quat_to_matrix(q[self.ends[:, 1]])
        return np.einsum("kji,kjl->kil", c0, c1)

    def resid(self, p: np.ndarray, parts: tuple | None = None) -> np.ndarray:
        """G1 for ``M = p`` (9,), the rotations used, stacked (2K,)."""
        r = self.rotations(p.reshape(3, 3), parts)
        v = np.einsum("kji,kj->ki", r, self.dirs[:-1]) - self.dirs[1:]
        return np.einsum("kij,kj->ki", self.basis, v)[self.used].ravel()

    def direction_jacobian(self, m: np.ndarray) -> np.ndarray:
        """d G1 / d (stacked directions): ``P_k R_k^T`` on ``u_k``, ``-P_k`` on ``u_k+1`` -> (2K, 3(K + 1))."""
        r = self.rotations(m)
        k = len(r)
        out = np.zeros((k, 2, 3 * (k + 1)))
        for i in range(k):
            out[i, :, 3 * i:3 * i + 3] = self.basis[i] @ r[i].T
            out[i, :, 3 * i + 3:3 * i + 6] = -self.basis[i]
        return out[self.used].reshape(-1, 3 * (k + 1))


def signed_permutations() -> np.ndarray:
    """The 24 rotations that map axes onto axes (signed permutation matrices of determinant +1), (24, 3, 3),
    the identity first."""
    from itertools import permutations, product

    out = []
    for perm in permutations(range(3)):
        for signs in product((1.0, -1.0), repeat=3):
            q = np.zeros((3, 3))
            q[range(3), perm] = signs
            if np.linalg.det(q) > 0:
                out.append(q)
    return np.array(out)


def _start(problem: _Problem) -> np.ndarray:
    """The best ``s P`` over the scale scan and the 48 signed permutations ``P`` (a gyro whose axes are turned
    or mirrored relative to the accelerometer's: two chips, columns in another order or of another sign).

    For a proper ``Q`` the rates ``(s Q)^-1 g = Q^T (g / s)`` turn the body by ``R_k(s Q) = Q^T R_k(s I) Q``
    (``Q^T [v]x Q = [Q^T v]x``), and ``R_k(-s Q) = Q^T R_k(-s I) Q``: two integrations per scale serve all 48.
    """
    perms = signed_permutations()
    u0, u1 = problem.dirs[:-1][problem.used], problem.dirs[1:][problem.used]
    best = (np.inf, np.eye(3))
    for s in _SCAN:
        for sign in (1.0, -1.0):
            r0 = problem.rotations(sign * s * np.eye(3))[problem.used]                  # (K, 3, 3)
            r = np.einsum("pji,kjl,plm->pkim", perms, r0, perms)                         # Q^T R0 Q
            v = np.einsum("pkji,kj->pki", r, u0) - u1                                    # R^T u_k - u_k+1
            cost = (v ** 2).sum(axis=2) - np.einsum("pki,ki->pk", v, u1) ** 2            # |P_k v|^2
            total = cost.sum(axis=1)
            j = int(np.argmin(total))
            if total[j] < best[0] * (1 - 1e-9):
                best = (float(total[j]), sign * s * perms[j])
    return best[1]


def direction_covariance(means: np.ndarray, var_means: np.ndarray, m_a: np.ndarray, b_a: np.ndarray) -> tuple:
    """The poses' unit gravity directions and their covariance, through the accelerometer's ``|a| = g`` fit.

    ``u_k = f_k / |f_k|``, ``f_k = U (m_k - b)`` with ``U = M_a^-1``; the means ``m_k`` carry white noise
    (``var_means``) and move ``U`` and ``b`` too (the fit ``r_i = |U (m_i - b)| - g`` re-solved, to first
    order: ``d theta = -(J_theta^+) J_m dm``), so the directions' errors are correlated across poses.

    Parameters
    ----------
    means, var_means : ndarray, shape (P, 3)
        Each pose's mean reading and the variance of that mean (readings, readings^2).
    m_a, b_a : ndarray, shapes (3, 3), (3,)
        The accelerometer's fit.

    Returns
    -------
    dirs : ndarray, shape (P, 3)
    cov : ndarray, shape (3P, 3P)
    """
    u_mat = np.linalg.inv(m_a)
    d = means - b_a
    f = d @ u_mat.T
    nf = np.linalg.norm(f, axis=1)
    dirs = f / nf[:, None]
    p = len(means)
    iu = np.triu_indices(3)
    # d f_k / d theta: U's six upper elements (e_p d_q), then b (-U)
    df_dth = np.zeros((p, 3, 9))
    for c, (i, j) in enumerate(zip(*iu)):
        df_dth[:, i, c] = d[:, j]
    df_dth[:, :, 6:] = -u_mat
    j_th = np.einsum("ki,kic->kc", dirs, df_dth)                  # accel fit residuals vs theta (P, 9)
    j_m = np.zeros((p, 3 * p))
    for k in range(p):
        j_m[k, 3 * k:3 * k + 3] = dirs[k] @ u_mat
    norms = np.linalg.norm(j_th, axis=0)
    norms[norms == 0] = 1.0
    dth_dm = -np.linalg.lstsq(j_th / norms, j_m, rcond=None)[0] / norms[:, None]   # (9, 3P)
    proj = (np.eye(3) - dirs[:, :, None] * dirs[:, None, :]) / nf[:, None, None]
    jac = np.einsum("kij,kjc->kic", proj, np.einsum("kjc,cm->kjm", df_dth, dth_dm)).reshape(3 * p, 3 * p)
    for k in range(p):
        jac[3 * k:3 * k + 3, 3 * k:3 * k + 3] += proj[k] @ u_mat
    return dirs, (jac * np.asarray(var_means, float).ravel()) @ jac.T


def fit_gyro_matrix(t: np.ndarray, g: np.ndarray, spans: list, dirs: np.ndarray, used: np.ndarray | None = None,
                    m0: np.ndarray | None = None, dir_cov: np.ndarray | None = None,
                    offsets: np.ndarray | None = None, offset_cov: np.ndarray | None = None) -> GyroFit:
    """Solve G1 for the gyro's ``M``.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Time, s (the sample intervals of the integration come from it).
    g : ndarray, shape (n, 3)
        Gyro readings minus the bias, SI (rad/s) or counts.
    spans : list of (int, int)
        Rotation ``k``: from sample ``spans[k][0]`` (the last of pose ``k``) to ``spans[k][1]`` (the first of
        pose ``k + 1``), increasing and not overlapping.
    dirs : ndarray, shape (K + 1, 3)
        Unit gravity direction of every pose, accelerometer frame.
    used : ndarray of bool, shape (K,), optional
        The rotations in the fit (all when not given); the others are integrated and reported only.
    m0 : ndarray, shape (3, 3), optional
        Starting ``M``; default the best ``s P`` of a scan over the scale and the signed permutations.
    dir_cov : ndarray, shape (3(K + 1), 3(K + 1)), optional
        Covariance of the stacked directions (:func:`direction_covariance`).
    offsets, offset_cov : ndarray, shapes (m, n, 3) and (m, m), optional
        What was removed from the readings as ``sum_i theta_i offsets[i]`` (a constant bias: ``e_j`` at every
        sample; a g-sensitivity: ``f_i(t) e_j``) and the covariance of ``theta``.

    Notes
    -----
    ``cov(M) = J^+ (s^2 w^2 I + C) J^+T``: ``s^2 = sum r^2 / (2K - 9)`` the residual variance, ``w`` =
    ``t_(2K-9)(0.99865) / 3`` its widening for few degrees of freedom, ``C`` the residuals' covariance from
    the gravity directions and the removed offsets, propagated (errors shared by neighbouring or by all
    rotations, which the residuals cannot show). The residuals hold part of ``C`` too, so the sum leans
    to the safe side: on simulated sessions the errors' rms is about 0.8 sigma (subtracting that part,
    ``tr((I - J J^+) C)``, gives 1.0 on average but truncates to nothing on a few degrees of freedom).

    Returns
    -------
    GyroFit
    """
    from scipy.optimize import least_squares
    from scipy.stats import t as student

    used = np.ones(len(spans), bool) if used is None else np.asarray(used, bool)
    problem = _Problem(np.asarray(t, float), np.asarray(g, float), spans, np.asarray(dirs, float), used)
    x0 = (_start(problem) if m0 is None else np.asarray(m0, float)).ravel()
    sol = least_squares(problem.resid, x0, method="lm", x_scale="jac")
    m = sol.x.reshape(3, 3)
    k = int(used.sum())
    dof = max(2 * k - 9, 1)
    jac = sol.jac
    sv, vt = np.linalg.svd(jac, full_matrices=False)[1:]
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")
    weak = int(np.argmax((vt[-1].reshape(3, 3) ** 2).sum(axis=0)))
    pinv = (vt.T / np.where(sv > 0, sv, np.inf)) @ np.linalg.svd(jac, full_matrices=False)[0].T   # (9, 2K)
    extra = np.zeros((len(sol.fun), len(sol.fun)))
    if dir_cov is not None:
        grad = problem.direction_jacobian(m)
        extra += grad @ dir_cov @ grad.T
    if offsets is not None:
        assert offset_cov is not None, "offsets come with their covariance offset_cov"
        steps = 1e-3 * np.sqrt(np.maximum(np.diag(offset_cov), 1e-300))
        grad = np.stack([(problem.resid(sol.x, problem.split(problem.g - h * o[problem.lo:problem.hi + 1])) - sol.fun)
                         / h for o, h in zip(offsets, steps)], axis=1)
        extra += grad @ offset_cov @ grad.T
    s2 = float(np.sum(sol.fun ** 2)) / dof
    widening = float(student.ppf(0.99865, dof) / 3.0)
    cov = pinv @ (s2 * widening ** 2 * np.eye(len(sol.fun)) + extra) @ pinv.T
    sigma = np.sqrt(np.maximum(np.diag(cov), 0.0)).reshape(3, 3)
    rots = problem.rotations(m)
    pred = np.einsum("kji,kj->ki", rots, problem.dirs[:-1])
    resid = np.cross(pred, problem.dirs[1:])
    from scipy.spatial.transform import Rotation

    turns = Rotation.from_matrix(rots).as_rotvec()
    w = np.abs(np.linalg.solve(m if cond < 1e4 else x0.reshape(3, 3), problem.g.T).T)  # a wild M: the start
    dt_mid = np.concatenate([problem.dt, [0.0]])
    column_turn = np.zeros(3)
    for (a, b), u in zip(problem.ends, used):
        if u:
            column_turn += (w[a:b] * dt_mid[a:b, None]).sum(axis=0)
    ang = np.arctan2(np.linalg.norm(resid, axis=1), np.einsum("ki,ki->k", pred, problem.dirs[1:]))
    noise_ssr = float(np.trace(extra) - np.trace(jac @ pinv @ extra))
    return GyroFit(m, sigma, resid, ang, turns, column_turn, dof, widening, cond, weak,
                   float(np.sqrt(np.mean(ang[used] ** 2))), float(np.sum(sol.fun ** 2)), noise_ssr)
