"""The noise family refuses what it cannot analyse in one line naming the input: a constant or nearly constant
record (a stuck sensor), a record too short to fit, a sample rate outside its domain, corrupt samples, a malformed
or misspelled result file, plan inputs outside their domain; no warning and no Python exception escapes."""

import json
import warnings

import numpy as np
import pytest

from align.errors import InputError, TestError
from align.noise import AllanJob, allan, fit_noise, make_plan, model_curve, plan_from_allan, point_readouts, run_allan
from align.noise.allan import AllanResult, ArrayChunks
from align.noise.job import MIN_SAMPLES
from align.noise.planner import PlanResult
from align.units import DEG, DEG_S


def _noise(n=20_000, seed=0):
    return np.random.default_rng(seed).normal(0, 0.01, (n, 3))


@pytest.mark.parametrize("data,words", [
    (np.zeros((2000, 3)), "the record is constant"),
    (np.full((2000, 3), -32768.0), "the record is constant"),
])
def test_a_constant_record_is_a_test_error_naming_file_and_channel(data, words):
    with pytest.raises(TestError, match=words) as info:
        run_allan([data], 100.0, ["gx", "gy", "gz"], "deg/s", where=["static.csv"])
    assert info.value.where == "static.csv: gx" and info.value.exit_code == 3


def test_a_nearly_constant_quantised_record_is_refused_without_an_index_error():
    data = np.zeros((100_000, 3))
    data[np.random.default_rng(1).integers(0, 100_000, 5), 0] = 1.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # and no numpy warning on the way
        with pytest.raises(TestError):
            run_allan([data], 100.0, ["gx", "gy", "gz"], "deg/s")


def test_fit_noise_alone_refuses_a_constant_channel():
    res = allan(np.column_stack([_noise()[:, 0], np.zeros(20_000)]), 100.0, ["a", "b"])
    fit_noise(res, 0)
    with pytest.raises(TestError, match="constant") as info:
        fit_noise(res, 1)
    assert info.value.where == "b"


def test_point_readouts_skip_zero_deviations_without_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = point_readouts(np.array([0.1, 1.0, 10.0]), np.array([0.0, 0.0, 0.0]))
        assert np.isnan(out["N_tau1"]) and out["B_floor"] == 0.0
        out = point_readouts(np.array([0.1, 1.0, 10.0, 100.0]), np.array([1.0, 0.0, 0.1, 0.05]))
        assert out["B_floor"] == pytest.approx(0.05 / 0.664)


def test_a_record_too_short_to_fit():
    with pytest.raises(InputError, match=f"only 5 samples; .* at least {MIN_SAMPLES}") as info:
        run_allan([_noise(5)], 100.0, ["a", "b", "c"], "deg/s", where=["short.csv"])
    assert info.value.where == "short.csv"


@pytest.mark.parametrize("fs", [0.0, -100.0, float("nan"), float("inf")])
def test_a_sample_rate_outside_its_domain(fs):
    with pytest.raises(InputError, match="sample rate must be a finite number of Hz > 0"):
        run_allan([_noise(200)], fs, ["a", "b", "c"], "deg/s")
    with pytest.raises(InputError, match="sample rate"):
        allan(_noise(200), fs)


@pytest.mark.parametrize("bad,words", [(np.nan, "NaN or inf"), (np.inf, "NaN or inf"), (1e300, "beyond")])
def test_corrupt_samples_are_named_by_file_and_sample(bad, words):
    data = _noise(5000)
    data[1234, 1] = bad
    with pytest.raises(InputError, match=f"{words}.*sample 1234") as info:
        allan(ArrayChunks(data), 100.0, ["a", "b", "c"], where="static.npy")
    assert info.value.where == "static.npy"


def test_allan_result_refuses_arrays_of_the_wrong_shapes():
    with pytest.raises(ValueError, match="do not match"):
        AllanResult(np.array([1.0, 2.0]), np.array([1, 2]), np.ones((3, 3)), None, 100, 1.0, ("a", "b", "c"))


@pytest.fixture(scope="module")
def job_dict():
    job = run_allan([_noise()], 100.0, ["gx", "gy", "gz"], "deg/s")
    return job.replace(plan=plan_from_allan(job, 100 * DEG_S, 0.1 * DEG)).to_dict()


def test_the_allan_file_round_trips(job_dict):
    assert AllanJob.from_dict(json.loads(json.dumps(job_dict))).to_dict() == job_dict


@pytest.mark.parametrize("change,words", [
    (lambda d: d.__setitem__("adevs", d.pop("adev")), ["unknown key 'adevs'", "did you mean 'adev'"]),
    (lambda d: d.__setitem__("calibraton_note", "x"), ["unknown key 'calibraton_note'"]),
    (lambda d: d["plan"].__setitem__("noise_ratoi", 10), ["unknown key 'noise_ratoi'", "noise_ratio"]),
    (lambda d: d.pop("adev"), ["malformed imu-align.allan result", "regenerate it"]),
    (lambda d: d.__setitem__("tau", None), ["malformed imu-align.allan result"]),
    (lambda d: d.__setitem__("figures", []), ["malformed imu-align.allan result"]),
    (lambda d: d.__setitem__("fit", {"gx": 1}), ["malformed imu-align.allan result"]),
    (lambda d: d["plan"].pop("test_plan"), ["malformed imu-align.plan result"]),
])
def test_a_malformed_or_misspelled_allan_file_is_one_input_error(job_dict, change, words):
    d = json.loads(json.dumps(job_dict))
    change(d)
    with pytest.raises(InputError) as info:
        AllanJob.from_dict(d, "allan.json")
    text = str(info.value)
    assert text.startswith("allan.json") and "\n" not in text
    for w in words:
        assert w in text, text
    for python in ("Error(", "Error: ", "np.float64("):
        assert python not in text, text


@pytest.mark.parametrize("kwargs,field", [
    ({"rate": 0.0}, "rate"), ({"rate": float("nan")}, "rate"), ({"accuracy": -1e-3}, "accuracy"),
    ({"ratio": 0.0}, "ratio"), ({"turn_angle": 0.0}, "turn_angle"), ({"steps": 0}, "steps"),
    ({"settle": -1.0}, "settle"), ({"settle": float("inf")}, "settle"),
])
def test_make_plan_refuses_values_outside_their_domain(kwargs, field):
    args = {"rate": 100 * DEG_S, "accuracy": 0.1 * DEG, "ratio": 10.0, **kwargs}
    rest = {k: v for k, v in kwargs.items() if k not in ("rate", "accuracy", "ratio")}
    with pytest.raises(InputError) as info:
        make_plan(args["rate"], args["accuracy"], args["ratio"], "model", sigma=model_curve(1e-4), **rest)
    assert info.value.fields == [field]


def test_make_plan_refuses_a_curve_with_no_positive_point():
    with pytest.raises(InputError, match="no positive finite point"):
        make_plan(100 * DEG_S, 0.1 * DEG, 10.0, "measured", tau=np.array([1.0, 2.0]), adev=np.array([0.0, np.nan]))


def test_plan_result_refuses_unknown_keys(job_dict):
    d = dict(job_dict["plan"], feasable=True)
    with pytest.raises(InputError, match="unknown key 'feasable'.*did you mean 'feasible'"):
        PlanResult.from_dict(d, "plan.json")
