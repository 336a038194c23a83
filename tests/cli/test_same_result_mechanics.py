"""budget, allowable, check and drift: the command line (--json), the library job and the report give the same
result on the same inputs (provenance aside: it is not compared)."""

import pytest
from support import ROOT

from align.results import load_result
from align.units import DEG_H
from align.values import approx_equal

MOUNT = ROOT / "examples" / "budget" / "example1.toml"
MANOEUVRE = ROOT / "examples" / "sensitivity" / "example2.toml"


@pytest.fixture(autouse=True)
def _no_user_parts(monkeypatch):
    monkeypatch.delenv("IMU_ALIGN_PARTS", raising=False)


@pytest.fixture(scope="module")
def report_results():
    from align.present.story import make_report

    return make_report(MOUNT, MANOEUVRE, monte_carlo=3000, seed=2).results


def test_budget(run_cli, tmp_path, report_results):
    from mechanics.jobs import budget

    out = tmp_path / "b.json"
    assert run_cli("budget", MOUNT, "--monte-carlo", "3000", "--seed", "2", "--json", out).code == 0
    cli = load_result(out)
    lib = budget(mount=MOUNT, monte_carlo=3000, seed=2)
    assert approx_equal(cli, lib, rtol=1e-12)
    assert approx_equal(report_results["budget"], lib, rtol=1e-12)
    assert cli.provenance.job == lib.provenance.job == report_results["budget"].provenance.job == "budget"


def test_allowable(run_cli, tmp_path, report_results):
    from align.sensitivity.jobs import allowable

    out = tmp_path / "a.json"
    assert run_cli("allowable", MANOEUVRE, "--json", out).code == 0
    lib = allowable(manoeuvre=MANOEUVRE)
    assert approx_equal(load_result(out), lib, rtol=1e-12)
    assert approx_equal(report_results["allowable"], lib, rtol=1e-12)


@pytest.mark.parametrize("basis", ["rss", "worst"])
def test_check(run_cli, tmp_path, report_results, basis):
    from align.present.story import make_report
    from align.sensitivity.jobs import check

    out = tmp_path / "c.json"
    res = run_cli("check", MOUNT, MANOEUVRE, "--basis", basis, "--json", out)
    lib = check(mount=MOUNT, manoeuvre=MANOEUVRE, basis=basis)
    assert res.code == (0 if lib.passed else 4), res.err
    assert approx_equal(load_result(out), lib, rtol=1e-12)
    rep = report_results if basis == "rss" else make_report(MOUNT, MANOEUVRE, monte_carlo=0, basis=basis).results
    assert approx_equal(rep["check"], lib, rtol=1e-12)
    assert lib.inputs["mount"] == str(MOUNT) and lib.inputs["part"] == "ADIS16485"
    # the report command takes check's --basis with its meaning
    res = run_cli("report", "--mount", MOUNT, "--manoeuvre", MANOEUVRE, "--basis", basis, "--monte-carlo", "0",
                  "--out", tmp_path / "r.html")
    assert f"budget ({basis}) {'PASSES' if lib.passed else 'FAILS'} the check" in res.out, res.err


def test_drift(run_cli, tmp_path):
    from align.navigation.jobs import drift
    from align.present.story import make_report

    out = tmp_path / "d.json"
    args = ["--imu", "ADIS16485", "--gyro-bias", "10 deg/h", "--budget", MOUNT, "--manoeuvre", MANOEUVRE,
            "--duration", "30 s", "--runs", "20", "--rate-hz", "20", "--seed", "4"]
    res = run_cli("drift", *args, "--json", out)
    assert res.code == 0, res.err
    lib = drift(imu="ADIS16485", gyro_bias=10 * DEG_H, budget=MOUNT, manoeuvre=MANOEUVRE, duration=30.0, runs=20,
                rate_hz=20.0, seed=4)
    cli = load_result(out)
    assert approx_equal(cli, lib, rtol=1e-9, atol=1e-15)
    assert cli.provenance.job == "drift" and {f.role for f in cli.provenance.files} == {"budget", "manoeuvre"}
    # the report shows the drift command's result file as it is
    rep = make_report(drift=[out]).results
    assert approx_equal(rep[f"drift {out.stem}"], lib, rtol=1e-9, atol=1e-15)


def test_builders_make_the_commands_options():
    from align.cli.builders import options_builder
    from align.navigation.jobs import DriftOptions
    from align.sensitivity.jobs import CheckOptions
    from mechanics.jobs import BudgetOptions

    assert options_builder("budget")(mount=MOUNT, monte_carlo=10, seed=1, json_out="x.json") == \
        BudgetOptions(mount=MOUNT, monte_carlo=10, seed=1)
    assert options_builder("check")(mount=MOUNT, manoeuvre=MANOEUVRE, basis="worst") == \
        CheckOptions(mount=MOUNT, manoeuvre=MANOEUVRE, basis="worst")
    assert options_builder("drift")(duration=60.0, imu="ADIS16485", plot="p.png") == \
        DriftOptions(duration=60.0, imu="ADIS16485")


def _turn_log(path, names):
    import numpy as np

    fs, rate = 50.0, 0.2
    t = np.arange(int(20 * fs) + 1) / fs
    rows = np.column_stack([t, np.tile([0.0, 0.0, np.degrees(rate)], (len(t), 1)),
                            np.tile([0.0, 0.0, -9.80665], (len(t), 1))])
    np.savetxt(path, rows, delimiter=",", header=",".join(names), comments="")


def test_drift_trajectory_columns_by_the_one_convention(run_cli, tmp_path):
    """Old default names (gyr_x) are read by default; a time column of another name is --time-column; four
    --gyro-columns keep meaning time first: the same result each way, and the library's."""
    from align.io.source import LogSource
    from align.navigation.jobs import drift

    old, named = tmp_path / "old.csv", tmp_path / "named.csv"
    _turn_log(old, ["time", "gyr_x", "gyr_y", "gyr_z", "acc_x", "acc_y", "acc_z"])
    _turn_log(named, ["stamp", "gx", "gy", "gz", "ax", "ay", "az"])
    common = ["--gyro-bias", "20 deg/h", "--runs", "10", "--seed", "1"]
    outs = []
    for k, extra in enumerate([["--trajectory", old],
                               ["--trajectory", named, "--time-column", "stamp", "--gyro-columns", "gx,gy,gz",
                                "--accel-columns", "ax,ay,az"],
                               ["--trajectory", named, "--gyro-columns", "stamp,gx,gy,gz", "--accel-columns",
                                "ax,ay,az"]]):
        out = tmp_path / f"d{k}.json"
        res = run_cli("drift", *extra, *common, "--json", out)
        assert res.code == 0, res.err
        outs.append(load_result(out))
    lib = drift(trajectory=LogSource(path=old), gyro_bias=20 * DEG_H, runs=10, seed=1)
    for got in outs:
        assert approx_equal(got.sigma, lib.sigma, rtol=1e-9, atol=1e-15)
    assert approx_equal(outs[0], lib, rtol=1e-9, atol=1e-15)
    res = run_cli("drift", "--trajectory", named, "--gyro-columns", "gx,gx,gz", "--time-column", "stamp", *common)
    assert res.code == 2 and "--gyro-columns" in res.err and len(res.err.strip().splitlines()) == 1
