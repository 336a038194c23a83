"""The five-term noise fit (align.noise.fit) against simulated truth; the seed's noise figures."""

import numpy as np
import pytest

from align.noise.allan import allan
from align.noise.fit import fit_noise, noise_figures
from align.noise.sim import NoiseSpec, simulate_noise
from align.units import parse_quantity as q

ARW = q("0.3 deg/sqrt(h)", "angle_random_walk")


def _fit(spec, seed, n=1_000_000, fs=100.0):
    e = simulate_noise(n, fs, spec, 1, seed)
    return fit_noise(allan(e, fs), 0)


def test_fit_recovers_simulated_arw_and_bias_instability_and_flags_rrw():
    b = q("5 deg/h", "angular_rate")
    fits = [_fit(NoiseSpec(white=ARW, flicker=b), seed) for seed in range(5)]
    n_ratio = np.median([f.params[1] / ARW for f in fits])
    b_ratio = np.median([f.params[2] / b for f in fits])
    assert abs(n_ratio - 1) < 0.05 and abs(b_ratio - 1) < 0.05
    for f in fits:
        assert f.identifiable[1]  # white
        assert not f.identifiable[3]  # rate random walk: not in the data, not identifiable
        note = next(n for n in f.notes if n.startswith("random_walk (K): not identifiable"))
        assert "h of record would identify" in note and np.isfinite(f.upper[3]) and f.upper[3] > 0
        assert f.needed[3] > 1_000_000 / 100.0  # longer than this record


def test_noise_figures_follow_seed_definitions():
    y = np.arange(1000.0)
    fig = noise_figures(y, 10.0, (1.0,))
    means = y.reshape(100, 10).mean(axis=1)
    assert fig["bias"] == pytest.approx(499.5)
    assert fig["stability"][1.0] == pytest.approx(np.std(means, ddof=1))
    # the Allan job reads the same figures off the phase: the same numbers
    rng = np.random.default_rng(5)
    z = rng.normal(0.3, 1.0, 12_345)
    r = allan(z, 100.0, periods=(1.0, 10.0))
    direct = noise_figures(z, 100.0, (1.0, 10.0))
    assert r.bias[0] == pytest.approx(direct["bias"], rel=1e-12)
    for p in (1.0, 10.0):
        assert r.stability[p][0] == pytest.approx(direct["stability"][p], rel=1e-9)
