"""The closed forms of the static error growth (seed 002 Eq 4) against the Monte Carlo through the integrator."""

from __future__ import annotations

import numpy as np
import pytest

from align.navigation.closed import QUANTITIES, dominance, static_sigma, term_sigmas
from align.navigation.mission import static_mission
from align.navigation.montecarlo import monte_carlo, slow_grid
from align.navigation.residuals import ResidualErrors, SensorErrors
from align.units import DEG, DEG_H, parse_quantity

RUNS = 1500
DURATION = 120.0
ARW = parse_quantity("0.3 deg/sqrt(h)", "angle_random_walk")
VRW = parse_quantity("0.06 m/s/sqrt(h)", "velocity_random_walk")
# one term at a time (small enough for the first-order closed forms), then all of them together
CASES = {
    "gyro bias": ResidualErrors(gyro=SensorErrors("gyroscope", bias=[20 * DEG_H, 10 * DEG_H, 30 * DEG_H])),
    "angle random walk": ResidualErrors(gyro=SensorErrors("gyroscope", white=ARW)),
    "gyro bias instability": ResidualErrors(gyro=SensorErrors("gyroscope", flicker=10 * DEG_H)),
    "rate random walk": ResidualErrors(gyro=SensorErrors("gyroscope", random_walk=parse_quantity(
        "200 deg/h/sqrt(h)", "rate_random_walk"))),
    "rate ramp": ResidualErrors(gyro=SensorErrors("gyroscope", ramp=0.05 * DEG_H)),
    "accel bias and scale/misalignment": ResidualErrors(accel=SensorErrors(
        "accelerometer", bias=5e-3, matrix=np.full((3, 3), 3e-4))),
    "velocity random walk": ResidualErrors(accel=SensorErrors("accelerometer", white=VRW)),
    "all terms, heading 30 deg": ResidualErrors(
        SensorErrors("gyroscope", bias=10 * DEG_H, white=ARW, flicker=5 * DEG_H, tilt=0.3 * DEG,
                     random_walk=parse_quantity("30 deg/h/sqrt(h)", "rate_random_walk")),
        SensorErrors("accelerometer", bias=[2e-3, 1e-3, 3e-3], white=VRW, flicker=2e-4, random_walk=1e-4)),
}


def _closed(errors, mission, mc):
    steps = int(round(mc.t[-1] * mission.fs / round(mission.fs / mc.nav_rate)))
    terms = term_sigmas(errors, mc.t, mission.gravity, mission.heading, mission.earth_body, float(mc.t[-1]),
                        slow_grid(steps))
    return terms, static_sigma(terms, mc.sigma.shape)


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.slow
def test_closed_forms_agree_with_the_monte_carlo(case):
    errors = CASES[case]
    heading = 30 * DEG if "heading" in case else 0.0
    mission = static_mission(DURATION, 100.0, heading=heading)
    mc = monte_carlo(mission, errors, RUNS, seed=7)
    _, cf = _closed(errors, mission, mc)
    # the sample standard deviation of RUNS Gaussian draws is within 4.5 of its own sigma, 1/sqrt(2 (RUNS-1)) = 1.8 %
    tol = 4.5 / np.sqrt(2 * (RUNS - 1))
    for i in (len(mc.t) // 10, len(mc.t) // 2, len(mc.t) - 1):
        live = cf[i] > 1e-9 * cf.max(axis=0).clip(1e-300)
        assert np.any(live)
        ratio = mc.sigma[i, live] / cf[i, live]
        names = [q for q, k in zip(QUANTITIES, live) if k]
        assert np.all(np.abs(ratio - 1) < tol + 0.02), dict(zip(names, np.round(ratio, 3)))
        # where the closed forms have none (the down channel from a gyro) only the second order is left: the
        # vertical specific force's g (1 - cos eps) ~ g eps^2 / 2 of the tilt error eps
        t, tilt2 = mc.t[i], mc.sigma[i, 0] ** 2 + mc.sigma[i, 1] ** 2
        bound = np.array([0, 0, 0, 0, 0, 2 * 9.81 * tilt2 * t, 0, 0, 9.81 * tilt2 * t * t])
        assert np.all(mc.sigma[i, ~live] <= bound[~live] + 1e-12)
        # zero-mean errors: the mean is within 4.5 standard errors of zero
        assert np.all(np.abs(mc.mean[i, live]) < 4.5 * mc.sigma[i, live] / np.sqrt(RUNS) + 1e-12)


@pytest.mark.parametrize("term, powers", [("bias", (1, 2, 3)), ("white", (0.5, 1.5, 2.5)),
                                          ("random_walk", (1.5, 2.5, 3.5)), ("ramp", (2, 3, 4))])
@pytest.mark.slow
def test_gyro_errors_grow_as_the_seed_says(term, powers):
    # seed 002 after Eq 4: attitude error linear in a gyro drift, velocity quadratic, position cubic;
    # the random walks: sqrt(t), t^1.5, t^2.5; the Monte Carlo's log-log slopes over a decade
    gyro = SensorErrors("gyroscope", **{term: {"bias": 10 * DEG_H, "white": ARW, "random_walk": 1e-5,
                                               "ramp": 1e-6}[term]})
    mission = static_mission(200.0, 100.0)
    mc = monte_carlo(mission, ResidualErrors(gyro=gyro), 600, seed=3, points=201)
    a, b = np.searchsorted(mc.t, 20.0), len(mc.t) - 1
    for col, power in zip((2, 3, 6), powers):  # heading, north velocity, north position
        slope = np.log(mc.sigma[b, col] / mc.sigma[a, col]) / np.log(mc.t[b] / mc.t[a])
        assert abs(slope - power) < 0.08, (QUANTITIES[col], slope)


def test_closed_form_reference_numbers():
    # hand-computed: 10 deg/h of gyro bias after 10 min: 1.6667 deg of heading; g sigma t^2 / 2 of velocity;
    # 0.3 deg/sqrt(h) of ARW after 1 h: 0.3 deg; 1 mg of accel bias after 60 s: 0.5 g t^2 = 17.65 m
    g = 9.80665
    e = ResidualErrors(SensorErrors("gyroscope", bias=10 * DEG_H, white=ARW), SensorErrors("accelerometer", bias=1e-3 * g))
    terms = term_sigmas(e, np.array([60.0, 600.0, 3600.0]), g, duration=3600.0)
    bias, arw, acc = terms[("gyroscope", "bias")], terms[("gyroscope", "white")], terms[("accelerometer", "bias")]
    assert bias[1, 2] / DEG == pytest.approx(10 / 6, rel=1e-12)
    assert bias[1, 3] == pytest.approx(g * 10 * DEG_H * 600**2 / 2, rel=1e-12)
    assert bias[1, 6] == pytest.approx(g * 10 * DEG_H * 600**3 / 6, rel=1e-12)
    assert arw[2, 2] / DEG == pytest.approx(0.3, rel=1e-12)
    assert acc[0, 6] == pytest.approx(0.5 * 1e-3 * g * 60**2, rel=1e-12)


def test_flicker_closed_form_is_the_integral_of_its_spectrum():
    # the line sum (E4) against the integral of the one-sided PSD B^2 / (pi f) over the band the lines stand for
    # (line k for [k, k + 1] df from the stated cutoff 1 / (SYNTHESIS_SPAN T) up; issue 23: the lines of the
    # midpoint rule reached down to half the cutoff), by quadrature
    from scipy.integrate import quad

    from align.navigation.closed import SYNTHESIS_SPAN, _flicker_s, flicker_lines

    duration, points, t = 600.0, 129, 300.0
    f, c2 = flicker_lines(duration, points)
    s1 = _flicker_s(np.array([t]), (f, c2))[0, 0]
    df = 1 / (SYNTHESIS_SPAN * duration)
    lo, hi = df, f[-1]
    expect, _ = quad(lambda x: 4 * np.sin(np.pi * x * t) ** 2 / (2 * np.pi * x) ** 2 / (np.pi * x), lo, hi, limit=400)
    assert s1**2 == pytest.approx(expect, rel=0.05)


def test_which_error_dominates_switches_where_the_closed_forms_cross():
    # heading: ARW N sqrt(t) against bias sigma t cross at t = (N / sigma)^2
    e = ResidualErrors(gyro=SensorErrors("gyroscope", bias=5 * DEG_H, white=ARW))
    t = np.linspace(0, 600, 6001)
    rows = [r for r in dominance(t, term_sigmas(e, t, 9.8, duration=600.0)) if r["quantity"] == "heading"]
    assert [r["term"] for r in rows] == ["angle random walk", "gyro bias"]
    assert rows[1]["from_s"] == pytest.approx((ARW / (5 * DEG_H)) ** 2, abs=0.2)
