"""Test planning (align.noise.planner): Example 3 of the reference, the plan command, PlanResult's JSON form."""

import json

import numpy as np
import pytest

from align.noise.planner import averaging_time, model_curve, noise_target
from align.units import DEG_H
from align.units import parse_quantity as q

ARW = q("0.3 deg/sqrt(h)", "angle_random_walk")


def test_example3_noise_target_and_white_noise_averaging_time():
    target = noise_target(q("100 deg/s", "angular_rate"), q("0.1 deg", "angle"), 10)
    assert target / DEG_H == pytest.approx(62.83, abs=0.005)
    t = averaging_time(target, sigma=model_curve(ARW)).tau
    assert t == pytest.approx(0.0821, abs=5e-5)
    assert t == pytest.approx((ARW / target) ** 2, rel=1e-9)  # sigma = N / sqrt(tau)


def test_plan_cli_example3_and_infeasible(tmp_path, run_cli):
    out = tmp_path / "p.json"
    res = run_cli("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--arw", "0.3 deg/sqrt(h)", "--json", out)
    assert res.code == 0, res.err
    d = json.loads(out.read_text())
    assert d["noise_target_deg_h"] == pytest.approx(62.83, abs=0.005)
    assert d["averaging_time_s"] == pytest.approx(0.0821, abs=5e-5)
    res = run_cli("plan", "--rate", "10 deg/s", "--accuracy", "0.01 deg", "--imu", "ADIS16470", "--json", out)
    d = json.loads(out.read_text())
    assert d["feasible"] is False and "floor" in d["reason"]
    res = run_cli("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg")
    assert res.code == 2 and "exactly one noise source" in res.err


#: every key a plan file had before it became a registered result (a contract: add, never rename)
PLAN_KEYS = {"format", "version", "generator", "units", "rate_deg_s", "accuracy_deg", "noise_ratio",
             "noise_target_deg_h", "averaging_time_s", "feasible", "reason", "floor_deg_h", "floor_tau_s",
             "noise_source", "angle_method", "test_plan"}


def _plans():
    from align.noise.planner import make_plan

    w, a = q("100 deg/s", "angular_rate"), q("0.1 deg", "angle")
    model = make_plan(w, a, 10, "model", sigma=model_curve(ARW, q("5 deg/h", "angular_rate")))
    tau = np.geomspace(0.01, 1000, 40)
    measured = make_plan(w, a, 10, "measured", tau=tau, adev=model_curve(ARW, q("5 deg/h", "angular_rate"))(tau),
                         turn_angle=q("90 deg", "angle"), steps=4, settle=1.5)
    infeasible = make_plan(q("10 deg/s", "angular_rate"), q("0.01 deg", "angle"), 10, "model",
                           sigma=model_curve(ARW, q("50 deg/h", "angular_rate")))
    return model, measured, infeasible


def test_plan_numbers_as_before():
    """make_plan gives the numbers it gave before the model moved to align.noise.model."""
    model, _, infeasible = _plans()
    assert model.averaging.tau == pytest.approx(0.08230022061508611, rel=1e-9)
    # bias instability without a rising term: the floor is 0.664 B exactly, approached as tau grows
    assert model.averaging.floor == pytest.approx(np.sqrt(2 * np.log(2) / np.pi) * q("5 deg/h", "angular_rate"), rel=1e-12)
    assert model.averaging.floor_tau is None
    assert model.longest_turn == pytest.approx(54.98233445448352, rel=1e-9)
    assert infeasible.averaging.tau is None and "floor" in infeasible.averaging.reason


def test_plan_result_round_trips_through_the_loader(tmp_path):
    from align.noise.planner import PlanResult
    from align.results import load_result, save_result
    from align.values import approx_equal

    for k, plan in enumerate(_plans()):
        plan = plan.replace(inputs={"allan": "allan.json"} if k == 1 else {})
        d = plan.to_dict()
        assert PLAN_KEYS <= set(d) and list(d)[:5] == ["format", "version", "generator", "convention", "units"]
        assert d["format"] == "imu-align.plan" and d["feasible"] is (plan.averaging.tau is not None)
        assert approx_equal(PlanResult.from_dict(d), plan, rtol=1e-12)
        path = tmp_path / f"plan{k}.json"
        save_result(path, plan)
        back = load_result(path)
        assert type(back) is PlanResult
        assert approx_equal(back, plan, rtol=1e-12)
        assert PlanResult.from_dict(back.to_dict()) == PlanResult.from_dict(json.loads(path.read_text()))
    with pytest.raises(AttributeError):
        plan.rate = 0.0


def test_malformed_plan_file_is_refused_in_one_line(tmp_path):
    from align.errors import InputError
    from align.noise.planner import PlanResult

    d = _plans()[0].to_dict()
    del d["test_plan"]
    with pytest.raises(InputError, match="malformed imu-align.plan result") as err:
        PlanResult.from_dict(d, "p.json")
    assert str(err.value).startswith("p.json: ") and "--" not in str(err.value)
