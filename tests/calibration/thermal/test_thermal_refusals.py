"""What a thermal calibration refuses, one line each naming what to do (issue 25, "Checks and refusals"), and how
its model clamps outside the range it was fitted over."""

from __future__ import annotations

import numpy as np
import pytest

from align.calibration.thermal.model import AxisModel, ThermalModel
from align.calibration.thermal.sensor import Settings, fit_sensor
from align.calibration.thermal.simulate import Profile, Truth, simulate
from align.errors import InputError

RATE_HZ = 5.0


def _run(profile: Profile, size: float = 0.01, seed: int = 0, **kw):
    """A static accelerometer in the chamber: a cubic of ``size`` per term, a small lag, no hysteresis."""
    rng = np.random.default_rng(seed)
    truth = Truth(np.full((3, 4), size), 0.5 * (profile.low + profile.high), 0.5 * (profile.high - profile.low),
                  np.full(3, 0.05), np.zeros(3))
    return simulate(profile, truth, RATE_HZ, 0.002, rng, **kw)


def _fit(run, **settings):
    return fit_sensor(run.t, run.temperature, run.data, "accelerometer", "m/s^2", RATE_HZ, Settings(**settings),
                      "log.csv")


def _refused(run, words: str, **settings) -> str:
    with pytest.raises(InputError) as err:
        _fit(run, **settings)
    text = str(err.value)
    assert words in text and "\n" not in text and text.startswith("log.csv: "), text
    return text


def test_a_span_too_narrow_for_the_order():
    narrow = _run(Profile(20.0, 30.0, 2 / 60, 2 / 60, 0.0, 1.0, tau_s=0.0))
    text = _refused(narrow, "too narrow for order 3", order=3)
    assert "at least 15 C" in text and "order" in text
    _refused(_run(Profile(25.0, 28.0, 0.5 / 60, 0.5 / 60, 0.0, 1.0, tau_s=0.0)), "spans only 3.0")
    # chosen, not fixed: orders above what the span allows are not tried, and the result says so
    assert "orders above 2 not tried" in _fit(narrow, hysteresis=False).notes[0]


def test_a_temperature_resolution_coarser_than_the_fit_needs():
    coarse = _run(Profile(-10.0, 60.0, 5 / 60, 5 / 60, 0.0, 1.0), size=0.05, resolution=1.0)
    _refused(coarse, "reads in steps of 1 C, coarser than the fit needs")
    # the same steps on a sensor whose bias barely moves per step are fine
    assert _fit(_run(Profile(-10.0, 60.0, 5 / 60, 5 / 60, 0.0, 1.0), size=1e-4, resolution=1.0)).resolution == 1.0


def test_a_recording_that_moves():
    run = _run(Profile(-10.0, 60.0, 5 / 60, 5 / 60, 0.0, 1.0))
    k = len(run.t) // 2
    run.data[k:k + 50, 2] -= 9.80665 * (1 - np.cos(np.linspace(0, 0.3, 50)))  # tilted by up to 17 deg, and back
    _refused(run, "the recording moves")


@pytest.mark.parametrize("offset, words", [(273.15, "if the column is in kelvin"), (-273.15, "check")])
def test_a_temperature_in_the_wrong_unit(offset, words):
    run = _run(Profile(-10.0, 60.0, 5 / 60, 5 / 60, 0.0, 1.0))
    moved = type(run)(run.t, run.temperature + offset, run.data, run.true_temperature, run.rate, run.state)
    text = _refused(moved, "is no chip's in a chamber")
    assert words in text and "temperature_units" in text


def test_a_branch_with_too_few_samples():
    # heats for 14 min, then cools for 8 s only
    profile = Profile(-10.0, 60.0, 5 / 60, 5 / 60, 0.0, 0.5, tau_s=0.0)
    run = _run(profile)
    tail = int(8 * RATE_HZ)
    down = run.temperature[-1] - 0.1 * np.arange(1, tail + 1) / RATE_HZ
    grown = type(run)(np.r_[run.t, run.t[-1] + np.arange(1, tail + 1) / RATE_HZ], np.r_[run.temperature, down],
                      np.vstack([run.data, run.data[-tail:]]), run.true_temperature, run.rate, run.state)
    text = _refused(grown, "the cooling branch has", min_branch_s=4.0, window_s=4.0)
    assert "hysteresis='false'" in text  # the command line says --no-hysteresis
    assert _fit(grown, hysteresis=False, window_s=4.0).branches == {}


def test_outside_its_range_the_model_clamps_and_says_so():
    ax = AxisModel(np.array([0.1, 0.01, 0.0, 1e-5]), None, np.zeros((4, 4)))
    model = ThermalModel("accelerometer", 20.0, 0.0, 40.0, (ax, ax, ax))
    out = model.compensate(np.zeros((3, 3)), np.array([-30.0, 20.0, 90.0]))
    # written out: b(T) = 0.1 + 0.01 d + 1e-5 d^3 at d = clip(T, 0, 40) - 20
    want = [-(0.1 + 0.01 * d + 1e-5 * d ** 3) for d in (-20.0, 0.0, 20.0)]
    assert out.data[:, 0] == pytest.approx(want, abs=1e-15)
    assert out.clamped == 2 and "2 samples outside the valid range 0.00 to 40.00 C" in out.note
    assert model.compensate(np.zeros((1, 3)), np.array([25.0])).note is None


def test_the_result_file_reads_back_and_a_malformed_one_is_refused_in_one_line():
    from align.calibration.thermal import ThermalCalibration
    from align.values import approx_equal

    run = _run(Profile(-10.0, 60.0, 5 / 60, 5 / 60, 0.0, 1.0))
    result = ThermalCalibration({"accelerometer": _fit(run)}, {"log": "log.csv"})
    d = result.to_dict()
    assert approx_equal(ThermalCalibration.from_dict(d).sensors, result.sensors, rtol=1e-12)
    axis = d["accelerometer"]["axes"][1]
    for change, words in ((lambda a: a.update(coefficent=[1.0]), "unknown key 'coefficent'"),
                          (lambda a: a.update(coefficients=[1.0]), "malformed thermal calibration"),
                          (lambda a: a.pop("order"), "missing key 'order'")):
        bad = {**d, "accelerometer": {**d["accelerometer"], "axes": [d["accelerometer"]["axes"][0], dict(axis),
                                                                      d["accelerometer"]["axes"][2]]}}
        change(bad["accelerometer"]["axes"][1])
        with pytest.raises(InputError, match=words) as err:
            ThermalCalibration.from_dict(bad, "r.json")
        assert "\n" not in str(err.value) and "r.json: accelerometer" in str(err.value)
