"""`report` takes the options of the commands whose inputs it reads, with their meaning: allan's for --allan REC
(--time-column, --grid, --per-decade, --modified, --noise-ratio, --memory-limit-mb), matrix's time column for --log
(--log-time-column), check's --basis."""

import numpy as np
from support import ROOT

from align.results import load_result
from align.values import approx_equal


def _record(path, name="stamp"):
    rng = np.random.default_rng(0)
    t = np.arange(30_000) / 100.0
    counts = np.round(rng.normal(0, 0.05, (len(t), 3)) * 131)
    np.savetxt(path, np.column_stack([t, counts]), delimiter=",", header=f"{name},gx,gy,gz", comments="", fmt="%.6g")


def test_report_allan_takes_allan_s_options(tmp_path, run_cli, monkeypatch):
    from align.present import story

    rec = tmp_path / "rec.csv"
    _record(rec)
    opts = ["--columns", "gx,gy,gz", "--time-column", "stamp", "--units", "131 LSB/(deg/s)", "--grid", "octave",
            "--modified", "--noise-ratio", "5", "--memory-limit-mb", "500"]
    res = run_cli("allan", rec, *opts, "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--json", tmp_path / "a.json")
    assert res.code == 0, res.err
    by_cli = load_result(tmp_path / "a.json")
    seen = {}
    real = story.make_report

    def spy(*args, **kwargs):
        out = real(*args, **kwargs)
        seen.update(out.results)
        return out

    monkeypatch.setattr(story, "make_report", spy)
    res = run_cli("report", "--allan", rec, *opts, "--out", tmp_path / "r.html")
    assert res.code == 0, res.err
    got = seen["allan"]
    assert approx_equal(got.replace(inputs=by_cli.inputs), by_cli, rtol=1e-12)
    res = run_cli("report", "--allan", rec, "--columns", "gx,gy,gz", "--units", "131 LSB/(deg/s)", "--out",
                  tmp_path / "r.html")
    assert res.code == 2 and "'time'" in res.err and "name its time column with --time-column" in res.err


def test_report_log_takes_matrix_s_time_column(tmp_path, run_cli):
    out = tmp_path / "sim"
    assert run_cli("simulate", "session", out, "--dwell", "2 s", "--gap", "1 s", "--rate-hz", "50 Hz").code == 0
    lines = (out / "session.csv").read_text().splitlines()
    renamed = tmp_path / "renamed.csv"
    renamed.write_text("\n".join([lines[0].replace("time", "stamp", 1), *lines[1:]]) + "\n")
    base = run_cli("report", "--log", out / "session.csv", "--plan", out / "plan.toml", "--out", tmp_path / "a.html")
    res = run_cli("report", "--log", renamed, "--plan", out / "plan.toml", "--log-time-column", "stamp", "--out",
                  tmp_path / "b.html")
    assert base.code == res.code == 0, res.err
    assert res.out.splitlines()[0] == base.out.splitlines()[0]
    res = run_cli("report", "--log", renamed, "--plan", out / "plan.toml", "--log-time-column", "nope", "--out",
                  tmp_path / "b.html")
    assert res.code == 2 and "nope" in res.err and len(res.err.strip().splitlines()) == 1


def test_report_mount_takes_check_s_basis(tmp_path, run_cli):
    mount, man = ROOT / "examples/budget/example1.toml", ROOT / "examples/sensitivity/example2.toml"
    for basis in ("rss", "worst"):
        res = run_cli("report", "--mount", mount, "--manoeuvre", man, "--basis", basis, "--monte-carlo", "0",
                      "--out", tmp_path / "r.html")
        assert f"budget ({basis})" in res.out, res.err
