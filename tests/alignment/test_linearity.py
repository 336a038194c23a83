"""Scale factor across the range (issue 26): nonlinearity and asymmetry against an independent simulator.

The truth is computed here, from the definitions of IEEE Std 952/1431 (least-squares line through the output
at the rates tested; largest deviation over full-scale output; K+ against K- from a line each), with
``numpy.polyfit`` on the noise-free function; the readings come from this module's own dwell simulator
``y = s (1 + a sign(w) / 2) w + k2 w^2 + k3 w^3 + b + noise``.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from align.alignment.linearity import ScaleErrors, fit_axis, linearity_axes, linearity_plan, measure_linearity
from align.alignment.pipeline import align
from align.alignment.plan import Plan, Step
from align.alignment.result import AlignmentResult
from align.alignment.simulate import SessionSpec, simulate_session
from align.model import SensorModel
from align.present.text import alignment_summary

DEG = math.pi / 180

RATES = np.radians([5.0, 20.0, 60.0, 150.0, 300.0])


def bent(w, s, asym, k2, k3):
    """The gyro's output for input ``w`` (rad/s): this module's own model."""
    return s * (1 + asym * np.sign(w) / 2) * w + k2 * w**2 + k3 * w**3


def truth(rates, s, asym, k2, k3):
    """Nonlinearity (fraction of full-scale output) and asymmetry of the noise-free output at the rates tested."""
    w = np.unique(rates)
    y = bent(w, s, asym, k2, k3)
    slope, icpt = np.polyfit(w, y, 1)
    fs = np.max(np.abs(w))
    nl = np.max(np.abs(y - (slope * w + icpt))) / (slope * fs)
    kp = np.polyfit(w[w > 0], y[w > 0], 1)[0]
    kn = np.polyfit(w[w < 0], y[w < 0], 1)[0]
    return nl, (kp - kn) / ((kp + kn) / 2), slope


#: (scale, asymmetry, k2 [s/rad], k3 [s^2/rad^2]) with full scale 300 deg/s = 5.236 rad/s
CASES = [(1.001, 0.0, 0.0, 4e-4 / 5.236**2),  # cubic: the largest deviations at both ends (a tie)
         (0.998, 1.5e-3, 3e-4 / 5.236, 0.0),  # asymmetry and a quadratic term
         (1.0, -8e-4, 0.0, -2e-4 / 5.236**2)]  # asymmetry and a cubic term


def dwell_means(rng, rates, case, n=400, sigma=0.05 * DEG, bias=0.3 * DEG):
    """Mean and variance of the mean of each dwell, from ``n`` samples with white noise ``sigma`` (rad/s)."""
    samples = bent(rates, *case)[:, None] + bias + rng.normal(0, sigma, (len(rates), n))
    return samples.mean(axis=1), samples.var(axis=1, ddof=1) / n


def test_the_reported_sigmas_cover_the_truth_over_many_seeds():
    seeds = 300
    cyclic = np.concatenate([np.ravel([[r, -r] for r in RATES]), np.ravel([[r, -r] for r in RATES[::-1]])])
    z_nl, z_as, z_k = [], [], []
    for c, case in enumerate(CASES):
        rates = cyclic if c == 2 else np.ravel([[r, -r] for r in RATES])  # one case runs the rates up and down
        nl, asym, slope = truth(rates, *case)
        assert nl > 1e-4 and (c == 0 or abs(asym) > 5e-4)
        rng = np.random.default_rng(100 + c)
        for _ in range(seeds):
            y, var = dwell_means(rng, rates, case)
            a = fit_axis(rates, y, var)
            assert a.significant
            z_nl.append((a.nonlinearity - nl) / a.nonlinearity_sigma)
            z_as.append((a.asymmetry - asym) / a.asymmetry_sigma)
            z_k.append((a.scale - slope) / a.scale_sigma)
    n = len(z_nl)
    band = 3 * math.sqrt(0.6827 * 0.3173 / n)  # binomial: 3 standard deviations of the 1-sigma coverage
    for z in (z_nl, z_as, z_k):
        z = np.abs(np.array(z))
        assert abs(np.mean(z < 1) - 0.6827) < band, np.mean(z < 1)
        assert np.sum(z > 3) <= 6  # expected 0.27 % of 900 = 2.4
    # the cubic case's two-way tie biases the largest deviation up, by about half a sigma: still covered
    assert abs(np.mean(z_nl[:seeds])) < 0.8


def test_noise_free_figures_are_the_definitions():
    x = np.ravel([[r, -r] for r in RATES])
    for case in CASES:
        a = fit_axis(x, bent(x, *case), np.zeros(len(x)))
        nl, asym, slope = truth(x, *case)
        assert a.nonlinearity == pytest.approx(nl, rel=1e-9)
        assert a.asymmetry == pytest.approx(asym, rel=1e-9, abs=1e-15)
        assert a.scale == pytest.approx(slope, rel=1e-12)
        assert a.full_scale == pytest.approx(RATES[-1])
    # analytic: a quadratic term k2 w^2 over symmetric rates deviates from the line by k2 (w^2 - mean w^2)
    k2 = 1e-4
    a = fit_axis(x, x + k2 * x**2, np.zeros(len(x)))
    m2 = np.mean(RATES**2)
    assert a.nonlinearity == pytest.approx(k2 * max(RATES[-1] ** 2 - m2, m2) / RATES[-1], rel=1e-9)


def test_no_nonlinearity_is_flagged_as_the_noise_and_never_as_measured():
    x = np.ravel([[r, -r] for r in RATES])
    y, var = dwell_means(np.random.default_rng(5), x, (1.0, 0.0, 0.0, 0.0))
    a = fit_axis(x, y, var)
    assert not a.significant and a.nonlinearity < 4 * a.nonlinearity_sigma
    with pytest.raises(Exception, match="two rates in each direction"):
        fit_axis(np.radians([10, -10, 20]), np.radians([10, -10, 20]), np.ones(3))


def test_plan_with_one_rate_per_direction_has_no_linearity_and_the_same_file():
    plan = Plan.standard_rate(100 * DEG)
    assert linearity_axes(plan) == (False, False, False)
    m = np.array([[1.002, 0.003, -0.002], [-0.004, 0.998, 0.001], [0.002, -0.001, 1.001]])
    t, g, _ = simulate_session(plan, SensorModel(m, np.zeros(3)), SessionSpec(noise_density=0.0), seed=1)
    r = align(t, g, plan)
    assert r.linearity is None and "linearity" not in r.to_dict() and "linearity_rate" not in r.to_dict()["units"]
    assert np.allclose(r.M, m, atol=1e-6)
    assert not any(f.name.startswith(("nonlinearity", "asymmetry")) for f in r.figures_of_merit())


def test_pipeline_measures_the_simulated_nonlinearity_and_writes_it(tmp_path):
    fs_rate = 200 * DEG
    plan = linearity_plan(np.radians([10.0, 50.0, 120.0, 200.0]), axes=(0, 2))  # y: one rate per direction
    plan = Plan(plan.steps + (Step(1, 1, rate=100 * DEG), Step(1, 1, rate=-100 * DEG)))
    assert linearity_axes(plan) == (True, False, True)
    m = np.array([[1.002, 0.003, -0.002], [-0.004, 0.998, 0.001], [0.002, -0.001, 1.001]])
    asym, quad, cubic = (1e-3, 0.0, -6e-4), (2e-4, 0.0, 0.0), (0.0, 0.0, 3e-4)
    errors = ScaleErrors.from_full_scale(fs_rate, asym, quad, cubic)
    spec = SessionSpec(dwell_s=4.0, static_s=1.0, scale_errors=errors)
    t, g, _ = simulate_session(plan, SensorModel(m, np.radians([0.1, -0.2, 0.05])), spec, seed=3)
    r = align(t, g, plan)
    lin = r.linearity
    assert lin is not None and lin.axes[1] is None
    for i in (0, 2):
        a = lin.axes[i]
        assert a is not None
        # the gyro's linear reading is M_ii w (dwells about axis i); this module's model bends it
        nl, asy, slope = truth(np.radians([10, 50, 120, 200, -10, -50, -120, -200]), m[i, i], asym[i],
                               quad[i] / fs_rate, cubic[i] / fs_rate**2)
        assert abs(a.nonlinearity - nl) < 3 * a.nonlinearity_sigma, (i, a.nonlinearity, nl, a.nonlinearity_sigma)
        assert abs(a.asymmetry - asy) < 3 * a.asymmetry_sigma, (i, a.asymmetry, asy)
        assert abs(a.scale - slope) < 3 * a.scale_sigma + 1e-6
        assert a.full_scale == pytest.approx(fs_rate, rel=1e-3) and not a.clipped
    figs = {f.name: f for f in lin.figures()}
    assert set(figs) == {f"{k}_{a}" for k in ("nonlinearity", "asymmetry", "scale") for a in "xyz"}
    assert all(f.unit == "1" for f in figs.values())
    assert math.isnan(figs["nonlinearity_y"].value) and "not measured" in figs["nonlinearity_y"].detail
    names = {f.name for f in r.figures_of_merit()}
    assert {"nonlinearity_x", "asymmetry_z", "scale_x"} <= names
    path = tmp_path / "alignment.json"
    path.write_text(json.dumps(r.to_dict()))
    back = AlignmentResult.from_dict(json.loads(path.read_text()))
    assert back.linearity == lin
    assert "nonlinearity" in alignment_summary(r) and "ppm" in alignment_summary(r)


def test_clipped_readings_are_stated():
    plan = linearity_plan(np.radians([20.0, 100.0, 200.0]), axes=(2,))
    plan = Plan(plan.steps + tuple(Step(a, 1, rate=s * 50 * DEG) for a in (0, 1) for s in (1, -1)))
    m = np.diag([1.0, 1.0, 1.003])
    spec = SessionSpec(dwell_s=3.0, static_s=1.0, gyro_range=196 * DEG)
    t, g, _ = simulate_session(plan, SensorModel(m, np.zeros(3)), spec, seed=2)
    r = align(t, g, plan)  # the range not told to align: the readings show it
    assert r.linearity is not None and r.linearity.axes[2] is not None
    assert r.linearity.axes[2].clipped and r.linearity.axes[2].peak == pytest.approx(196 * DEG)
    assert "clipped" in r.linearity.summary()
    assert measure_linearity([], Plan.standard_rate(DEG), np.eye(3)) is None
