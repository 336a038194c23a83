"""imu-align simulate --kind poses, then calibrate gyro: truth recovered through the files; the options' refusals;
calibrate accel --plot."""

import json

import numpy as np
import pytest
from conftest import SHARED

from align.calibration import CalibrationSet
from align.calibration.posesim import TURN_AXES
from align.cli.simulate import TURN_AXES as CLI_TURN_AXES
from align.results import load_result

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    from align.cli import main

    out = tmp_path_factory.mktemp("poses") / "sim"
    with pytest.raises(SystemExit) as done:
        main(["simulate", str(out), "--kind", "poses", "--seed", "7", "--rate-hz", "50", "--head", "20 s"])
    assert done.value.code == 0
    return out


def test_the_cli_lists_the_library_s_turn_axes():
    assert CLI_TURN_AXES == TURN_AXES


@pytest.mark.slow
def test_simulated_session_calibrated_through_the_files(run_cli, session, tmp_path):
    out, png = tmp_path / "cal.json", tmp_path / "poses.png"
    res = run_cli("calibrate", "gyro", session / "session.csv", "--json", out, "--plot", png)
    assert res.code == 0, res.err
    truth = load_result(session / "truth.json")
    got = load_result(out)
    assert isinstance(got, CalibrationSet) and isinstance(truth, CalibrationSet)
    g, tg = got.sensor("gyroscope"), truth.sensor("gyroscope")
    assert np.abs((g.M - tg.M) / g.sigma_M).max() < 3.5
    a, ta = got.sensor("accelerometer"), truth.sensor("accelerometer")
    assert np.abs(a.M - ta.M).max() < 5e-3
    assert [list(p) for p in got.inputs["poses"]] != [] and len(got.inputs["poses"]) == 20
    assert png.read_bytes().startswith(PNG)
    assert res.out.count("->") == 19 and "observability: condition number" in res.out


@pytest.mark.slow
def test_system_frame_from_a_result_and_from_a_mounting(run_cli, session, tmp_path):
    base, turned, mounted = tmp_path / "c.json", tmp_path / "t.json", tmp_path / "m.json"
    assert run_cli("calibrate", "gyro", session / "session.csv", "--json", base).code == 0
    # the truth file is a calibration in the accelerometer frame: as a "rate-table result" it gives R ~ I
    res = run_cli("calibrate", "gyro", session / "session.csv", "--frame", session / "truth.json", "--json", turned)
    assert res.code == 0, res.err
    m0 = np.array(json.loads(base.read_text())["gyroscope"]["M"])
    m1 = np.array(json.loads(turned.read_text())["gyroscope"]["M"])
    assert np.abs(m1 - m0).max() < 5e-3
    assert "in the system frame: M = M_c R" in res.out
    res = run_cli("calibrate", "gyro", session / "session.csv", "--mounting", "+y,-x,+z", "--json", mounted)
    assert res.code == 0, res.err
    n = np.array([[0, 1, 0], [-1, 0, 0], [0, 0, 1]], float)
    assert np.allclose(np.array(json.loads(mounted.read_text())["gyroscope"]["M"]), m0 @ n, atol=1e-9)
    res = run_cli("calibrate", "gyro", session / "session.csv", "--frame", session / "truth.json", "--mounting", "+x,+y,+z")
    assert res.code == 2 and "give the system frame once" in res.err


def test_an_accelerometer_log_with_other_time_stamps_is_refused(run_cli, session, tmp_path):
    data = np.loadtxt(session / "session.csv", delimiter=",", skiprows=1)
    acc = tmp_path / "acc.csv"
    np.savetxt(acc, np.column_stack([data[:, 0] + 0.5, data[:, 1:4]]), delimiter=",", header="time,a1,a2,a3",
               comments="")  # names that are no default, old or new (ax,ay,az are accepted as old defaults)
    res = run_cli("calibrate", "gyro", session / "session.csv", "--accel-log", acc, "--accel-columns", "time,a1,a2,a3")
    assert res.code == 2 and "time stamps are not the gyro log's" in res.err and "\n" not in res.err.strip()
    res = run_cli("calibrate", "gyro", session / "session.csv", "--accel-log", acc)
    assert res.code == 2 and "--accel-columns" in res.err


def test_a_poses_session_refuses_rate_table_options(run_cli, tmp_path):
    res = run_cli("simulate", tmp_path / "x", "--kind", "poses", "--latitude", "45 deg")
    assert res.code == 2 and "--latitude belongs to a rate-table session" in res.err
    assert not (tmp_path / "x").exists()


def test_calibrate_accel_draws_its_static_intervals(run_cli, tmp_path):
    xsens = SHARED / "data" / "multiposition" / "xsens_mti_imu_tk"
    png = tmp_path / "statics.png"
    res = run_cli("calibrate", "accel", xsens / "xsens_acc.mat", "--columns", "col0,col1,col2,col3", "--accel-units",
                  "counts", "--gravity", "9.81744 m/s^2", "--init-static", "50 s", "--plot", png)
    assert res.code == 0, res.err
    assert png.read_bytes().startswith(PNG)
