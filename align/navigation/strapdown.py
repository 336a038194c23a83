"""A strapdown integrator: attitude, velocity and position in a local level north-east-down frame.

Frames: the navigation frame ``n`` is local level, **north, east, down** (NED), fixed to the Earth
at the start point; the body frame ``b`` is the sensor's (x forward, y right, z down when level).
``q`` is the attitude quaternion (scalar first, :mod:`align.attitude`), ``C = C(q)`` maps body
vectors to NED. Seed 002's Eq 1 with the transport rate ``omega_en`` left out (low speed over a
small area: its Eq 2; the Earth rate is kept as an option)::

    dC/dt = C [omega_ib x] - [omega_ie x] C                                           (N1)
    dv/dt = C f - 2 omega_ie x v + g                                                  (N2)
    dp/dt = v                                                                         (N3)

with ``omega_ib`` the gyro rates, ``f`` the specific force (the accelerometers), ``omega_ie`` the
Earth rate in NED, ``Omega (cos L, 0, -sin L)`` at latitude ``L`` (zero when the Earth rate is
left out), ``g = (0, 0, g)`` the local gravity (normal gravity, :func:`normal_gravity`) and ``p``
the position in metres north, east and down of the start point.

Two speeds (Savage, *Strapdown Analytics* ch. 7): the sensor samples at ``fs`` are first summed
into increments over each navigation step of ``m`` samples (:func:`step_increments`): the
rotation vector of the step, from the attitude integrated sample by sample with the coning term
(:func:`align.attitude.integrate`, Q3/Q4 of that module), and the velocity increment
``dv = int C(q_start^-1 q(t)) f dt`` in the body frame at the step's start (rotation and sculling
included, trapezoid rule over the samples). The navigation update at ``h = m / fs`` is then
(``(I - [omega_ie h x] / 2)`` takes ``dv``, summed in the body's inertial turn, to the turning
navigation frame: without it a body at rest would creep at ``omega_ie g h / 2``)::

    q_k+1 = exp(-omega_ie h) (x) q_k (x) exp(dtheta_k)                              (N4)
    v_k+1 = v_k + (I - [omega_ie h x] / 2) C(q_k) dv_k + (g - 2 omega_ie x v_k) h     (N5)
    p_k+1 = p_k + (v_k + v_k+1) h / 2                                                 (N6)

The attitude error falls as ``dt^4`` (Q4) on smooth motion, velocity and position as ``h^2``
(trapezoid rules; ``tests/navigation/test_strapdown*.py``). The compiled step
:func:`nav_step` is shared by :func:`navigate` (one record) and the Monte Carlo
(:mod:`align.navigation.montecarlo`).

Public names
------------
Trajectory, navigate, step_increments, nav_step, normal_gravity, earth_rate_ned, euler_from_quat,
quat_from_euler, quat_log, level_attitude, rotate
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from align.attitude import integrate, qexp, qmul, quat_multiply
from align.earth import EARTH_RATE
from align.errors import InputError
from align.values import Value

#: the identity quaternion
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


def normal_gravity(latitude: float = 0.0, height: float = 0.0) -> float:
    """Normal gravity (m/s^2) at geodetic ``latitude`` (rad) and ``height`` (m): Somigliana's formula on
    WGS-84 with the free-air term ``-3.086e-6 height`` (gravity plus centrifugal: what a static
    accelerometer measures)."""
    s2 = np.sin(latitude) ** 2
    return float(9.7803253359 * (1 + 0.00193185265241 * s2) / np.sqrt(1 - 0.00669437999013 * s2) - 3.086e-6 * height)


def earth_rate_ned(latitude: float) -> np.ndarray:
    """Earth rate in NED at ``latitude`` (rad): ``Omega (cos L, 0, -sin L)``, rad/s, shape (3,)."""
    return EARTH_RATE * np.array([np.cos(latitude), 0.0, -np.sin(latitude)])


def rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``C(q) v`` for quaternions (..., 4) and vectors (..., 3), broadcast: ``v + 2 w (u x v) + 2 u x (u x v)``."""
    q, v = np.asarray(q, float), np.asarray(v, float)
    u = q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + q[..., :1] * t + np.cross(u, t)


def quat_log(q: np.ndarray) -> np.ndarray:
    """Rotation vectors (..., 3), rad, of unit quaternions (..., 4) (the inverse of Q2; angle in [0, pi])."""
    q = np.asarray(q, float)
    q = np.where(q[..., :1] < 0, -q, q)
    s = np.linalg.norm(q[..., 1:], axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(s, q[..., :1])
    small = s < 1e-12
    factor = np.where(small, 2.0 / np.maximum(q[..., :1], 1e-300), angle / np.where(small, 1.0, s))
    return factor * q[..., 1:]


def euler_from_quat(q: np.ndarray) -> np.ndarray:
    """Roll, pitch and heading (..., 3), rad, of body-to-NED quaternions (..., 4): ``C = Rz(heading) Ry(pitch)
    Rx(roll)``; heading in (-pi, pi]."""
    q = np.asarray(q, float)
    w, x, y, z = np.moveaxis(q / np.linalg.norm(q, axis=-1, keepdims=True), -1, 0)
    roll = np.arctan2(2 * (y * z + w * x), 1 - 2 * (x * x + y * y))
    pitch = -np.arcsin(np.clip(2 * (x * z - w * y), -1.0, 1.0))
    heading = np.arctan2(2 * (x * y + w * z), 1 - 2 * (y * y + z * z))
    return np.stack([roll, pitch, heading], axis=-1)


def quat_from_euler(roll: float = 0.0, pitch: float = 0.0, heading: float = 0.0) -> np.ndarray:
    """The body-to-NED quaternion (4,) of roll, pitch, heading (rad): ``Rz(heading) Ry(pitch) Rx(roll)``."""
    def axis(k: int, a: float) -> np.ndarray:
        out = np.zeros(4)
        out[0], out[k] = np.cos(a / 2), np.sin(a / 2)
        return out
    return quat_multiply(quat_multiply(axis(3, heading), axis(2, pitch)), axis(1, roll))


def level_attitude(f_mean: np.ndarray, heading: float = 0.0) -> np.ndarray:
    """Coarse levelling: the quaternion whose roll and pitch make the mean specific force ``f_mean`` (3,) of a
    static body point up (``f = C^T (0, 0, -g)``), at the given heading (rad)."""
    fx, fy, fz = np.asarray(f_mean, float)
    roll = np.arctan2(-fy, -fz)
    pitch = np.arctan2(fx, np.hypot(fy, fz))
    return quat_from_euler(roll, pitch, heading)


def step_increments(w: np.ndarray, f: np.ndarray, dt: float, m: int = 1, order: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Sensor samples summed into the increments of navigation steps of ``m`` samples (module docstring).

    Parameters
    ----------
    w, f : ndarray, shape (n, 3)
        Body rates (rad/s, inertial: what gyros measure) and specific force (m/s^2) at the samples.
    dt : float
        Sample interval, s.
    m : int
        Samples per navigation step; ``(n - 1) // m`` steps are formed (a remainder is left out).
    order : {4, 2}
        Attitude order within a step (:func:`align.attitude.increments`).

    Returns
    -------
    dtheta : ndarray, shape (K, 3)
        Rotation vector of each step (the body's turn over it, coning included), rad.
    dv : ndarray, shape (K, 3)
        ``int C(q_start^-1 q(t)) f dt`` over each step, in the body frame at its start, m/s.
    """
    w, f = np.asarray(w, float), np.asarray(f, float)
    if w.shape != f.shape or w.ndim != 2 or w.shape[1] != 3:
        raise ValueError("rates and specific force must both have shape (n, 3)")
    steps = (len(w) - 1) // m
    if steps < 1:
        raise InputError(f"{len(w)} samples make no navigation step of {m} samples", "{duration}")
    n = steps * m + 1
    q = integrate(w[:n], dt, order=order)
    start = q[:-1:m]
    idx = np.arange(steps)[:, None] * m + np.arange(m + 1)[None, :]  # (K, m + 1) samples of each step
    rel = quat_multiply((start * np.array([1.0, -1.0, -1.0, -1.0]))[:, None, :], q[idx])
    g = rotate(rel, f[idx])  # specific force in the step-start body frame
    dv = 0.5 * dt * (g[:, :-1] + g[:, 1:]).sum(axis=1)
    return quat_log(rel[:, -1]), dv


@njit(cache=True)
def nav_step(q: np.ndarray, v: np.ndarray, p: np.ndarray, dth: np.ndarray, dv: np.ndarray, h: float,
             g: np.ndarray, wie: np.ndarray, qe: np.ndarray) -> None:
    """One navigation update (N4-N6) in place: ``q`` (4,), ``v`` (3,), ``p`` (3,); ``qe = exp(-omega_ie h)``."""
    qn = qmul(q, qexp(dth))
    if wie[0] != 0.0 or wie[1] != 0.0 or wie[2] != 0.0:
        qn = qmul(qe, qn)
    w, x, y, z = q[0], q[1], q[2], q[3]
    a0 = (1 - 2 * (y * y + z * z)) * dv[0] + 2 * (x * y - w * z) * dv[1] + 2 * (x * z + w * y) * dv[2]
    a1 = 2 * (x * y + w * z) * dv[0] + (1 - 2 * (x * x + z * z)) * dv[1] + 2 * (y * z - w * x) * dv[2]
    a2 = 2 * (x * z - w * y) * dv[0] + 2 * (y * z + w * x) * dv[1] + (1 - 2 * (x * x + y * y)) * dv[2]
    e0, e1, e2 = 0.5 * h * wie[0], 0.5 * h * wie[1], 0.5 * h * wie[2]
    a0, a1, a2 = a0 - (e1 * a2 - e2 * a1), a1 - (e2 * a0 - e0 * a2), a2 - (e0 * a1 - e1 * a0)
    c0 = wie[1] * v[2] - wie[2] * v[1]
    c1 = wie[2] * v[0] - wie[0] * v[2]
    c2 = wie[0] * v[1] - wie[1] * v[0]
    v0 = v[0] + a0 + (g[0] - 2 * c0) * h
    v1 = v[1] + a1 + (g[1] - 2 * c1) * h
    v2 = v[2] + a2 + (g[2] - 2 * c2) * h
    p[0] += 0.5 * (v[0] + v0) * h
    p[1] += 0.5 * (v[1] + v1) * h
    p[2] += 0.5 * (v[2] + v2) * h
    v[0], v[1], v[2] = v0, v1, v2
    norm = np.sqrt(qn[0] * qn[0] + qn[1] * qn[1] + qn[2] * qn[2] + qn[3] * qn[3])
    for j in range(4):
        q[j] = qn[j] / norm


@njit(cache=True)
def _navigate(dth: np.ndarray, dv: np.ndarray, h: float, q0: np.ndarray, v0: np.ndarray, p0: np.ndarray,
              g: np.ndarray, wie: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    k = dth.shape[0]
    qs, vs, ps = np.empty((k + 1, 4)), np.empty((k + 1, 3)), np.empty((k + 1, 3))
    q, v, p = q0.copy(), v0.copy(), p0.copy()
    qe = qexp(-wie * h)
    qs[0], vs[0], ps[0] = q, v, p
    for i in range(k):
        nav_step(q, v, p, dth[i], dv[i], h, g, wie, qe)
        qs[i + 1], vs[i + 1], ps[i + 1] = q, v, p
    return qs, vs, ps


@dataclass(frozen=True, eq=False)
class Trajectory(Value):
    """A navigation solution at the navigation steps.

    Attributes
    ----------
    t : ndarray, shape (K + 1,)
        Time from the start, s.
    q : ndarray, shape (K + 1, 4)
        Body-to-NED attitude quaternions.
    v, p : ndarray, shape (K + 1, 3)
        Velocity (m/s) and position (m) north, east, down.
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    p: np.ndarray

    @property
    def euler(self) -> np.ndarray:
        """Roll, pitch, heading (K + 1, 3), rad."""
        return euler_from_quat(self.q)


def navigate(w: np.ndarray, f: np.ndarray, dt: float, q0: np.ndarray | None = None, v0=(0.0, 0.0, 0.0),
             p0=(0.0, 0.0, 0.0), step: int = 1, latitude: float = 0.0, earth_rate: bool = False,
             gravity: float | None = None, order: int = 4) -> Trajectory:
    """Navigate a record of gyro rates and specific force (N1-N6).

    Parameters
    ----------
    w : ndarray, shape (n, 3)
        Gyro readings (inertial body rates), rad/s, uniformly sampled.
    f : ndarray, shape (n, 3)
        Accelerometer readings (specific force), m/s^2.
    dt : float
        Sample interval, s.
    q0 : ndarray, shape (4,), optional
        Initial attitude (body to NED); level and heading north when not given.
    v0, p0 : array_like, shape (3,)
        Initial velocity (m/s) and position (m), NED.
    step : int
        Samples per navigation step (1: every sample; more: the two-speed form).
    latitude : float
        rad; sets the normal gravity and, with ``earth_rate``, the Earth rate.
    earth_rate : bool
        Include the Earth rate (N1) and the Coriolis term (N2).
    gravity : float, optional
        Gravity magnitude, m/s^2 (normal gravity at ``latitude`` when not given).
    order : {4, 2}
        See :func:`step_increments`.

    Returns
    -------
    Trajectory
        ``t`` (K + 1,), s; ``q`` (K + 1, 4) body to NED; ``v`` (m/s) and ``p`` (m), (K + 1, 3), NED.

    Examples
    --------
    Level and at rest but turning at 0.1 rad/s about the down axis for 10 s: the heading reaches
    1 rad, and the specific force ``(0, 0, -g)`` cancels gravity (no velocity, no position).

    >>> import numpy as np
    >>> w, f = np.tile([0.0, 0.0, 0.1], (1001, 1)), np.tile([0.0, 0.0, -9.80665], (1001, 1))
    >>> tr = navigate(w, f, 0.01, gravity=9.80665)
    >>> round(float(tr.t[-1]), 6), round(float(tr.euler[-1, 2]), 6), float(np.abs(tr.p).max())
    (10.0, 1.0, 0.0)
    """
    if not (np.isfinite(dt) and dt > 0):
        raise InputError("the sample interval must be finite and positive", "{rate_hz}")
    dth, dv = step_increments(w, f, dt, step, order)
    h = step * dt
    g = np.array([0.0, 0.0, normal_gravity(latitude) if gravity is None else float(gravity)])
    wie = earth_rate_ned(latitude) if earth_rate else np.zeros(3)
    start = IDENTITY if q0 is None else np.asarray(q0, float) / np.linalg.norm(q0)
    qs, vs, ps = _navigate(np.ascontiguousarray(dth), np.ascontiguousarray(dv), h, start.copy(),
                           np.array(v0, float), np.array(p0, float), g, wie)
    return Trajectory(np.arange(len(qs)) * h, qs, vs, ps)
