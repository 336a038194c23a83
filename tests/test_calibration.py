"""Sensor calibration: imucal's real session side by side, imu_tk's Xsens session, simulated truth,
magnetometer gates and real captures."""

import json

import numpy as np
import pandas as pd
import pytest

from align.calibration.accel import Calibration, calibrate_accel, ferraris
from align.errors import InputError, TestError
from align.calibration.magnetometer import calibrate_magnetometer
from align.units import DEG

from conftest import SHARED
from magsim import F, capture, truth

FERRARIS = SHARED / "data" / "multiposition" / "imucal_ferraris"
XSENS = SHARED / "data" / "multiposition" / "xsens_mti_imu_tk"
MAG = SHARED / "data" / "magnetometer"


def _session():
    df = pd.read_csv(FERRARIS / "example_ferraris_session.csv")
    sections = {k: (v["start"], v["end"]) for k, v in json.loads((FERRARIS / "example_ferraris_session_list.json").read_text()).items()}
    return df, sections


def test_ferraris_session_against_imucal():
    imucal = pytest.importorskip("imucal")
    df, sections = _session()
    acc, gyr = df[["acc_x", "acc_y", "acc_z"]].to_numpy(), df[["gyr_x", "gyr_y", "gyr_z"]].to_numpy() * DEG
    a, g = ferraris(acc, gyr, 102.4, sections, -2 * np.pi, gravity=9.81)
    sl = pd.DataFrame(json.loads((FERRARIS / "example_ferraris_session_list.json").read_text())).T
    regions = imucal.ferraris_regions_from_section_list(df.set_index("n_samples")[["acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z"]], sl)
    info = imucal.FerrarisCalibration(grav=9.81, expected_angle=-360).compute(regions, 102.4, "m/s^2", "deg/s")
    # accelerometer: the same matrix (OLS on the six faces is Ferraris' difference formula) and pairwise bias
    assert np.allclose(a.M, info.K_a @ info.R_a, atol=1e-12)
    assert np.allclose(a.bias, info.b_a, atol=1e-12)
    # gyro: the same g-sensitivity; the bias estimators differ (imucal pools the raw face samples, we weight the
    # faces' means after removing K_ga a), and that difference alone explains the matrix difference:
    # M_ours - M_imucal = (b_imucal - b_ours) T_rot / theta, column by column (Eq 31)
    assert np.allclose(g.g_sensitivity / DEG, info.K_ga, atol=1e-12)
    db = info.b_g - g.bias / DEG
    t_rot = np.array([sections[f"{x}_rot"][1] - sections[f"{x}_rot"][0] for x in "xyz"]) / 102.4
    explained = np.outer(db, t_rot) / -360.0
    assert np.allclose(g.M - info.K_g @ info.R_g, explained, atol=1e-12)
    assert 1e-7 < np.abs(g.M - info.K_g @ info.R_g).max() < 1e-4


def test_imucal_reads_our_file_and_corrects_like_apply(tmp_path, run_cli):
    pytest.importorskip("imucal")
    from imucal.management import load_calibration_info

    out, imu_json = tmp_path / "cal.json", tmp_path / "imucal.json"
    res = run_cli("calibrate", "ferraris", FERRARIS / "example_ferraris_session.csv", "--sections",
                  FERRARIS / "example_ferraris_session_list.json", "--rate-hz", "102.4", "--gravity", "9.81 m/s^2",
                  "--json", out, "--imucal-json", imu_json)
    assert res.code == 0, res.err
    d = json.loads(out.read_text())
    for sensor in ("accelerometer", "gyroscope"):
        assert {"M", "bias", "units"} <= set(d[sensor])
    info = load_calibration_info(imu_json)
    assert type(info).__name__ == "FerrarisCalibrationInfo"
    df, _ = _session()
    acc, gyr = df[["acc_x", "acc_y", "acc_z"]].to_numpy(), df[["gyr_x", "gyr_y", "gyr_z"]].to_numpy()
    acc_i, gyr_i = info.calibrate(acc, gyr, "m/s^2", "deg/s")
    a = Calibration.from_dict(d["accelerometer"])
    g = Calibration.from_dict(d["gyroscope"])
    acc_o = a.correct(acc)
    assert np.allclose(acc_i, acc_o, atol=1e-10)
    assert np.allclose(gyr_i * DEG, g.correct(gyr * DEG, acc_o), atol=1e-10)
    corrected = tmp_path / "acc.csv"
    res = run_cli("apply", FERRARIS / "example_ferraris_session.csv", "--alignment", out, "--sensor", "accelerometer",
                  "--columns", "acc_x,acc_y,acc_z", "--rate-hz", "102.4", "--out", corrected)
    assert res.code == 0, res.err
    assert np.allclose(pd.read_csv(corrected).to_numpy(), acc_i, atol=1e-9)


def test_accelerometer_multiposition_on_simulated_truth():
    rng = np.random.default_rng(0)
    m_true = np.eye(3) + rng.normal(0, 0.01, (3, 3))
    b_true = rng.normal(0, 0.1, 3)
    g = 9.80665
    ups = {f"{s}{a}": np.eye(3)[i] * (1 if s == "+" else -1) for i, a in enumerate("xyz") for s in "+-"}
    ups.update({"45 xz": np.array([1, 0, 1]) / np.sqrt(2), "45 -yz": np.array([0, -1, 1]) / np.sqrt(2)})  # seed 004
    means = {k: m_true @ (g * u) + b_true + rng.normal(0, 1e-3, 3) for k, u in ups.items()}
    cal = calibrate_accel(means, ups, g, holdout=("45 xz", "45 -yz"))
    assert np.all(np.abs(cal.M - m_true) < 5 * cal.sigma_M + 1e-4)
    assert np.abs(cal.bias - b_true).max() < 5e-3
    for k in ("45 xz", "45 -yz"):
        assert np.abs(cal.checks[k]).max() < 5e-3  # the held-out positions are predicted
    with pytest.raises(InputError, match="at least 6"):
        calibrate_accel({k: means[k] for k in list(means)[:5]}, ups, g)


def test_xsens_session_detected_and_calibrated_against_datasheet(tmp_path, run_cli):
    out = tmp_path / "xs.json"
    res = run_cli("calibrate", "accel", XSENS / "xsens_acc.mat", "--columns", "col0,col1,col2,col3", "--units", "counts",
                  "--gravity", "9.81744 m/s^2", "--init-static", "50 s", "--json", out)
    assert res.code == 0, res.err
    assert "38 static intervals detected" in res.out
    d = json.loads(out.read_text())["accelerometer"]
    scale = np.diag(np.array(d["M"]))
    assert np.allclose(scale, [415, 413, 415], rtol=0.01)  # SOURCE.txt: factory scale, counts per m/s^2
    assert np.allclose(d["bias"], [33123, 33276, 32360], atol=10)  # and nominal offsets, counts


def test_magnetometer_simulated_truth_and_gates():
    for seed in range(3):
        s, h = truth(seed)
        m, acc = capture("sphere", s, h, seed=seed + 10)
        for field in (None, F):
            c = calibrate_magnetometer(m, "uT", field=field, acc=acc)
            w_true = np.linalg.inv(s) * (c.field / F)
            assert np.abs(c.hard_iron - h).max() < 0.2e-6  # 0.2 uT of a 50 uT field, noise 0.5 uT
            assert np.abs(c.soft_iron - w_true).max() < 5e-3
            assert np.linalg.det(c.soft_iron) > 0
            assert c.spread_after < c.spread_before / 10
            assert c.dip == pytest.approx(-60 * DEG, abs=1 * DEG)
        if field is not None:
            assert c.field == pytest.approx(F)
        for kind in ("tilt45", "level", "planar"):
            m, _ = capture(kind, s, h, seed=seed + 10)
            with pytest.raises(TestError, match="coverage too small|planar or near-level"):
                calibrate_magnetometer(m, "uT")


@pytest.mark.parametrize("name,columns,units", [
    ("bazhin/mag_out.txt", "col0,col1,col2", "counts"),
    ("ck_explorer/acc_mag_log.csv", "mx,my,mz", "gauss"),
    ("hmc5883l_sunsided/hmc5883l_compass.csv", "mag_x_gauss,mag_y_gauss,mag_z_gauss", "gauss"),
])
def test_magnetometer_real_captures(tmp_path, run_cli, name, columns, units):
    out = tmp_path / "mag.json"
    res = run_cli("calibrate", "mag", MAG / name, "--columns", columns, "--mag-units", units, "--json", out)
    assert res.code == 0, res.err
    d = json.loads(out.read_text())
    assert {"hard_iron", "soft_iron", "convention"} <= set(d) and d["convention"] == "m_cal = soft_iron (m_raw - hard_iron)"
    q = d["quality"]
    assert q["field_spread_after"] < q["field_spread_before"] / 5
    assert np.linalg.det(np.array(d["soft_iron"])) > 0


def test_calibration_bad_input(tmp_path, run_cli):
    res = run_cli("calibrate", "mag", MAG / "bazhin" / "mag_out.txt", "--columns", "col0,col1,col2", "--mag-units", "m/s^2")
    assert res.code == 2 and "--mag-units" in res.err
    res = run_cli("calibrate", "accel", XSENS / "xsens_acc.mat", "--columns", "col0,col1,col2,col3", "--units", "deg/s")
    assert res.code == 2 and "acceleration" in res.err
    df, sections = _session()
    bad = {k: {"start": a, "end": b} for k, (a, b) in sections.items()}
    bad["x_p"] = {"start": 6770, "end": 7093}  # a turn where a static face should be
    sec = tmp_path / "sections.json"
    sec.write_text(json.dumps(bad))
    res = run_cli("calibrate", "ferraris", FERRARIS / "example_ferraris_session.csv", "--sections", sec, "--rate-hz", "102.4",
                  "--json", tmp_path / "never.json")
    assert res.code == 3 and "x_p" in res.err and "not static" in res.err
    assert not (tmp_path / "never.json").exists()
    m = np.ones((50, 3))
    m[7, 1] = np.nan
    with pytest.raises(InputError, match="row 8"):
        calibrate_magnetometer(m, "uT")


def test_apply_accel_and_mag_round_trip(tmp_path, run_cli):
    s, h = truth(1)
    m, _ = capture("sphere", s, h, seed=3, noise=0.0)
    c = calibrate_magnetometer(m, "uT", field=F)
    cal = c.correct(m)
    assert np.allclose(np.linalg.norm(cal, axis=1), F, rtol=1e-6)
    from align.calibration.magnetometer import MagCalibration

    again = MagCalibration.from_dict(json.loads(json.dumps(c.to_dict())))
    assert np.allclose(again.correct(m), cal, rtol=1e-12)


def test_ferraris_turn_in_the_wrong_direction_is_an_error(tmp_path, run_cli):
    # imucal returns a matrix with -1 on the diagonal here, silently (anchors.md)
    res = run_cli("calibrate", "ferraris", FERRARIS / "example_ferraris_session.csv", "--sections",
                  FERRARIS / "example_ferraris_session_list.json", "--rate-hz", "102.4", "--turn-angle", "360 deg",
                  "--json", tmp_path / "never.json")
    assert res.code == 3 and "wrong way" in res.err and "x_rot" in res.err
    assert not (tmp_path / "never.json").exists()
