"""No traceback ever: the issue's unhandled cases are one line with their status, warnings never reach the
terminal, Ctrl-C is status 130 with nothing written, a closed pipe is quiet, and no message shows a numpy repr
or names an option the command does not have.
"""

import json
import subprocess
import sys
import time

import numpy as np
import pytest
from support import ROOT, imu_align_command

MOUNT = ROOT / "examples" / "budget" / "example1.toml"
MANOEUVRE = ROOT / "examples" / "sensitivity" / "example2.toml"
SESSION, PLAN = ROOT / "examples" / "alignment" / "session.csv", ROOT / "examples" / "alignment" / "plan.toml"


def one_line(res, code):
    assert res.code == code, (res.code, res.out, res.err)
    lines = res.err.splitlines()
    assert len(lines) == 1 and "Traceback" not in res.err, res.err
    assert "np.float64(" not in lines[0] and "Warning" not in lines[0], lines[0]
    return lines[0]


def _npy(path, arr):
    np.save(path, arr)
    return path


@pytest.mark.parametrize("name,make,code,words", [
    ("zeros", lambda: np.zeros((2000, 3)), 3, ["zeros.npy: gyro_x", "constant", "stuck"]),
    ("constant", lambda: np.full((2000, 3), 5.0), 3, ["constant.npy: gyro_x", "constant"]),
    ("one_stuck", lambda: np.column_stack([np.random.default_rng(0).normal(size=2000), np.zeros(2000),
                                           np.random.default_rng(1).normal(size=2000)]), 3, ["gyro_y", "constant"]),
    ("text", lambda: np.array([["a", "b", "c"]] * 20), 2, ["text.npy", "expected numbers"]),
    ("complex", lambda: np.ones((20, 3), complex), 2, ["complex.npy", "expected numbers"]),
    ("boolean", lambda: np.ones((20, 3), bool), 2, ["boolean.npy"]),
])
def test_allan_on_records_it_cannot_analyse(tmp_path, run_cli, name, make, code, words):
    log = _npy(tmp_path / f"{name}.npy", make())
    line = one_line(run_cli("allan", log, "--rate-hz", "100", "--json", tmp_path / "a.json"), code)
    for w in words:
        assert w in line, line
    assert not (tmp_path / "a.json").exists()


@pytest.mark.parametrize("dtype", ["<i2", ">i2", "<u2", "<f4", "<f2", "<i8"])
def test_allan_on_integer_and_narrow_float_records(tmp_path, run_cli, dtype):
    rng = np.random.default_rng(0)
    data = (rng.normal(0, 50, (5000, 3))).astype(dtype) if dtype[1] != "u" else rng.integers(0, 60, (5000, 3)).astype(dtype)
    res = run_cli("allan", _npy(tmp_path / "x.npy", data), "--rate-hz", "100")
    assert res.code == 0, res.err
    assert res.err == ""  # no warning on the terminal


def test_allan_on_a_nearly_constant_quantised_record(tmp_path, run_cli):
    data = np.zeros((100_000, 3), np.int16)
    data[np.random.default_rng(1).integers(0, 100_000, 5), 0] = 1
    res = run_cli("allan", _npy(tmp_path / "q.npy", data), "--rate-hz", "100")
    one_line(res, 3)


def test_allan_rate_hz_zero_is_refused_as_a_value_not_as_a_missing_time_column(tmp_path, run_cli):
    line = one_line(run_cli("allan", _npy(tmp_path / "s.npy", np.ones((100, 3))), "--rate-hz", "0"), 2)
    assert "no time column" not in line and "--rate-hz" in line and "sample rate > 0" in line


def test_library_refuses_a_sample_rate_outside_its_domain():
    from align.errors import InputError
    from align.io import read_log, read_static

    for fs in (0.0, -100.0, float("nan"), float("inf")):
        with pytest.raises(InputError, match="sample rate must be a finite number of Hz > 0") as info:
            read_log(SESSION, ["gyro_x", "gyro_y", "gyro_z"], "deg/s", None, fs)
        assert "rate_hz" in str(info.value) and "np.float64" not in str(info.value)
        with pytest.raises(InputError, match="sample rate"):
            read_static(SESSION, ["gyro_x", "gyro_y", "gyro_z"], fs)


def test_parquet_with_a_text_cell(tmp_path, run_cli):
    import pyarrow as pa
    import pyarrow.parquet as pq

    t = np.arange(100) / 100
    pq.write_table(pa.table({"time": t, "gyro_x": ["a"] * 100, "gyro_y": t, "gyro_z": t}), tmp_path / "x.parquet")
    line = one_line(run_cli("matrix", tmp_path / "x.parquet", "--plan", PLAN), 2)
    assert "x.parquet" in line and "'gyro_x'" in line and "not numbers" in line


@pytest.mark.parametrize("content,words", [
    ("1 2 3\n4 5 6\xe9\n".encode("latin-1"), ["line 2", "0xe9"]),
    (b"1 2 3\n4 five 6\n", ["line 2", "'five' is not a number"]),
    (b"1 2 3\n4 {rate_hz} 6\n", ["line 2", "(rate_hz)"]),   # braces in a file are never read as a placeholder
])
def test_text_log_that_is_not_numbers_or_not_utf8(tmp_path, run_cli, content, words):
    log = tmp_path / "m.txt"
    log.write_bytes(content)
    line = one_line(run_cli("calibrate", "mag", log, "--columns", "col0,col1,col2"), 2)
    for w in ["m.txt", *words]:
        assert w in line, line


def test_report_with_a_missing_mount(tmp_path, run_cli):
    line = one_line(run_cli("report", "--mount", tmp_path / "absent.toml", "--manoeuvre", MANOEUVRE,
                            "--out", tmp_path / "r.html"), 2)
    assert "absent.toml" in line and "file not found" in line
    assert not (tmp_path / "r.html").exists()


@pytest.fixture(scope="module")
def allan_json(tmp_path_factory):
    folder = tmp_path_factory.mktemp("allan")
    log = folder / "s.npy"
    np.save(log, np.random.default_rng(0).normal(0, 0.01, (20_000, 3)))
    from align.cli import run

    assert run(["allan", str(log), "--rate-hz", "100", "--json", str(folder / "a.json")]) == 0
    return json.loads((folder / "a.json").read_text())


def _without(d, *path):
    d = json.loads(json.dumps(d))
    here = d
    for key in path[:-1]:
        here = here[key]
    del here[path[-1]]
    return d


def _with(d, value, *path):
    d = json.loads(json.dumps(d))
    here = d
    for key in path[:-1]:
        here = here[key]
    here[path[-1]] = value
    return d


MALFORMED = [(("drop",) + k) for k in [("tau",), ("adev",), ("fit",), ("figures",), ("fs_hz",), ("samples",), ("runs",),
                                        ("ci_low",), ("ci_high",), ("fit", "gyro_x", "terms"),
                                        ("fit", "gyro_y", "ieee_point_readouts"), ("figures", "gyro_z", "bias")]] + [
    ("set", "a list", "adev"), ("set", [], "figures"), ("set", {"gyro_x": 1}, "fit"), ("set", "many", "samples"),
    ("set", None, "tau"), ("set", {"gyro_x": "x"}, "figures"), ("set", ["a"], "tau")]


@pytest.mark.parametrize("change", MALFORMED, ids=lambda c: f"{c[0]} {'/'.join(str(k) for k in c[1 + (c[0] == 'set'):])}")
def test_plan_from_a_malformed_allan_result_is_one_line(tmp_path, run_cli, allan_json, change):
    d = _without(allan_json, *change[1:]) if change[0] == "drop" else _with(allan_json, change[1], *change[2:])
    bad = tmp_path / "allan.json"
    bad.write_text(json.dumps(d))
    res = run_cli("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--allan", bad, "--json", tmp_path / "p.json")
    line = one_line(res, 2)
    assert "allan.json" in line, line
    assert not (tmp_path / "p.json").exists()


def test_warnings_never_reach_the_terminal(tmp_path, run_cli, monkeypatch):
    import align.present.text as text

    real = text.plan_summary

    def noisy(*args, **kwargs):
        np.log(np.zeros(2))  # RuntimeWarning: divide by zero
        np.float64(1.0) / 0.0
        return real(*args, **kwargs)

    monkeypatch.setattr(text, "plan_summary", noisy)
    res = run_cli("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--arw", "0.3 deg/sqrt(h)")
    assert res.code == 0 and res.err == "", res.err


def test_ctrl_c_in_a_monte_carlo_stops_at_once(tmp_path, run_cli, monkeypatch):
    """The Monte Carlo's worker threads do not run their remaining batches after Ctrl-C."""
    import align.cli.budget as cmd  # budget has its own module (issue 22)

    class interrupting:
        def __init__(self, *args):
            pass

        def __enter__(self):
            def tick(done):
                raise KeyboardInterrupt

            return tick

        def __exit__(self, *exc):
            pass

    monkeypatch.setattr(cmd, "progress", interrupting)
    start = time.perf_counter()
    res = run_cli("budget", MOUNT, "--monte-carlo", "50000000", "--json", tmp_path / "b.json")
    assert time.perf_counter() - start < 20
    line = one_line(res, 130)
    assert "interrupted" in line and not (tmp_path / "b.json").exists()


@pytest.mark.slow
def test_a_closed_pipe_is_quiet():
    cmd = imu_align_command() + ["plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--arw", "0.3 deg/sqrt(h)"]
    res = subprocess.run(["sh", "-c", " ".join(f"'{c}'" for c in cmd) + " | true"], capture_output=True, text=True,
                         timeout=120)
    assert "Traceback" not in res.stderr and "BrokenPipe" not in res.stderr, res.stderr
    assert res.stderr.count("\n") <= 1


@pytest.mark.slow
def test_messages_name_only_options_the_command_has(tmp_path, run_cli):
    """``report`` runs the alignment of ``matrix`` without its segmentation options: a segmentation failure
    speaks of the segmentation window and shortest dwell in words, not as ``--window`` or ``--min-dwell``."""
    rng = np.random.default_rng(0)
    static = tmp_path / "static.csv"
    t = np.arange(3000) / 100
    static.write_text("time,gyro_x,gyro_y,gyro_z\n" + "\n".join(f"{a},{b},{c},{d}" for a, b, c, d in
                                                                zip(t, *rng.normal(0, 0.01, (3, 3000)))) + "\n")
    res = run_cli("report", "--mount", MOUNT, "--manoeuvre", MANOEUVRE, "--out", tmp_path / "r.html", "--log", static,
                  "--plan", PLAN, "--monte-carlo", "0")
    line = one_line(res, res.code)
    assert res.code in (2, 3), line
    for flag in ("--window", "--min-dwell", "--segments", "--static-threshold", "--method"):
        assert flag not in line, line
    assert not (tmp_path / "r.html").exists()


@pytest.mark.slow
def test_python_dash_m_exits_130_on_sigint(tmp_path):
    """A real Ctrl-C (SIGINT) during a long job: status 130, one line, no output file."""
    import signal

    cmd = imu_align_command() + ["budget", str(MOUNT), "--monte-carlo", "100000000", "--json", str(tmp_path / "b.json")]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(3)
    proc.send_signal(signal.SIGINT)
    try:
        out, err = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        raise
    assert proc.returncode == 130, (proc.returncode, err)
    assert err.strip().splitlines() == ["imu-align: interrupted; nothing was written"], err
    assert not (tmp_path / "b.json").exists()
    assert sys.executable  # the test ran in this interpreter's environment


@pytest.mark.parametrize("content,words", [
    (b"\xff\xfet\x00i\x00m\x00e\x00", ["UTF-16"]),
    ("time,gyro_x,gyro_y,gyro_z\xe9\n0,1,2,3\n".encode("latin-1"), ["header is not UTF-8"]),
    (b"time,gyro_x,gyro_y,gyro_z\n", ["no data rows"]),
    (b"", ["cannot read CSV"]),
])
def test_csv_logs_that_cannot_be_read(tmp_path, run_cli, content, words):
    log = tmp_path / "log.csv"
    log.write_bytes(content)
    line = one_line(run_cli("matrix", log, "--plan", PLAN), 2)
    for w in ["log.csv", *words]:
        assert w in line, line


@pytest.fixture(scope="module")
def alignment_json(tmp_path_factory):
    from align.cli import run

    path = tmp_path_factory.mktemp("alignment") / "alignment.json"
    assert run(["matrix", str(SESSION), "--plan", str(PLAN), "--json", str(path)]) == 0
    return path


@pytest.mark.parametrize("bad,words", [("nan", "NaN or inf"), ("1e300", "beyond"), ("-1e300", "beyond")])
@pytest.mark.parametrize("command", ["matrix", "apply", "allan", "mag"])
def test_a_corrupt_sample_is_named_by_file_and_row(tmp_path, run_cli, bad, words, command, alignment_json):
    lines = SESSION.read_text().splitlines()
    cells = lines[101].split(",")
    cells[2] = bad
    lines[101] = ",".join(cells)
    log = tmp_path / "session.csv"
    log.write_text("\n".join(lines) + "\n")
    args = {"matrix": ("matrix", log, "--plan", PLAN),
            "apply": ("apply", log, "--alignment", alignment_json, "--out", tmp_path / "c.csv"),
            "allan": ("allan", log, "--rate-hz", "100"),
            "mag": ("calibrate", "mag", log, "--columns", "gyro_x,gyro_y,gyro_z")}[command]
    res = run_cli(*args)
    line = one_line(res, 2)
    assert "session.csv" in line and words in line and "row 101" in line, line
    assert not (tmp_path / "c.csv").exists()


def test_apply_refuses_a_unit_of_another_dimension_than_the_result_s(tmp_path, run_cli):
    from align.calibration.results import Calibration, CalibrationSet
    from align.results import save_result

    rng = np.random.default_rng(0)
    a = rng.normal(0, 0.01, (2000, 3)) + np.array([0, 0, 9.81])
    log = tmp_path / "acc.csv"
    log.write_text("time,acc_x,acc_y,acc_z\n" + "\n".join(f"{i / 100},{x},{y},{z}" for i, (x, y, z) in enumerate(a)) + "\n")
    cal = Calibration("accelerometer", np.eye(3), np.zeros(3), np.zeros((3, 3)), np.zeros(3), "m/s^2", "test")
    result = tmp_path / "cal.json"
    save_result(result, CalibrationSet({"accelerometer": cal}, {}))
    line = one_line(run_cli("apply", log, "--alignment", result, "--units", "deg/s", "--out", tmp_path / "c.csv"), 2)
    assert "--units" in line and "'deg/s'" in line, line
    assert not (tmp_path / "c.csv").exists()
    res = run_cli("apply", log, "--alignment", result, "--out", tmp_path / "c.csv")
    assert res.code == 0, res.err


def test_an_output_on_a_data_file_a_manoeuvre_names_is_refused(tmp_path, run_cli):
    rates = tmp_path / "rates.csv"
    t = np.arange(200) / 100
    rates.write_text("time,gyro_x,gyro_y,gyro_z\n" + "\n".join(f"{v},0,0,10" for v in t) + "\n")
    man = tmp_path / "series.toml"
    man.write_text('[series]\nfile = "rates.csv"\n\n[limits]\ny = "1 deg"\nz = "1 deg"\n')
    before = rates.read_bytes()
    for args in (("allowable", man, "--json", rates), ("check", MOUNT, man, "--json", rates),
                 ("report", "--mount", MOUNT, "--manoeuvre", man, "--monte-carlo", "0", "--out", rates)):
        line = one_line(run_cli(*args), 2)
        assert "rates.csv" in line and "also an input" in line, line
    assert rates.read_bytes() == before
