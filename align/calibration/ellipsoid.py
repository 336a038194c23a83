"""Ellipsoid fits for the magnetometer: algebraic starting values and the soft-iron parametrisation.

A quadric ``a x^2 + b y^2 + c z^2 + 2f yz + 2g xz + 2h xy + 2p x + 2q y + 2r z + d = 0``
fitted to the (normalised) readings gives the centre (hard iron) and shape
``Q`` of the ellipsoid ``(x - c)^T Q (x - c) = 1``; ``W = Q^(1/2)`` maps it to
the unit sphere. Three models: a sphere (``W`` a multiple of the identity), an
axis-aligned ellipsoid (``W`` diagonal), a general one (``W`` symmetric, Li and
Griffiths 2004, ellipsoid-specific). :func:`refine` then fits the ellipsoid
geometrically, by the first-order distance of each reading from it in the
readings' own space (the Sampson distance), and gives the parameters'
Gauss-Newton covariance scaled by the residual variance.

Public names
------------
MODELS, algebraic_fit, pack, unpack, sampson, refine, FULL, full_params
"""

from __future__ import annotations

import numpy as np

from align.errors import TestError

#: soft-iron models: W a multiple of the identity, diagonal, symmetric
MODELS = ("sphere", "diagonal", "symmetric")


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


def algebraic_fit(x: np.ndarray, model: str) -> tuple[np.ndarray, np.ndarray]:
    """Algebraic fit on normalised data: centre and ``W`` with ``|W (x - c)| ~ 1``.

    Parameters
    ----------
    x : ndarray, shape (n, 3)
        Readings, centred and scaled to about unit radius.
    model : {"sphere", "diagonal", "symmetric"}
        ``W`` a multiple of the identity, diagonal, or symmetric (Li-Griffiths).

    Returns
    -------
    centre : ndarray, shape (3,)
    W : ndarray, shape (3, 3)
        Symmetric positive definite.
    """
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


def pack(w: np.ndarray, model: str) -> np.ndarray:
    """The free parameters of ``W`` under ``model``: 1, 3 or 6 (upper triangle)."""
    if model == "sphere":
        return np.array([w[0, 0]])
    if model == "diagonal":
        return np.diag(w).copy()
    return w[np.triu_indices(3)]


def unpack(p: np.ndarray, model: str) -> np.ndarray:
    """``W`` (3, 3) from the parameters written by :func:`pack`."""
    if model == "sphere":
        return np.eye(3) * p[0]
    if model == "diagonal":
        return np.diag(p)
    w = np.zeros((3, 3))
    w[np.triu_indices(3)] = p
    return w + np.triu(w, 1).T


#: the full parameter vector of a calibration: the centre (3) and the upper triangle of ``W`` (6),
#: ``W[0,0], W[0,1], W[0,2], W[1,1], W[1,2], W[2,2]``
FULL = ("h_x", "h_y", "h_z", "W_xx", "W_xy", "W_xz", "W_yy", "W_yz", "W_zz")


def full_params(centre: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``(centre, upper triangle of W)``, shape (9,), the order of :data:`FULL`."""
    return np.concatenate([np.asarray(centre, float), np.asarray(w, float)[np.triu_indices(3)]])


def sampson(p: np.ndarray, x: np.ndarray, model: str, target: float = 1.0, noise: float = 0.0) -> np.ndarray:
    """Signed first-order distance of each reading from the ellipsoid ``|W (x - c)| = target``.

    With ``y = W (x - c)`` and ``rho = |y|``, the algebraic residual ``rho - target``
    divided by its gradient's length in the readings' space, ``g = |d rho / d x| = |W y| / rho``
    (``W`` symmetric)::

        r = (rho - target) / g  -  noise^2 kappa / 2,    kappa = (tr W^2 - n^T W^2 n) / (rho g)

    The first term is the Euclidean distance to the surface to first order, whatever ``W``. The plain
    residual ``rho - target`` is that distance times ``g``, a gain that depends on the parameters:
    least squares then buys a smaller cost by shrinking the gain where the data are few (a larger
    ellipsoid along the poorly covered direction), a bias of order ``sigma^2`` that does not fall
    with more samples (on hemisphere captures, 2 sigma at 1 % noise, and growing with the sample
    count). The normalised residual has unit gain and no such bias. The second term removes the
    remaining second-order one: isotropic noise of variance ``noise^2`` moves a reading off the
    surface by ``noise^2 kappa / 2`` on average, ``kappa`` the sum of the surface's principal
    curvatures (``n = W y / |W y|`` the normal; ``2 / R`` on a sphere of radius ``R``, where the
    offset is the familiar ``E|x + e| - |x| = noise^2 / R``); without it a known field pulls ``W``
    low by ``noise^2 / R^2``.

    Parameters
    ----------
    p : ndarray
        ``(c, pack(W, model))``.
    x : ndarray, shape (n, 3)
        Readings (normalised: centred and scaled).
    model : str
    target : float
        Radius of the sphere the calibration maps to.
    noise : float
        1-sigma of the readings' noise per axis, unit of ``x`` (0: no second-order term).

    Returns
    -------
    ndarray, shape (n,)
        Distances, same unit as ``x``.
    """
    w = unpack(p[3:], model)
    y = (x - p[:3]) @ w.T
    rho = np.linalg.norm(y, axis=1)
    wy = y @ w.T
    g = np.linalg.norm(wy, axis=1) / rho
    r = (rho - target) / g
    if noise:
        w2 = w @ w
        nrm = wy / np.linalg.norm(wy, axis=1, keepdims=True)
        kappa = (np.trace(w2) - np.einsum("ni,ij,nj->n", nrm, w2, nrm)) / (rho * g)
        r = r - 0.5 * noise**2 * kappa
    return r


def _jacobian(fun, p: np.ndarray, step: float = 1e-6) -> np.ndarray:
    """Central-difference Jacobian of ``fun`` at ``p``, shape (len(fun(p)), len(p))."""
    cols = []
    for k in range(len(p)):
        dp = np.zeros(len(p))
        dp[k] = step * max(1.0, abs(p[k]))
        cols.append((fun(p + dp) - fun(p - dp)) / (2 * dp[k]))
    return np.column_stack(cols)


def refine(x: np.ndarray, centre: np.ndarray, w: np.ndarray, model: str, target: float | None = None,
           leash: float = 0.3) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """Geometric fit of the ellipsoid by the Sampson distance (:func:`sampson`), from the algebraic fit.

    Minimises ``sum r_i^2`` over ``p = (c, pack(W))`` (Levenberg-Marquardt; a centre that moves
    ``leash`` data radii or more from the start is running away along a poorly covered direction);
    a second pass adds the curvature offset of the noise the first pass's residuals show.
    The covariance is Gauss-Newton's with the residual variance,
    ``cov = (J^T J)^-1 sum r_i^2 / (n - k)`` (``J = dr/dp`` by central differences at the solution).

    Parameters
    ----------
    x : ndarray, shape (n, 3)
        Normalised readings (about unit radius).
    centre, w : ndarray, shapes (3,) and (3, 3)
        Starting values (:func:`algebraic_fit`).
    model : str
    target : float, optional
        Known radius; without it the radius is 1 and the size goes into ``W``.
    leash : float
        Largest move of the centre.

    Returns
    -------
    p : ndarray, shape (3 + k,)
        ``(c, pack(W, model))``.
    cov : ndarray, shape (3 + k, 3 + k)
    residuals : ndarray, shape (n,)
    at_bound : bool
        The centre moved ``leash`` or more (a runaway fit).
    """
    from scipy.optimize import least_squares

    t = 1.0 if target is None else float(target)
    p0 = np.concatenate([centre, pack(w, model)])
    # Levenberg-Marquardt (MINPACK: no threaded BLAS, fast on a busy machine); the leash is checked after
    sol = least_squares(sampson, p0, args=(x, model, t), method="lm", x_scale="jac")
    dof = max(len(x) - len(sol.x), 1)
    noise = float(np.sqrt(np.sum(sol.fun**2) / dof))  # second pass: the curvature offset of this noise
    sol = least_squares(sampson, sol.x, args=(x, model, t, noise), method="lm", x_scale="jac")
    at_bound = bool(np.max(np.abs(sol.x[:3] - centre)) >= leash or not np.all(np.isfinite(sol.x)))
    r = sampson(sol.x, x, model, t, noise)
    jac = _jacobian(lambda q: sampson(q, x, model, t, noise), sol.x)
    cov = np.linalg.pinv(jac.T @ jac) * float(r @ r) / dof
    return sol.x, cov, r, at_bound
