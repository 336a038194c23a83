"""``apply`` checks the log against the result before it writes anything (issue 28, "apply checks nothing about the
log against the result"): the unit's dimension against the result's, raw counts read as a rate, a magnetometer log
in another field unit; and the one column convention (``--columns`` data names with ``--time-column``).

The truth comes from outside the program: sessions simulated with a known model, written in a known unit."""

import json
from pathlib import Path

import numpy as np
import pytest
from support import write_session

from align.alignment.plan import Plan
from align.alignment.simulate import SessionSpec, simulate_session
from align.calibration.results import Calibration, CalibrationSet
from align.io import write_csv
from align.model import SensorModel
from align.results import save_result
from align.units import DEG
from align.units import parse_quantity as q

SPEC = SessionSpec(noise_density=q("0.3 deg/sqrt(h)", "angle_random_walk"))
#: an MPU-6050 at +/-250 deg/s: 131 counts per deg/s
LSB = 131.0
MODEL = SensorModel(np.array([[1.003, 0.004, -0.002], [-0.003, 0.998, 0.005], [0.002, -0.004, 1.001]]),
                    np.array([0.5, -0.4, 0.3]) * DEG)


def one_line(res, code=2):
    assert res.code == code, (res.code, res.out, res.err)
    line = res.err.strip()
    assert line.startswith("imu-align: error:") and "\n" not in line and "Traceback" not in res.err, res.err
    return line


@pytest.fixture(scope="module")
def aligned(tmp_path_factory):
    """A deg/s alignment result of MODEL, made by ``matrix`` from a simulated session."""
    from align.cli import run

    folder = tmp_path_factory.mktemp("aligned")
    plan = Plan.standard_rate(100 * DEG)
    t, g, _ = simulate_session(plan, MODEL, SPEC, 0)
    log, plan_path = write_session(folder, t, g, plan)
    result = folder / "alignment.json"
    assert run(["matrix", str(log), "--plan", str(plan_path), "--json", str(result)]) == 0
    return result


def _counts_log(folder, rate_deg_s):
    """A session of MODEL at ``rate_deg_s`` on the table, written in raw counts (131 per deg/s), and its true rates."""
    plan = Plan.standard_rate(rate_deg_s * DEG)
    t, g, w = simulate_session(plan, MODEL, SPEC, 5)
    log = folder / "counts.csv"
    write_csv(log, ["time", "gyro_x", "gyro_y", "gyro_z"], np.column_stack([t, np.round(g / DEG * LSB)]))
    return log, w


@pytest.mark.parametrize("rate", [100.0, 20.0])  # 13100 "deg/s" in a dwell; 2620 in a dwell but 93 at rest
def test_a_raw_count_log_corrected_with_a_deg_s_result_is_refused(tmp_path, run_cli, aligned, rate):
    log, _ = _counts_log(tmp_path, rate)
    out = tmp_path / "c.csv"
    line = one_line(run_cli("apply", log, "--alignment", aligned, "--out", out))
    assert "counts.csv" in line and "--gyro-units" in line and "raw counts" in line, line
    assert not out.exists()


def test_the_same_log_with_the_size_of_one_count_is_corrected_to_the_true_rates(tmp_path, run_cli, aligned):
    log, w = _counts_log(tmp_path, 20.0)
    out = tmp_path / "c.csv"
    res = run_cli("apply", log, "--alignment", aligned, "--out", out, "--gyro-units", "131 LSB/(deg/s)")
    assert res.code == 0, res.err
    written = np.loadtxt(out, delimiter=",", skiprows=2)[:, 1:]  # written in the log's unit: counts
    err = np.abs(written / LSB * DEG - w)
    assert np.median(err) < 0.05 * DEG, np.median(err) / DEG


def test_a_deg_s_log_read_as_counts_is_refused(tmp_path, run_cli, aligned):
    plan = Plan.standard_rate(100 * DEG)
    t, g, _ = simulate_session(plan, MODEL, SPEC, 6)
    log, _ = write_session(tmp_path, t, g, plan)
    out = tmp_path / "c.csv"
    line = one_line(run_cli("apply", log, "--alignment", aligned, "--out", out, "--gyro-units", "counts"))
    assert "session.csv" in line or "--gyro-units" in line, line
    assert "--gyro-units" in line and "raw counts" in line, line
    assert not out.exists()


def test_a_gyro_log_given_a_unit_of_another_dimension_is_refused(tmp_path, run_cli, aligned):
    plan = Plan.standard_rate(100 * DEG)
    t, g, _ = simulate_session(plan, MODEL, SPEC, 6)
    log, _ = write_session(tmp_path, t, g, plan)
    line = one_line(run_cli("apply", log, "--alignment", aligned, "--out", tmp_path / "c.csv", "--units", "m/s^2"))
    assert "--units" in line and "'m/s^2'" in line and "alignment.json" in line, line


def test_a_gyro_calibration_in_counts_needs_a_count_log_and_writes_deg_s(tmp_path, run_cli):
    m = MODEL.M * LSB / DEG  # counts per rad/s
    bias = MODEL.bias / DEG * LSB  # counts
    cal = Calibration("gyroscope", m, bias, np.zeros((3, 3)), np.zeros(3), "counts", "test")
    result = tmp_path / "cal.json"
    save_result(result, CalibrationSet({"gyroscope": cal}, {}))
    t = np.arange(500) / 100
    w = np.column_stack([np.zeros(500), np.zeros(500), np.where(t > 2, 30.0, 0.0)]) * DEG
    raw = w @ m.T + bias
    log = tmp_path / "raw.csv"
    write_csv(log, ["time", "gyro_x", "gyro_y", "gyro_z"], np.column_stack([t, raw]))
    out = tmp_path / "c.csv"
    line = one_line(run_cli("apply", log, "--alignment", result, "--out", out))  # default --gyro-units deg/s
    assert "'deg/s'" in line and "counts" in line and "--gyro-units counts" in line, line
    res = run_cli("apply", log, "--alignment", result, "--out", out, "--gyro-units", "counts")
    assert res.code == 0, res.err
    assert "(deg/s)" in res.out and "written in deg/s" in res.out, res.out
    written = np.loadtxt(out, delimiter=",", skiprows=2)[:, 1:]
    assert np.allclose(written, w / DEG, atol=1e-9)


def test_a_gauss_log_read_as_ut_is_refused_though_the_hard_iron_hides_it(tmp_path, run_cli):
    from align.calibration.magnetometer import calibrate_magnetometer

    rng = np.random.default_rng(0)
    u = rng.normal(size=(2000, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    soft = np.array([[1.1, 0.05, 0.0], [0.05, 0.95, 0.02], [0.0, 0.02, 1.02]])
    hard = np.array([12.0, -7.0, 3.0])  # uT: corrected, the gauss log reads |W h| = 14 uT, within Earth's range
    raw_ut = (u * 48.0) @ soft.T + hard
    result = tmp_path / "mag.json"
    save_result(result, calibrate_magnetometer(raw_ut * 1e-6, "uT"))
    log, out = tmp_path / "mag.csv", tmp_path / "corrected.csv"
    write_csv(log, ["time", "mag_x", "mag_y", "mag_z"], np.column_stack([np.arange(len(u)) * 0.01, raw_ut / 100]))
    line = one_line(run_cli("apply", log, "--alignment", result, "--out", out))
    assert "mag.csv" in line and "gauss" in line and "--units gauss" in line, line
    assert not out.exists()
    res = run_cli("apply", log, "--alignment", result, "--out", out, "--units", "gauss")
    assert res.code == 0, res.err
    m = np.loadtxt(out, delimiter=",", skiprows=2)[:, 1:]
    assert np.allclose(np.linalg.norm(m, axis=1), np.linalg.norm(m, axis=1).mean(), rtol=1e-6)


# ------------------------------------------------------------------ the one column convention

def _renamed(tmp_path):
    plan = Plan.standard_rate(100 * DEG)
    t, g, _ = simulate_session(plan, MODEL, SPEC, 7)
    log = tmp_path / "renamed.csv"
    write_csv(log, ["stamp", "wx", "wy", "wz"], np.column_stack([t, g / DEG]))
    plan_path = tmp_path / "plan.toml"
    plan_path.write_text(plan.to_toml())
    return log, plan_path


def test_time_column_and_three_data_columns_on_matrix_and_apply(tmp_path, run_cli):
    import json

    log, plan = _renamed(tmp_path)
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    assert run_cli("matrix", log, "--plan", plan, "--columns", "wx,wy,wz", "--time-column", "stamp", "--json", a).code == 0
    assert run_cli("matrix", log, "--plan", plan, "--columns", "stamp,wx,wy,wz", "--json", b).code == 0
    ra, rb = json.loads(a.read_text()), json.loads(b.read_text())
    assert ra["M"] == rb["M"] and ra["inputs"]["columns"] == "stamp,wx,wy,wz"
    out = tmp_path / "c.csv"
    res = run_cli("apply", log, "--alignment", a, "--out", out, "--columns", "wx,wy,wz", "--time-column", "stamp")
    assert res.code == 0, res.err
    first, header = out.read_text().splitlines()[:2]
    assert header.replace('"', "") == "stamp,wx,wy,wz" and first.endswith("units: stamp=s, wx=deg/s, wy=deg/s, wz=deg/s")


@pytest.mark.parametrize("command", ["matrix", "apply"])
@pytest.mark.parametrize("columns, extra, words", [
    ("wx,wx,wz", (), "named twice"),
    ("stamp,wx,stamp,wz", (), "both the time column and a data column"),
    ("wx,wy,wz", ("--time-column", "wx"), "both the time column and a data column"),
    ("wx,wy", (), "give 3 names"),
])
def test_a_duplicate_or_missing_column_name_is_one_line_exit_2(tmp_path, run_cli, command, columns, extra, words):
    log, plan = _renamed(tmp_path)
    if command == "matrix":
        args = ("matrix", log, "--plan", plan, "--json", tmp_path / "r.json")
    else:
        result = tmp_path / "a.json"
        assert run_cli("matrix", log, "--plan", plan, "--columns", "stamp,wx,wy,wz", "--json", result).code == 0
        args = ("apply", log, "--alignment", result, "--out", tmp_path / "c.csv")
    line = one_line(run_cli(*args, "--columns", columns, *extra))
    assert "--columns" in line and words in line, line
    assert not (tmp_path / "r.json").exists() and not (tmp_path / "c.csv").exists()


def test_the_corrected_csv_states_its_units_and_reads_back_with_them(run_cli, tmp_path):
    """issue 28: apply's CSV states no unit. Its first line now does; every reader takes it (a unit typed against it
    is refused) and the corrected session aligns to the identity (A M = I)."""
    root = Path(__file__).resolve().parents[2] / "examples" / "alignment"
    result, out = tmp_path / "r.json", tmp_path / "c.csv"
    assert run_cli("matrix", root / "session.csv", "--plan", root / "plan.toml", "--json", result).code == 0
    assert run_cli("apply", root / "session.csv", "--alignment", result, "--out", out).code == 0
    assert out.read_text().startswith("# imu-align ") and "(w = A (g - b), A = M^-1)" in out.read_text()[:200]
    again = tmp_path / "again.json"
    res = run_cli("matrix", out, "--plan", root / "plan.toml", "--json", again)
    assert res.code == 0, res.err
    m = np.array(json.loads(again.read_text())["M"])
    assert np.abs(m - np.eye(3)).max() < 1e-6   # its 1-sigma is 1.5e-5
    res = run_cli("matrix", out, "--plan", root / "plan.toml", "--gyro-units", "rad/s")
    assert res.code == 2 and "states its readings in deg/s" in res.err and len(res.err.splitlines()) == 1


def _static_log(folder, name, bias, factor, seed):
    """A still unit of MODEL (Earth's rate left out) whose bias is ``bias`` (rad/s), written as rad/s times
    ``1 / factor`` (``factor`` the SI size of the unit written: DEG for deg/s, 1 for rad/s)."""
    rng = np.random.default_rng(seed)
    n, fs = 4000, 200.0
    g = (MODEL.M @ np.zeros(3) + bias)[None, :] + rng.normal(0.0, 0.05 * DEG, (n, 3))
    log = folder / name
    write_csv(log, ["time", "gyro_x", "gyro_y", "gyro_z"], np.column_stack([np.arange(n) / fs, g / factor]))
    return log


def test_a_rad_s_log_read_as_deg_s_is_refused_by_the_bias_at_rest(tmp_path, run_cli, aligned):
    """Issue 28: "a rad/s log gets a deg/s bias subtracted". The log states no unit; at rest it reads the unit's
    bias (MODEL's 0.5, -0.4, 0.3 deg/s) divided by 57.3 when read as deg/s, and the line says so and names rad/s."""
    log = _static_log(tmp_path, "rad.csv", MODEL.bias, 1.0, 1)
    out = tmp_path / "out.csv"
    line = one_line(run_cli("apply", log, "--alignment", aligned, "--out", out))
    assert "is the log in rad/s? give it with --gyro-units rad/s" in line and not out.exists()
    res = run_cli("apply", log, "--alignment", aligned, "--gyro-units", "rad/s", "--out", out)
    assert res.code == 0, res.err
    done = np.loadtxt(out, delimiter=",", skiprows=2)[:, 1:]
    assert np.abs(done.mean(axis=0)).max() < 0.01  # rad/s: corrected to rest


@pytest.mark.parametrize("change", [0.0, 0.3, 0.8])
def test_a_deg_s_log_whose_bias_moved_since_is_not_refused(tmp_path, run_cli, aligned, change):
    """No false alarm: the same unit turned on again, its bias moved by up to 80 % of itself (a turn-on's change
    or temperature), read in its own unit, is corrected (the moved bias is what remains at rest)."""
    moved = MODEL.bias + change * np.array([-1.0, 0.5, 1.0]) * np.abs(MODEL.bias)
    log = _static_log(tmp_path, "deg.csv", moved, DEG, 2)
    out = tmp_path / "out.csv"
    res = run_cli("apply", log, "--alignment", aligned, "--out", out)
    assert res.code == 0, res.err
    done = np.loadtxt(out, delimiter=",", skiprows=2)[:, 1:]
    want = np.linalg.solve(MODEL.M, moved - MODEL.bias) / DEG
    assert np.allclose(done.mean(axis=0), want, atol=0.02)
