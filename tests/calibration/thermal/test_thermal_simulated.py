"""Thermal fits against simulated chambers of known truth (issue 25's "Done means", first point).

The truth is the simulation's, written out in this module from its documented model (a cubic in the scaled
temperature per axis, a lag term in dT/dt, a hysteresis state), never read back from the fit: the static curve
``sum a_k u^k`` is compared with the fitted curve and its reported 3-sigma band across the range, the order
chosen with 3, and the reported hysteresis with the heating-minus-cooling difference of the noise-free readings
(each branch fitted here with numpy.polyfit, on samples labelled from the true rate).
"""

from __future__ import annotations

import numpy as np
import pytest

from align.calibration.thermal.sensor import Settings, fit_sensor
from align.calibration.thermal.simulate import Profile, Truth, simulate

#: the nominal chamber: -10..60 C, 5 C/min both ways, 1.5 cycles; 5 Hz (short records: a fast test)
NOMINAL = Profile(-10.0, 60.0, 5 / 60, 5 / 60, 0.0, 1.5)
RATE_HZ = 5.0
SEEDS = range(24)
SIZE, WHITE, CORRELATED = 0.01, 0.002, 0.001  # m/s^2: cubic terms, white noise, 20 s Gauss-Markov noise


def _truth(rng: np.random.Generator, profile: Profile, hysteresis: float) -> Truth:
    """Cubic terms of 0.5..1.5 SIZE each with random signs, a lag moving the reading by about 0.1 SIZE per
    (C/min), a hysteresis of ``hysteresis`` SIZE."""
    def draw(shape):
        return rng.choice([-1.0, 1.0], size=shape) * rng.uniform(0.5, 1.5, shape)

    return Truth(draw((3, 4)) * SIZE, 0.5 * (profile.low + profile.high), 0.5 * (profile.high - profile.low),
                 draw(3) * SIZE * 6.0, draw(3) * SIZE * hysteresis)


def _static(truth: Truth, temperature: np.ndarray) -> np.ndarray:
    """The documented static curve ``sum_k a_k u^k``, ``u = (T - tref) / hs``, written out here."""
    u = (temperature - truth.tref) / truth.hs
    return np.column_stack([sum(truth.a[i, k] * u ** k for k in range(4)) for i in range(3)])


def _branch_difference(run, truth: Truth, order: int) -> np.ndarray:
    """Heating minus cooling where largest over the overlap, from noise-free readings (3,): each branch (the
    samples whose true rate is at least half the typical one, as the issue's branch rule says) fitted with
    numpy.polyfit of ``order`` against the true temperature."""
    T, r = run.true_temperature, run.rate
    y = _static(truth, T) + np.outer(r, truth.lag) + np.outer(run.state, truth.h / 2)
    floor = 0.5 * np.median(np.abs(r)[np.abs(r) > 0.002])
    heat, cool = r > floor, r < -floor
    grid = np.linspace(max(T[heat].min(), T[cool].min()), min(T[heat].max(), T[cool].max()), 201)
    out = []
    for i in range(3):
        d = np.polyval(np.polyfit(T[heat], y[heat, i], order), grid) - np.polyval(np.polyfit(T[cool], y[cool, i],
                                                                                             order), grid)
        out.append(d[np.argmax(np.abs(d))])
    return np.array(out)


def test_fitted_curves_lie_in_their_3_sigma_band_and_the_true_order_is_chosen():
    inside, orders, lags = [], [], []
    for seed in SEEDS:
        rng = np.random.default_rng(seed)
        truth = _truth(rng, NOMINAL, 0.0)
        run = simulate(NOMINAL, truth, RATE_HZ, WHITE, rng, correlated=CORRELATED)
        got = fit_sensor(run.t, run.temperature, run.data, "accelerometer", "m/s^2", RATE_HZ, Settings(), "sim")
        grid = np.linspace(got.model.tmin, got.model.tmax, 101)
        z = (got.model.bias(grid)[0] - _static(truth, grid)) / got.model.sigma(grid)
        inside += list(np.abs(z).max(axis=0) < 3)
        orders += [a.order for a in got.axes]
        lags += [a.lag for a in got.axes]
    cases = len(SEEDS) * 3
    assert np.mean(inside) >= 0.9, f"{cases - sum(inside)} of {cases} curves leave their 3-sigma band"
    assert np.mean(np.array(orders) == 3) >= 0.9, f"orders chosen: {np.bincount(orders)}"
    assert all(lags), "the lag term, which the truth has, was left out"


def test_the_hysteresis_found_lies_within_its_3_sigma_of_the_truth():
    profile = Profile(-10.0, 60.0, 4 / 60, 6 / 60, 60.0, 1.5)
    z, ratio = [], []
    for seed in SEEDS:
        rng = np.random.default_rng(100 + seed)
        truth = _truth(rng, profile, 0.5)
        run = simulate(profile, truth, RATE_HZ, WHITE, rng, correlated=CORRELATED)
        got = fit_sensor(run.t, run.temperature, run.data, "accelerometer", "m/s^2", RATE_HZ, Settings(), "sim")
        want = _branch_difference(run, truth, 3)
        for i, a in enumerate(got.axes):
            assert a.hysteresis is not None
            z.append((a.hysteresis.value - want[i]) / a.hysteresis.sigma)
            # and it is about what a branch comparison sees on the ramps: h + lag (r_up + r_down)
            ratio.append(a.hysteresis.value / (truth.h[i] + truth.lag[i] * (profile.rate_up + profile.rate_down)))
    z = np.abs(z)
    assert np.mean(z < 3) >= 0.95, f"{np.sum(z >= 3)} of {len(z)} beyond 3 sigma: {np.sort(z)[-5:]}"
    assert 0.8 < np.median(ratio) < 1.2


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_the_model_compensates_what_it_was_fitted_on(axis):
    rng = np.random.default_rng(7)
    truth = _truth(rng, NOMINAL, 0.0)
    run = simulate(NOMINAL, truth, RATE_HZ, WHITE, rng)
    got = fit_sensor(run.t, run.temperature, run.data, "accelerometer", "m/s^2", RATE_HZ, Settings(), "sim")
    a = got.axes[axis]
    clean = _static(truth, run.true_temperature)[:, axis] + truth.lag[axis] * run.rate
    # before: the thermal curve and the noise; after: the white noise alone, which the band need not inflate for
    assert a.rms_before == pytest.approx(np.hypot(clean.std(), WHITE), rel=0.05)
    assert a.rms_after == pytest.approx(WHITE, rel=0.05)
    assert a.max_after < 6 * WHITE
    assert 1.0 <= a.inflation < 2.0  # the blocking estimate takes the largest of its batch sizes: conservative
