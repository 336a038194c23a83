"""Seed 002's experiment: its figures from records of known truth, and its Eq 19-21 table."""

from __future__ import annotations

import numpy as np
import pytest

from align.navigation.experiment import METHODS, seed_experiment, seed_figures, table_rows
from align.noise import NoiseSpec, simulate_noise
from align.units import DEG, STANDARD_GRAVITY

FS = 100.0
N_G, N_A = 2.0 * DEG / 60, 0.2 / 60  # 2 deg/sqrt(h), 0.2 m/s/sqrt(h)
BIAS = np.array([0.4 * DEG, -0.3 * DEG, 0.2 * DEG, 0.05, -0.02, -STANDARD_GRAVITY])


def _record(seconds: float, seed: int) -> np.ndarray:
    n = int(seconds * FS)
    gyro = simulate_noise(n, FS, NoiseSpec(white=N_G), 3, seed)
    acc = simulate_noise(n, FS, NoiseSpec(white=N_A), 3, seed + 100)
    return np.hstack([gyro, acc]) + BIAS


@pytest.fixture(scope="module")
def figures():
    rec = _record(2000.0, 1)
    return seed_figures(rec[:, :3], rec[:, 3:], FS, 200.0)


def test_figures_of_white_noise_around_a_bias(figures):
    white = np.r_[[N_G] * 3, [N_A] * 3]
    assert figures.segments == 10
    # Eq 5-6: the mean of 2000 s of white noise N: within 4 standard errors N / sqrt(2000 s)
    assert np.all(np.abs(figures.bias - BIAS) < 4 * white / np.sqrt(2000))
    # Eq 7-8: the std of 1-s means of white noise is N / sqrt(1 s); Eq 9: of 200-s means, N / sqrt(200 s)
    assert np.allclose(figures.stability, white, rtol=0.05)
    assert np.allclose(figures.repeatability, white / np.sqrt(200), rtol=0.6)
    # the Allan fit: N, and no bias instability in white noise
    assert np.allclose(figures.white, white, rtol=0.05)
    assert np.all(figures.instability < 0.1 * white)


def test_eq_19_to_21_and_the_table(figures):
    real = _record(30.0, 7)
    exp = seed_experiment(real[:, :3], real[:, 3:], FS, figures, repetitions=3, seed=2)
    end = np.abs(exp.real[-1])
    for m in METHODS:
        d = exp.real[None] - exp.sims[m]  # Eq 19
        assert np.allclose(exp.e_abs[m], np.abs(d).max(axis=1))  # Eq 20
        assert np.allclose(exp.e_rel[m], exp.e_abs[m] / end * 100)  # Eq 21
        assert exp.sims[m].shape == (3, len(exp.t), 3)
    # from rest, level: the real record's drift follows its own bias; with these figures every method's mean drift
    # is the real one's (the same bias), so the differences stay well inside the drift itself
    assert np.all(np.mean([exp.mean_rel(m) for m in METHODS], axis=0) < 100)
    rows = table_rows(exp)
    assert len(rows) == 6 and all(len(r) == 4 for r in rows)
    assert rows[4][0] == "largest absolute heading error (deg)"
    ranking = exp.ranking()
    assert len(ranking) == 6 and all(sorted(r) == sorted(METHODS) for r in ranking)


def test_heading_drift_of_a_record_is_its_z_bias_times_time(figures):
    # a real record without noise, turning about z only: heading from rest = z gyro bias x t (level, no Earth rate)
    n = int(20 * FS) + 1
    real = np.tile(BIAS, (n, 1))
    real[:, [0, 1, 3, 4]] = 0.0
    exp = seed_experiment(real[:, :3], real[:, 3:], FS, figures, repetitions=2, seed=1)
    t = exp.t
    assert np.allclose(exp.real[:, 2], BIAS[2] * t, rtol=1e-12, atol=1e-15)
    assert np.abs(exp.real[:, :2]).max() < 1e-9  # level, at rest: no horizontal drift
