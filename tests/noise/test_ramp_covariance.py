"""The ramp's cross term in the covariance of the Allan variances (issue 23), against a Monte Carlo of the estimator.

A rate ramp ``R`` plus noise: every second difference is ``R tau^2 + e_m(i)``, so the overlapping Allan variance
gains ``R ebar_m`` (linear in the noise) and its variance ``R^2 var(ebar_m)``, most of the variance at long taus of
a strong ramp. Truth from outside align.noise: many records from the independent simulator (independent_noise.py)
and the overlapping estimator written here from NIST SP 1065 Eq 14 (``sum d^2 / (2 tau^2 (N - 2m))`` over the phase
``x = [0, cumsum(y) / fs]``); the sample variance and correlation of the estimates over the records against
``align.noise.covariance.avar_covariance``. Without the cross term the long-tau variances would be several times too
small, which the test also checks (it can fail).
"""

from __future__ import annotations

import numpy as np
import pytest
from independent_noise import record

from align.noise.covariance import avar_covariance

FS = 1.0
N_SAMPLES = 2048
M = np.array([16, 64, 256, 512])
RAMP = 1e-3  # rad/s^2: R^2 tau^2 / 2 = 0.13 at tau = 512 s


def _oavar(y: np.ndarray, fs: float, m: np.ndarray) -> np.ndarray:
    """Overlapping Allan variance (NIST SP 1065 Eq 14) of each column of the rate ``y`` (n, C), shape (C, len(m))."""
    x = np.vstack([np.zeros((1, y.shape[1])), np.cumsum(y, axis=0) / fs])
    out = []
    for k in m:
        d = x[2 * k:] - 2 * x[k:-k] + x[:-2 * k]
        out.append(np.mean(d * d, axis=0) / (2 * (k / fs) ** 2))
    return np.array(out).T


@pytest.mark.parametrize("term, size, channels", [("white", 1.0, 4000), ("random_walk", 1e-2, 4000),
                                                   ("flicker", 0.05, 1500)])
def test_ramp_cross_term_matches_monte_carlo(term, size, channels):
    y = record(N_SAMPLES, FS, channels=channels, seed=23, ramp=RAMP, **{term: size})
    est = _oavar(y, FS, M)
    params = np.zeros(5)
    params[{"white": 1, "flicker": 2, "random_walk": 3}[term]] = size
    params[4] = RAMP
    model = avar_covariance(M, N_SAMPLES + 1, FS, params)
    noise_only = avar_covariance(M, N_SAMPLES + 1, FS, np.r_[params[:4], 0.0])
    var = np.var(est, axis=0, ddof=1)
    # the sample variance of ``channels`` nearly Gaussian estimates: relative standard error about sqrt(2 / channels)
    tol = 5 * np.sqrt(2 / channels)
    ratio = var / np.diag(model)
    # at 16 s the variance is the noise's own, and the simulator's Gauss-Markov flicker is ~10 % off ideal flicker there
    check = ratio[1:] if term == "flicker" else ratio
    assert np.all(np.abs(check - 1) < tol), ratio
    assert var[-1] > 3 * noise_only[-1, -1]  # the cross term is most of it at the longest tau
    corr = np.corrcoef(est.T)
    model_corr = model / np.sqrt(np.outer(np.diag(model), np.diag(model)))
    assert np.abs(corr[2, 3] - model_corr[2, 3]) < 0.1, (corr[2, 3], model_corr[2, 3])
    assert np.abs(corr[1, 3] - model_corr[1, 3]) < 0.1, (corr[1, 3], model_corr[1, 3])
