"""imu-align report and the files results name: never overwritten; read again as recorded (format, folder); the
log's own column options; the parts file read only when a part is looked up; the measured misalignment verdict
from the manoeuvre's own propagation (the review of issue 14, bugs 1-5, 9, 12); a failed design check governs
only without a measurement."""

import json
import re

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from support import ROOT, write_session

from align.alignment.plan import Plan
from align.alignment.simulate import SessionSpec, simulate_session
from align.model import SensorModel
from align.sensitivity.symbolic import matrix_from_angles
from align.units import DEG
from align.units import parse_quantity as q

MOUNT = ROOT / "examples" / "budget" / "example1.toml"
TWO = '[[rotation]]\naxis = "y"\nangle = "60 deg"\n\n[[rotation]]\naxis = "z"\nangle = "60 deg"\n\n[limits]\nx = "{} deg"\n'
TIGHT = '[[rotation]]\naxis = "z"\nangle = "30 deg"\n\n[limits]\nx = "0.1667 deg"\ny = "1 deg"\nz = "1 deg"\n'


def session(folder, m=None, seed=0):
    """A six-dwell session of a unit with response ``m`` (default: turned 0.05 deg about x, y and z)."""
    truth = (SensorModel(np.asarray(m, float), np.array([0.1, -0.2, 0.05]) * DEG) if m is not None else
             SensorModel.from_rotation(Rotation.from_rotvec(np.full(3, 0.05 * DEG))))
    plan = Plan.standard_rate(100 * DEG)
    t, g, _ = simulate_session(plan, truth, SessionSpec(noise_density=q("0.3 deg/sqrt(h)", "angle_random_walk")), seed)
    folder.mkdir(exist_ok=True)
    return write_session(folder, t, g, plan)


def _x_error(d):
    """The reviewer's manoeuvre (y 60 deg, then z 60 deg, body frame) by scipy's rotations: the largest |x| of
    rotvec(measured) - rotvec(true) after each turn, the gyros reading ``d`` (unit rows) times each increment."""
    d = d / np.linalg.norm(d, axis=1, keepdims=True)
    true, meas, worst = Rotation.identity(), Rotation.identity(), 0.0
    for theta in (np.array([0, 60 * DEG, 0]), np.array([0, 0, 60 * DEG])):
        true, meas = true * Rotation.from_rotvec(theta), meas * Rotation.from_rotvec(d @ theta)
        worst = max(worst, abs((meas.as_rotvec() - true.as_rotvec())[0]))
    return worst


@pytest.mark.slow
def test_the_reviewers_unit_fails_the_manoeuvre_and_exits_4(tmp_path, run_cli):
    """phi_xy 0.085 deg and phi_xz 0.095 deg, each within its allowance alone, give the x gyro 0.170 deg over a
    0.1 deg limit."""
    log, plan = session(tmp_path, matrix_from_angles({"phi_xy": 0.085 * DEG, "phi_xz": 0.095 * DEG}))
    man, aj, out = tmp_path / "two.toml", tmp_path / "a.json", tmp_path / "r.html"
    man.write_text(TWO.format(0.1))
    assert run_cli("matrix", log, "--plan", plan, "--json", aj).code == 0
    res = run_cli("report", "--alignment", aj, "--manoeuvre", man, "--out", out)
    assert res.code == 4 and "measured misalignment vs allowance failed (output x" in res.err
    m = np.array(json.loads(aj.read_text())["M"])
    error = _x_error(m) / DEG
    assert error == pytest.approx(0.170, abs=0.003)
    got = re.search(r"measured vs allowance: FAIL \(output x: error ([0-9.]+) ± ([0-9.]+) deg", res.out)
    assert float(got.group(1)) == pytest.approx(error, abs=1e-4) and 0 < float(got.group(2)) < 0.01
    page = out.read_text()
    assert page.split("<h2>Summary</h2>")[1].startswith('<p class="banner fail">FAIL')
    for element in ("phi_xy", "phi_xz"):  # the diagnosis: each alone passes
        assert re.search(rf'<td class="l">{element}</td>(<td class="">[^<]*</td>){{5}}<td class="pass">PASS', page)


@pytest.mark.slow
def test_within_the_guard_band_is_warn_and_counted(tmp_path, run_cli):
    """A limit equal to the unit's own error (computed here by scipy): margin 0, inside +-2 sigma: WARN, exit 0."""
    log, plan = session(tmp_path, matrix_from_angles({"phi_xy": 0.04 * DEG, "phi_xz": 0.03 * DEG}))
    aj, man, out = tmp_path / "a.json", tmp_path / "two.toml", tmp_path / "r.html"
    assert run_cli("matrix", log, "--plan", plan, "--json", aj).code == 0
    man.write_text(TWO.format(f"{_x_error(np.array(json.loads(aj.read_text())['M'])) / DEG:.7f}"))
    res = run_cli("report", "--alignment", aj, "--manoeuvre", man, "--out", out)
    assert res.code == 0, res.err
    assert "measured vs allowance: WARN" in res.out and "summary: WARN (measured misalignment vs allowance" in res.out
    page = out.read_text()
    assert '<p class="banner warn">WARN: none of 3 checks failed; 1 WARN (measured misalignment vs allowance)' in page
    assert "Guard band k = 2" in page


@pytest.mark.slow
def test_a_failed_budget_is_a_design_check_when_the_unit_is_measured(tmp_path, run_cli):
    """Example 1's mount (1.3 deg) fails a 1/6 deg manoeuvre; a unit measured within it passes: exit 0, the budget
    labelled a design check. Without the measurement the budget governs: exit 4."""
    log, plan = session(tmp_path)
    man = tmp_path / "tight.toml"
    man.write_text(TIGHT)
    out = tmp_path / "r.html"
    res = run_cli("report", "--mount", MOUNT, "--manoeuvre", man, "--log", log, "--plan", plan, "--monte-carlo", "0",
                  "--out", out)
    assert res.code == 0, res.err
    assert "design check mounting budget (rss) vs allowance FAIL" in res.out and "the measured unit governs" in res.out
    page = out.read_text()
    assert "FAIL (design check)" in page and "the measurement governs" in page
    res = run_cli("report", "--mount", MOUNT, "--manoeuvre", man, "--monte-carlo", "0", "--out", out)
    assert res.code == 4 and "mounting budget (rss) vs allowance failed" in res.err


@pytest.mark.parametrize("which", ["log", "plan"])
def test_out_may_not_be_a_file_the_result_names(tmp_path, run_cli, which):
    log, plan = session(tmp_path / "s")
    aj = tmp_path / "a.json"
    assert run_cli("matrix", log, "--plan", plan, "--json", aj).code == 0
    target = {"log": log, "plan": plan}[which]
    before = target.read_bytes()
    res = run_cli("report", "--alignment", aj, "--out", target)
    assert res.code == 2 and f"--out: {target} is a data file a.json names" in res.err
    assert target.read_bytes() == before


def test_out_may_not_be_the_capture_or_recording_a_result_names(tmp_path, run_cli):
    from align.io import write_csv

    rng = np.random.default_rng(0)
    static = tmp_path / "static.csv"
    write_csv(static, ["gyro_x", "gyro_y", "gyro_z"], rng.normal(0, 0.01, (6000, 3)))
    al = tmp_path / "al.json"
    assert run_cli("allan", static, "--rate-hz", "100", "--json", al).code == 0
    before = static.read_bytes()
    res = run_cli("report", "--allan", al, "--out", static)
    assert res.code == 2 and "is a data file al.json names" in res.err and static.read_bytes() == before


@pytest.mark.slow
def test_redrawn_as_recorded_and_found_beside_the_result(tmp_path, run_cli, monkeypatch):
    """A log read with a preamble and ';' (matrix --skip-rows 2 --delimiter ';', run in its own folder with relative
    paths): the report from another folder draws it again with no format option; a wrong option given says why in
    the terminal in the command line's spelling."""
    log, plan = session(tmp_path / "mv")
    text = log.read_text().replace(",", ";")
    (tmp_path / "mv" / "pre.csv").write_text("# logger v1\n# rate 200\n" + text)
    monkeypatch.chdir(tmp_path / "mv")
    assert run_cli("matrix", "pre.csv", "--plan", "plan.toml", "--skip-rows", "2", "--delimiter", ";", "--json",
                   "a.json").code == 0
    monkeypatch.chdir(tmp_path)
    before = (tmp_path / "mv" / "pre.csv").read_bytes()  # named relative to the result's folder: refused too
    res = run_cli("report", "--alignment", "mv/a.json", "--out", "mv/pre.csv")
    assert res.code == 2 and "a.json names" in res.err and (tmp_path / "mv" / "pre.csv").read_bytes() == before
    res = run_cli("report", "--alignment", "mv/a.json", "--out", "r.html")
    assert res.code == 0, res.err
    page = (tmp_path / "r.html").read_text()
    assert page.count("data:image/png") == 1 and "no segmentation picture" not in page + res.out
    res = run_cli("report", "--alignment", "mv/a.json", "--out", "r2.html", "--delimiter", ",")
    assert res.code == 0, res.err
    line = next(x for x in res.out.splitlines() if "no segmentation picture" in x)
    assert "--comment '#'" in line and "comment='" not in line and "{" not in line
    assert "give comment = #" in (tmp_path / "r2.html").read_text()


@pytest.mark.slow
def test_a_log_with_its_own_column_names_and_no_time(tmp_path, run_cli):
    log, plan = session(tmp_path)
    rows = np.loadtxt(log, delimiter=",", skiprows=1)
    renamed, notime = tmp_path / "renamed.csv", tmp_path / "notime.csv"
    np.savetxt(renamed, rows, delimiter=",", header="t,gx,gy,gz", comments="")
    np.savetxt(notime, rows[:, 1:], delimiter=",", header="gx,gy,gz", comments="")
    out = tmp_path / "r.html"
    res = run_cli("report", "--log", renamed, "--plan", plan, "--out", out)
    assert res.code == 2 and "--gyro-columns" in res.err and "--columns" not in res.err.replace("--gyro-columns", "")
    base = run_cli("report", "--log", log, "--plan", plan, "--out", out).out.splitlines()[0]
    res = run_cli("report", "--log", renamed, "--plan", plan, "--gyro-columns", "t,gx,gy,gz", "--out", out)
    assert res.code == 0 and res.out.splitlines()[0] == base  # the same alignment as from the usual names
    res = run_cli("report", "--log", notime, "--plan", plan, "--gyro-columns", "gx,gy,gz", "--out", out)
    assert res.code == 2 and "--log-rate-hz" in res.err
    rate = 1 / np.median(np.diff(rows[:, 0]))
    res = run_cli("report", "--log", notime, "--plan", plan, "--gyro-columns", "gx,gy,gz", "--log-rate-hz", f"{rate:.6f}",
                  "--out", out)
    assert res.code == 0 and res.out.splitlines()[0] == base


@pytest.mark.slow
def test_the_parts_file_is_read_only_when_a_part_is_looked_up(tmp_path, run_cli, monkeypatch):
    bad = tmp_path / "bad.toml"
    bad.write_text("[X]\nnot_a_field = 1\n")
    monkeypatch.setenv("IMU_ALIGN_PARTS", str(bad))
    log, plan = session(tmp_path)
    out = tmp_path / "r.html"
    assert run_cli("report", "--log", log, "--plan", plan, "--out", out).code == 0
    res = run_cli("report", "--mount", MOUNT, "--monte-carlo", "0", "--out", out)  # Example 1 names the ADIS16485
    assert res.code == 2 and "IMU_ALIGN_PARTS" in res.err
