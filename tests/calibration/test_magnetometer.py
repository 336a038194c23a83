"""Magnetometer calibration: simulated truth and gates, real captures, bad input, rotation to the accelerometer frame."""

import json

import numpy as np
import pytest
from magsim import F, capture, truth
from scipy.spatial.transform import Rotation
from support import SHARED

from align.calibration import MagCalibration, calibrate_magnetometer, with_gravity_alignment
from align.errors import InputError, TestError
from align.units import DEG

MAG = SHARED / "data" / "magnetometer"


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
        for kind in ("level", "planar"):  # a 45-deg tilt capture is accepted since version 2: test_mag_uncertainty
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


def test_magnetometer_bad_input(run_cli):
    res = run_cli("calibrate", "mag", MAG / "bazhin" / "mag_out.txt", "--columns", "col0,col1,col2", "--mag-units", "m/s^2")
    assert res.code == 2 and "--mag-units" in res.err
    m = np.ones((50, 3))
    m[7, 1] = np.nan
    with pytest.raises(InputError, match="row 8"):
        calibrate_magnetometer(m, "uT")
    with pytest.raises(InputError, match="unknown model") as exc:
        calibrate_magnetometer(np.ones((50, 3)), "uT", model="cube")
    assert exc.value.fields == ["model"]


def test_apply_accel_and_mag_round_trip(tmp_path, run_cli):
    s, h = truth(1)
    m, _ = capture("sphere", s, h, seed=3, noise=0.0)
    c = calibrate_magnetometer(m, "uT", field=F)
    cal = c.correct(m)
    assert np.allclose(np.linalg.norm(cal, axis=1), F, rtol=1e-6)

    again = MagCalibration.from_dict(json.loads(json.dumps(c.to_dict())))
    assert np.allclose(again.correct(m), cal, rtol=1e-12)


def test_rotation_to_the_accelerometer_frame_from_gravity():
    s, h = truth(2)
    m, acc = capture("sphere", s, h, seed=4, noise=0.0)
    body = (m - h) @ np.linalg.inv(s).T  # the field in the accelerometer's frame
    r0 = Rotation.from_rotvec(np.array([2.0, -1.0, 3.0]) * DEG).as_matrix()  # the magnetometer is mounted rotated
    raw = (body @ r0.T) @ s.T + h
    c = calibrate_magnetometer(raw, "uT", field=F, acc=acc)
    assert c.misalignment is None
    c2 = with_gravity_alignment(c, raw, acc)
    assert isinstance(c2, MagCalibration) and c2.replace(misalignment=None, misalignment_method=None, notes=c.notes) == c
    assert c2.misalignment_method == "gravity"
    assert c2.notes[:-1] == c.notes and c2.notes[-1].startswith("rotation to the accelerometer frame from gravity")
    # m_body = misalignment m_cal: calibrated and rotated readings are the field in the accelerometer frame
    assert np.abs(c2.correct(raw) @ c2.misalignment.T - body).max() < 1e-3 * F
    assert np.allclose(c2.misalignment @ c2.misalignment.T, np.eye(3), atol=1e-12)
