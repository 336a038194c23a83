"""Limits and verdicts where the work is done (issue 27): figures of merit judged against a limits file and the
default limits; exit 4 with the files written when a figure FAILs or is NOT USABLE.

Truth: hand-computed verdicts of figures whose value and 1-sigma are set here; the bundled alignment session
(examples/alignment, simulated with a known M, truth.json) for the commands; imu_tk's Xsens session (38 poses,
real) as a good accelerometer calibration.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from align.errors import InputError
from align.judge import DEFAULT_LIMITS, judge, verdict_line
from align.limits import limits_from_text
from align.merit import Figure
from align.vocab import Status

ROOT = Path(__file__).resolve().parents[2]
SESSION, PLAN = ROOT / "examples/alignment/session.csv", ROOT / "examples/alignment/plan.toml"
XSENS = ROOT.parent / "shared/data/multiposition/xsens_mti_imu_tk/xsens_acc.mat"
DEG = math.pi / 180


def _phi(value_deg: float, sigma_deg: float) -> Figure:
    return Figure("phi_xy", "gyroscope", value_deg * DEG, sigma_deg * DEG, "rad")


@pytest.mark.parametrize("value, sigma, status", [
    (0.05, 0.001, Status.PASS),        # 0.05 + 2 x 0.001 < 0.1: conformance shown
    (0.099, 0.001, Status.WARN),       # inside the limit, closer than 2 sigma
    (-0.0995, 0.001, Status.WARN),     # the lower side of |x| <= 0.1
    (0.1005, 0.001, Status.FAIL),      # outside
    (0.05, 2.0, Status.NOT_USABLE),    # 1-sigma above sigma_max = 1 deg (a default limit): not usable at any value
    (math.nan, 0.001, Status.NOT_CHECKED),
])
def test_a_figure_against_its_limit_guard_band_and_sigma_max(value, sigma, status):
    limits = limits_from_text('phi_xy = { abs_max = "0.1 deg" }', "l.toml")
    got = judge([_phi(value, sigma)], limits)[0]
    assert got.status == status, got
    assert "|phi_xy| <= 0.1 deg (l.toml)" in got.limit and "sigma(phi_xy) <= 1 deg (default limits)" in got.limit


def test_a_stated_guard_and_a_relative_scale_sigma():
    limits = limits_from_text('"scale_*" = { abs_max = "0.5 %", guard = "0.1 %", sigma_max = "0.05 %" }', "l.toml")
    f = Figure("scale_x", "gyroscope", 1.0045, 1e-5)
    assert judge([f], limits)[0].status == Status.WARN                  # 0.45 % is within 0.1 % of 0.5 %
    assert judge([Figure("scale_x", "gyroscope", 1.003, 1e-5)], limits)[0].status == Status.PASS
    # a scale in counts per unit: its 1-sigma is judged relative (0.06 % > 0.05 %), its value is not judged
    counts = judge([Figure("scale_x", "gyroscope", 7500.0, 4.5, "count")], limits)[0]
    assert counts.status == Status.NOT_USABLE and "0.06 %" in counts.detail
    assert judge([Figure("scale_x", "gyroscope", 7500.0, 1.5, "count")], limits)[0].status == Status.NOT_CHECKED


def test_the_defaults_judge_only_whether_a_figure_is_usable_and_say_so():
    assert not DEFAULT_LIMITS.limits and len(DEFAULT_LIMITS.usability) == 24
    fine, bad = judge([_phi(3.4, 0.01), _phi(3.4, 247.0)])
    assert fine.status == Status.PASS and bad.status == Status.NOT_USABLE
    assert verdict_line([fine, bad]) == "NOT USABLE: 1 NOT USABLE (gyroscope phi_xy)"
    # a bias in counts against an SI default: not checked, never passed
    counts = judge([Figure("bias_x", "accelerometer", 700.0, 20.0, "count")])[0]
    assert counts.status == Status.NOT_CHECKED
    # a figure no limit names stays INFO
    assert judge([Figure("arw_x", "gyroscope", 1e-4, 1e-6, "rad/sqrt(s)")])[0].status == Status.INFO


@pytest.mark.parametrize("text, words", [
    ('phi_xy = { guard = "1 deg" }', "give a bound (min, max, abs_max) or sigma_max"),
    ('phi_xy = { abs_max = "0.1 deg", guard = "-1 deg" }', "guard: must be >= 0"),
    ('phi_xy = { abs_max = "0.1 deg", sigma_max = "1 m/s^2" }', "of different dimensions"),
    ('phi_xy = { sigma = "0.1 deg" }', "unknown bound 'sigma'"),
])
def test_a_bad_limit_is_one_error_naming_the_key(text, words):
    with pytest.raises(InputError) as exc:
        limits_from_text(text, "l.toml")
    assert words in str(exc.value) and "l.toml" in str(exc.value)


def test_matrix_passes_a_good_session_and_fails_a_limit_with_the_files_written(run_cli, tmp_path):
    out = tmp_path / "a.json"
    res = run_cli("matrix", SESSION, "--plan", PLAN, "--json", out)
    assert res.code == 0 and "verdict: PASS: 18 figures within their limits (judged against default limits" in res.out
    truth = json.loads((ROOT / "examples/alignment/truth.json").read_text())
    merit = {f["name"]: f for f in json.loads(out.read_text())["figures_of_merit"]}
    m_true = np.array(truth["M"])
    phi_true = math.asin(m_true[0, 1] / np.linalg.norm(m_true[0]))
    assert abs(merit["phi_xy"]["value"] - phi_true) < 4 * merit["phi_xy"]["sigma"]   # the figure against its truth
    # a limit the unit does not meet: exit 4 naming figure, value, uncertainty and limit; the result still written
    limits = tmp_path / "limits.toml"
    limits.write_text('"phi_*" = { abs_max = "0.3 deg" }\n')
    out.unlink()
    res = run_cli("matrix", SESSION, "--plan", PLAN, "--json", out, "--limits", limits)
    assert res.code == 4 and out.exists()
    assert "FAIL: gyroscope phi_xy = -0.5406" in res.out and "outside |phi_xy| <= 0.3 deg" in res.out
    assert "+/- 0.00098 deg" in res.out and "figures of merit fail" in res.err and len(res.err.splitlines()) == 1
    saved = {f["name"]: f for f in json.loads(out.read_text())["figures_of_merit"]}
    assert saved["phi_xy"]["status"] == "FAIL" and saved["phi_yz"]["status"] == "PASS"


def test_the_verdicts_read_back_and_a_bad_limits_file_is_refused_before_the_log(tmp_path):
    import align.api as ia
    from align.results import load_result, save_result

    r = ia.matrix(log=str(SESSION), plan=str(PLAN))
    assert {f.status for f in r.verdicts} == {Status.PASS, Status.INFO} and all(f.test == "matrix" for f in r.verdicts)
    assert [f.name for f in r.verdicts if f.status == Status.INFO][:2] == ["M_xx", "M_xy"]   # no limit names them
    save_result(tmp_path / "r.json", r)
    back = load_result(tmp_path / "r.json")
    assert [(f.name, f.status, f.value) for f in back.verdicts] == [(f.name, f.status, f.value) for f in r.verdicts]
    (tmp_path / "bad.toml").write_text('phi_xy = { abs_max = "0.1 m" }\n')
    with pytest.raises(InputError) as exc:
        ia.matrix(log=str(tmp_path / "no-such-log.csv"), plan=str(PLAN), limits=str(tmp_path / "bad.toml"))
    assert "bad.toml" in str(exc.value) and "not a unit of phi_xy" in str(exc.value)


@pytest.mark.skipif(not XSENS.exists(), reason="../shared/data not beside the project")
def test_a_good_accelerometer_session_passes(run_cli):
    res = run_cli("calibrate", "accel", XSENS, "--columns", "col0,col1,col2,col3", "--accel-units", "counts",
                  "--gravity", "9.81744 m/s^2", "--init-static", "50 s")
    assert res.code == 0 and "verdict: PASS: 18 figures within their limits" in res.out, res.out[-500:]


def test_a_parts_datasheet_gives_limits_for_what_the_file_does_not_limit():
    text = 'part = "ADIS16485"\n"delta_xy" = { abs_max = "0.2 deg" }\n'
    limits = limits_from_text(text, "l.toml")
    deltas = {lim.figure: lim for lim in limits.limits if lim.figure.startswith("delta_")}
    assert deltas["delta_xy"].key == "delta_xy" and deltas["delta_xz"].key == "part ADIS16485: axis_to_axis"
    # ADIS16485: axis-to-axis 0.05 deg (align.parts), applied to the gyroscope
    assert deltas["delta_xz"].high == pytest.approx(0.05 * DEG) and deltas["delta_xz"].sensor == "gyroscope"
    f = judge([Figure("delta_xz", "gyroscope", 0.06 * DEG, 0.001 * DEG, "rad")], limits)[0]
    assert f.status == Status.FAIL and "(l.toml, part ADIS16485: axis_to_axis)" in f.limit
    with pytest.raises(InputError, match="l.toml: part"):
        limits_from_text('part = "NO-SUCH-PART"\n', "l.toml")


ADIS = ROOT.parent / "shared/data/static/adis16405_smac/adis_16405_imu1.csv.gz"


@pytest.mark.skipif(not ADIS.exists(), reason="../shared/data not beside the project")
def test_allan_judges_n_against_the_datasheet_of_its_part(run_cli, tmp_path):
    """A real ADIS16405 run (N about 2.2 deg/sqrt(h)) against its datasheet's noise density, 0.05 deg/s/sqrt(Hz)
    (N = 3 deg/sqrt(h)): PASS; against a limit of 1 deg/sqrt(h): FAIL, exit 4, the result written."""
    limits, out = tmp_path / "limits.toml", tmp_path / "allan.json"
    limits.write_text('part = "ADIS16405"\n')
    args = ("allan", ADIS, "--columns", "gyro_x_dps,gyro_y_dps,gyro_z_dps", "--rate-hz", "100", "--json", out)
    res = run_cli(*args, "--limits", limits)
    assert res.code == 0 and "verdict: PASS: 3 figures within their limits" in res.out, res.out[-400:]
    merit = {f["name"]: f for f in json.loads(out.read_text())["figures_of_merit"]}
    assert "(" + str(limits) + ", part ADIS16405: noise_density)" in merit["arw_x"]["limit"]
    limits.write_text('"arw_?" = { max = "1 deg/sqrt(h)" }\n')
    res = run_cli(*args, "--limits", limits)
    assert res.code == 4 and "FAIL: gyroscope arw_x = 2." in res.out and out.exists()
