"""Simulated multi-position sessions (static poses separated by hand rotations) of known truth.

The physics, written apart from the estimator (:mod:`align.calibration.gyro`): the attitude of
every sample is analytic, never integrated. Rotation ``k`` takes the body from attitude ``C_k``
through::

    C(t) = C_k exp(alpha(t) [a]x) exp(beta(t) [b]x)                                   (S1)

with unit axes ``a``, ``b`` (body frame) and smooth angle profiles ``alpha = alpha_f s(tau)``,
``beta = beta_f s(tau)``, ``s(tau) = tau - sin(2 pi tau) / (2 pi)`` (``tau`` from 0 to 1 over the
rotation: rate and acceleration zero at both ends). Differentiating S1, the body rate is::

    w = beta' b + exp(beta [b]x)^T alpha' a                                            (S2)

whose direction changes when ``a`` and ``b`` differ (coning). Readings: ``g = M_g w + b_g + n_g``,
``a = M_a C^T (0, 0, gravity) + b_a + n_a`` (the sensor at the centre of rotation: specific force is
gravity only), white noise of the given densities.

The calibration can only see the sensors relative to the accelerometer's own frame ``c``
(``x`` along the accelerometer's x axis, ``y`` in its x-y plane): with ``M_a = T Q`` (``T`` upper
triangular, positive diagonal, ``Q`` a rotation; scipy's RQ decomposition), ``f_c = Q f_body`` and
the truth in that frame is ``M_a' = T``, ``M_g' = M_g Q^T`` (the biases unchanged).

Public names
------------
PoseSessionSpec, PoseSession, simulate_poses, random_sensors, accel_frame_truth, TURN_AXES
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.alignment.kinematics import axis_rotations
from align.units import DEG, STANDARD_GRAVITY

#: the choices of rotation axes: any (two random axes per rotation), or rotations about the listed body axes only
TURN_AXES = ("any", "x", "y", "z", "xy", "xz", "yz", "xyz")


@dataclass(frozen=True)
class PoseSessionSpec:
    """What to simulate.

    Attributes
    ----------
    fs : float
        Sample rate, Hz.
    poses : int
        Static poses, the initial one included.
    init_s, pose_s, turn_s : float
        Durations of the initial static period, of every later pose and of every rotation, s.
    turn_range : tuple of float
        Smallest and largest turn of a rotation, rad.
    axes : str
        One of :data:`TURN_AXES`: ``"any"``, or the body axes rotations turn about (one per rotation, in turn).
    wobble : float
        With ``axes`` other than ``"any"``: each axis is tilted by a random vector of this size (a hand's
        imprecision; 0 for exact axes).
    gyro_noise, accel_noise : float
        White-noise densities: rad/s/sqrt(Hz) (angle random walk, rad/sqrt(s)) and m/s^2/sqrt(Hz).
    gravity : float
        m/s^2.
    """

    fs: float = 100.0
    poses: int = 20
    init_s: float = 30.0
    pose_s: float = 4.0
    turn_s: float = 2.5
    turn_range: tuple[float, float] = (60 * DEG, 150 * DEG)
    axes: str = "any"
    wobble: float = 0.03
    gyro_noise: float = 0.3 * DEG / 60.0
    accel_noise: float = 0.002
    gravity: float = STANDARD_GRAVITY


@dataclass(frozen=True, eq=False)
class PoseSession:
    """A simulated session: time (n,) s; accelerometer and gyro readings (n, 3), SI; the poses as sample
    ranges ``(start, end)`` (end exclusive); the true attitude (n, 3, 3) body to reference; the true body
    rates (n, 3) rad/s; the sensors' truth (body frame: ``M_a``, ``b_a``, ``M_g``, ``b_g``)."""

    t: np.ndarray
    acc: np.ndarray
    gyr: np.ndarray
    poses: tuple
    attitude: np.ndarray
    rates: np.ndarray
    M_a: np.ndarray
    b_a: np.ndarray
    M_g: np.ndarray
    b_g: np.ndarray


def random_sensors(rng: np.random.Generator, misalignment: float = 1.0 * DEG, scale_sd: float = 0.01,
                   gyro_bias_sd: float = 0.5 * DEG, accel_bias_sd: float = 0.05) -> tuple:
    """Random true ``M_a, b_a, M_g, b_g`` (body frame): each row an axis turned by ``misalignment`` (1 sigma
    per component) times a scale ``1 + N(0, scale_sd)``; biases in m/s^2 and rad/s."""

    def matrix() -> np.ndarray:
        rows = np.eye(3) + rng.normal(0.0, misalignment, (3, 3)) * (1 - np.eye(3))
        rows /= np.linalg.norm(rows, axis=1, keepdims=True)
        return rows * (1 + rng.normal(0.0, scale_sd, 3))[:, None]

    return matrix(), rng.normal(0.0, accel_bias_sd, 3), matrix(), rng.normal(0.0, gyro_bias_sd, 3)


def accel_frame_truth(m_a: np.ndarray, m_g: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(T, M_g Q^T, Q)`` with ``M_a = T Q`` (``T`` upper triangular with a positive diagonal, ``Q`` a rotation):
    the truth in the accelerometer's frame, where the calibration reports it."""
    from scipy.linalg import rq

    t, q = rq(m_a)
    d = np.diag(np.sign(np.diag(t)))
    t, q = t @ d, d @ q
    return t, m_g @ q.T, q


def _axes(spec: PoseSessionSpec, k: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, float, float]:
    lo, hi = spec.turn_range
    angle = rng.uniform(lo, hi) * rng.choice([-1.0, 1.0])
    if spec.axes == "any":
        a, b = rng.normal(size=3), rng.normal(size=3)
        share = rng.uniform(0.3, 0.7)
        return a / np.linalg.norm(a), b / np.linalg.norm(b), angle * share, angle * (1 - share)
    axis = np.eye(3)["xyz".index(spec.axes[k % len(spec.axes)])] + rng.normal(0.0, spec.wobble, 3)
    return axis / np.linalg.norm(axis), np.array([1.0, 0.0, 0.0]), angle, 0.0


def simulate_poses(spec: PoseSessionSpec, m_a: np.ndarray, b_a: np.ndarray, m_g: np.ndarray, b_g: np.ndarray,
                   rng: np.random.Generator, k_ga: np.ndarray | None = None) -> PoseSession:
    """Simulate a session (S1, S2): an initial static period, then ``poses - 1`` rotations each followed by a pose.

    The first attitude is random; ``k_ga`` (3, 3), (rad/s) per (m/s^2), adds a g-sensitivity ``K_ga f`` to
    the gyro (``f`` the specific force, body frame). Returns a :class:`PoseSession`.
    """
    if spec.axes not in TURN_AXES:
        raise ValueError(f"axes must be one of {', '.join(TURN_AXES)}")
    dt = 1.0 / spec.fs
    n_init, n_pose, n_turn = (int(round(d * spec.fs)) for d in (spec.init_s, spec.pose_s, spec.turn_s))
    from scipy.spatial.transform import Rotation

    c = Rotation.random(random_state=rng).as_matrix()
    atts, rates, poses = [np.repeat(c[None], n_init, 0)], [np.zeros((n_init, 3))], [(0, n_init)]
    n = n_init
    tau = (np.arange(1, n_turn + 1)) / n_turn           # the rotation's samples, its last one at tau = 1
    s = tau - np.sin(2 * np.pi * tau) / (2 * np.pi)
    ds = (1 - np.cos(2 * np.pi * tau)) / (n_turn * dt)  # ds/dt
    for k in range(spec.poses - 1):
        a, b, fa, fb = _axes(spec, k, rng)
        ea, eb = axis_rotations(a, fa * s), axis_rotations(b, fb * s)
        atts.append(c @ ea @ eb)
        rates.append(fb * ds[:, None] * b + np.einsum("kji,j->ki", eb, a) * (fa * ds)[:, None])
        c = atts[-1][-1]
        atts.append(np.repeat(c[None], n_pose, 0))
        rates.append(np.zeros((n_pose, 3)))
        poses.append((n + n_turn, n + n_turn + n_pose))
        n += n_turn + n_pose
    att, w = np.concatenate(atts), np.concatenate(rates)
    f = np.einsum("kji,j->ki", att, np.array([0.0, 0.0, spec.gravity]))
    root = np.sqrt(spec.fs)
    gyr = w @ m_g.T + b_g + rng.normal(0.0, spec.gyro_noise * root, w.shape)
    if k_ga is not None:
        gyr += f @ np.asarray(k_ga, float).T
    acc = f @ m_a.T + b_a + rng.normal(0.0, spec.accel_noise * root, f.shape)
    return PoseSession(np.arange(len(w)) * dt, acc, gyr, tuple(poses), att, w, m_a, b_a, m_g, b_g)
