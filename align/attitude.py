"""Attitude kinematics: unit quaternions and the integration of sampled body rates.

A quaternion is ``q = (w, x, y, z)`` (scalar first, unit norm); its direction cosine matrix
``C(q)`` maps body vectors to the reference frame, ``v_ref = C(q) v_body``. With the body rate
``omega`` (rad/s, body frame) the attitude obeys::

    dq/dt = 1/2 q (x) (0, omega)                                                    (Q1)

and over one sample interval ``[t_k, t_k+1]`` it is updated by the rotation vector ``phi_k`` of
that interval::

    q_k+1 = q_k (x) exp(phi_k),   exp(phi) = (cos(|phi|/2), sin(|phi|/2) phi/|phi|)   (Q2)

The rotation vector of an interval follows from Bortz's equation ``dphi/dt = omega + 1/2 phi x
omega + ...``; for rates sampled at the interval's ends and varying linearly between them, to
third order in ``dt``::

    phi_k = (omega_k + omega_k+1) dt/2 + dt^2/12 (omega_k x omega_k+1)              (Q3)

(the second term is the coning correction: zero for a rate of fixed direction). A record's
smooth rates are integrated more closely with the first term replaced by the integral of the
cubic through the four samples around the interval (uniform steps: ``dt/24 (-omega_k-1 +
13 omega_k + 13 omega_k+1 - omega_k+2)``)::

    phi_k = int_k p(t) dt + dt^2/12 (omega_k x omega_k+1)                            (Q4)

On a coning motion (half-angle 0.05 rad at 5 Hz, 2 s) Q4's attitude error falls as ``dt^4``
(1.5e-4 rad at 100 Hz, 3.7e-8 rad at 800 Hz) where Q3's falls as ``dt^2`` (5.1e-3, 8.0e-5 rad);
``tests/foundation/test_attitude.py`` holds both orders. ``(x)`` is the Hamilton product.
The compiled kernels :func:`qmul`, :func:`qexp` and :func:`increment` (Q3) may be called from
other numba code (a strapdown integrator's inner loop).

Public names
------------
qmul, qexp, increment, increments, integrate_increments, integrate, rotation, quat_to_matrix, quat_multiply, quat_from_rotvec
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def qmul(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product ``p (x) q`` of two quaternions (4,) (compiled)."""
    out = np.empty(4)
    out[0] = p[0] * q[0] - p[1] * q[1] - p[2] * q[2] - p[3] * q[3]
    out[1] = p[0] * q[1] + p[1] * q[0] + p[2] * q[3] - p[3] * q[2]
    out[2] = p[0] * q[2] - p[1] * q[3] + p[2] * q[0] + p[3] * q[1]
    out[3] = p[0] * q[3] + p[1] * q[2] - p[2] * q[1] + p[3] * q[0]
    return out


@njit(cache=True, inline="always")
def qexp(phi: np.ndarray) -> np.ndarray:
    """The unit quaternion of rotation vector ``phi`` (3,), rad (Q2; series near zero) (compiled)."""
    a2 = phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2]
    out = np.empty(4)
    if a2 < 1e-12:  # cos and sin(a/2)/a by their series: exact to double precision here
        out[0] = 1.0 - a2 / 8.0
        s = 0.5 - a2 / 48.0
    else:
        a = np.sqrt(a2)
        out[0] = np.cos(0.5 * a)
        s = np.sin(0.5 * a) / a
    out[1], out[2], out[3] = s * phi[0], s * phi[1], s * phi[2]
    return out


@njit(cache=True, inline="always")
def increment(w0: np.ndarray, w1: np.ndarray, dt: float) -> np.ndarray:
    """Rotation vector (3,) of one interval from the rates (3,) at its ends (Q3) (compiled)."""
    out = np.empty(3)
    c = dt * dt / 12.0
    out[0] = 0.5 * dt * (w0[0] + w1[0]) + c * (w0[1] * w1[2] - w0[2] * w1[1])
    out[1] = 0.5 * dt * (w0[1] + w1[1]) + c * (w0[2] * w1[0] - w0[0] * w1[2])
    out[2] = 0.5 * dt * (w0[2] + w1[2]) + c * (w0[0] * w1[1] - w0[1] * w1[0])
    return out


@njit(cache=True)
def _integrate(phi: np.ndarray, q0: np.ndarray) -> np.ndarray:
    n = phi.shape[0] + 1
    out = np.empty((n, 4))
    q = q0.copy()
    out[0] = q
    for k in range(n - 1):
        q = qmul(q, qexp(phi[k]))
        # renormalise: keeps |q| = 1 to rounding over millions of steps
        q = q / np.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
        out[k + 1] = q
    return out


def _steps(dt: float | np.ndarray, n: int) -> np.ndarray:
    d = np.broadcast_to(np.asarray(dt, float), (max(n - 1, 0),))
    if not np.all(np.isfinite(d)) or np.any(d <= 0):
        raise ValueError("sample intervals must be finite and positive")
    return np.ascontiguousarray(d)


def _cubic_weights(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each interval of the times ``t`` (n >= 4): the first of its four nodes, and the weights
    (n - 1, 4) that integrate the cubic through them over the interval (Q4)."""
    n = len(t)
    first = np.clip(np.arange(n - 1) - 1, 0, n - 4)
    h = t[1:] - t[:-1]
    x = (t[first[:, None] + np.arange(4)] - t[:-1, None]) / h[:, None]  # nodes, the interval is [0, 1]
    vander = x[:, None, :] ** np.arange(4)[None, :, None]  # (n-1, power, node)
    moments = 1.0 / np.arange(1, 5)  # int_0^1 x^p dx
    weights = np.linalg.solve(vander, np.broadcast_to(moments, (n - 1, 4))[..., None])[..., 0]
    return first, weights * h[:, None]


def increments(w: np.ndarray, dt: float | np.ndarray, order: int = 4) -> np.ndarray:
    """Rotation vectors of every sample interval: Q4 (``order=4``), or Q3 (``order=2``, or fewer than 4 samples).

    Parameters
    ----------
    w : ndarray, shape (n, 3)
        Body rates at the samples, rad/s.
    dt : float or ndarray, shape (n - 1,)
        Sample intervals, s (an array for a time column's own, uneven steps).
    order : {4, 2}
        The order of the attitude error in ``dt`` on smooth motion.

    Returns
    -------
    ndarray, shape (n - 1, 3)
        ``phi_k``, rad.
    """
    w = np.asarray(w, float)
    d = _steps(dt, len(w))
    w0, w1 = w[:-1], w[1:]
    coning = (d * d / 12.0)[:, None] * np.cross(w0, w1)
    if order == 2 or len(w) < 4:
        return 0.5 * d[:, None] * (w0 + w1) + coning
    first, weights = _cubic_weights(np.concatenate([[0.0], np.cumsum(d)]))
    nodes = w[first[:, None] + np.arange(4)]  # (n-1, 4, 3)
    return np.einsum("kj,kjc->kc", weights, nodes) + coning


def integrate_increments(phi: np.ndarray, q0: np.ndarray | None = None) -> np.ndarray:
    """Attitudes (n + 1, 4) from rotation vectors (n, 3) (Q2), starting at ``q0`` (identity when not given)."""
    start = np.array([1.0, 0.0, 0.0, 0.0]) if q0 is None else np.asarray(q0, float)
    return _integrate(np.ascontiguousarray(phi, float).reshape(-1, 3), start / np.linalg.norm(start))


def integrate(w: np.ndarray, dt: float | np.ndarray, q0: np.ndarray | None = None, order: int = 4) -> np.ndarray:
    """Attitude at every sample from the body rates (Q1, Q2, Q4; Q3 with ``order=2``).

    Parameters
    ----------
    w : ndarray, shape (n, 3)
        Body rates at the samples, rad/s.
    dt : float or ndarray, shape (n - 1,)
        Sample intervals, s (an array for a time column's own steps).
    q0 : ndarray, shape (4,), optional
        Attitude at the first sample (identity when not given).
    order : {4, 2}
        See :func:`increments`.

    Returns
    -------
    ndarray, shape (n, 4)
        Unit quaternions (scalar first); ``C(q_k)`` maps body vectors at sample ``k`` to the
        reference frame of ``q0``.
    """
    w = np.ascontiguousarray(w, float)
    if w.ndim != 2 or w.shape[1] != 3 or len(w) < 1:
        raise ValueError("rates must have shape (n, 3), n >= 1")
    return integrate_increments(increments(w, dt, order), q0)


def rotation(w: np.ndarray, dt: float | np.ndarray, order: int = 4) -> np.ndarray:
    """The body's turn over the record: ``C`` of the last attitude relative to the first.

    A vector fixed in the reference frame reads ``v_end = C^T v_start`` in the body frame (gravity
    seen by a sensor before and after a rotation).

    Returns
    -------
    ndarray, shape (3, 3)
    """
    return quat_to_matrix(integrate(w, dt, order=order)[-1])


def quat_multiply(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product of quaternion arrays (..., 4), broadcast."""
    p, q = np.asarray(p, float), np.asarray(q, float)
    pw, px, py, pz = np.moveaxis(p, -1, 0)
    qw, qx, qy, qz = np.moveaxis(q, -1, 0)
    return np.stack([pw * qw - px * qx - py * qy - pz * qz, pw * qx + px * qw + py * qz - pz * qy,
                     pw * qy - px * qz + py * qw + pz * qx, pw * qz + px * qy - py * qx + pz * qw], axis=-1)


def quat_from_rotvec(phi: np.ndarray) -> np.ndarray:
    """Unit quaternions (..., 4) of rotation vectors (..., 3), rad (Q2)."""
    phi = np.asarray(phi, float)
    a = np.linalg.norm(phi, axis=-1, keepdims=True)
    small = a < 1e-6
    s = np.where(small, 0.5 - a * a / 48.0, np.sin(0.5 * a) / np.where(small, 1.0, a))
    return np.concatenate([np.where(small, 1.0 - a * a / 8.0, np.cos(0.5 * a)), s * phi], axis=-1)


def quat_to_matrix(q: np.ndarray) -> np.ndarray:
    """Direction cosine matrices (..., 3, 3) of unit quaternions (..., 4): ``v_ref = C v_body``."""
    q = np.asarray(q, float)
    w, x, y, z = np.moveaxis(q / np.linalg.norm(q, axis=-1, keepdims=True), -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
    ], axis=-2)
