"""The one IEEE noise model (align.noise.model): Std 952's slopes, and the numbers fit and planner gave before."""

import numpy as np
import pytest

from align.noise import fit, planner
from align.noise.model import FLICKER_FACTOR, TERMS, NoiseModel, avar_design, model_adev
from align.units import DEG_H
from align.units import parse_quantity as q
from align.values import approx_equal

ARW = q("0.3 deg/sqrt(h)", "angle_random_walk")
TAU = np.array([0.01, 0.1, 1.0, 10.0, 100.0, 1000.0])


def _planner_before(white, flicker=0.0, random_walk=0.0, quantization=0.0):
    """planner.model_curve as it was written before the model had one home (the oracle)."""
    ln = 2 * np.log(2) / np.pi

    def sigma(tau):
        tau = np.asarray(tau, dtype=float)
        return np.sqrt(3 * quantization**2 / tau**2 + white**2 / tau + ln * flicker**2 + random_walk**2 * tau / 3)
    return sigma


def _fit_before(tau, params):
    """fit.model_adev as it was written before (the oracle)."""
    tau = np.asarray(tau, dtype=float)
    design = np.column_stack([3 / tau**2, 1 / tau, np.full_like(tau, 2 * np.log(2) / np.pi), tau / 3, tau**2 / 2])
    return np.sqrt(design @ np.square(np.asarray(params, dtype=float)))


def test_ieee_952_slopes_and_readouts():
    """Each term alone reads back as IEEE Std 952 says: N at tau = 1 s, 0.664 B, K at tau = 3 s, ..."""
    n, b, k, qn, r = ARW, 5 * DEG_H, 3 * DEG_H / 60, 1e-6, 1e-9
    assert FLICKER_FACTOR == pytest.approx(2 * np.log(2) / np.pi, rel=1e-15)
    assert NoiseModel(white=n)(1.0) == pytest.approx(n, rel=1e-15)
    assert NoiseModel(flicker=b)(123.0) == pytest.approx(0.664 * b, rel=1e-3)
    assert NoiseModel(random_walk=k)(3.0) == pytest.approx(k, rel=1e-15)
    assert NoiseModel(quantization=qn)(2.0) == pytest.approx(np.sqrt(3) * qn / 2.0, rel=1e-15)
    assert NoiseModel(ramp=r)(4.0) == pytest.approx(r * 4.0 / np.sqrt(2), rel=1e-15)
    whole = NoiseModel(qn, n, b, k, r)
    assert np.allclose(whole.avar(TAU), sum(whole.only(t).avar(TAU) for t in TERMS), rtol=1e-14, atol=0)


def test_unified_model_reproduces_the_planner_and_the_fit_before():
    n, b, k, qn = ARW, 5 * DEG_H, 3 * DEG_H / 60, 1e-6
    assert np.allclose(planner.model_curve(n, b, k, qn)(TAU), _planner_before(n, b, k, qn)(TAU), rtol=1e-14, atol=0)
    params = [qn, n, b, k, 1e-9]
    assert np.array_equal(fit.model_adev(TAU, params), _fit_before(TAU, params))
    assert np.array_equal(model_adev(TAU, params), NoiseModel.from_params(params)(TAU))
    # the numbers the two modules gave before the change (bit for bit then; 1e-12 allows a BLAS change)
    assert np.allclose(model_adev(TAU, params), [0.000889833043536569, 0.0002769722957486844, 8.875669433403416e-05,
                                                 3.195411048102063e-05, 1.8368834051284002e-05, 1.6941020360530965e-05],
                       rtol=1e-12, atol=0)
    curve = planner.model_curve(n, b, k, qn)
    assert np.allclose(curve(TAU), [0.000889833043536569, 0.00027697229574867534, 8.875669433121747e-05,
                                    3.195410969864866e-05, 1.8368697950688033e-05, 1.6926256847156865e-05],
                       rtol=1e-12, atol=0)
    before = [0.0826970756537555, 3.642267969294268, 23.22809315099879]
    for target, tau in zip((62.83 * DEG_H, 10 * DEG_H, 5 * DEG_H), before):
        a = planner.averaging_time(target, sigma=curve)
        assert a.tau == pytest.approx(tau, rel=1e-9)
        assert a.floor == pytest.approx(1.6844056380992906e-05, rel=1e-9)
        assert a.tau == pytest.approx(planner.averaging_time(target, sigma=_planner_before(n, b, k, qn)).tau, rel=1e-9)


def test_noise_model_is_a_value_and_keeps_the_shape_of_tau():
    m = NoiseModel(white=ARW, flicker=5 * DEG_H)
    assert np.ndim(m(2.0)) == 0 and m(TAU).shape == TAU.shape and m(TAU.reshape(2, 3)).shape == (2, 3)
    assert avar_design(TAU).shape == (6, 5)
    assert NoiseModel.from_params(m.params) == m and m != NoiseModel(white=ARW)
    with pytest.raises(AttributeError):
        m.white = 0.0
    assert approx_equal(m.replace(white=ARW * (1 + 1e-13)), m, rtol=1e-12)
