"""``imu-align calibrate thermal`` and ``imu-align simulate thermal`` on the command line: the thin layer over the
job (parse, options, run, write all or none, one line for a refusal)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from support import SHARED

from align.calibration.thermal import ThermalCalibration, firmware
from align.results import load_result

LOG = SHARED / "data" / "thermal" / "tofupilot_cycle" / "imu_raw_data.csv"
REAL = ["--delimiter", "tab", "--time-units", "us", "--time-column", "timestamp", "--temperature-column",
        "imu.temperature", "--gyro-columns", "imu.gyro.x,imu.gyro.y,imu.gyro.z", "--accel-columns",
        "imu.acc.x,imu.acc.y,imu.acc.z"]


def test_simulate_then_calibrate_writes_the_result_and_both_firmware_files(tmp_path, run_cli):
    sim = tmp_path / "chamber"
    got = run_cli("simulate", "thermal", sim, "--low", "0", "--high", "50", "--ramp", "10", "--ramp-down", "10",
                  "--cycles", "1", "--seed", "4")
    assert got.code == 0, got.err
    out = tmp_path / "out"
    out.mkdir()
    got = run_cli("calibrate", "thermal", sim / "thermal.csv", "--temperature-column", "temperature", "--max-order",
                  "3", "--json", out / "r.json", "--ardupilot", out / "tcal.parm", "--px4", out / "tc.params",
                  "--gyro-id", "11", "--accel-id", "12", "--instance", "1")
    assert got.code == 0, got.err
    assert "hysteresis" in got.out and "valid" in got.out and "clamped outside" in got.out
    result = load_result(out / "r.json")
    assert isinstance(result, ThermalCalibration) and set(result.sensors) == {"gyroscope", "accelerometer"}
    truth = json.loads((sim / "truth.json").read_text())
    want = np.array(truth["accelerometer"]["apparent_hysteresis"])
    found = np.array([a.hysteresis.value for a in result.sensors["accelerometer"].axes])
    assert found == pytest.approx(want, rel=0.2)  # what the CLI wrote is the simulation's (the statistics: elsewhere)
    ap = firmware.read_ardupilot((out / "tcal.parm").read_text())
    px = firmware.read_px4((out / "tc.params").read_text())
    assert ap["INS_TCAL2_ENABLE"] == 1 and "INS_TCAL2_GYR3_Z" in ap
    assert px["TC_G1_ID"] == 11 and px["TC_A1_ID"] == 12


def test_the_real_cycle_through_the_command_line(tmp_path, run_cli):
    if not LOG.exists():
        pytest.skip("the shared thermal cycle is not here")
    parm = tmp_path / "tcal.parm"
    # by default the accelerometer's x axis takes order 5: no firmware file, and nothing written at all
    got = run_cli("calibrate", "thermal", LOG, *REAL, "--ardupilot", parm, "--json", tmp_path / "r.json")
    assert got.code == 2 and "--max-order 3" in got.err and len(got.err.strip().splitlines()) == 1
    assert not parm.exists() and not (tmp_path / "r.json").exists()
    got = run_cli("calibrate", "thermal", LOG, *REAL, "--max-order", "3", "--ardupilot", parm)
    assert got.code == 0, got.err
    assert "0.131" in got.out  # acc z: heating minus cooling where largest, m/s^2
    assert "INS_TCAL1_ACC3_Z" in firmware.read_ardupilot(parm.read_text())


def test_one_columns_option_for_both_sensors(tmp_path, run_cli):
    if not LOG.exists():
        pytest.skip("the shared thermal cycle is not here")
    cols = "timestamp,imu.gyro.x,imu.gyro.y,imu.gyro.z,imu.acc.x,imu.acc.y,imu.acc.z"
    got = run_cli("calibrate", "thermal", LOG, "--delimiter", "tab", "--time-units", "us", "--columns", cols,
                  "--temperature-column", "imu.temperature", "--json", tmp_path / "r.json")
    assert got.code == 0, got.err
    inputs = load_result(tmp_path / "r.json").inputs
    assert inputs["columns"]["accelerometer"] == "timestamp,imu.acc.x,imu.acc.y,imu.acc.z"
    got = run_cli("calibrate", "thermal", LOG, "--delimiter", "tab", "--columns", "a,b,c,d",
                  "--temperature-column", "imu.temperature")
    assert got.code == 2 and "--columns" in got.err and "give 6 names" in got.err


def test_without_its_temperature_column_the_command_says_which_option(tmp_path, run_cli):
    log = tmp_path / "log.csv"
    log.write_text("time,acc_x,acc_y,acc_z\n" + "".join(f"{k / 10},0,0,9.8\n" for k in range(300)))
    got = run_cli("calibrate", "thermal", log, "--sensors", "accel", "--time-units", "s")
    assert got.code == 2 and "--temperature-column" in got.err and len(got.err.strip().splitlines()) == 1


def test_the_commands_are_listed(run_cli):
    assert "thermal" in run_cli("calibrate", "--help").out
    assert "thermal" in run_cli("simulate", "--help").out


def test_the_batch_builds_the_same_options():
    from align.cli.builders import files_builder, options_builder

    o = options_builder("calibrate thermal")(log="x.csv", temperature_column="T", sensors="accel", order=2)
    assert o.sensors == ("accelerometer",) and o.order == 2 and o.log.temperature_column == "T"
    assert files_builder("calibrate thermal") is not None


def test_apply_compensates_a_log_with_its_thermal_result_against_the_simulated_truth(tmp_path, run_cli):
    """Issue 25: `apply` with a thermal result removes the bias's change from the reference temperature. Truth from the
    simulator (truth.json: sum_k a_k u^k + lag dT/dt, u = (T - tref) / hs, and the hysteresis h/2 the model does not
    take): what remains of the true change after the compensation is a small part of it."""
    sim, result, out = tmp_path / "chamber", tmp_path / "r.json", tmp_path / "c.csv"
    assert run_cli("simulate", "thermal", sim, "--seed", "3").code == 0
    assert run_cli("calibrate", "thermal", sim / "thermal.csv", "--temperature-column", "temperature", "--json",
                   result).code == 0
    args = ("apply", sim / "thermal.csv", "--alignment", result, "--sensor", "accelerometer", "--columns",
            "acc_x,acc_y,acc_z", "--out", out)
    refused = run_cli(*args)
    assert refused.code == 2 and "--temperature-column" in refused.err and not out.exists()
    res = run_cli(*args, "--temperature-column", "temperature")
    assert res.code == 0, res.err
    raw = np.loadtxt(sim / "thermal.csv", delimiter=",", skiprows=1)
    done = np.loadtxt(out, delimiter=",", skiprows=2)
    assert out.read_text().startswith("# imu-align ") and "acc_x=m/s^2" in out.read_text().splitlines()[0]
    truth = json.loads((sim / "truth.json").read_text())["accelerometer"]
    t, temp = raw[:, 0], raw[:, -1]
    u, u_ref = (temp - truth["tref"]) / truth["hs"], 0.0
    k = int(10.0 / (t[1] - t[0]))                             # dT/dt: a centred 20 s difference (the noise averaged)
    rate = np.gradient(temp, t)
    rate[k:-k] = (temp[2 * k:] - temp[:-2 * k]) / (t[2 * k:] - t[:-2 * k])
    for k in range(3):
        a = np.array(truth["a"][k])
        change = np.polyval(a[::-1], u) - np.polyval(a[::-1], u_ref) + truth["lag"][k] * rate
        left = done[:, 1 + k] - (raw[:, 4 + k] - change)     # the compensation's error against the truth
        left -= np.median(left)                               # the constant: the reference bias, not compensated
        assert np.sqrt(np.mean(left**2)) < 0.25 * np.sqrt(np.mean((change - change.mean()) ** 2)), k
    # a temperature column that is not there: the line names the temperature option, not the data columns'
    out.unlink()
    wrong = run_cli(*args, "--temperature-column", "tmp")
    assert wrong.code == 2 and not out.exists() and len(wrong.err.strip().splitlines()) == 1
    assert "no temperature column 'tmp'" in wrong.err and "--temperature-column" in wrong.err
    assert "--columns" not in wrong.err


def test_verify_refuses_a_thermal_result_naming_it(tmp_path, run_cli):
    """verify replays a rate-table correction; a thermal result is refused in one line naming its file (not a flag
    verify lacks)."""
    sim, result = tmp_path / "chamber", tmp_path / "r.json"
    assert run_cli("simulate", "thermal", sim, "--seed", "3").code == 0
    assert run_cli("calibrate", "thermal", sim / "thermal.csv", "--temperature-column", "temperature", "--json",
                   result).code == 0
    assert run_cli("simulate", "session", tmp_path / "s").code == 0
    got = run_cli("verify", result, tmp_path / "s" / "session.csv", "--plan", tmp_path / "s" / "plan.toml")
    assert got.code == 2 and len(got.err.strip().splitlines()) == 1 and "r.json" in got.err  # before --sensor
    assert "thermal calibration" in got.err and "--temperature-column" not in got.err and "--sensor" not in got.err
    got = run_cli("calibrate", "thermal-matrix", result, result.with_name("other.json"), "--temperatures",
                  "20 degC,40 degC")
    assert got.code == 2 and "r.json: is a thermal calibration" in got.err and "--sensor" not in got.err
