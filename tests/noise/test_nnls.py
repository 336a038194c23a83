"""The Allan fit's NNLS (Lawson and Hanson's active set) reaches the optimum the enumeration of all supports finds."""

from __future__ import annotations

import numpy as np

from align.noise.gls import _nnls_enumerated, nnls_small


def test_active_set_nnls_reaches_the_enumerated_optimum_on_allan_like_designs():
    rng = np.random.default_rng(7)
    for _ in range(400):
        t, k = int(rng.integers(6, 40)), int(rng.integers(2, 7))
        tau = np.logspace(-1, 4, t)
        cols = [tau**-2, tau**-1, np.ones(t), tau, tau**2, np.sin(tau / 10 ** rng.uniform(0, 3)) ** 2 / np.maximum(tau, 1)]
        a = np.column_stack(cols[:k]) * (1 + rng.normal(0, 0.01, (t, k)))
        a /= np.linalg.norm(a, axis=0)
        b = a @ np.maximum(rng.normal(0, 1, k), 0) + rng.normal(0, rng.uniform(0, 0.5), t)
        x, ref = nnls_small(a, b), _nnls_enumerated(a, b)
        assert np.all(x >= 0)
        r, r_ref = np.sum((a @ x - b) ** 2), np.sum((a @ ref - b) ** 2)
        assert r <= r_ref * (1 + 1e-9) + 1e-300
