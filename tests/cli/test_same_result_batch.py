"""`imu-align batch` and the single commands give the same result on the same inputs, job by job (matrix, allan,
calibrate ferraris | accel | mag | gyro): a unit's OUT/units/SERIAL.JOB.json is the single command's --json
(provenance and generator aside, their job, files and options compared too), and a refused unit's message is
the single command's one stderr line, with its exit status."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
from support import SHARED

from align.alignment.simulate import SessionSpec
from align.io import write_csv
from align.production import simulate_lot
from align.units import DEG
from align.values import approx_equal

FERRARIS = SHARED / "data" / "multiposition" / "imucal_ferraris"
HMC = SHARED / "data" / "magnetometer" / "hmc5883l_sunsided" / "hmc5883l_compass.csv"
XSENS = SHARED / "data" / "multiposition" / "xsens_mti_imu_tk"
#: job -> the option the manifest's plan column is given as
PLAN_FLAG = {"matrix": "--plan", "calibrate ferraris": "--sections", "calibrate accel": "--positions"}


def _static_gyro(path, arw=0.3 * DEG / 60, fs=100.0, seconds=120.0, seed=2):
    """White rate noise of a known angle random walk (rad/sqrt(s)) at rest, deg/s."""
    rng = np.random.default_rng(seed)
    n = int(fs * seconds)
    g = rng.normal(0, arw * math.sqrt(fs), (n, 3)) + np.array([0.01, -0.02, 0.005])
    write_csv(path, ["time", "gyro_x", "gyro_y", "gyro_z"], np.column_stack([np.arange(n) / fs, g / DEG]))
    return path


@pytest.fixture(scope="module")
def units(tmp_path_factory):
    """(serial, job, log, plan or None, options) of units the jobs accept, and of units they refuse."""
    folder = tmp_path_factory.mktemp("same").resolve()
    lot = simulate_lot(folder / "lot", 3, session=SessionSpec(fs=200.0, dwell_s=2.0, static_s=1.0),
                       bad={"wrong direction": 1}, seed=11)
    good, wrong = lot.serials("good")[0], lot.serials("wrong direction")[0]
    session = lot.folder / "sessions"
    static = _static_gyro(folder / "static.csv")
    poses = folder / "poses"
    from align.cli import run

    assert run(["simulate", str(poses), "--kind", "poses", "--seed", "7", "--rate-hz", "50", "--head", "20 s"]) == 0
    ferraris = (FERRARIS / "example_ferraris_session.csv", FERRARIS / "example_ferraris_session_list.json")
    ok = [
        ("G1", "matrix", session / f"{good}.csv", lot.plan, ("--margin", "0.15 s", "--method", "lsq")),
        ("N1", "allan", static, None, ("--grid", "octave")),
        ("F1", "calibrate ferraris", *ferraris, ("--rate-hz", "102.4")),
        ("A1", "calibrate accel", XSENS / "xsens_acc.mat", None,
         ("--columns", "col0,col1,col2,col3", "--accel-units", "counts", "--gravity", "9.81744 m/s^2",
          "--init-static", "50 s")),
        ("M1", "calibrate mag", HMC, None, ("--columns", "mag_x_gauss,mag_y_gauss,mag_z_gauss", "--mag-units", "gauss")),
        ("Y1", "calibrate gyro", poses / "session.csv", None, ()),
        ("G3", "matrix", session / f"{good}.csv", lot.plan, ("--c-header", "G3.h", "--plot", "G3.png")),  # extra files
    ]
    refused = [
        ("G2", "matrix", session / f"{wrong}.csv", lot.plan, ()),  # the job refuses the readings (status 3)
        ("N2", "allan", session / f"{good}.csv", None, ()),  # a rate-table session is no noise record
        ("M2", "calibrate mag", HMC, None, ("--columns", "mag_x_gauss,mag_y_gauss,mag_x_gauss")),  # refused options
        ("F2", "calibrate ferraris", *ferraris, ("--rate-hz", "102.4", "--gyro-columns", "gyr_x,gyr_x,gyr_z")),
        ("A2", "calibrate accel", XSENS / "xsens_acc.mat", None, ("--columns", "col0,col1,col2", "--time-column", "col0")),
    ]
    return folder, ok, refused


def _manifest(path, rows):
    import shlex

    lines = ["serial,job,log,plan,options"]
    for serial, job, log, plan, options in rows:
        lines.append(f'{serial},{job},{log},{plan or ""},"{shlex.join(options)}"')
    path.write_text("\n".join(lines) + "\n")
    return path


def _alone(job, log, plan, options) -> list[str]:
    """The single command of a unit, its files named as the batch names them (resolved against the manifest)."""
    log, plan = Path(log).resolve(), None if plan is None else Path(plan).resolve()
    return [*job.split(), str(log), *([PLAN_FLAG[job], str(plan)] if plan is not None else []), *options]


@pytest.fixture(scope="module")
def batch_run(units, tmp_path_factory):
    """One batch over every unit (accepted and refused), run once for the module."""
    from align.cli import run

    folder, ok, refused = units
    manifest = _manifest(folder / "manifest.csv", ok + refused)
    out = folder / "out"
    code = run(["batch", str(manifest), "--out", str(out), "--workers", "2"])
    table = pq.read_table(out / "results.parquet").to_pandas().set_index("serial")
    return code, out, table


def _bare(path) -> dict:
    data = json.loads(path.read_text())
    data.pop("generator", None)
    return data


@pytest.mark.parametrize("k", range(7), ids=["matrix", "allan", "ferraris", "accel", "mag", "gyro", "matrix-files"])
def test_a_unit_s_result_is_the_single_command_s(units, batch_run, run_cli, tmp_path, k, monkeypatch):
    monkeypatch.chdir(tmp_path)  # a row's relative output files, written by the single command here
    folder, ok, _ = units
    code, out, table = batch_run
    serial, job, log, plan, options = ok[k]
    assert (table.loc[[serial], "status"] == "ok").all()  # one row per sensor (Ferraris: two)
    alone = tmp_path / "alone.json"
    res = run_cli(*_alone(job, log, plan, options), "--json", alone)
    assert res.code == 0, res.err
    ours, theirs = _bare(out / "units" / f"{serial}.{'-'.join(job.split())}.json"), _bare(alone)
    mine, its = ours.pop("provenance", None), theirs.pop("provenance", None)
    assert approx_equal(ours, theirs, rtol=1e-12), job
    if its is not None:  # the same job, input files and options
        assert mine is not None and mine["job"] == its["job"] and mine["files"] == its["files"]
        assert mine["options"] == its["options"]


def test_a_unit_s_extra_files_are_the_single_command_s(units, batch_run, run_cli, tmp_path):
    """--c-header and --plot in a row's options: written by the batch beside the unit's result (relative to the
    manifest), the header the single command's, the picture a PNG."""
    folder, ok, _ = units
    serial, job, log, plan, _ = ok[6]
    header = tmp_path / "alone.h"
    assert run_cli(*_alone(job, log, plan, ("--c-header", header))).code == 0
    assert (folder / "G3.h").read_text() == header.read_text()
    assert (folder / "G3.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("k", range(5), ids=["matrix", "allan", "mag-options", "ferraris-options", "accel-options"])
def test_a_refused_unit_says_what_the_single_command_says(units, batch_run, run_cli, k):
    folder, _, refused = units
    code, out, table = batch_run
    serial, job, log, plan, options = refused[k]
    res = run_cli(*_alone(job, log, plan, options), "--json", folder / "never.json")
    assert res.code in (2, 3, 4) and res.err.count("\n") == 1, res.err
    row = table.loc[serial]
    assert row["status"] == "failed" and row["exit_code"] == res.code
    assert row["message"] == res.err.strip()
    assert not (out / "units" / f"{serial}.{'-'.join(job.split())}.json").exists()
    assert code == 3


def test_every_batch_job_runs_its_library_job(units):
    """No command line inside the worker: every job of a batch has its options builder, and a unit's task holds
    the job's options, built from its row in this process."""
    import align.api as ia
    from align.cli.batchjobs import JOBS, _jobs, check_options, task_maker
    from align.cli.builders import BUILDERS
    from align.production import Task, Unit

    assert set(_jobs()) == set(JOBS) and set(JOBS) <= set(BUILDERS)
    assert "args" not in Task.__dataclass_fields__
    folder, ok, _ = units
    make = task_maker(folder)
    for k, (serial, job, log, plan, options) in enumerate(ok):
        unit = Unit(serial, job, log, plan, tuple(options), None, k, f"line {k + 2}")
        check_options(unit, "m.csv")
        task = make(unit, folder / "x" / unit.result_name, "r")
        assert task.refused is None and isinstance(task.options, ia.job(job).options), job
