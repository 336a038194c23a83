"""``allan`` and ``plan``: the command line, the library job and the report's noise step give the same result on
the same inputs; ``report --allan REC`` takes allan's options with allan's meaning; the checks of a record are
one line, exit 2, naming the file and the option (issue 22, issue 28).

Records are simulated with numpy alone.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from align.noise.job import AllanJob
from align.noise.jobs import PLAN, PlanOptions, allan, plan
from align.results import load_result
from align.units import DEG
from align.values import approx_equal

FS = 100.0
N = 30_000


def _strip(d: dict) -> dict:
    d = dict(d)
    d.pop("provenance", None)
    d.pop("generator", None)
    return d


def _same(a, b) -> bool:
    return approx_equal(_strip(a.to_dict()), _strip(b.to_dict()), rtol=1e-12)


def _csv(path, header: str, *cols) -> None:
    np.savetxt(path, np.column_stack(cols), delimiter=",", header=header, comments="", fmt="%.10g")


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    d = tmp_path_factory.mktemp("same_allan")
    rng = np.random.default_rng(7)
    rate = rng.standard_normal((N, 3)) * 0.05 + np.array([0.2, -0.1, 0.3])  # deg/s
    t = np.arange(N) / FS
    _csv(d / "static.csv", "time,gyro_x,gyro_y,gyro_z", t, rate)
    _csv(d / "counts.csv", "time,gyro_x,gyro_y,gyro_z", t, np.round(rate * 131))  # raw counts, 131 LSB/(deg/s)
    return d


def _report_step(rec, **kwargs):
    from align.present.jobs import Report, allan_job

    rep = Report()
    allan_job(rep, rec, **kwargs)
    return rep.results["allan"]


def test_cli_library_and_report_step_agree(records, tmp_path, run_cli):
    rec = records / "static.csv"
    out = tmp_path / "allan.json"
    res = run_cli("allan", rec, "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--json", out)
    assert res.code == 0, res.err
    by_cli = load_result(out, (AllanJob,))
    by_lib = allan(logs=rec, rate=100 * DEG, accuracy=0.1 * DEG)
    by_report = _report_step(rec, columns="gyro_x,gyro_y,gyro_z", units="deg/s")
    assert _same(by_cli, by_lib)
    assert _same(by_report, by_lib)
    assert json.loads(out.read_text())["provenance"]["job"] == "allan"


def test_report_takes_a_raw_count_record_as_allan_does(records, tmp_path, run_cli):
    """`report --allan REC --units "131 LSB/(deg/s)"` refused a record `allan` reads ("cannot read unit")."""
    rec = records / "counts.csv"
    out = tmp_path / "allan.json"
    res = run_cli("allan", rec, "--units", "131 LSB/(deg/s)", "--rate", "100 deg/s", "--accuracy", "0.1 deg",
                  "--json", out)
    assert res.code == 0, res.err
    by_cli = load_result(out, (AllanJob,))
    assert by_cli.units == "deg/s"
    assert _same(_report_step(rec, columns="gyro_x,gyro_y,gyro_z", units="131 LSB/(deg/s)"), by_cli)
    page = tmp_path / "report.html"
    res = run_cli("report", "--out", page, "--allan", rec, "--units", "131 LSB/(deg/s)")
    assert res.code == 0, res.err
    assert page.exists()


def test_report_step_takes_options_built_by_the_command_line(records):
    from align.cli.allan import allan_options

    rec = records / "static.csv"
    opts = allan_options(logs=[rec], columns="time,gyro_x,gyro_y,gyro_z", rate="100 deg/s", accuracy="0.1 deg",
                         grid="octave", json_out="ignored.json", plot=None)
    assert opts.columns == ("time", "gyro_x", "gyro_y", "gyro_z") and opts.rate == pytest.approx(100 * DEG)
    by_report = _report_step(rec, options=opts)
    assert _same(by_report, allan(logs=rec, grid="octave", rate=100 * DEG, accuracy=0.1 * DEG))


def test_four_columns_time_first_no_longer_an_internal_error(records, run_cli):
    rec = records / "static.csv"
    res = run_cli("allan", rec, "--columns", "time,gyro_x,gyro_y,gyro_z")
    assert res.code == 0, res.err
    res = run_cli("allan", rec, "--columns", "time,gyro_x,gyro_y,gyro_z", "--rate-hz", "100")
    assert res.code == 0, res.err
    assert "time" not in res.out.split("gyro_x")[0].split("\n", 1)[1]  # no channel named time analysed
    res = run_cli("allan", rec, "--columns", "gyro_x,gyro_x,gyro_z")
    assert res.code == 2 and "--columns" in res.err and res.err.strip().count("\n") == 0


def _one_line(res, *words):
    assert res.code == 2, (res.code, res.err)
    line = res.err.strip()
    assert line.count("\n") == 0, line
    for w in words:
        assert w in line, (w, line)


def test_the_checks_are_one_line_exit_2_naming_file_and_option(records, tmp_path, run_cli):
    rec = records / "static.csv"
    _one_line(run_cli("allan", rec, "--rate-hz", "50"), str(rec), "--rate-hz", "100 Hz")
    _one_line(run_cli("allan", rec, "--time-units", "ms"), str(rec), "--time-units", "100 kHz")
    n = 20_000
    rng = np.random.default_rng(8)
    t = np.arange(n) / FS
    table = rng.standard_normal((n, 3)) * 0.05
    table[:, 0] += np.where((np.arange(n) // 1000) % 2 == 1, 100.0, -100.0)
    path = tmp_path / "table.csv"
    _csv(path, "time,gyro_x,gyro_y,gyro_z", t, table)
    _one_line(run_cli("allan", path), str(path), "not a static record", "--columns")
    acc = tmp_path / "acc.csv"
    _csv(acc, "time,acc_x,acc_y,acc_z", t, rng.standard_normal((n, 3)) * 0.002 + np.array([0.0, 0.0, 1.0]))
    _one_line(run_cli("allan", acc, "--units", "m/s^2", "--columns", "acc_x,acc_y,acc_z"), str(acc), "--units g")


def test_plan_cli_equals_the_library(tmp_path, run_cli):
    out = tmp_path / "plan.json"
    res = run_cli("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--arw", "0.3 deg/sqrt(h)",
                  "--bias-instability", "6 deg/h", "--json", out)
    assert res.code == 0, res.err
    from align.noise.planner import PlanResult

    by_cli = load_result(out, (PlanResult,))
    by_lib = plan(rate=100 * DEG, accuracy=0.1 * DEG, arw=0.3 * DEG / 60, bias_instability=6 * DEG / 3600)
    assert approx_equal(_strip(by_cli.to_dict()), _strip(by_lib.to_dict()), rtol=1e-9)
    assert by_lib.provenance.job == "plan"
    assert "ARW 0.3 deg/sqrt(h), bias instability 6 deg/h" in by_lib.to_dict()["noise_source"]
    preset = PLAN.run(PlanOptions(rate=100 * DEG, accuracy=0.1 * DEG, imu="ADIS16485"))
    assert math.isfinite(preset.noise_target)
