"""Outputs are checked before any work, the same way on every command; apply reads every result kind."""

import json

import numpy as np
import pytest
from support import ROOT, truth_model, write_session

from align.alignment.plan import Plan
from align.alignment.simulate import SessionSpec, simulate_session
from align.units import DEG

MOUNT = ROOT / "examples" / "budget" / "example1.toml"


@pytest.fixture
def session(tmp_path):
    t, g, _ = simulate_session(Plan.standard_rate(100 * DEG), truth_model(0), SessionSpec(dwell_s=2.0, static_s=1.0), 0)
    return write_session(tmp_path, t, g, Plan.standard_rate(100 * DEG))


def fails(run_cli, *args, words=()):
    res = run_cli(*args)
    assert res.code == 2, (res.code, res.out, res.err)
    line = res.err.strip()
    assert line.startswith("imu-align: error:") and "\n" not in line, res.err
    for w in words:
        assert w in line, line
    assert res.out == ""  # nothing computed, nothing printed
    return line


def test_output_equal_to_an_input_is_refused_before_the_work(tmp_path, session, run_cli):
    log, plan = session
    before = log.read_bytes()
    fails(run_cli, "matrix", log, "--plan", plan, "--json", log, words=["--json", "also an input"])
    fails(run_cli, "matrix", log, "--plan", plan, "--c-header", tmp_path / "." / plan.name, words=["--c-header"])
    assert log.read_bytes() == before


def test_two_outputs_on_one_file(tmp_path, session, run_cli):
    log, plan = session
    line = fails(run_cli, "matrix", log, "--plan", plan, "--json", tmp_path / "r", "--c-header", tmp_path / "r")
    assert "--c-header" in line and "--json" in line
    line = fails(run_cli, "budget", MOUNT, "--picture", tmp_path / "a.png", "--plot", tmp_path / "a.png",
                 "--monte-carlo", "100")
    assert "--plot" in line and "--picture" in line


def test_output_in_a_missing_folder_or_on_a_folder(tmp_path, session, run_cli):
    log, plan = session
    fails(run_cli, "matrix", log, "--plan", plan, "--json", tmp_path / "no" / "r.json", words=["--json", "does not exist"])
    fails(run_cli, "matrix", log, "--plan", plan, "--json", tmp_path, words=["--json", "is a folder"])
    fails(run_cli, "apply", log, "--alignment", tmp_path / "r.json", "--out", tmp_path / "no" / "c.csv", words=["--out"])
    fails(run_cli, "report", "--mount", MOUNT, "--manoeuvre", MOUNT, "--out", tmp_path / "no" / "r.html", words=["--out"])
    fails(run_cli, "allan", log, "--plot", tmp_path / "no" / "a.png", words=["--plot"])
    fails(run_cli, "calibrate", "mag", log, "--json", tmp_path, words=["--json"])


def test_outputs_are_checked_before_the_inputs_are_read(tmp_path, run_cli):
    # the input does not exist either: the output is what the user hears about first, before any work
    fails(run_cli, "budget", tmp_path / "absent.toml", "--json", tmp_path / "no" / "b.json", words=["--json"])
    fails(run_cli, "calibrate", "ferraris", tmp_path / "absent.csv", "--sections", tmp_path / "s.json", "--rate-hz", "100",
          "--imucal-json", tmp_path / "no" / "i.json", words=["--imucal-json"])


def test_output_folders_are_created_and_never_a_file(tmp_path, run_cli):
    nested = tmp_path / "a" / "b"
    res = run_cli("simulate", nested, "--dwell", "2 s", "--gap", "1 s")
    assert res.code == 0, res.err
    assert (nested / "session.csv").exists() and (nested / "truth.json").exists()
    afile = tmp_path / "file"
    afile.write_text("x")
    fails(run_cli, "simulate", afile, words=["OUT_DIR", "is a file"])
    fails(run_cli, "demo", "--out", afile, words=["--out", "is a file"])
    # simulate's plan.toml in its own folder would overwrite its input plan
    fails(run_cli, "simulate", nested, "--plan", nested / "plan.toml", words=["OUT_DIR", "also an input"])


def test_apply_refuses_unknown_and_newer_results_in_one_line(tmp_path, session, run_cli):
    log, _ = session
    for d, words in (({"format": "imu-align.alignment", "version": 99}, ["newer", "upgrade imu-align"]),
                     ({"format": "someone-else", "version": 1}, ["not an imu-align result"]),
                     ({"version": 1}, ["not an imu-align result"])):
        bad = tmp_path / "bad.json"
        bad.write_text(json.dumps(d))
        fails(run_cli, "apply", log, "--alignment", bad, "--out", tmp_path / "c.csv", words=words)
        assert not (tmp_path / "c.csv").exists()


def test_apply_refuses_a_result_that_corrects_nothing(tmp_path, session, run_cli):
    log, _ = session
    out = tmp_path / "check.json"
    assert run_cli("check", MOUNT, ROOT / "examples" / "sensitivity" / "example2.toml", "--json", out).code == 0
    fails(run_cli, "apply", log, "--alignment", out, "--out", tmp_path / "c.csv", words=["imu-align.check"])


def test_apply_magnetometer_result(tmp_path, run_cli):
    """A MagCalibration file (load_result picks its type) corrects a capture onto a sphere."""
    from align.calibration import calibrate_magnetometer
    from align.io import write_csv
    from align.results import save_result

    rng = np.random.default_rng(3)
    u = rng.normal(size=(2000, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    soft = np.array([[1.1, 0.05, 0.0], [0.05, 0.95, 0.02], [0.0, 0.02, 1.02]])
    raw_ut = (u * 48.0) @ soft.T + np.array([12.0, -7.0, 3.0])
    cal = calibrate_magnetometer(raw_ut * 1e-6, "uT")
    result = tmp_path / "mag.json"
    save_result(result, cal)
    log, out = tmp_path / "mag.csv", tmp_path / "corrected.csv"
    write_csv(log, ["time", "mag_x", "mag_y", "mag_z"], np.column_stack([np.arange(len(u)) * 0.01, raw_ut]))
    res = run_cli("apply", log, "--alignment", result, "--out", out)
    assert res.code == 0, res.err
    assert "magnetometer" in res.out
    m = np.loadtxt(out, delimiter=",", skiprows=2)[:, 1:]   # line 1 states the units, line 2 names the columns
    norms = np.linalg.norm(m, axis=1)
    assert norms.std() < 1e-6 * norms.mean()


def test_check_failure_is_status_4_with_one_line(tmp_path, run_cli):
    tight = tmp_path / "tight.toml"
    tight.write_text((ROOT / "examples" / "sensitivity" / "example2.toml").read_text().replace('y = "1 deg"', 'y = "0.3 deg"'))
    res = run_cli("check", MOUNT, tight)
    assert res.code == 4 and "FAIL (phi_yz)" in res.out
    assert res.err.strip().count("\n") == 0 and res.err.startswith("imu-align: error:") and "phi_yz" in res.err
