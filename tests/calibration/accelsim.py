"""Simulated accelerometer sessions of known truth: the six faces, or many attitudes, as a log (SI)."""

import numpy as np
from scipy.spatial.transform import Rotation


def six_faces(m_true, b_true, g, n=200, rng=None):
    """A log of the six faces (n samples each, separated by moves) and its positions list."""
    rng = rng or np.random.default_rng(1)
    blocks, positions = [], []
    for i, a in enumerate("xyz"):
        for s in (1, -1):
            u = np.eye(3)[i] * s
            blocks.append(m_true @ (g * u) + b_true + rng.normal(0, 1e-3, (n, 3)))
            positions.append({"name": f"{'+' if s > 0 else '-'}{a}", "up": f"{'+' if s > 0 else '-'}{a}"})
    return np.vstack(blocks), positions


def attitudes(m_true, b_true, g, k=16, n=200, seed=2):
    """Static means of ``k`` random attitudes (for the ``|a| = g`` fit), shape (k, 3), and a log of them
    (``n`` samples each) with its intervals."""
    rng = np.random.default_rng(seed)
    ups = Rotation.random(k, random_state=seed).apply(np.array([0.0, 0.0, 1.0]))
    blocks = [m_true @ (g * u) + b_true + rng.normal(0, 1e-3, (n, 3)) for u in ups]
    return np.array([b.mean(axis=0) for b in blocks]), np.vstack(blocks), [(j * n, (j + 1) * n) for j in range(k)]
