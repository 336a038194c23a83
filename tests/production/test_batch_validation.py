"""A batch pairs each unit's calibration with its validation run (issue 27, "verify after apply"): the unit's result
is replayed on a rate-table session it was not fitted to (``imu-align verify``), in the same batch.

Truth from the simulator: each unit's validation session is simulated again from the unit's true ``M`` and bias
(truth.csv) with noise of its own; a unit paired with another unit's session is a deliberately wrong calibration.
"""

from __future__ import annotations

import csv

import numpy as np
import pytest

from align.alignment.simulate import SensorModel, SessionSpec, simulate_run
from align.errors import InputError
from align.production import latest_rows, read_manifest, read_table, simulate_lot
from align.production.rehearsal import lot_plan
from align.units import DEG, DEG_S

SPEC = SessionSpec(fs=200.0, dwell_s=2.0, static_s=1.0)


def _truth(lot, serial: str) -> dict:
    return next(r for r in csv.DictReader(line for line in open(lot.truth) if not line.startswith("#"))
                if r["serial"] == serial)


def _true_m(lot, serial: str) -> np.ndarray:
    t = _truth(lot, serial)
    return np.array([[float(t[f"M_{a}{b}"]) for b in "xyz"] for a in "xyz"])


def _validation_session(lot, serial: str, seed: int):
    """A second session of ``serial``'s true sensor (truth.csv), written as the lot's sessions are (deg/s)."""
    bias = np.array([float(_truth(lot, serial)[f"bias_{a}"]) for a in "xyz"])
    run = simulate_run(lot_plan(), SensorModel(_true_m(lot, serial), bias), SPEC, np.random.default_rng(seed))
    path = lot.folder / "validation" / f"{serial}.csv"
    path.parent.mkdir(exist_ok=True)
    g = run.g / DEG_S
    path.write_text('"time","gyro_x","gyro_y","gyro_z"\n'
                    + "".join(",".join(map(repr, map(float, (a, *row)))) + "\n" for a, row in zip(run.t, g)))
    return path


@pytest.fixture
def lot(tmp_path):
    lot = simulate_lot(tmp_path / "lot", 3, session=SPEC, bad=0, seed=5)
    for k, serial in enumerate(("SN0001", "SN0002", "SN0003")):
        _validation_session(lot, serial, 100 + k)
    return lot


@pytest.mark.slow
def test_a_right_calibration_passes_its_validation_and_a_wrong_one_fails(lot, run_cli):
    manifest = lot.folder / "checked.csv"
    manifest.write_text("serial,job,log,plan,validation,validation_options\n"
                        "SN0001,matrix,sessions/SN0001.csv,plan.toml,validation/SN0001.csv,\n"
                        # SN0002's calibration replayed on SN0003's sensor: the wrong calibration
                        "SN0002,matrix,sessions/SN0002.csv,plan.toml,validation/SN0003.csv,--tolerance-angle '0.05 deg'\n"
                        "SN0003,matrix,sessions/SN0003.csv,plan.toml,,\n")
    out = lot.folder / "out"
    res = run_cli("batch", manifest, "--out", out, "--workers", 2)
    assert res.code == 4, res.err + res.out  # a unit outside its limits: its validation failed
    rows = {(r["serial"], r["job"]): r for r in latest_rows(read_table(out / "results.parquet"))}
    good, wrong = rows[("SN0001", "verify matrix")], rows[("SN0002", "verify matrix")]
    assert good["verdict"] in ("pass", "warn") and wrong["verdict"] == "fail"
    # the residual: the right calibration's within its noise, the wrong one's the two sensors' difference
    phis = [f"residual_phi_{p}" for p in ("xy", "xz", "yx", "yz", "zx", "zy")]
    assert max(abs(good[p]) for p in phis) < 0.02 * DEG and "FAIL" in wrong["message"]
    # SN0002's correction on SN0003's sensor: M_res = M_2^-1 M_3, its rows' norms - 1 the residual scales
    m2, m3 = _true_m(lot, "SN0002"), _true_m(lot, "SN0003")
    scales = np.linalg.norm(np.linalg.solve(m2, m3), axis=1) - 1
    for a, want in zip("xyz", scales):
        assert wrong[f"residual_scale_{a}"] == pytest.approx(want, abs=2e-4), (a, wrong[f"residual_scale_{a}"], want)
    assert max(abs(good[f"residual_scale_{a}"]) for a in "xyz") < 2e-4
    assert ("SN0003", "verify matrix") not in rows and rows[("SN0003", "matrix")]["status"] == "ok"
    assert (out / "units" / "SN0001.matrix.verify.json").exists() and "SN0002" in res.out
    # a rerun skips every unit, its validation rows and verdicts still counted (a FAIL of a result's own figures of
    # merit stays a FAIL when judged again)
    again = run_cli("batch", manifest, "--out", out, "--workers", 1)
    assert again.code == 4 and "ran 0, skipped 3" in again.out
    # a changed validation session reruns its unit (the validation run's files enter the content hash)
    (lot.folder / "validation" / "SN0003.csv").write_text((lot.folder / "validation" / "SN0001.csv").read_text())
    third = run_cli("batch", manifest, "--out", out, "--workers", 1)
    assert "ran 1, skipped 2" in third.out, third.out


@pytest.mark.parametrize("row, words", [
    ("SN0001,calibrate accel,sessions/SN0001.csv,,validation/SN0001.csv,,", "column validation: the calibrate accel"),
    ("SN0001,matrix,sessions/SN0001.csv,plan.toml,,plan.toml,", "column validation: empty, while validation_plan"),
    ("SN0001,calibrate gyro,sessions/SN0001.csv,,validation/SN0001.csv,,", "column validation_plan: empty"),
])
def test_a_validation_that_cannot_be_run_is_refused_naming_the_row(lot, row, words):
    manifest = lot.folder / "m.csv"
    manifest.write_text("serial,job,log,plan,validation,validation_plan,validation_options\n" + row + "\n")
    jobs = {"matrix": "required", "calibrate accel": "optional", "calibrate gyro": "none"}
    with pytest.raises(InputError, match=f"line 2, {words}"):
        read_manifest(manifest, jobs)


@pytest.mark.slow
def test_verify_s_own_refusals_before_any_unit_runs(lot, run_cli):
    manifest = lot.folder / "m.csv"
    manifest.write_text("serial,job,log,plan,validation,validation_options\n"
                        "SN0001,matrix,sessions/SN0001.csv,plan.toml,validation/SN0001.csv,--tolerance-angel 1\n")
    res = run_cli("batch", manifest, "--out", lot.folder / "o", "--workers", 1)
    assert res.code == 2 and "line 2, column validation_options: verify has no option --tolerance-angel" in res.err
    assert not (lot.folder / "o").exists()
    # the session the unit is fitted on is no validation: verify's refusal, recorded against the unit
    manifest.write_text("serial,job,log,plan,validation\nSN0001,matrix,sessions/SN0001.csv,plan.toml,"
                        "sessions/SN0001.csv\n")
    res = run_cli("batch", manifest, "--out", lot.folder / "o", "--workers", 1)
    (row,) = [r for r in latest_rows(read_table(lot.folder / "o" / "results.parquet")) if r["job"] == "verify matrix"]
    assert res.code == 3 and row["status"] == "failed" and "fitted on" in row["message"]
