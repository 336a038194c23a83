"""The whitening of the Allan variances' model covariance (issue 23): a correlation matrix whose lag sums leave it
slightly indefinite is whitened with a ridge, not replaced by independent points.

Truth: a correlation matrix built here with known eigenvalues (one of -1e-4, as the rate random walk's dense grid
gave), and the whitening's defining property ``W C W' = I`` checked with numpy alone.
"""

import numpy as np

from align.noise.gls import whitener


def _matrix(eigen: np.ndarray, seed: int) -> np.ndarray:
    q, _ = np.linalg.qr(np.random.default_rng(seed).standard_normal((len(eigen), len(eigen))))
    c = (q * eigen) @ q.T
    s = np.sqrt(np.diag(c))
    return c / np.outer(s, s)


def test_a_positive_definite_covariance_is_whitened_exactly():
    c = _matrix(np.geomspace(1e-3, 20.0, 24), 1) * np.outer(np.geomspace(1, 1e6, 24), np.geomspace(1, 1e6, 24))
    w = whitener(c, np.diag(c))
    assert np.allclose(w @ c @ w.T, np.eye(24), atol=1e-6)


def test_an_indefinite_correlation_keeps_its_correlations():
    c = _matrix(np.r_[-1e-4, np.geomspace(1e-3, 1.0, 23)], 2)
    assert -1e-3 < np.linalg.eigvalsh(c)[0] < 0             # -6e-4 once scaled to unit diagonal
    w = whitener(c, np.diag(c))
    assert not np.allclose(w, np.diag(np.diag(w)))        # not the independent-points fallback
    ridge = np.linalg.inv(w) @ np.linalg.inv(w).T - c      # L L' - C: a ridge r I, r from 1e-4 to 1e-2
    r = ridge[0, 0]
    assert np.allclose(ridge, r * np.eye(24), atol=1e-9) and 1e-4 <= r <= 1e-2
    assert np.allclose(w @ (c + r * np.eye(24)) @ w.T, np.eye(24), atol=1e-8)
