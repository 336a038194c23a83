"""Review 15/16 fixes of `imu-align drift`: counts calibrations, the mount as an initial attitude error, the flicker
cutoff, the one-signed down channel, a recorded trajectory from the CLI, and the nits. Every expected number is a
hand calculation (heading b t; tilt g theta t^2 / 2; accel bias b t^2 / 2; ARW N sqrt(t)) or a direct simulation."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from support import ROOT

from align.navigation import drift, navigate, static_mission
from align.navigation.closed import flicker_lines, term_sigmas
from align.navigation.residuals import ResidualErrors, SensorErrors, mount_rotation
from align.units import DEG, DEG_H, STANDARD_GRAVITY

G = STANDARD_GRAVITY
HERE = Path(__file__).parent


def _counts_set(path):
    from align.calibration.results import Calibration, CalibrationSet
    from align.results import save_result

    # a gyro in counts: 4000/5000/4500 counts per rad/s, bias 1-sigma 10/20/30 deg/h and dM 1e-3 expressed in counts;
    # an accelerometer at 400 counts per m/s^2 with 1 mg of bias 1-sigma
    mg = np.diag([4000.0, 5000.0, 4500.0])
    gyro = Calibration("gyroscope", mg, np.full(3, 32768.0), 1e-3 * np.diag(mg)[:, None] * np.ones((3, 3)),
                       np.diag(mg) * np.array([10, 20, 30]) * DEG_H, "counts", "hand-written")
    ma = 400.0 * np.eye(3)
    acc = Calibration("accelerometer", ma, np.full(3, 32768.0), np.full((3, 3), 0.04), np.full(3, 400 * 1e-3 * G),
                      "counts", "hand-written")
    save_result(path, CalibrationSet({"gyroscope": gyro, "accelerometer": acc}))


@pytest.mark.slow
def test_a_counts_calibration_is_read_through_m_inverse(run_cli, tmp_path):
    cal, out = tmp_path / "cal.json", tmp_path / "d.json"
    _counts_set(cal)
    r = run_cli("drift", "--alignment", cal, "--duration", "1 min", "--runs", "200", "--json", out)
    assert r.code == 0, r.err
    d = json.loads(out.read_text())
    terms = d["term_sigma_final"]
    # heading b t: 30 deg/h for 60 s = 0.5 deg; roll 10 deg/h -> 1/6 deg
    assert terms["gyro bias"]["attitude_deg"]["heading"] == pytest.approx(0.5, rel=1e-9)
    assert terms["gyro bias"]["attitude_deg"]["roll"] == pytest.approx(10 / 60, rel=1e-9)
    # 1 mg of accelerometer bias: b t^2 / 2 = 0.5 * 9.80665e-3 * 60^2 = 17.65 m north
    assert terms["accel bias"]["position_m"]["north"] == pytest.approx(0.5e-3 * G * 3600, rel=1e-9)
    from align.results import load_result

    res = load_result(out)
    assert np.allclose(res.errors.gyro.matrix, 1e-3) and np.allclose(res.errors.accel.matrix, 1e-4)
    # and nothing absurd: the 88 deg of roll of the counts read as SI is gone
    assert d["final"]["attitude_deg"]["roll"]["sigma"] < 0.25


@pytest.mark.slow
def test_the_xsens_gyro_calibration_costs_its_bias_sigma_over_the_datasheet_scale(run_cli, tmp_path):
    # data/xsens_gyro_counts.json: `imu-align calibrate gyro` on imu_tk's Xsens MTi session (counts), the command of
    # examples/calibration/README.md (../shared/data/multiposition/xsens_mti_imu_tk), kept as written
    cal, out = HERE / "data/xsens_gyro_counts.json", tmp_path / "d.json"
    sigma_bz = json.loads(cal.read_text())["gyroscope"]["uncertainty"]["bias"][2]  # counts
    r = run_cli("drift", "--alignment", cal, "--duration", "10 min", "--runs", "300", "--json", out)
    assert r.code == 0, r.err
    d = json.loads(out.read_text())
    heading = d["term_sigma_final"]["gyro bias"]["attitude_deg"]["heading"]
    # b t with the datasheet scale of SOURCE.txt, 4766 counts per rad/s: ~2.7 deg at 10 min, not tens of degrees
    assert heading == pytest.approx(sigma_bz / 4766 * 600 / DEG, rel=0.01)
    assert 2.0 < heading < 3.5 and d["final"]["attitude_deg"]["roll"]["sigma"] < 3.5


@pytest.mark.slow
def test_a_rigidly_tilted_imu_costs_g_theta_t2_over_2_from_the_start():
    # the physics, by direct simulation: the IMU pitched by theta on a level vehicle reads R^T (0, 0, -g); navigated
    # from the vehicle's (level) attitude its north position runs away as g sin(theta) t^2 / 2, its down as
    # g (1 - cos theta) t^2 / 2 (one-signed)
    theta, t_end, fs = 0.5 * DEG, 120.0, 100.0
    n = int(t_end * fs) + 1
    f = np.tile([G * np.sin(theta), 0.0, -G * np.cos(theta)], (n, 1))
    tr = navigate(np.zeros((n, 3)), f, 1 / fs, step=10, gravity=G)
    assert tr.p[-1, 0] == pytest.approx(G * np.sin(theta) * t_end**2 / 2, rel=1e-6)
    assert tr.p[-1, 2] == pytest.approx(G * (1 - np.cos(theta)) * t_end**2 / 2, rel=1e-4)
    # the Monte Carlo's model of it: an initial attitude error drawn per run, 1-sigma s about x, y, z
    s = np.array([0.2, 0.5, 0.3]) * DEG
    runs = 2000
    res = drift(static_mission(t_end, fs, gravity=G), ResidualErrors(mount=s), runs=runs, seed=11)
    tol = 4.5 / np.sqrt(2 * (runs - 1))
    hand = {0: s[0], 1: s[1], 2: s[2], 3: G * s[1] * t_end, 4: G * s[0] * t_end,
            6: G * s[1] * t_end**2 / 2, 7: G * s[0] * t_end**2 / 2}
    for col, value in hand.items():
        assert res.closed[-1, col] == pytest.approx(value, rel=1e-9)
        assert res.sigma[-1, col] == pytest.approx(value, rel=tol)
    # the angles are constant from t = 0 (heading too): the first time after the start already has them
    assert res.sigma[1, 2] == pytest.approx(s[2], rel=tol)
    # down: one-signed, g (1 - cos eps) t^2 / 2 with E[eps^2] = s_x^2 + s_y^2: no run goes up
    assert res.down_percentiles[0, -1, 1] >= -1e-6
    assert res.mean[-1, 8] == pytest.approx(G * (s[0] ** 2 + s[1] ** 2) / 2 * t_end**2 / 2, rel=0.08)
    assert any("initial attitude error" in n for n in res.notes)


@pytest.mark.slow
def test_a_budget_is_a_rigid_rotation_by_default_and_turns_only_when_asked(run_cli, tmp_path):
    import mechanics
    from align.io import read_toml
    from mechanics import mount_from_dict

    path = ROOT / "examples/budget/example1.toml"
    p = mechanics.budget(mount_from_dict(read_toml(path), str(path), path.parent)).per_axis
    # R2 by hand: axis x moves by the rotations about y and z, so P_x^2 = s_y^2 + s_z^2, ...
    s = np.sqrt([(p[1] ** 2 + p[2] ** 2 - p[0] ** 2) / 2, (p[0] ** 2 + p[2] ** 2 - p[1] ** 2) / 2,
                 (p[0] ** 2 + p[1] ** 2 - p[2] ** 2) / 2])
    assert np.allclose(mount_rotation(p)[0], s, rtol=1e-12)
    out = tmp_path / "d.json"
    r = run_cli("drift", "--budget", path, "--duration", "10 min", "--runs", "1500", "--json", out)
    assert r.code == 0, r.err
    d = json.loads(out.read_text())
    g = d["mission"]["gravity_m_s2"]
    north = d["position_m"]["north"]
    assert north["closed_form_sigma"][-1] == pytest.approx(g * s[1] * 600**2 / 2, rel=1e-9)  # ~23 km
    assert north["sigma"][-1] == pytest.approx(g * s[1] * 600**2 / 2, rel=0.12)
    assert d["attitude_deg"]["heading"]["sigma"][-1] == pytest.approx(s[2] / DEG, rel=0.12)
    assert "rms" in d["errors"]["imu"]["mount"]["source"] and "1-sigma" in d["errors"]["imu"]["mount"]["source"]
    # turns: aligned in place, a static mission costs nothing, and the output says so
    r = run_cli("drift", "--budget", path, "--mount-error", "turns", "--duration", "10 min", "--runs", "20")
    assert r.code == 0, r.err
    assert "costs nothing from it" in r.out and "none: no error term grows" in r.out


@pytest.mark.slow
def test_the_flicker_cutoff_is_stated_and_an_option(run_cli, tmp_path):
    b, t = 5 * DEG_H, 600.0
    f, c2 = flicker_lines(t, 129, 32)
    assert f[c2 > 0][0] == pytest.approx(1 / (32 * t), rel=1e-12)  # the first line that carries variance: the cutoff
    assert not c2[f < 1 / (32 * t) * (1 - 1e-12)].any()
    # doubling the span adds the lines from 1/(64 T) to 1/(32 T): below 1/T the angle is c_k t each, so the angle
    # variance grows by B^2 t^2 * integral df / (pi f) = B^2 t^2 ln(2) / pi (to sinc^2(pi/32) = 0.997)
    e = ResidualErrors(gyro=SensorErrors("gyroscope", flicker=b))
    v = [term_sigmas(e, np.array([t]), G, duration=t, points=129, span=k)[("gyroscope", "flicker")][0, 2] ** 2
         for k in (32, 64)]
    # (to 3 %: two lines of df = f_c / REFINE carry that octave, each at its band's lower edge: closed.flicker_lines)
    assert v[1] - v[0] == pytest.approx(b**2 * t**2 * np.log(2) / np.pi, rel=0.03)
    out = tmp_path / "d.json"
    r = run_cli("drift", "--imu", "ADIS16485", "--duration", "10 min", "--runs", "20", "--flicker-span", "32",
                "--json", out)
    assert r.code == 0, r.err
    assert f"from {1 / (32 * 600):.3g} Hz (1 / (32 T)" in r.out
    assert json.loads(out.read_text())["inputs"]["flicker_span"] == 32
    r = run_cli("drift", "--imu", "ADIS16485", "--duration", "10 min", "--runs", "20")
    assert f"from {1 / (8 * 600):.3g} Hz (1 / (8 T)" in r.out


def _turn_log(path, fs=100.0, seconds=40.0, rate=0.3, radius=20.0):
    """A level coordinated turn at ``rate`` rad/s as a logger writes it: a preamble, ';' separators, deg/s and g."""
    from align.navigation.strapdown import rotate

    t = np.arange(int(seconds * fs) + 1) / fs
    q = np.stack([np.cos(rate * t / 2), 0 * t, 0 * t, np.sin(rate * t / 2)], -1)
    acc = radius * rate**2 * np.stack([-np.sin(rate * t), np.cos(rate * t), 0 * t], -1)
    f = rotate(q * np.array([1, -1, -1, -1]), acc - np.array([0, 0, G]))
    rows = np.column_stack([t, np.tile([0, 0, rate / DEG], (len(t), 1)), f / G])
    with open(path, "w") as fh:
        fh.write("logger v1\nsn 1234\ntime;gx;gy;gz;ax;ay;az\n")
        for row in rows:
            fh.write(";".join(f"{v:.10g}" for v in row) + "\n")


def test_a_recorded_trajectory_from_the_command_line(run_cli, tmp_path):
    log, out = tmp_path / "turn.csv", tmp_path / "d.json"
    _turn_log(log)
    opts = ["--trajectory", log, "--gyro-columns", "time,gx,gy,gz", "--accel-columns", "ax,ay,az", "--accel-units", "g",
            "--skip-rows", "2", "--delimiter", ";"]
    r = run_cli("drift", *opts, "--gyro-bias", "20 deg/h", "--runs", "400", "--json", out)
    assert r.code == 0, r.err
    d = json.loads(out.read_text())
    assert d["mission"]["kind"] == "recorded" and d["mission"]["duration_s"] == pytest.approx(40.0)
    assert "turn.csv" in d["mission"]["description"] and d["inputs"]["trajectory"] == str(log)
    # heading b t, turning or not: 20 deg/h for 40 s
    assert d["final"]["attitude_deg"]["heading"]["sigma"] == pytest.approx(20 * 40 / 3600, rel=0.1)
    r = run_cli("drift", *opts, "--gyro-bias", "20 deg/h", "--runs", "50", "--duration", "10 s")
    assert r.code == 0, r.err
    assert "1,001 samples" in r.out
    r = run_cli("drift", *opts, "--gyro-bias", "20 deg/h", "--duration", "1 min")
    assert r.code == 2 and "longer than the trajectory" in r.err and "--duration" in r.err
    r = run_cli("drift", *opts, "--gyro-bias", "20 deg/h", "--manoeuvre", ROOT / "examples/sensitivity/sequence.toml")
    assert r.code == 2 and "--trajectory" in r.err


@pytest.mark.slow
def test_the_nits(run_cli, tmp_path):
    # the navigation rate capped at the sample rate, or rounded to whole samples, is said
    r = run_cli("drift", "--gyro-bias", "1 deg/h", "--duration", "10 s", "--runs", "10", "--nav-rate", "1000")
    assert r.code == 0 and "navigation rate 1000 Hz is above the sample rate" in r.out and "at 100 Hz" in r.out
    r = run_cli("drift", "--gyro-bias", "1 deg/h", "--duration", "10 s", "--runs", "10", "--nav-rate", "30")
    assert "navigation at 33.3333 Hz, not 30 Hz" in r.out
    # a latitude beyond the poles is refused as a dip angle is
    r = run_cli("drift", "--gyro-bias", "1 deg/h", "--duration", "10 s", "--latitude", "100 deg")
    assert r.code == 2 and "--latitude" in r.err and "within -90 deg and 90 deg" in r.err
    # --plot writes its PNG whatever the suffix, as every other command's --plot does
    png = tmp_path / "out.txt"
    r = run_cli("drift", "--gyro-bias", "1 deg/h", "--duration", "10 s", "--runs", "10", "--plot", png)
    assert r.code == 0 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
