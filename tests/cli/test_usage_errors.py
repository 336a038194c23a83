"""Every kind of usage mistake, in a real process: exit status 2, one line on stderr, no traceback.

Each run uses the installed ``imu-align`` console script (``python -m align.cli`` when the
script is not beside this Python) and one ``python -m align.cli``, so both entry points are covered.
"""

import os
import subprocess
import sys

import pytest
from support import imu_align_command, slow_beyond

MODULE = [sys.executable, "-m", "align.cli"]


def run(*args, entry=None, env=None):
    cmd = (entry or imu_align_command()) + [str(a) for a in args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120, env=env)


def one_line(res, code=2):
    assert res.returncode == code, (res.returncode, res.stdout, res.stderr)
    assert "Traceback" not in res.stderr
    lines = res.stderr.splitlines()
    assert len(lines) == 1, res.stderr
    return lines[0]


@pytest.mark.parametrize("args,words", slow_beyond(3, [  # a process each: the first three in the fast lane
    ((), ["imu-align: missing command", "usage: imu-align COMMAND", "matrix", "see imu-align --help"]),
    (("matrix",), ["imu-align matrix: missing argument LOG",
                   "usage: imu-align matrix LOG --plan PLAN.toml [options]", "see imu-align matrix --help"]),
    (("matrix", "log.csv"), ["imu-align matrix: missing option --plan", "see imu-align matrix --help"]),
    (("report", "--manoeuvre", "m.toml"), ["imu-align report: missing option --out",
                                           "usage: imu-align report --out REPORT.html"]),
    (("budget", "mount.toml", "--montecarlo", "10"), ["unknown option --montecarlo", "did you mean --monte-carlo?"]),
    (("budget", "mount.toml", "--monte-carlo", "ten"), ["invalid value", "'ten'", "--monte-carlo"]),
    (("matrix", "log.csv", "--plan", "p.toml", "--rate-hz", "fast"), ["invalid value", "--rate-hz"]),
    (("matrix", "log.csv", "--plan", "p.toml", "--min-dwell", "2 mm"), ["invalid value '2 mm' for --min-dwell"]),
    (("check", "a.toml", "b.toml", "--basis", "best"), ["invalid value", "--basis", "rss"]),
    (("budget", "mount.toml", "--json"), ["imu-align budget:", "--json", "requires an argument"]),
    (("matirx", "log.csv"), ["imu-align: unknown command matirx (did you mean matrix?)", "see imu-align --help"]),
    (("calibrate",), ["imu-align calibrate: missing command", "ferraris|accel|mag"]),
    (("calibrate", "magg", "x.csv"), ["imu-align calibrate: unknown command magg (did you mean mag?)"]),
    (("calibrate", "mag"), ["imu-align calibrate mag: missing argument LOG"]),
    (("--verbose",), ["imu-align: unknown option --verbose", "see imu-align --help"]),
]))
def test_usage_error_is_one_line_with_status_2(args, words):
    line = one_line(run(*args))
    for w in words:
        assert w in line, line


@pytest.mark.slow
def test_python_dash_m_behaves_the_same():
    line = one_line(run("budget", "mount.toml", "--montecarlo", "10", entry=MODULE))
    assert "did you mean --monte-carlo?" in line


def test_version():
    res = run("--version")
    assert res.returncode == 0 and res.stderr == ""
    from align import __version__

    assert res.stdout.strip() == f"imu-align {__version__}"


@pytest.mark.slow
def test_library_error_is_one_line_with_its_status(tmp_path):
    line = one_line(run("matrix", tmp_path / "absent.csv", "--plan", tmp_path / "absent.toml"))
    assert line.startswith("imu-align: error:") and "file not found" in line


@pytest.mark.slow
def test_internal_error_is_one_line_and_debug_shows_the_traceback(tmp_path):
    mount = tmp_path / "m.toml"
    mount.write_text("this is not toml = = =\n")
    # an unexpected failure: make the TOML reader itself break
    code = "import sys, align.io; align.io.read_toml = lambda *a: 1 / 0; from align.cli import main; main(sys.argv[1:])"
    cmd = [sys.executable, "-c", code]
    line = one_line(run("budget", mount, entry=cmd), code=1)
    assert line.startswith("imu-align: internal error: ZeroDivisionError") and "IMU_ALIGN_DEBUG=1" in line
    res = run("budget", mount, entry=cmd, env={**os.environ, "IMU_ALIGN_DEBUG": "1"})
    assert res.returncode == 1 and "Traceback" in res.stderr and "ZeroDivisionError" in res.stderr


@pytest.mark.slow
def test_help_exits_0_on_stdout():
    for args in ((), ("matrix",), ("calibrate",), ("calibrate", "mag")):
        res = run(*args, "--help")
        assert res.returncode == 0 and res.stderr == "" and "Usage:" in res.stdout
