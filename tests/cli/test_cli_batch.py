"""`imu-align batch` and `imu-align lot` on small lots: every job, options, reruns, exit statuses, one-line errors."""

from __future__ import annotations

import math
import sys

import numpy as np
import pyarrow.parquet as pq
import pytest
from scipy.spatial.transform import Rotation

from align.alignment.simulate import SessionSpec
from align.io import write_csv
from align.production import simulate_lot
from align.units import DEG, STANDARD_GRAVITY

SHORT = SessionSpec(fs=200.0, dwell_s=2.0, static_s=1.0)


def _table(out):
    return pq.read_table(out / "results.parquet").to_pandas()


def _accel_session(folder, m, b, n=150, fs=100.0, seed=0):
    """Six static faces (+x, -x, ... up) of an accelerometer ``a = M (g up) + b + noise``, and its positions file."""
    rng = np.random.default_rng(seed)
    faces = ["+x", "-x", "+y", "-y", "+z", "-z"]
    rows, text = [], ""
    for k, face in enumerate(faces):
        up = np.eye(3)["xyz".index(face[1])] * (1 if face[0] == "+" else -1)
        rows.append(m @ (STANDARD_GRAVITY * up) + b + rng.normal(0, 2e-3, (n, 3)))
        text += f'[[position]]\nname = "{face}"\nup = "{face}"\nstart = {k * n}\nend = {(k + 1) * n}\n\n'
    a = np.vstack(rows)
    write_csv(folder / "acc.csv", ["time", "acc_x", "acc_y", "acc_z"], np.column_stack([np.arange(len(a)) / fs, a]))
    (folder / "positions.toml").write_text(text)


def _mag_capture(folder, s, h, n=1500, seed=1):
    """Readings ``S m + h`` over uniform attitudes of a 50 uT field (uT), as tests/calibration/magsim.py makes them."""
    rng = np.random.default_rng(seed)
    field = 50e-6 * np.array([math.cos(math.radians(60)), 0, -math.sin(math.radians(60))])
    body = Rotation.random(n, random_state=seed).inv().apply(field)
    raw = body @ s.T + h + rng.normal(0, 0.3e-6, (n, 3))
    write_csv(folder / "mag.csv", ["mag_x", "mag_y", "mag_z"], raw * 1e6)


def _static_gyro(folder, arw, fs=100.0, seconds=300.0, seed=2):
    """White rate noise of a known angle random walk (rad/sqrt(s)), deg/s."""
    rng = np.random.default_rng(seed)
    n = int(fs * seconds)
    g = rng.normal(0, arw * math.sqrt(fs), (n, 3)) + np.array([0.01, -0.02, 0.005])
    write_csv(folder / "static.csv", ["time", "gyro_x", "gyro_y", "gyro_z"],
              np.column_stack([np.arange(n) / fs, g / DEG]))


@pytest.mark.slow
def test_every_job_of_a_mixed_manifest_gives_its_figures_against_truth(tmp_path, run_cli):
    lot = simulate_lot(tmp_path / "lot", 2, session=SHORT, bad=0, seed=5)
    m_acc, b_acc = np.diag([1.01, 0.99, 1.0]) + 0.003, np.array([0.1, -0.2, 0.05])
    _accel_session(tmp_path / "lot", m_acc, b_acc)
    s_mag, h_mag = np.eye(3) + 0.05 * np.array([[0, 1, 0], [1, 0, 0.5], [0, 0.5, 0]]), np.array([20e-6, -15e-6, 30e-6])
    _mag_capture(tmp_path / "lot", s_mag, h_mag)
    arw = 0.3 * DEG / 60  # 0.3 deg/sqrt(h)
    _static_gyro(tmp_path / "lot", arw)
    (tmp_path / "lot" / "plots").mkdir()
    manifest = tmp_path / "lot" / "units.toml"
    manifest.write_text('''
[defaults]
plan = "plan.toml"
job = "matrix"

[[unit]]
serial = "G1"
log = "sessions/SN0001.csv"
options = ["--plot", "plots/{serial}.png"]

[[unit]]
serial = "G2"
log = "sessions/SN0002.csv"
slot = 2

[[unit]]
serial = "A1"
job = "calibrate accel"
log = "acc.csv"
plan = "positions.toml"

[[unit]]
serial = "M1"
job = "calibrate mag"
plan = ""
log = "mag.csv"

[[unit]]
serial = "N1"
job = "allan"
plan = ""
log = "static.csv"
options = "--grid octave"
''')
    res = run_cli("batch", manifest, "--workers", 2, "--out", tmp_path / "out")
    assert res.code == 0, res.out + res.err
    assert res.err == ""  # quiet: no progress bar off a terminal
    t = _table(tmp_path / "out").set_index("serial")
    assert sorted(t.index) == ["A1", "G1", "G2", "M1", "N1"] and (t.status == "ok").all()
    assert (tmp_path / "lot" / "plots" / "G1.png").stat().st_size > 1000  # an option's path: relative to the manifest
    assert t.loc["G2", "slot"] == "2" and t.loc["G1", "order"] == 0 and t.loc["N1", "order"] == 4
    truth = {u["serial"]: u for u in lot.units}
    for serial, sn in (("G1", "SN0001"), ("G2", "SN0002")):
        m = np.array([[t.loc[serial, f"M_{a}{b}"] for b in "xyz"] for a in "xyz"])
        m_true = np.array([[truth[sn][f"M_{a}{b}"] for b in "xyz"] for a in "xyz"])
        sig = np.array([[t.loc[serial, f"M_{a}{b}_sigma"] for b in "xyz"] for a in "xyz"])
        assert np.all(np.abs(m - m_true) < 5 * sig)
        assert t.loc[serial, "sensor"] == "gyroscope" and "directions: pass" in t.loc[serial, "checks"]
    acc = t.loc["A1"]
    assert acc.sensor == "accelerometer" and acc.bias_unit == "m/s^2"
    assert np.allclose([[acc[f"M_{a}{b}"] for b in "xyz"] for a in "xyz"], m_acc, atol=2e-4)
    assert np.allclose([acc.bias_x, acc.bias_y, acc.bias_z], b_acc, atol=2e-3)
    mag = t.loc["M1"]
    assert mag.sensor == "magnetometer"
    assert np.allclose([mag.bias_x, mag.bias_y, mag.bias_z], h_mag, atol=0.5e-6)
    w = np.array([[mag[f"M_{a}{b}"] for b in "xyz"] for a in "xyz"])  # soft_iron^-1: S up to the field's scale
    assert np.allclose(w / np.cbrt(np.linalg.det(w)), s_mag / np.cbrt(np.linalg.det(s_mag)), atol=5e-3)
    noise = t.loc["N1"]
    assert noise.sensor == "gyroscope" and noise.job == "allan"
    assert all(abs(noise[f"arw_{a}"] / arw - 1) < 0.1 for a in "xyz")
    assert np.isnan(noise.M_xx) and np.isnan(acc.arw_x)  # a figure a job does not give is null
    # the unit's result is the single command's own file, the same as running it alone
    alone = run_cli("calibrate", "accel", tmp_path / "lot" / "acc.csv", "--positions",
                    tmp_path / "lot" / "positions.toml", "--json", tmp_path / "alone.json")
    assert alone.code == 0
    from align.results import load_result

    ours, theirs = load_result(tmp_path / "out" / "units" / "A1.calibrate-accel.json"), load_result(tmp_path / "alone.json")
    assert np.array_equal(ours.sensors["accelerometer"].M, theirs.sensors["accelerometer"].M)


@pytest.fixture
def small_lot(tmp_path):
    lot = simulate_lot(tmp_path / "lot", 8, session=SHORT, bad={"wrong direction": 1, "out of spec": 1}, seed=11)
    spec = tmp_path / "spec.toml"
    spec.write_text('"phi_*" = { abs_max = "0.1 deg" }\n')
    return lot, spec


@pytest.mark.slow
def test_exit_status_and_summary_say_how_many_units_failed(small_lot, tmp_path, run_cli):
    lot, spec = small_lot
    out = tmp_path / "out"
    res = run_cli("batch", lot.manifest, "--workers", 2, "--out", out, "--spec", spec)
    wrong, off = lot.serials("wrong direction")[0], lot.serials("out of spec")[0]
    assert res.code == 3 and res.err.strip().splitlines() == [
        "imu-align: error: batch: 1 of 8 units failed or gave an error, 1 outside the spec or their limits (listed above)"]
    assert "8 units; ran 8, skipped 0 (done before, inputs unchanged); 7 ok (1 outside the spec), 1 failed, 0 errors" \
        in res.out
    lines = {line.split()[0]: line for line in res.out.splitlines() if line.startswith("  ")}
    assert "failed" in lines[wrong] and "turned the wrong way" in lines[wrong]
    assert "fail " in lines[off] and "outside |phi_" in lines[off]
    # the failed unit alone, repaired: the rerun runs it only and reports the out-of-spec one
    good = lot.serials("good")[0]
    (lot.folder / "sessions" / f"{wrong}.csv").write_bytes((lot.folder / "sessions" / f"{good}.csv").read_bytes())
    res = run_cli("batch", lot.manifest, "--workers", 1, "--out", out, "--spec", spec)
    assert res.code == 4 and "ran 1, skipped 7" in res.out and "8 ok (1 outside the spec), 0 failed" in res.out
    assert res.err.strip() == "imu-align: error: batch: 1 of 8 units outside the spec or their limits (listed above)"
    # without the spec every unit passes: exit 0; the table has every run's rows
    res = run_cli("batch", lot.manifest, "--out", out)
    assert res.code == 0 and "ran 0, skipped 8" in res.out and "8 ok, 0 failed" in res.out
    t = _table(out)
    assert len(t) == 9 and t.run.nunique() == 2 and str(t.time.dt.tz) == "UTC"


@pytest.mark.slow
def test_a_changed_input_or_option_runs_that_unit_again(small_lot, tmp_path, run_cli):
    lot, _ = small_lot
    out = tmp_path / "out"
    assert run_cli("batch", lot.manifest, "--out", out).code == 3
    first = _table(out).set_index("serial")
    a, b = lot.serials("good")[:2]
    log = lot.folder / "sessions" / f"{a}.csv"
    text = log.read_text()
    log.write_text(text)  # the same content, written again: not a change
    rows = [line.split(",") for line in lot.manifest.read_text().splitlines()]
    for r in rows:
        if r[0] == b:
            r[4] = "--margin '0.15 s'"  # the options column
    lot.manifest.write_text("\n".join(",".join(r) for r in rows) + "\n")
    res = run_cli("batch", lot.manifest, "--out", out)
    assert "ran 2, skipped 6" in res.out, res.out  # the changed option, and the failed unit
    log.write_text(text.replace("\n0.005,", "\n0.0050,", 1))  # one byte more: another content
    res = run_cli("batch", lot.manifest, "--out", out)
    assert "ran 2, skipped 6" in res.out, res.out
    t = _table(out)
    assert (t.serial == a).sum() == 2 and t[t.serial == a].input_hash.nunique() == 2
    assert first.loc[b, "input_hash"] != t[t.serial == b].input_hash.iloc[-1]


@pytest.mark.parametrize("text, words", [
    ("serial,job,log,plan\nA1,matrix,a.csv,p.toml\nA1,matrix,b.csv,p.toml\n",
     "manifest.csv: line 3, column serial: A1 with job matrix is also stated at line 2; give each (serial, job) "
     "once"),
    ("serial,job,log,plan\nA1,matix,a.csv,p.toml\n",
     "manifest.csv: line 2, column job: unknown job 'matix' (did you mean matrix?)"),
    ("serial,job,log,plan\nA1,matrix,a.csv,\n", "manifest.csv: line 2, column plan: empty; the matrix job needs one"),
    ("serial,job,log,plan,options\nA1,matrix,a.csv,p.toml,--json x.json\n",
     "manifest.csv: line 2, column options: --json is the batch's own"),
    ("serial,job,log,plan,options\nA1,matrix,a.csv,p.toml,\"--columns 'a,b\"\n",
     "manifest.csv: line 2, column options: cannot be split (No closing quotation); check the quotes"),
    ("serial,jobs,log\n", "manifest.csv: line 1: unknown column 'jobs' (did you mean job?)"),
    ("serial,job,log\nA/1,allan,a.csv\n", "manifest.csv: line 2, column serial: 'A/1' cannot name a file"),
])
def test_a_bad_manifest_is_one_line_naming_row_and_column(tmp_path, run_cli, text, words):
    manifest = tmp_path / "manifest.csv"
    manifest.write_text(text)
    res = run_cli("batch", manifest, "--out", tmp_path / "out")
    assert res.code == 2 and res.err.count("\n") == 1 and words in res.err, res.err
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


@pytest.mark.slow
def test_scheduler_errors_are_one_line(small_lot, tmp_path, run_cli, monkeypatch):
    lot, _ = small_lot
    res = run_cli("batch", lot.manifest, "--scheduler", "tcp://127.0.0.1:8786", "--workers", 2)
    assert res.code == 2 and "imu-align: error: --workers: goes with the process pool or a local cluster" in res.err
    import align.production.pools as pools

    monkeypatch.setattr(pools, "CONNECT_TIMEOUT", 1.0)
    res = run_cli("batch", lot.manifest, "--scheduler", "tcp://127.0.0.1:9", "--out", tmp_path / "out")
    assert res.code == 2 and res.err.count("\n") == 1, res.err
    assert res.err.startswith("imu-align: error: --scheduler: cannot reach the Dask scheduler at tcp://127.0.0.1:9 (")
    assert not (tmp_path / "out").exists()  # nothing ran: no folder left
    monkeypatch.setitem(sys.modules, "dask", None)  # as if the cluster extra were not installed
    res = run_cli("batch", lot.manifest, "--scheduler", "local", "--out", tmp_path / "out")
    assert res.code == 2 and res.err == ("imu-align: error: --scheduler: Dask is not installed: "
                                         "pip install 'imu-align[cluster]'\n")


@pytest.mark.slow
def test_lot_without_a_spec_describes_the_key_figures_and_passes(small_lot, tmp_path, run_cli):
    lot, _ = small_lot
    run_cli("batch", lot.manifest, "--out", tmp_path / "out")
    res = run_cli("lot", tmp_path / "out" / "results.parquet")
    assert res.code == 4 and "1 of 8 units do not pass" in res.err  # the wrong-direction unit failed
    assert "no spec" in res.out and "phi_xy" in res.out and "bias_x" in res.out and "Cpk" in res.out
    res = run_cli("lot", tmp_path / "nowhere.parquet")
    assert res.code == 2 and "nowhere.parquet: file not found" in res.err


@pytest.mark.slow
def test_a_progress_bar_over_units_on_a_terminal_only(small_lot, tmp_path, run_cli, monkeypatch):
    import io

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    lot, _ = small_lot
    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    run_cli("batch", lot.manifest, "--workers", 2, "--out", tmp_path / "out")
    drawn = terminal.getvalue()
    assert "\runits [" in drawn and "] 8/8" in drawn and "] 1/8" in drawn
    assert "imu-align: error: batch: 1 of 8 units failed" in drawn  # the summary line after the bar


@pytest.mark.slow
def test_units_run_in_threads_at_once_keep_their_own_messages(small_lot, tmp_path, monkeypatch):
    """A Dask worker may run several units in threads of one process: each unit's result and message is its own,
    and the worker touches no stream of the process."""
    from concurrent.futures import ThreadPoolExecutor

    from align.cli.batch import _jobs, run_unit, task_maker
    from align.production import read_manifest

    lot, _ = small_lot
    streams = sys.stdout, sys.stderr
    units = read_manifest(lot.manifest, _jobs()).units
    make = task_maker(lot.folder.resolve())
    (tmp_path / "units").mkdir()
    tasks = [make(u, tmp_path / "units" / f"{u.serial}.json", "r") for u in units] * 3
    wrong = lot.serials("wrong direction")[0]
    with ThreadPoolExecutor(4) as ex:
        results = list(ex.map(run_unit, tasks))
    for task, rows in zip(tasks, results):
        (row,) = rows
        assert row["serial"] == task.unit.serial
        if task.unit.serial == wrong:
            assert row["status"] == "failed" and f"{wrong}.csv: step" in row["message"]
        else:
            assert row["status"] == "ok" and row["message"] == ""
    assert (sys.stdout, sys.stderr) == streams


@pytest.mark.slow
def test_ctrl_c_keeps_the_units_done_and_says_so(small_lot, tmp_path, run_cli, monkeypatch):
    import contextlib

    import align.cli.progress

    @contextlib.contextmanager
    def interrupted_after_three(total, label):
        def tick(done):
            if done == 3:
                raise KeyboardInterrupt
        yield tick

    lot, _ = small_lot
    monkeypatch.setattr(align.cli.progress, "progress", interrupted_after_three)
    res = run_cli("batch", lot.manifest, "--workers", 2, "--out", tmp_path / "out")
    assert res.code == 130 and res.err == ("imu-align: interrupted; the units done are kept (results.parquet, units/): "
                                           "run the same command again to finish the rest\n")
    done = _table(tmp_path / "out")
    # the units running at Ctrl-C finish (workers ignore it): each result written has its row
    written = sorted(p.name.split(".")[0] for p in (tmp_path / "out" / "units").glob("*.json"))
    assert 3 <= len(done) < 8 and sorted(done.serial[done.status == "ok"]) == written
    assert not (tmp_path / "out" / ".batch.lock").exists()
    monkeypatch.undo()
    res = run_cli("batch", lot.manifest, "--workers", 2, "--out", tmp_path / "out")
    ok_before = int((done.status == "ok").sum())
    assert f"ran {8 - ok_before}, skipped {ok_before}" in res.out
