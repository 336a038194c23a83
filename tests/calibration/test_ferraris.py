"""Ferraris sessions: imucal's real session side by side, imucal reading our file, wrong turns and moving faces."""

import json

import numpy as np
import pandas as pd
import pytest
from support import SHARED

from align.calibration import Calibration, ferraris
from align.units import DEG

FERRARIS = SHARED / "data" / "multiposition" / "imucal_ferraris"


def _session():
    df = pd.read_csv(FERRARIS / "example_ferraris_session.csv")
    listed = json.loads((FERRARIS / "example_ferraris_session_list.json").read_text())
    sections = {k: (v["start"], v["end"]) for k, v in listed.items()}
    return df, sections


def test_ferraris_session_against_imucal():
    imucal = pytest.importorskip("imucal")
    df, sections = _session()
    acc, gyr = df[["acc_x", "acc_y", "acc_z"]].to_numpy(), df[["gyr_x", "gyr_y", "gyr_z"]].to_numpy() * DEG
    a, g = ferraris(acc, gyr, 102.4, sections, -2 * np.pi, gravity=9.81)
    sl = pd.DataFrame(json.loads((FERRARIS / "example_ferraris_session_list.json").read_text())).T
    columns = ["acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z"]
    regions = imucal.ferraris_regions_from_section_list(df.set_index("n_samples")[columns], sl)
    info = imucal.FerrarisCalibration(grav=9.81, expected_angle=-360).compute(regions, 102.4, "m/s^2", "deg/s")
    # accelerometer: the same matrix (OLS on the six faces is Ferraris' difference formula) and pairwise bias
    assert np.allclose(a.M, info.K_a @ info.R_a, atol=1e-12)
    assert np.allclose(a.bias, info.b_a, atol=1e-12)
    # gyro: the same g-sensitivity; the bias estimators differ (imucal pools the raw face samples, we weight the
    # faces' means after removing K_ga a), and that difference alone explains the matrix difference:
    # M_ours - M_imucal = (b_imucal - b_ours) T_rot / theta, column by column (Eq 31); to 1e-7 (0.003 sigma), not
    # exactly: without a latitude the fit also weighs the Earth rate a face and the turn after it share (issue 23)
    assert np.allclose(g.g_sensitivity / DEG, info.K_ga, atol=1e-12)
    db = info.b_g - g.bias / DEG
    t_rot = np.array([sections[f"{x}_rot"][1] - sections[f"{x}_rot"][0] for x in "xyz"]) / 102.4
    explained = np.outer(db, t_rot) / -360.0
    assert np.allclose(g.M - info.K_g @ info.R_g, explained, atol=3e-7)
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
    assert np.allclose(pd.read_csv(corrected, comment="#").to_numpy(), acc_i, atol=1e-9)   # line 1 states the units


def test_ferraris_static_face_that_moves_is_an_error(tmp_path, run_cli):
    df, sections = _session()
    bad = {k: {"start": a, "end": b} for k, (a, b) in sections.items()}
    bad["x_p"] = {"start": 6770, "end": 7093}  # a turn where a static face should be
    sec = tmp_path / "sections.json"
    sec.write_text(json.dumps(bad))
    res = run_cli("calibrate", "ferraris", FERRARIS / "example_ferraris_session.csv", "--sections", sec, "--rate-hz", "102.4",
                  "--json", tmp_path / "never.json")
    assert res.code == 3 and "x_p" in res.err and "not static" in res.err
    assert not (tmp_path / "never.json").exists()


def test_ferraris_turn_in_the_wrong_direction_is_an_error(tmp_path, run_cli):
    # imucal returns a matrix with -1 on the diagonal here, silently (anchors.md)
    res = run_cli("calibrate", "ferraris", FERRARIS / "example_ferraris_session.csv", "--sections",
                  FERRARIS / "example_ferraris_session_list.json", "--rate-hz", "102.4", "--turn-angle", "360 deg",
                  "--json", tmp_path / "never.json")
    assert res.code == 3 and "wrong way" in res.err and "x_rot" in res.err
    assert not (tmp_path / "never.json").exists()


def test_ferraris_sections_missing_or_outside_the_log_name_the_input():
    from align.errors import InputError

    df, sections = _session()
    acc, gyr = df[["acc_x", "acc_y", "acc_z"]].to_numpy(), df[["gyr_x", "gyr_y", "gyr_z"]].to_numpy() * DEG
    with pytest.raises(InputError, match="missing sections z_rot") as exc:
        ferraris(acc, gyr, 102.4, {k: v for k, v in sections.items() if k != "z_rot"}, -2 * np.pi)
    assert exc.value.fields == ["sections"]
    with pytest.raises(InputError, match="not inside the log") as exc:
        ferraris(acc, gyr, 102.4, {**sections, "x_p": (0, len(acc) + 1)}, -2 * np.pi)
    assert exc.value.fields == ["sections"] and "x_p" in str(exc.value)
