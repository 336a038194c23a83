"""Ellipsoid fits for the magnetometer: algebraic starting values and the soft-iron parametrisation.

A quadric ``a x^2 + b y^2 + c z^2 + 2f yz + 2g xz + 2h xy + 2p x + 2q y + 2r z + d = 0``
fitted to the (normalised) readings gives the centre (hard iron) and shape
``Q`` of the ellipsoid ``(x - c)^T Q (x - c) = 1``; ``W = Q^(1/2)`` maps it to
the unit sphere. Three models: a sphere (``W`` a multiple of the identity), an
axis-aligned ellipsoid (``W`` diagonal), a general one (``W`` symmetric, Li and
Griffiths 2004, ellipsoid-specific).

Public names
------------
MODELS, algebraic_fit, pack, unpack
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
