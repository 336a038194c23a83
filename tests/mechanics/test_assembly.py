"""Mechanics, assembly: the 3-D composition of skew and tilt against scipy's rotations."""

import numpy as np
from scipy.spatial.transform import Rotation

from mechanics.assembly import rotate_axes


def test_rotation_composition_matches_scipy():
    rng = np.random.default_rng(0)
    n = 50
    a, b, skew = rng.normal(0, 0.02, n), rng.normal(0, 0.02, n), rng.normal(0, 0.02, n)
    axes = np.eye(3)[None] + rng.normal(0, 0.02, (n, 3, 3))
    got = rotate_axes(a, b, skew, axes)
    for i in range(n):
        normal = np.array([-a[i], -b[i], 1.0]) / np.sqrt(1 + a[i] ** 2 + b[i] ** 2)
        k = np.cross([0, 0, 1.0], normal)
        tilt = Rotation.from_rotvec(k / np.linalg.norm(k) * np.arctan2(np.linalg.norm(k), normal[2]))
        u = (tilt * Rotation.from_rotvec([0, 0, skew[i]])).apply(axes[i] / np.linalg.norm(axes[i], axis=1, keepdims=True))
        assert np.allclose(np.arccos(np.clip(np.diag(u), -1, 1)), got[i], atol=1e-9)
