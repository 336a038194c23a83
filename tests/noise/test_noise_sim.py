"""The sensor-error simulator (align.noise.sim): its terms recovered by the fit, seeding, the seed's methods."""

import numpy as np
import pytest
from test_noise_fit import ARW, _fit  # simulate, then fit: the simulator checked by the fit

from align.noise.fit import noise_figures
from align.noise.sim import NoiseSpec, seed_method_a, seed_method_b, seed_restoring, simulate_noise
from align.units import parse_quantity as q


@pytest.mark.slow
def test_simulator_checks_itself_other_terms():
    k = q("30 deg/h/sqrt(h)", "rate_random_walk")
    f = _fit(NoiseSpec(white=ARW, random_walk=k), 3)
    assert f.params[3] / k == pytest.approx(1, abs=0.15) and f.identifiable[3]
    qn = 2e-5  # rad
    f = _fit(NoiseSpec(white=ARW * 0.1, quantization=qn), 4, n=200_000)
    assert f.params[0] / qn == pytest.approx(1, abs=0.05)
    gm = [_fit(NoiseSpec(white=ARW, flicker=q("5 deg/h", "angular_rate"), flicker_model="gauss-markov"), s) for s in range(3)]
    assert np.median([g.params[2] for g in gm]) / q("5 deg/h", "angular_rate") == pytest.approx(1, abs=0.1)


def test_simulator_is_seeded_and_pure():
    spec = NoiseSpec(white=ARW, flicker=1e-5, random_walk=1e-6, turn_on=1e-3)
    a, b = simulate_noise(1000, 100.0, spec, 3, 7), simulate_noise(1000, 100.0, spec, 3, 7)
    assert np.array_equal(a, b)
    truth = np.zeros(1000)
    out = seed_method_a(truth, 100.0, 0.1, 0.01, 1.0, 1e-3, 1)
    assert np.array_equal(truth, np.zeros(1000)) and out.shape == (1000,)


def test_seed_statistics_restoring_method():
    fs, period, stab, rep = 100.0, 1.0, 2e-3, 5e-3
    biases = []
    for seed in range(200):
        out = seed_restoring(np.zeros(20_000), fs, 0.1, rep, stab, period, 1e-3, seed)
        fig = noise_figures(out, fs, (period,))
        assert fig["stability"][period] == pytest.approx(stab, rel=1e-9)  # restored exactly (its Eq 18)
        biases.append(fig["bias"])
    assert np.mean(biases) == pytest.approx(0.1, abs=3 * rep / np.sqrt(200))
    assert np.std(biases, ddof=1) == pytest.approx(rep, rel=0.2)  # run-to-run (its Eq 14)
    b = seed_method_b(np.zeros(20_000), fs, 0.1, 1e-4, 1e-3, 0)
    assert b.shape == (20_000,)


def test_spec_names_its_model_and_refuses_an_unknown_flicker_model():
    from align.errors import InputError
    from align.noise.model import NoiseModel

    spec = NoiseSpec(white=ARW, flicker=1e-5, random_walk=1e-6, quantization=1e-7, ramp=1e-9, bias=3.0)
    assert spec.model == NoiseModel(1e-7, ARW, 1e-5, 1e-6, 1e-9)
    assert spec == NoiseSpec(white=ARW, flicker=1e-5, random_walk=1e-6, quantization=1e-7, ramp=1e-9, bias=3.0)
    with pytest.raises(InputError) as err:
        NoiseSpec(flicker=1e-5, flicker_model="pink")
    assert err.value.fields == ["flicker_model"] and "gauss-markov" in str(err.value)
