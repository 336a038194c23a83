"""A simulated lot of 200 units (5 bad) through batch and lot, checked against the truth the simulation kept.

The truth is the simulator's own (each unit's true M, written to truth.csv before any estimate); the
figures, Cpk and yield the tool reports are compared with a direct computation from it here (numpy, not
the tool's code), and every failing unit's message with the single command's own message. The same lot
then runs on a local Dask cluster and gives the same table.

One test runs the lot once and makes every check in turn (``_check_*``): under ``pytest -n 2`` a module
fixture would run the lot again on each worker.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
from _lots import cli, make_lot
from scipy import stats as sst

from align.production.rehearsal import read_truth
from align.units import DEG

PHI_MAX = 0.1 * DEG
SCALE = (0.997, 1.003)
AX = "xyz"


def _run_lot(folder):
    truth, spec = make_lot(folder)
    code, out, err = cli("batch", truth.manifest, "--workers", 2, "--out", folder / "out", "--spec", spec)
    table = pq.read_table(folder / "out" / "results.parquet").to_pandas().set_index("serial")
    head, truth_rows = read_truth(truth.truth)
    assert head["format"] == "imu-align.lot-truth" and head["units"]["M_"] == "1" and head["units"]["bias_"] == "rad/s"
    rows = {r["serial"]: r for r in truth_rows}
    return {"truth": truth, "spec": spec, "code": code, "out": out, "err": err, "table": table, "rows": rows,
            "folder": folder}


def _true_m(row) -> np.ndarray:
    return np.array([[float(row[f"M_{a}{b}"]) for b in AX] for a in AX])


def _true_figures(m: np.ndarray) -> dict:
    """Scale factors and cross-axis angles of a true M, straight from their definitions: ``s_i = |row i|``,
    ``phi_ij = asin(M_ij / s_i)`` (reference section 1)."""
    s = np.linalg.norm(m, axis=1)
    out = {f"scale_{AX[i]}": s[i] for i in range(3)}
    out |= {f"phi_{AX[i]}{AX[j]}": math.asin(m[i, j] / s[i]) for i in range(3) for j in range(3) if i != j}
    return out


def _passes(fig: dict) -> bool:
    return all(abs(v) <= PHI_MAX for k, v in fig.items() if k.startswith("phi_")) and \
        all(SCALE[0] <= v <= SCALE[1] for k, v in fig.items() if k.startswith("scale_"))


def _check_the_batch_ran_every_unit_and_says_how_many_failed(lot):
    t = lot["table"]
    assert len(t) == 200 and t.index.is_unique
    broken = set(lot["truth"].serials("wrong direction")) | set(lot["truth"].serials("nan rows"))
    assert set(t.index[t.status == "failed"]) == broken
    assert lot["code"] == 3  # units failed
    assert lot["err"].strip().splitlines() == [f"imu-align: error: batch: {len(broken)} of 200 units failed or gave an "
                                               f"error, {(t.verdict == 'fail').sum()} outside the spec or their limits "
                                               "(listed above)"]


def _check_every_good_unit_s_M_is_within_its_3_sigma_of_truth(lot):
    t, rows = lot["table"], lot["rows"]
    measured = [s for s in t.index if t.loc[s, "status"] == "ok"]
    assert len(measured) == 200 - 3
    z = []
    for s in measured:
        m = np.array([[t.loc[s, f"M_{a}{b}"] for b in AX] for a in AX])
        sig = np.array([[t.loc[s, f"M_{a}{b}_sigma"] for b in AX] for a in AX])
        z.append(((m - _true_m(rows[s])) / sig).ravel())
    z = np.abs(np.array(z))
    # a 3-sigma bound is exceeded by 0.27 % of honest normal errors: no more than chance allows (99.9 %)
    allowed = sst.binom.ppf(0.999, z.size, 2 * sst.norm.sf(3))
    assert (z > 3).sum() <= allowed, np.sort(z.ravel())[-10:]
    assert z.max() < 5
    assert 0.5 < np.sqrt(np.mean(z ** 2)) < 1.3  # the sigmas are the errors' size, not far above it


def _check_bad_units_are_reported_by_serial_with_the_single_command_s_message(lot, folder):
    t, truth = lot["table"], lot["truth"]
    for s in truth.serials("wrong direction") + truth.serials("nan rows"):
        log = (truth.folder / "sessions" / f"{s}.csv").resolve()
        code, _, err = cli("matrix", log, "--plan", truth.plan.resolve(), "--json", lot["folder"] / "alone.json")
        assert code == t.loc[s, "exit_code"] == (3 if s in truth.serials("wrong direction") else 2)
        assert t.loc[s, "message"] == err.strip()
        assert ("turned the wrong way" if s in truth.serials("wrong direction") else "NaN") in err
        assert f"{s}  " in lot["out"] or f"{s} " in lot["out"]  # listed in the batch's summary
        assert err.strip() in lot["out"]


def _check_out_of_spec_units_fail_the_spec_and_pass_fail_agrees_with_truth(lot):
    t, rows, truth = lot["table"], lot["rows"], lot["truth"]
    for s in truth.serials("out of spec"):
        assert t.loc[s, "status"] == "ok" and t.loc[s, "verdict"] == "fail"
        assert "phi_" in t.loc[s, "message"] and "outside |phi_" in t.loc[s, "message"]
    ok = t[t.status == "ok"]
    for s in ok.index:
        true = _passes(_true_figures(_true_m(rows[s])))
        if (ok.loc[s, "verdict"] != "fail") != true:  # only a unit within its measurement noise of a limit may flip
            fig = _true_figures(_true_m(rows[s]))
            margin = min(min(abs(abs(v) - PHI_MAX) for k, v in fig.items() if k.startswith("phi_")),
                         min(min(abs(v - SCALE[0]), abs(v - SCALE[1])) for k, v in fig.items() if k.startswith("scale_")))
            assert margin < 4 * np.nanmax([ok.loc[s, f"M_{a}{b}_sigma"] for a in AX for b in AX]), s


def _check_cpk_and_yield_equal_a_direct_computation_from_the_truth(lot):
    from align.production import latest_rows, lot_statistics, read_spec, read_table

    t, rows = lot["table"], lot["rows"]
    stats = lot_statistics(latest_rows(read_table(lot["folder"] / "out" / "results.parquet")), read_spec(lot["spec"]))
    measured = [s for s in t.index if t.loc[s, "status"] == "ok"]
    truth = {s: _true_figures(_true_m(rows[s])) for s in measured}
    by_name = {fs.figure: fs for fs in stats.figures}
    assert set(by_name) == {f"phi_{a}{b}" for a in AX for b in AX if a != b} | {f"scale_{a}" for a in AX}
    for name, fs in by_name.items():
        x = np.array([truth[s][name] for s in measured])
        low, high = (-PHI_MAX, PHI_MAX) if name.startswith("phi") else SCALE
        cpk_true = min(high - x.mean(), x.mean() - low) / (3 * x.std(ddof=1))
        n = len(x)
        se = math.sqrt(1 / (9 * n) + cpk_true ** 2 / (2 * (n - 1)))  # Bissell's standard error
        assert fs.n == n and abs(fs.cpk - cpk_true) < 3 * se, (name, fs.cpk, cpk_true, se)
        assert abs(fs.cpk_sigma - se) < 0.1 * se
        assert abs(fs.mean - x.mean()) < 3 * x.std(ddof=1) / math.sqrt(n)
        assert abs(fs.yield_ - np.mean((x >= low) & (x <= high))) <= 2 / n
    yield_true = sum(_passes(truth[s]) for s in measured) / 200  # the 3 broken units count as not passing
    lo, hi = stats.yield_interval  # Wilson 95 %
    assert lo - 2 / 200 <= yield_true <= hi + 2 / 200 and lo < stats.yield_ < hi
    assert stats.count == 200 and 0.9 < stats.yield_ < 1.0


def _check_lot_command_lists_failing_units_first_and_draws_the_report(lot, folder):
    truth = lot["truth"]
    folder.mkdir()
    report = folder / "lot.html"
    code, out, err = cli("lot", lot["folder"] / "out" / "results.parquet", "--spec", lot["spec"], "--report", report)
    assert code == 4 and err.count("\n") == 1 and "units do not pass" in err
    listed = out.split("units not passing")[1].split("\n\n")[0].splitlines()[1:]
    serials = [line.split()[0] for line in listed]
    bad = set(truth.serials()) - set(truth.serials("good"))
    assert bad <= set(serials)
    html = report.read_text()
    assert html.index("Units not passing") < html.index("Statistics") < html.index("Histograms")
    assert html.count("data:image/png;base64,") == 2
    for s in bad:
        assert s in html
    for s in truth.serials("out of spec"):  # far outside the others: robust outliers
        assert s in out.split("outliers")[-1]


def _check_the_example_spec_fails_exactly_the_bad_units(lot):
    """examples/production/spec.toml goes with this rehearsal: every out-of-spec unit fails it (on phi), every good
    unit passes it, the 3 broken ones do not pass (review 17, bug 11)."""
    example = Path(__file__).resolve().parents[2] / "examples" / "production" / "spec.toml"
    code, out, err = cli("lot", lot["folder"] / "out" / "results.parquet", "--spec", example)
    truth = lot["truth"]
    listed = out.split("units not passing")[1].split("\n\n")[0].splitlines()[1:]
    verdicts = {line.split()[0]: line.split()[1] for line in listed}
    assert code == 4 and set(verdicts) == set(truth.serials()) - set(truth.serials("good")), out
    for s in truth.serials("out of spec"):
        assert verdicts[s] == "fail" and "phi_" in out.split(s)[1].splitlines()[0]
    assert "yield 195 of 200" in out


def _check_a_rerun_with_nothing_changed_runs_only_the_failed_units(lot):
    code, out, _ = cli("batch", lot["truth"].manifest, "--workers", 2, "--out", lot["folder"] / "out",
                       "--spec", lot["spec"])
    assert code == 3
    assert "ran 3, skipped 197" in out and "197 ok (" in out and "3 failed" in out


def _check_a_local_dask_cluster_gives_the_same_table(lot):
    from align.production import FIGURES

    folder = lot["folder"]
    code, out, err = cli("batch", lot["truth"].manifest, "--scheduler", "local", "--workers", 2, "--out",
                         folder / "dask", "--spec", lot["spec"])
    assert code == lot["code"] and "local Dask cluster of 2 workers" in out, err
    a = lot["table"].sort_index()
    b = pq.read_table(folder / "dask" / "results.parquet").to_pandas().set_index("serial").sort_index()
    assert list(a.index) == list(b.index)
    for col in ("job", "order", "slot", "status", "exit_code", "verdict", "checks", "input_hash"):
        assert (a[col].fillna("-") == b[col].fillna("-")).all(), col
    messages = a.message.fillna("").str.replace("/out/units/", "/dask/units/")  # the unit's own result path
    assert (messages == b.message.fillna("")).all()
    np.testing.assert_array_equal(a[list(FIGURES)].to_numpy(float), b[list(FIGURES)].to_numpy(float))


@pytest.mark.slow
def test_a_lot_of_200_units_through_batch_and_lot_against_its_truth(tmp_path):
    lot = _run_lot(tmp_path)
    for check in (_check_the_batch_ran_every_unit_and_says_how_many_failed,
                  _check_every_good_unit_s_M_is_within_its_3_sigma_of_truth,
                  _check_out_of_spec_units_fail_the_spec_and_pass_fail_agrees_with_truth,
                  _check_cpk_and_yield_equal_a_direct_computation_from_the_truth,
                  _check_a_local_dask_cluster_gives_the_same_table):
        check(lot)
    for check in (_check_bad_units_are_reported_by_serial_with_the_single_command_s_message,
                  _check_lot_command_lists_failing_units_first_and_draws_the_report):
        check(lot, tmp_path / check.__name__)
    _check_the_example_spec_fails_exactly_the_bad_units(lot)
    _check_a_rerun_with_nothing_changed_runs_only_the_failed_units(lot)
