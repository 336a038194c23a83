"""The batch through the command line: one serial with several jobs (a result file per job),
options checked against the job's command when the manifest is read, --axis-down's files resolved and hashed,
--rerun, a foreign table and a bad scheduler address as one line."""

from __future__ import annotations

import os

import pandas as pd
import pytest

from align.alignment.simulate import SessionSpec
from align.production import read_manifest, simulate_lot
from align.results import load_result


@pytest.fixture
def lot3(tmp_path):
    return simulate_lot(tmp_path / "lot", 3, session=SessionSpec(fs=200.0, dwell_s=2.0, static_s=1.0), bad=0, seed=3)


def _static_record(folder):
    """A static gyro record (white noise at rest, deg/s) for the allan job: a rate-table session is no noise record."""
    import numpy as np

    from align.io import write_csv

    rng = np.random.default_rng(4)
    n, fs = 6000, 100.0
    write_csv(folder / "static.csv", ["time", "gyro_x", "gyro_y", "gyro_z"],
              np.column_stack([np.arange(n) / fs, rng.normal(0, 0.05, (n, 3))]))


def _manifest(path, *rows):
    path.write_text("serial,job,log,plan,options\n" + "".join(r + "\n" for r in rows))
    return path


@pytest.mark.slow
def test_one_serial_with_two_jobs_keeps_a_result_per_job_and_is_one_unit(lot3, tmp_path, run_cli):
    folder = lot3.folder
    _static_record(folder)
    both = _manifest(folder / "both.csv", "SN0001,matrix,sessions/SN0001.csv,plan.toml,",
                     "SN0001,allan,static.csv,,", "SN0002,matrix,sessions/SN0002.csv,plan.toml,")
    out = tmp_path / "out"
    res = run_cli("batch", both, "--out", out, "--workers", 1)
    assert res.code == 0, res.err
    assert "2 units; ran 2, skipped 0" in res.out  # units are serials
    assert sorted(p.name for p in (out / "units").iterdir()) == ["SN0001.allan.json", "SN0001.matrix.json",
                                                                 "SN0002.matrix.json"]
    assert type(load_result(out / "units" / "SN0001.matrix.json")).FORMAT == "imu-align.alignment"
    assert type(load_result(out / "units" / "SN0001.allan.json")).FORMAT == "imu-align.allan"
    res = run_cli("lot", out / "results.parquet")
    assert res.code == 0 and "lot of" in res.out and ": 2 units" in res.out, res.out
    # the review's sequence: matrix, then allan, then matrix again from separate manifests of the same serial
    a = _manifest(folder / "a.csv", "SN0001,matrix,sessions/SN0001.csv,plan.toml,")
    b = _manifest(folder / "b.csv", "SN0001,allan,static.csv,,")
    assert "ran 0, skipped 1" in run_cli("batch", a, "--out", out).out
    assert "ran 0, skipped 1" in run_cli("batch", b, "--out", out).out
    assert type(load_result(out / "units" / "SN0001.matrix.json")).FORMAT == "imu-align.alignment"
    res = run_cli("batch", a, "--out", out, "--rerun")
    assert res.code == 0 and "ran 1, skipped 0" in res.out


def test_the_same_serial_and_job_twice_is_refused(lot3):
    m = _manifest(lot3.folder / "d.csv", "SN0001,matrix,sessions/SN0001.csv,plan.toml,",
                  "SN0001,allan,sessions/SN0001.csv,,", "sn0001,matrix,sessions/SN0002.csv,plan.toml,")
    from align.cli.batch import _jobs
    from align.errors import InputError

    with pytest.raises(InputError, match="line 4, column serial: sn0001 with job matrix is also stated at line 2"):
        read_manifest(m, _jobs())


@pytest.mark.parametrize("options, words", [
    ("--bogus 3", "line 2, column options: matrix has no option --bogus"),
    ("--margn '0.2 s'", "matrix has no option --margn (did you mean --margin?)"),
    ("--mag-units gauss", "matrix has no option --mag-units"),
    ("--plan p.toml", "--plan is given in column plan; remove it from the options"),
    ("--json x.json", "--json is the batch's own"),
    ("extra.csv", "'extra.csv' is not an option of matrix"),
    ("--margin", "--margin needs a value"),
    ("--margin abc", "line 2, column options: invalid value for --margin: 'abc' does not start with a number"),
    ("--method best", "line 2, column options: invalid value for --method"),
])
def test_options_are_checked_against_the_command_when_the_manifest_is_read(lot3, tmp_path, run_cli, options, words):
    m = _manifest(lot3.folder / "o.csv", f'SN0001,matrix,sessions/SN0001.csv,plan.toml,"{options}"',
                  "SN0002,matrix,sessions/SN0002.csv,plan.toml,")
    res = run_cli("batch", m, "--out", tmp_path / "out")
    assert res.code == 2 and res.err.count("\n") == 1 and words in res.err and "o.csv" in res.err, res.err
    assert not (tmp_path / "out").exists()  # refused before any unit ran


def test_axis_down_files_resolve_against_the_manifest_and_enter_the_hash(tmp_path, monkeypatch):
    from align.cli.batch import _jobs, check_options, task_maker

    data = tmp_path / "data"
    data.mkdir()
    for name in ("mag.csv", "xd.csv", "yd.csv"):
        (data / name).write_text("time,mag_x,mag_y,mag_z\n0,1,2,3\n")
    m = _manifest(data / "m.csv", "M1,calibrate mag,mag.csv,,\"--axis-down x=xd.csv,y=yd.csv,z=100:900\"")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)  # a worker's cwd is not the manifest's folder
    unit = read_manifest(os.path.relpath(m, elsewhere), _jobs()).units[0]
    check_options(unit, str(m))
    make = task_maker(data.resolve())
    task = make(unit, tmp_path / "out" / unit.result_name, "r")
    assert task.refused is None  # the job's options, built in this process
    assert dict(task.options.axis_down) == {"x": (data / "xd.csv").resolve(), "y": (data / "yd.csv").resolve(),
                                            "z": (100, 900)}
    assert (data / "xd.csv").resolve() in task.inputs and (data / "yd.csv").resolve() in task.inputs
    before = task.digest()
    (data / "xd.csv").write_text("time,mag_x,mag_y,mag_z\n0,1,2,4\n")  # the capture edited: the unit reruns
    assert task.digest() != before
    bad = _manifest(data / "bad.csv", "M1,calibrate mag,mag.csv,,--axis-down x=xd.csv")
    from align.errors import InputError

    with pytest.raises(InputError, match=r"line 2, column options: --axis-down: .*x, y and z"):
        check_options(read_manifest(bad, _jobs()).units[0], str(bad))


def test_a_foreign_parquet_and_a_bad_scheduler_are_one_line(lot3, tmp_path, run_cli):
    pd.DataFrame({"serial": ["SN0001"], "kind": ["good"]}).to_parquet(tmp_path / "foreign.parquet")
    res = run_cli("lot", tmp_path / "foreign.parquet")
    assert res.code == 2 and res.err.count("\n") == 1 and "not an imu-align lot table (no column job)" in res.err
    out = tmp_path / "o"
    out.mkdir()
    (out / "results.parquet").write_bytes((tmp_path / "foreign.parquet").read_bytes())
    res = run_cli("batch", lot3.manifest, "--out", out)
    assert res.code == 2 and res.err.count("\n") == 1 and "not an imu-align lot table" in res.err, res.err
    res = run_cli("batch", lot3.manifest, "--out", tmp_path / "o2", "--scheduler", "bogus")
    assert res.code == 2 and res.err.count("\n") == 1 and "'bogus' is not a Dask scheduler address" in res.err, res.err
    assert "internal error" not in res.err and not (tmp_path / "o2").exists()


def test_old_spellings_of_options_are_taken_as_the_command_takes_them(tmp_path):
    """``calibrate ferraris --acc-units`` (today --accel-units) in a manifest: the unit's options are the single
    command's."""
    from align.cli.batch import _jobs, check_options, task_maker
    from align.cli.options import ALIASES

    old, new = next(iter(ALIASES["calibrate ferraris"].items()))
    assert (old, new) == ("--acc-units", "--accel-units")
    (tmp_path / "s.json").write_text("{}")
    rows = [f'F1,calibrate ferraris,f.csv,s.json,"--rate-hz 100 {flag} g"' for flag in (old, new)]
    tasks = []
    for k, row in enumerate(rows):
        m = _manifest(tmp_path / f"m{k}.csv", row)
        unit = read_manifest(m, _jobs()).units[0]
        check_options(unit, str(m))
        tasks.append(task_maker(tmp_path.resolve())(unit, tmp_path / "out" / unit.result_name, "r"))
    assert tasks[0].refused is None and tasks[0].options == tasks[1].options
