"""Estimators against known truth: exact without noise, honest sigmas with noise."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from support import truth_model

from align.alignment.estimate import fit_rate_pairs
from align.alignment.job import AlignOptions, align
from align.alignment.observe import Observation
from align.alignment.plan import Plan, Step
from align.alignment.segment import Segment
from align.alignment.simulate import SessionSpec, simulate_session
from align.alignment.twoaxis import two_axis_error_bound
from align.model import SensorModel
from align.units import DEG
from align.units import parse_quantity as q

NOISELESS = SessionSpec(noise_density=0.0)


def test_eq30_pairwise_difference_drops_the_bias():
    # Eq 28-30: rotate about y at +w and -w; M32 = (g_z(+) - g_z(-)) / (2 w), bias drops out.
    m = truth_model(3)
    w = 100 * DEG
    plan = Plan.standard_rate(w)
    obs = []
    for k, step in enumerate(plan.steps):
        y = m.measure(step.rate * step.unit_axis)
        obs.append(Observation(Segment(f"s{k}", "rate", 0, 10, k), y, np.append(step.rate * step.unit_axis, 1.0),
                               np.full(3, 1e-12), 1.0))
    fit = fit_rate_pairs(obs, plan)
    gz_p, gz_m = obs[2].y[2], obs[3].y[2]
    assert fit.M[2, 1] == pytest.approx((gz_p - gz_m) / (2 * w), rel=1e-14)
    assert fit.M[2, 1] == pytest.approx(m.M[2, 1], rel=1e-12)
    assert np.allclose(fit.bias, m.bias, atol=1e-15)


@pytest.mark.parametrize("kind", ["rate", "angle"])
@pytest.mark.parametrize("method", ["lsq", "closed"])
def test_noiseless_session_is_exact(kind, method):
    m = truth_model(1)
    plan = Plan.standard_rate(100 * DEG) if kind == "rate" else Plan.standard_angle(360 * DEG)
    t, g, _ = simulate_session(plan, m, NOISELESS, 0)
    r = align(t, g, plan, AlignOptions(method=kind if method == "closed" else "lsq"))
    assert np.abs(r.M - m.M).max() < 1e-10
    assert np.abs(r.bias - m.bias).max() < 1e-10
    assert np.allclose(r.A, np.linalg.inv(m.M), atol=1e-10)


def test_general_lsq_any_axes_rates_and_lengths():
    # several rates per axis, unequal dwells, a tilted table axis is not needed: any spanning set works
    m = truth_model(2)
    steps = (Step(0, 1, rate=50 * DEG), Step(0, -1, rate=120 * DEG), Step(1, 1, rate=-80 * DEG),
             Step(2, 1, rate=30 * DEG), Step(2, 1, rate=-200 * DEG), Step(1, -1, rate=60 * DEG))
    plan = Plan(steps)
    t, g, _ = simulate_session(plan, m, NOISELESS, 0)
    r = align(t, g, plan, AlignOptions(method="lsq"))
    assert np.abs(r.M - m.M).max() < 1e-10


@pytest.mark.parametrize("kind", ["rate", "angle"])
def test_uncertainty_covers_truth_across_seeds(kind):
    """Reported 1-sigma is honest: |error| < 3 sigma for ~99.7 % of elements, z spread ~1."""
    plan = Plan.standard_rate(100 * DEG) if kind == "rate" else Plan.standard_angle(360 * DEG)
    spec = SessionSpec(noise_density=q("0.3 deg/sqrt(h)", "angle_random_walk"),
                       bias_walk=q("10 deg/h/sqrt(h)", "rate_random_walk"))
    z = []
    for seed in range(30):
        m = truth_model(seed)
        t, g, _ = simulate_session(plan, m, spec, seed)
        r = align(t, g, plan)
        z.append(((r.M - m.M) / r.sigma_M).ravel())
    z = np.array(z)
    assert np.mean(np.abs(z) > 3) <= 0.01
    assert 0.7 < np.std(z) < 1.3


def test_closed_forms_agree_with_lsq_on_their_design():
    m = truth_model(4)
    plan = Plan.standard_rate(100 * DEG)
    t, g, _ = simulate_session(plan, m, SessionSpec(noise_density=q("0.3 deg/sqrt(h)", "angle_random_walk")), 4)
    a, b = align(t, g, plan, AlignOptions(method="lsq")), align(t, g, plan, AlignOptions(method="rate"))
    # the +/- design is orthogonal, so only the per-segment weights separate them in M: well within 1 sigma
    assert np.all(np.abs(a.M - b.M) < a.sigma_M)
    # the bias: without a latitude lsq also weighs the Earth rate the segments share (issue 23) where the closed
    # form averages the three pairs: two estimators of one bias, apart by less than twice their combined sigma
    assert np.all(np.abs(a.bias - b.bias) < 2 * np.hypot(a.sigma_bias, b.sigma_bias))


def _two_axis_plan():
    return Plan(tuple(Step(a, 1, rate=r) for a in (1, 2) for r in (100 * DEG, -100 * DEG)))


@pytest.mark.parametrize("variant", ["cross", "procrustes"])
def test_two_axis_exact_for_orthogonal_gyros(variant):
    m = SensorModel.from_rotation(Rotation.from_rotvec([0.01, -0.02, 0.03]), bias=[0.01, 0.02, -0.01])
    plan = _two_axis_plan()
    t, g, _ = simulate_session(plan, m, NOISELESS, 0)
    r = align(t, g, plan, AlignOptions(method="auto", two_axis_variant=variant))
    assert r.method == "two-axis" and r.inferred_axis == 0
    assert np.abs(r.M - m.M).max() < 1e-10


def test_two_axis_error_equals_axis_to_axis_angle():
    # first order: the inferred M21 is off by -delta_xy, M31 by -delta_xz (see two_axis_error_bound)
    d = np.array([0.05, -0.04, 0.0]) * DEG
    m = SensorModel.from_rotation(Rotation.identity(), delta=d)
    plan = _two_axis_plan()
    t, g, _ = simulate_session(plan, m, NOISELESS, 0)
    r = align(t, g, plan, AlignOptions(method="two-axis", two_axis_variant="cross"))
    err = r.M[:, 0] - m.M[:, 0]
    assert err[1] == pytest.approx(-d[0], rel=0.02)
    assert err[2] == pytest.approx(-d[1], rel=0.02)
    assert np.linalg.norm(err[1:]) <= two_axis_error_bound(0.05 * DEG)


def test_procrustes_variant_not_scaled_by_scale_errors():
    m = SensorModel.from_rotation(Rotation.from_rotvec([0.0, 0.0, 0.01]), scale=[1.0, 1.01, 1.015])
    plan = _two_axis_plan()
    t, g, _ = simulate_session(plan, m, NOISELESS, 0)
    cross = align(t, g, plan, AlignOptions(method="two-axis", two_axis_variant="cross")).M[:, 0]
    proc = align(t, g, plan, AlignOptions(method="two-axis", two_axis_variant="procrustes")).M[:, 0]
    true = m.M[:, 0]
    assert np.linalg.norm(proc - true) < 0.2 * np.linalg.norm(cross - true)


def test_earth_rate_cancels_in_m_and_goes_to_bias():
    m = truth_model(5)
    lat = 48.0 * DEG
    spec = SessionSpec(noise_density=0.0, latitude=lat)
    plan = Plan.standard_rate(100 * DEG)
    t, g, _ = simulate_session(plan, m, spec, 0)
    # the unweighted closed form (Eq 28-30): noiseless data would give lsq degenerate weights
    r = align(t, g, plan, AlignOptions(method="rate"))
    # the vertical part cancels in +/- differences (uncancelled it would be ~Omega sin(lat) / w = 3e-5);
    # the horizontal part averages out up to a partial last revolution, < Omega / (w T) ~ 4e-6
    assert np.abs(r.M - m.M).max() < 1e-6
    shift = r.bias - m.bias
    expect = m.M @ (np.full(3, 7.2921150e-5 * np.sin(lat)) / 3)  # mean of the three vertical terms
    assert np.allclose(shift, expect, atol=3e-6)  # horizontal leftovers < Omega / (w T)
    assert any("Earth rate not modelled (no latitude" in n for n in r.notes)
    plan_lat = Plan(plan.steps, latitude=lat)
    r2 = align(t, g, plan_lat, AlignOptions(method="rate"))
    assert np.abs(r2.bias - m.bias).max() < 3e-6  # corrected: the vertical part is gone from the bias
    assert any("modelled the component along the spin axis" in n for n in r2.notes)
