"""``imu-align drift``: its file, its picture, where the residual errors come from, and its refusals."""

from __future__ import annotations

import json

import numpy as np
import pytest
from support import ROOT

from align.navigation.mission import rotation_mission
from align.navigation.montecarlo import monte_carlo
from align.navigation.residuals import ResidualErrors, SensorErrors
from align.units import DEG, DEG_H, STANDARD_GRAVITY, parse_quantity


@pytest.mark.slow
def test_static_drift_file_and_picture(run_cli, tmp_path):
    out, png = tmp_path / "drift.json", tmp_path / "drift.png"
    r = run_cli("drift", "--imu", "ADIS16485", "--gyro-bias", "10 deg/h", "--accel-bias", "1 mg", "--duration", "1 min",
                "--runs", "300", "--json", out, "--plot", png)
    assert r.code == 0, r.err
    assert "heading: angle random walk" in r.out and "then gyro bias" in r.out
    d = json.loads(out.read_text())
    assert d["format"] == "imu-align.drift" and d["version"] == 1 and d["units"]["attitude_deg"] == "deg"
    t = np.array(d["time_s"])
    assert t[0] == 0 and t[-1] == pytest.approx(60.0)
    for group, names in (("attitude_deg", ("roll", "pitch", "heading")), ("velocity_m_s", ("north", "east", "down")),
                         ("position_m", ("north", "east", "down"))):
        for name in names:
            assert len(d[group][name]["mean"]) == len(t) == len(d[group][name]["sigma"])
    # heading: 10 deg/h of bias for a minute and the preset's 0.3 deg/sqrt(h) of ARW, by hand
    terms = d["term_sigma_final"]
    assert terms["gyro bias"]["attitude_deg"]["heading"] == pytest.approx(10 / 60, rel=1e-9)
    assert terms["angle random walk"]["attitude_deg"]["heading"] == pytest.approx(0.3 * np.sqrt(1 / 60), rel=1e-9)
    assert set(terms) == {"gyro bias", "angle random walk", "gyro bias instability", "accel bias"}
    heading = d["attitude_deg"]["heading"]
    assert heading["sigma"][-1] == pytest.approx(heading["closed_form_sigma"][-1], rel=0.15)
    # north position: 1 mg for a minute, g 10 deg/h t^3 / 6, ARW g N sqrt(t^5 / 20), bias instability: all stated terms
    assert d["position_m"]["north"]["closed_form_sigma"][-1] > 0.5 * 1e-3 * STANDARD_GRAVITY * 3600
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    from align.results import load_result

    res = load_result(out)
    assert type(res).__name__ == "DriftResult" and res.runs == 300
    assert res.errors.gyro.white[0] == pytest.approx(parse_quantity("0.3 deg/sqrt(h)", "angle_random_walk"))


@pytest.mark.slow
def test_a_mounting_misalignment_costs_nothing_at_rest_and_its_angle_times_the_turn_when_turning():
    # a 90 deg turn about z with gyro axes tilted by theta in random directions: the x and y gyros pick up
    # dM_xz and dM_yz times the turn; integrated in the turning frame, |tilt|^2 = 2 (dM_xz^2 + dM_yz^2) for 90 deg,
    # whose mean is theta_x^2 + theta_y^2 (each tilt splits evenly on its two elements); heading sees none
    theta = np.array([0.5, 1.0, 2.0]) * DEG
    errors = ResidualErrors(gyro=SensorErrors("gyroscope", tilt=theta))
    mission = rotation_mission([("z", 90 * DEG)], 60.0, 100.0, 10 * DEG)
    mc = monte_carlo(mission, errors, 2000, seed=5)
    tilt2 = mc.sigma[-1, 0] ** 2 + mc.sigma[-1, 1] ** 2 + mc.mean[-1, 0] ** 2 + mc.mean[-1, 1] ** 2
    assert np.sqrt(tilt2) == pytest.approx(np.hypot(theta[0], theta[1]), rel=0.06)
    assert mc.sigma[-1, 2] < 0.02 * theta[2]
    still = monte_carlo(rotation_mission([("z", 90 * DEG)], 60.0, 100.0, 10 * DEG).replace(
        w=np.zeros_like(mission.w), kind="static"), errors, 50, seed=5)
    assert np.abs(still.sigma).max() < 1e-9


def test_a_scale_error_costs_its_fraction_of_the_turn():
    errors = ResidualErrors(gyro=SensorErrors("gyroscope", matrix=np.diag([0, 0, 1e-3])))
    mc = monte_carlo(rotation_mission([("z", 90 * DEG)], 30.0, 100.0, 10 * DEG), errors, 1500, seed=2)
    assert mc.sigma[-1, 2] == pytest.approx(1e-3 * np.pi / 2, rel=0.06)


def test_drift_with_a_manoeuvre_file_and_a_budget(run_cli, tmp_path):
    out = tmp_path / "m.json"
    r = run_cli("drift", "--manoeuvre", ROOT / "examples/sensitivity/sequence.toml", "--budget",
                ROOT / "examples/budget/example1.toml", "--mount-error", "turns", "--duration", "1 min", "--runs", "100",
                "--json", out)
    assert r.code == 0, r.err
    d = json.loads(out.read_text())
    assert d["mission"]["kind"] == "manoeuvre" and "z +90 deg; x +45 deg" in d["mission"]["description"]
    assert "closed_form_sigma" not in d["attitude_deg"]["roll"]
    assert d["dominance_method"].startswith("a Monte Carlo of 100 runs")
    assert "gyro mounting misalignment" in d["term_sigma_final"]
    assert d["attitude_deg"]["roll"]["sigma"][-1] > 0.1  # about a degree of budget turned through 90 deg


def test_residuals_from_a_calibration_file(run_cli, tmp_path):
    from align.calibration.results import Calibration, CalibrationSet
    from align.results import save_result

    sm = np.full((3, 3), 2e-4)
    cal = Calibration("gyroscope", np.eye(3), np.zeros(3), sm, np.full(3, 5 * DEG_H), "deg/s", "test")
    acc = Calibration("accelerometer", np.eye(3), np.zeros(3), sm, np.full(3, 1e-3), "m/s^2", "test")
    path, out = tmp_path / "cal.json", tmp_path / "d.json"
    save_result(path, CalibrationSet({"gyroscope": cal, "accelerometer": acc}))
    r = run_cli("drift", "--alignment", path, "--duration", "30 s", "--runs", "50", "--json", out, "--earth-rate")
    assert r.code == 0, r.err
    from align.results import load_result

    res = load_result(out)
    assert np.allclose(res.errors.gyro.matrix, sm) and np.allclose(res.errors.gyro.bias, 5 * DEG_H)
    assert np.allclose(res.errors.accel.bias, 1e-3) and res.mission["earth_rate"] is True
    assert "1-sigma of the gyroscope estimate" in res.errors.gyro.sources["bias"]


@pytest.mark.parametrize("args, words", [
    (["--duration", "1 min"], "no residual error to propagate: give at least one of --allan, --alignment, --budget, "
                              "--imu, --gyro-bias, --accel-bias"),
    (["--duration", "1 min", "--imu", "ADIS16485", "--alignment", "a.json", "--budget", "b.toml"], "--alignment"),
    (["--duration", "0 s", "--imu", "ADIS16485"], "--duration"),
    (["--duration", "1 min", "--imu", "NOPE"], "unknown part"),
    (["--duration", "1 min", "--imu", "ADIS16485", "--runs", "1"], "--runs"),
])
def test_refusals_are_one_line(run_cli, args, words):
    r = run_cli("drift", *args)
    assert r.code == 2 and words in r.err and "Traceback" not in r.err
    assert len(r.err.strip().splitlines()) == 1


def test_an_allan_result_gives_the_noise_terms(run_cli, tmp_path):
    from align.noise import NoiseSpec, simulate_noise

    n_true = parse_quantity("0.5 deg/sqrt(h)", "angle_random_walk")
    data = simulate_noise(200_000, 100.0, NoiseSpec(white=n_true), channels=3, seed=4) / DEG
    log, allan, out = tmp_path / "static.npy", tmp_path / "allan.json", tmp_path / "d.json"
    np.save(log, data)
    assert run_cli("allan", log, "--rate-hz", "100", "--columns", "x,y,z", "--json", allan).code == 0
    r = run_cli("drift", "--allan", allan, "--duration", "1 min", "--runs", "50", "--json", out)
    assert r.code == 0, r.err
    from align.results import load_result

    res = load_result(out)
    assert np.allclose(res.errors.gyro.white, n_true, rtol=0.05)
    assert "fit of" in res.errors.gyro.sources["white"]


def test_a_recorded_trajectory_carries_the_errors_along_it():
    # a recorded coordinated turn (level, rate about z): a z gyro bias alone turns the heading by b t, turning or not
    from align.navigation import drift, recorded_mission
    from align.navigation.strapdown import rotate

    fs, w_turn, radius = 100.0, 0.3, 20.0
    t = np.arange(int(40 * fs) + 1) / fs
    q = np.stack([np.cos(w_turn * t / 2), 0 * t, 0 * t, np.sin(w_turn * t / 2)], -1)
    acc = radius * w_turn**2 * np.stack([-np.sin(w_turn * t), np.cos(w_turn * t), 0 * t], -1)
    f = rotate(q * np.array([1, -1, -1, -1]), acc - np.array([0, 0, 9.8]))
    mission = recorded_mission(np.tile([0, 0, w_turn], (len(t), 1)), f, fs, q[0], gravity=9.8)
    bias = 20 * DEG_H
    res = drift(mission, ResidualErrors(gyro=SensorErrors("gyroscope", bias=[0, 0, bias])), runs=800, seed=1,
                term_runs=20)
    assert res.sigma[-1, 2] == pytest.approx(bias * 40, rel=0.08)
    assert res.sigma[-1, 0] < 1e-9 and res.closed is None and res.mission["kind"] == "recorded"
