"""The bias-drift model (align.alignment.biasdrift) against analytic cases and simulated random walks and flicker."""

from __future__ import annotations

import numpy as np
import pytest

from align.alignment.biasdrift import Drift, DriftObservation, estimate_drift, interval_means, with_drift
from align.alignment.estimate import fit_angle_pairs, fit_rate_pairs
from align.alignment.observe import Observation
from align.alignment.plan import Plan
from align.alignment.segment import Segment
from align.flicker import flicker_fft
from align.noise.model import model_avar
from align.units import DEG

FS = 100.0


def _static(k: int, a: int, b: int, x: np.ndarray, white: float) -> Observation:
    return Observation(Segment(f"static {k}", "static", a, b), x[a:b].mean(axis=0), np.array([0.0, 0.0, 0.0, 1.0]),
                       np.full(3, white**2 / (b - a)), (b - a) / FS)


def _statics(x: np.ndarray, count: int, length: float, every: float, white: float) -> list[Observation]:
    """Static periods of ``length`` s every ``every`` s (start to start) read from ``x`` (n, 3)."""
    starts = (np.arange(count) * every * FS).astype(int)
    return [_static(k, a, a + int(length * FS), x, white) for k, a in enumerate(starts)]


def test_interval_means_match_quadrature_and_the_known_square():
    spans = np.array([[0.0, 2.0], [5.0, 6.5], [6.5, 10.0]])
    m_abs, m_log = interval_means(spans)
    nodes, weights = np.polynomial.legendre.leggauss(200)
    for k in range(3):
        for j in range(3):
            if k == j:
                continue
            (a0, a1), (b0, b1) = spans[k], spans[j]
            s = (a0 + a1) / 2 + (a1 - a0) / 2 * nodes
            t = (b0 + b1) / 2 + (b1 - b0) / 2 * nodes
            w = np.outer(weights, weights) / 4
            assert m_abs[k, j] == pytest.approx(np.sum(w * np.abs(s[:, None] - t[None, :])), rel=1e-9)
            # touching spans put a log singularity on the corner: quadrature converges slowly there
            assert m_log[k, j] == pytest.approx(np.sum(w * np.log(np.abs(s[:, None] - t[None, :]))), rel=1e-3, abs=1e-3)
    # over one square [0, L]^2: <|s - t|> = L / 3 and <ln|s - t|> = ln L - 3 / 2
    assert m_abs[0, 0] == pytest.approx(2.0 / 3)
    assert m_log[0, 0] == pytest.approx(np.log(2.0) - 1.5)


@pytest.mark.parametrize("length,every", [(2.5, 2.5), (2.5, 14.0), (10.0, 60.0)])
def test_random_walk_difference_of_means_is_q2_times_separation(length, every):
    # two means over L, starts S apart, of a Wiener process of intensity q: var = q^2 (S - L / 3)
    q = 3e-4
    drift = Drift(np.full(3, q), np.zeros(3), "test", 2, "")
    g = drift.covariance(np.array([[0.0, length], [every, every + length]]))
    c = np.array([1.0, -1.0])
    assert c @ g[0] @ c == pytest.approx(q**2 * (every - length / 3), rel=1e-12)
    if every == length:  # adjacent: twice the Allan variance q^2 tau / 3 (IEEE 952)
        assert c @ g[1] @ c == pytest.approx(2 * model_avar(length, (0, 0, 0, q, 0)), rel=1e-12)


def test_flicker_adjacent_means_differ_by_twice_the_allan_floor():
    b = 2e-4
    drift = Drift(np.zeros(3), np.full(3, b), "test", 2, "")
    c = np.array([1.0, -1.0])
    for tau in (0.5, 5.0, 50.0):
        g = drift.covariance(np.array([[0.0, tau], [tau, 2 * tau]]))
        assert c @ g[2] @ c == pytest.approx(2 * model_avar(tau, (0, 0, b, 0, 0)), rel=1e-12)


def test_model_matches_simulated_random_walk_and_flicker():
    """Monte Carlo: the variance of consecutive static-mean differences (walk + flicker + white) is Eq D2 + noise."""
    rng = np.random.default_rng(5)
    q, b, white = 2e-3, 1e-2, 0.05
    length, every, count = 2.0, 8.0, 6
    n = int(count * every * FS)
    runs = 100
    x = (np.cumsum(rng.standard_normal((runs, n)), axis=1) * q / np.sqrt(FS)
         + np.stack([flicker_fft(n, FS, b, rng, 1)[:, 0] for _ in range(runs)])
         + rng.standard_normal((runs, n)) * white)
    starts = (np.arange(count) * every * FS).astype(int)
    means = np.stack([x[:, a:a + int(length * FS)].mean(axis=1) for a in starts], axis=1)
    emp = np.mean(np.diff(means, axis=1) ** 2)
    g = Drift(np.full(3, q), np.full(3, b), "test", 2, "").covariance(np.array([[0.0, length], [every, every + length]]))
    c = np.array([1.0, -1.0])
    model = c @ g[0] @ c + 2 * white**2 / (length * FS)
    assert emp == pytest.approx(model, rel=0.12)  # 500 correlated squares: about 8 % scatter


@pytest.mark.parametrize("q,b", [(3e-3, 0.0), (0.0, 5e-3), (2e-3, 5e-3)])
def test_estimate_drift_recovers_what_it_was_given(q, b):
    """From 40 static periods: the predicted variance of neighbouring and distant means is the true one
    within its scatter (39 differences per gyro: about 25 %; the estimate leans high, see estimate_drift)."""
    rng = np.random.default_rng(11)
    white, length, every, count = 0.02, 2.5, 12.0, 40
    n = int(count * every * FS) + 10
    x = rng.standard_normal((n, 3)) * white
    if q:
        x += np.cumsum(rng.standard_normal((n, 3)), axis=0) * q / np.sqrt(FS)
    if b:
        x += flicker_fft(n, FS, b, rng, 3)
    drift = estimate_drift(_statics(x, count, length, every, white), np.arange(n) / FS, np.full(3, white))
    spans = np.array([[0.0, length], [every, every + length], [3 * every, 3 * every + length]])
    truth = Drift(np.full(3, q), np.full(3, b), "truth", count, "").covariance(spans)
    got = drift.covariance(spans)
    for c in (np.array([1.0, -1.0, 0.0]), np.array([1.0, 0.0, -1.0])):
        ratio = np.einsum("j,ijl,l->i", c, got, c) / np.einsum("j,ijl,l->i", c, truth, c)
        assert 0.7 < np.mean(ratio) < 1.5 and np.all(ratio > 0.5)
    assert drift.source == "static periods" and drift.probes == count and "40 static periods" in drift.note


def test_no_drift_gives_nothing_and_leaves_the_variances():
    rng = np.random.default_rng(2)
    white = 0.01
    x = rng.standard_normal((4000, 3)) * white
    obs = _statics(x, 8, 2.0, 5.0, white)
    t = np.arange(4000) / FS
    drift = estimate_drift(obs, t, np.full(3, white))
    spans = np.array([[0.0, 2.0], [5.0, 7.0]])
    c = np.array([1.0, -1.0])
    # a drift estimate from pure white noise is small next to the noise of one mean
    assert np.all(np.einsum("j,ijl,l->i", c, drift.covariance(spans), c) < white**2 / 200 * 2)
    zero = Drift(np.zeros(3), np.zeros(3), "none", 0, "")
    for o, d in zip(obs, with_drift(obs, zero, t)):
        assert isinstance(d, DriftObservation) and np.array_equal(d.var, o.var) and np.array_equal(d.y, o.y)


def test_with_drift_adds_the_deviation_from_the_session_bias():
    # two equally long dwells under a random walk: each deviates from their mean by half their difference,
    # var = q^2 (S - L / 3) / 4; a turn of T carries T^2 times that
    q, length, every = 1e-3, 10.0, 14.0
    drift = Drift(np.full(3, q), np.zeros(3), "test", 2, "")
    t = np.arange(int(30 * FS)) / FS
    a, b = 0, int(every * FS)
    n = int(length * FS)
    noise = np.full(3, 1e-8)
    dwell = [Observation(Segment(f"s{k}", "rate", s, s + n, k), np.zeros(3), np.array([1.0, 0, 0, 1.0]), noise, length)
             for k, s in enumerate((a, b))]
    turn = [Observation(Segment(f"s{k}", "angle", s, s + n, k), np.zeros(3), np.array([6.0, 0, 0, length]), noise, length)
            for k, s in enumerate((a, b))]
    expect = q**2 * (every - length / 3) / 4
    for o in with_drift(dwell, drift, t):
        assert o.var - o.noise_var == pytest.approx(np.full(3, expect), rel=1e-9)
        assert o.span == pytest.approx((o.segment.start / FS, o.segment.start / FS + length))
    for o in with_drift(turn, drift, t):
        assert o.var - o.noise_var == pytest.approx(np.full(3, expect * length**2), rel=1e-9)


def test_with_drift_does_not_count_the_drift_inside_a_dwell_twice():
    """A static mean's batch-means variance (ten batches, as observe makes it) holds part of the walk: taken out."""
    q, n, white = 1e-3, 1000, 0.01
    rng = np.random.default_rng(8)
    walks = np.cumsum(rng.standard_normal((4000, n)), axis=1) * q / np.sqrt(FS)
    within = np.mean(np.var(walks.reshape(4000, 10, n // 10).mean(axis=2), axis=1, ddof=1) / 10)
    drift = Drift(np.full(3, q), np.zeros(3), "test", 2, "")
    obs = [Observation(Segment("static 1", "static", 0, n), np.zeros(3), np.array([0, 0, 0, 1.0]),
                       np.full(3, white**2 / n + within), n / FS)]
    out = with_drift(obs, drift, np.arange(2 * n) / FS, np.full(3, white))[0]
    assert out.noise_var == pytest.approx(np.full(3, white**2 / n), rel=0.05)
    # never below the white noise, whatever the batch-means variance held
    low = [Observation(Segment("static 1", "static", 0, n), np.zeros(3), np.array([0, 0, 0, 1.0]),
                       np.full(3, white**2 / n), n / FS)]
    assert with_drift(low, drift, np.arange(2 * n) / FS, np.full(3, white))[0].noise_var == pytest.approx(white**2 / n)


def _pair_session(kind: str, every: float, length: float):
    """Six exact +/- observations (no residuals: no inflation) every ``every`` s, static periods between turns."""
    plan = Plan.standard_rate(100 * DEG) if kind == "rate" else Plan.standard_angle(360 * DEG)
    m, bias, offset = np.eye(3) + 1e-3, 0.01, 5.0
    n = int(length * FS)
    obs = []
    for k, step in enumerate(plan.steps):
        s = int((offset + k * every) * FS)
        phi = np.append(step.rate * step.unit_axis, 1.0) if kind == "rate" else np.append(step.angle * step.unit_axis, length)
        obs.append(Observation(Segment(f"s{k}", kind, s, s + n, k), m @ phi[:3] + phi[3] * bias, phi,
                               np.full(3, 1e-10) * phi[3] ** 2, length))
    for k in range(7 if kind == "angle" else 0):
        s = int((offset + k * every - 3.5) * FS)
        obs.append(Observation(Segment(f"static {k}", "static", s, s + 300), np.full(3, bias), np.array([0, 0, 0, 1.0]),
                               np.full(3, 1e-10), 3.0))
    return plan, obs, np.arange(int((offset + 6 * every + 10) * FS)) / FS, m


@pytest.mark.parametrize("kind", ["rate", "angle"])
def test_closed_forms_carry_the_bias_change_between_the_pair(kind):
    # Eq 28-31 with drift: var(M_ia) = (noise(+) + noise(-) + T^2 q^2 (S - L / 3)) / span^2
    q, every, length = 2e-3, 14.0, 10.0
    plan, obs, t, m = _pair_session(kind, every, length)
    fit_plain = (fit_rate_pairs if kind == "rate" else fit_angle_pairs)(obs, plan)
    drift = Drift(np.full(3, q), np.zeros(3), "test", 7, "")
    fit = (fit_rate_pairs if kind == "rate" else fit_angle_pairs)(with_drift(obs, drift, t), plan)
    assert np.array_equal(fit.M, fit_plain.M) and np.array_equal(fit.bias, fit_plain.bias)  # estimates unchanged
    assert np.allclose(fit.M, m, atol=1e-12)
    span = 2 * (100 * DEG if kind == "rate" else 360 * DEG)
    bias_time = 1.0 if kind == "rate" else length
    noise = obs[0].var[0]
    expect = np.sqrt((2 * noise + bias_time**2 * q**2 * (every - length / 3)) / span**2)
    assert fit.sigma_M == pytest.approx(np.full((3, 3), expect), rel=1e-6)


def test_pairwise_biases_stand_in_without_static_periods():
    rng = np.random.default_rng(4)
    plan = Plan.standard_rate(100 * DEG)
    n, every, length = 1000, 14.0, 10.0
    t = np.arange(int(6 * every * FS)) / FS
    obs = []
    for k, step in enumerate(plan.steps):
        s = int(k * every * FS)
        phi = np.append(step.rate * step.unit_axis, 1.0)
        obs.append(Observation(Segment(f"s{k}", "rate", s, s + n, k), phi[:3] + rng.normal(0, 1e-3, 3), phi,
                               np.full(3, 1e-8), length))
    drift = estimate_drift(obs, t)
    assert drift.source == "pairwise biases" and drift.probes == 3 and "pairwise biases" in drift.note
    assert np.all(drift.flicker + drift.walk > 0)
    none = estimate_drift(obs[:1], t)
    assert none.source == "none" and "not measured" in none.note and not none.walk.any() and not none.flicker.any()
