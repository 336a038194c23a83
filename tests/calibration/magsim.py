"""Simulated magnetometer captures of known truth (hard iron, symmetric soft iron, field, dip)."""

import numpy as np
from scipy.spatial.transform import Rotation

F = 50e-6  # field strength, T
dip = np.radians(60)
fvec = F * np.array([np.cos(dip), 0, -np.sin(dip)])


def truth(seed=0):
    """A symmetric soft iron ``S`` near the identity and a hard iron ``h`` (T)."""
    rng = np.random.default_rng(seed)
    A = rng.normal(0, 0.1, (3, 3))
    S = np.eye(3) + 0.5 * (A + A.T)
    h = np.array([20e-6, -15e-6, 30e-6])
    return S, h


def capture(kind, S, h, n=1500, seed=1, noise=0.5e-6):
    """Raw readings ``S m_body + h + noise`` and the accelerometer (m/s^2) over ``n`` attitudes.

    ``kind``: "sphere" (uniform attitudes), or "tilt45", "level", "planar" (yaw with tilts up to 45, 5, 0 deg).
    """
    rng = np.random.default_rng(seed)
    if kind == "sphere":
        R = Rotation.random(n, random_state=seed)
    else:
        tilt = {"tilt45": 45, "level": 5, "planar": 0}[kind]
        yaw = rng.uniform(0, 360, n)
        d = np.column_stack([rng.normal(size=(n, 2)), np.zeros(n)])
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        mag = np.radians(rng.uniform(0, tilt, n))
        R = Rotation.from_rotvec(d * mag[:, None]) * Rotation.from_euler('z', yaw[:, None], degrees=True)
    body = R.inv().apply(fvec)
    acc = R.inv().apply(np.array([0, 0, 9.81]))
    return body @ S.T + h + rng.normal(0, noise, (n, 3)), acc
