"""imu-align report from any subset of results: a rate-table log alone and a calibration alone render in headless
Chromium with every picture decoding; a measured misalignment over the allowance is FAIL at the top and exit 4;
the summary's numbers are the underlying results' (read from the other commands' JSON)."""

import base64
import io
import json
import re
import shutil

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from support import ROOT, SHARED, in_chromium, write_session

from align.alignment.plan import Plan
from align.alignment.simulate import SessionSpec, simulate_session
from align.model import SensorModel
from align.units import DEG
from align.units import parse_quantity as q

MOUNT = ROOT / "examples" / "budget" / "example1.toml"
MANOEUVRE = ROOT / "examples" / "sensitivity" / "example2.toml"
MAG = SHARED / "data" / "magnetometer" / "hmc5883l_sunsided" / "hmc5883l_compass.csv"
FERRARIS = SHARED / "data" / "multiposition" / "imucal_ferraris"
#: Example 2's manoeuvre with the x gyro held within 1/6 deg: phi_xz <= asin((1/6) / 30) = 0.3184 deg
TIGHT = '[[rotation]]\naxis = "z"\nangle = "30 deg"\n\n[limits]\nx = "0.1667 deg"\ny = "1 deg"\nz = "1 deg"\n'


def session(folder, rotvec_deg=(0.05, -0.42, 0.1), seed=0):
    """A six-dwell session of an IMU turned by ``rotvec_deg`` (phi_xz = 0.42 deg for the default)."""
    truth = SensorModel.from_rotation(Rotation.from_rotvec(np.array(rotvec_deg) * DEG), bias=np.array([0.1, -0.2, 0.05]) * DEG)
    plan = Plan.standard_rate(100 * DEG)
    t, g, _ = simulate_session(plan, truth, SessionSpec(noise_density=q("0.3 deg/sqrt(h)", "angle_random_walk")), seed)
    return truth, *write_session(folder, t, g, plan)


def pictures(page: str) -> list:
    """Every embedded picture, decoded (PIL)."""
    from PIL import Image

    out = []
    for data in re.findall(r'src="data:image/png;base64,([^"]+)"', page):
        img = Image.open(io.BytesIO(base64.b64decode(data)))
        img.load()
        assert img.size[0] > 300 and img.size[1] > 200
        out.append(img)
    return out


def sections(page: str) -> list[str]:
    return re.findall(r"<h2>(.*?)</h2>", page)


browser = pytest.mark.skipif(shutil.which("chromium") is None, reason="Chromium not installed (CI installs it)")


@browser
@pytest.mark.slow
def test_report_of_a_rate_table_log_alone_renders(tmp_path, run_cli):
    _, log, plan = session(tmp_path)
    out = tmp_path / "report.html"
    res = run_cli("report", "--log", log, "--plan", plan, "--out", out, "--serial", "SN 0042", "--operator", "A. Tester",
                  "--test-id", "WO-7", "--title", "Acceptance of SN 0042")
    assert res.code == 0, res.err
    page = out.read_text()
    assert sections(page)[0] == "Summary" and sections(page)[-1] == "Inputs"
    assert "Mounting-misalignment budget" not in sections(page)  # no mount given: no budget
    for text in ("SN 0042", "A. Tester", "WO-7", "Acceptance of SN 0042", "imu-align 0.", "<td>date</td>"):
        assert text in page
    assert "phi (cross-axis)" in page and "mounting rotation" in page and "delta_ij = asin(u_i . u_j)" in page
    assert len(pictures(page)) == 1  # the segmentation of the log
    from PIL import Image

    shot = tmp_path / "shot.png"
    assert in_chromium(out, tmp_path, shot) == "images 1 broken 0"
    assert np.asarray(Image.open(shot).convert("L")).std() > 10


@browser
@pytest.mark.slow
def test_report_of_calibrations_alone_renders(tmp_path, run_cli):
    mag, fer = tmp_path / "mag.json", tmp_path / "ferraris.json"
    assert run_cli("calibrate", "mag", MAG, "--columns", "mag_x_gauss,mag_y_gauss,mag_z_gauss", "--mag-units", "gauss",
                   "--json", mag).code == 0
    assert run_cli("calibrate", "ferraris", FERRARIS / "example_ferraris_session.csv", "--sections",
                   FERRARIS / "example_ferraris_session_list.json", "--rate-hz", "102.4", "--json", fer).code == 0
    out = tmp_path / "cal.html"
    res = run_cli("report", "--calibration", mag, "--calibration", fer, "--out", out)
    assert res.code == 0, res.err
    page = out.read_text()
    assert sections(page)[0] == "Summary" and '<p class="banner pass">PASS: all 2 checks passed.</p>' in page
    assert "figures of merit (calibration ferraris)" in page and "figures of merit (calibration mag)" in page
    assert [s for s in sections(page) if s.startswith("Calibration")] == [
        f"Calibration: magnetometer ({mag})", f"Calibration: accelerometer ({fer})", f"Calibration: gyroscope ({fer})"]
    assert len(pictures(page)) == 1  # the magnetometer's capture, read again from the file the result names
    assert in_chromium(out, tmp_path) == "images 1 broken 0"
    # the summary's numbers are the calibrations' own
    d = json.loads(mag.read_text())
    assert f"heading error {d['quality']['predicted_heading_error_deg']:.3f} deg" in page
    g = json.loads(fer.read_text())["gyroscope"]
    worst = max(abs(v) for r in g["residuals"].values() for v in r)
    assert f"largest residual {worst:.3g} deg/s" in page


@pytest.mark.slow
def test_measured_misalignment_over_the_allowance_fails_at_the_top_and_exits_4(tmp_path, run_cli):
    truth, log, plan = session(tmp_path)
    man = tmp_path / "tight.toml"
    man.write_text(TIGHT)
    align_json = tmp_path / "alignment.json"
    assert run_cli("matrix", log, "--plan", plan, "--json", align_json).code == 0
    out = tmp_path / "report.html"
    res = run_cli("report", "--log", log, "--plan", plan, "--manoeuvre", man, "--out", out)
    assert res.code == 4 and out.exists()  # written, then the failure is the exit status (as check)
    assert "measured misalignment vs allowance" in res.err and "output x" in res.err
    page = out.read_text()
    assert sections(page)[:2] == ["Summary", "Measured misalignment against the allowance"]
    summary = page.split("<h2>Summary</h2>")[1].split("<h2>")[0]
    assert summary.startswith('<p class="banner fail">FAIL: 1 of 3 checks failed (measured misalignment vs allowance)')
    assert "figures of merit (alignment)" in summary                   # the third: judged by the default limits
    # the number behind it: one turn of 30 deg about z gives the x gyro sin(phi_xz) 30 deg (Eq 11-13 for a fixed axis,
    # exact), phi_xz the alignment result's (matrix --json), against the 1/6 deg limit
    d = json.loads(align_json.read_text())
    phi = d["angles"]["phi_deg"]["phi_xz"]
    assert abs(phi - 0.42) < 0.01  # the simulation's truth, to first order
    error = np.sin(np.radians(phi)) * 30
    shown = float(re.search(r"output x margin ([-+0-9.]+) deg", summary).group(1))
    assert shown == pytest.approx(0.1667 - error, abs=1e-4)
    assert f"error {error:.4f} ±" in summary and "against the 0.1667 deg limit" in summary
    assert "guard band 2 sigma" in summary and "Guard band k = 2" in page
    assert f"summary: FAIL (measured misalignment vs allowance: output x margin {shown:+.4f} deg)" in res.out
    # the diagnosis: phi_xz alone over its allowance asin((1/6 deg) / 30 deg)
    allowed = np.degrees(np.arcsin(0.1667 / 30))
    assert f"<td class=\"l\">phi_xz</td><td class=\"\">{phi:+.4f}</td>" in page and f"{allowed:.4f}" in page
    # the same from the result file, without the log: same numbers, same verdict, the log drawn again from its path
    again = tmp_path / "again.html"
    res2 = run_cli("report", "--alignment", align_json, "--manoeuvre", man, "--out", again)
    assert res2.code == 4
    assert f"output x margin {shown:+.4f} deg" in again.read_text()
    assert len(pictures(again.read_text())) == 1


def test_budget_and_noise_numbers_are_the_underlying_results(tmp_path, run_cli):
    _, log, plan = session(tmp_path, (0.1, -0.1, 0.2))
    check_json, allan_json = tmp_path / "check.json", tmp_path / "allan.json"
    assert run_cli("check", MOUNT, MANOEUVRE, "--json", check_json).code == 0
    from align.noise.sim import NoiseSpec, simulate_noise
    from align.units import to_unit

    static = tmp_path / "static.npy"  # 10 min at 100 Hz of an ADIS16485's datasheet noise
    np.save(static, to_unit(simulate_noise(60_000, 100.0, NoiseSpec(white=q("0.3 deg/sqrt(h)", "angle_random_walk"),
                                                                    flicker=q("6.25 deg/h", "angular_rate")), 3, 0), "deg/s"))
    assert run_cli("allan", static, "--rate-hz", "100", "--json", allan_json).code == 0
    out = tmp_path / "r.html"
    res = run_cli("report", "--mount", MOUNT, "--manoeuvre", MANOEUVRE, "--log", log, "--plan", plan,
                  "--allan", allan_json, "--monte-carlo", "0", "--out", out)
    assert res.code == 0, res.err
    page = out.read_text()
    rows = json.loads(check_json.read_text())["elements"]
    worst = min((r for r in rows if r["allowed_deg"] is not None), key=lambda r: r["margin_deg"])
    assert f"{worst['element']} margin {worst['margin_deg']:+.4f} deg" in page
    fit = json.loads(allan_json.read_text())["fit"]
    n = {k: f["ieee_point_readouts"]["N_at_tau_1s"] for k, f in fit.items()}
    k = max(n, key=n.get)
    assert f"{n[k]:.4g} deg/sqrt(h) ({k})" in page
    assert "bias repeatability" in page and "not measured" in page and "bias stability: std of the 10 s means" in page
    assert "Example 1" not in res.out and "source total 1.3043 deg" in res.out  # the budget's own figure, no aside


def test_budget_line_states_the_mount_own_total(tmp_path, run_cli):
    mount = tmp_path / "mount.toml"
    mount.write_text(MOUNT.read_text().replace('height_tolerance = "0.2 mm"', 'height_tolerance = "0.05 mm"')
                     .replace('hole_diameter = "2.85 mm"', 'hole_diameter = "2.2 mm"'))
    bj = tmp_path / "b.json"
    assert run_cli("budget", mount, "--json", bj).code == 0
    res = run_cli("report", "--mount", mount, "--monte-carlo", "0", "--out", tmp_path / "r.html")
    assert res.code == 0, res.err
    total = json.loads(bj.read_text())["total_deg"]
    assert f"budget: source total {total:.4f} deg" in res.out and "Example 1" not in res.out and "1.3043" not in res.out


def test_report_input_errors(tmp_path, run_cli):
    out = tmp_path / "r.html"
    res = run_cli("report", "--out", out)
    assert res.code == 2 and "nothing to report" in res.err and "--calibration" in res.err and not out.exists()
    _, log, plan = session(tmp_path)
    res = run_cli("report", "--log", log, "--out", out)
    assert res.code == 2 and "--plan" in res.err
    aj = tmp_path / "a.json"
    assert run_cli("matrix", log, "--plan", plan, "--json", aj).code == 0
    res = run_cli("report", "--log", log, "--plan", plan, "--alignment", aj, "--out", out)
    assert res.code == 2 and "--alignment" in res.err and not out.exists()
    res = run_cli("report", "--calibration", aj, "--out", out)  # an alignment is not a calibration
    assert res.code == 2 and "imu-align.calibration" in res.err and not out.exists()


@pytest.mark.slow
def test_apply_plot_and_all_or_none(tmp_path, run_cli, monkeypatch):
    _, log, plan = session(tmp_path)
    aj = tmp_path / "a.json"
    assert run_cli("matrix", log, "--plan", plan, "--json", aj).code == 0
    png, csv = tmp_path / "traces.png", tmp_path / "out.csv"
    assert run_cli("apply", log, "--alignment", aj, "--out", csv, "--plot", png).code == 0
    from PIL import Image

    assert Image.open(png).size[0] > 600 and csv.exists()
    import align.present.calplots
    from align.errors import InputError

    def boom(*a, **k):
        raise InputError("cannot draw (a failure injected by the test)", "test")

    monkeypatch.setattr(align.present.calplots, "apply_traces_png", boom)
    png2, csv2 = tmp_path / "t2.png", tmp_path / "o2.csv"
    res = run_cli("apply", log, "--alignment", aj, "--out", csv2, "--plot", png2)
    assert res.code == 2 and "injected" in res.err
    assert not png2.exists() and not csv2.exists()  # all or none: the CSV is not written without its picture


@pytest.mark.slow
def test_drift_section_and_its_number(tmp_path, run_cli):
    """Issue 16's error growth (align.present.navigation) in the report: its section before the inputs, its picture,
    and the summary's number the drift result's own (horizontal position 1-sigma at the end)."""
    _, log, plan = session(tmp_path)
    aj, dj = tmp_path / "a.json", tmp_path / "drift.json"
    assert run_cli("matrix", log, "--plan", plan, "--json", aj).code == 0
    res = run_cli("drift", "--duration", "1 min", "--alignment", aj, "--imu", "ADIS16485", "--runs", "50", "--json", dj)
    assert res.code == 0, res.err
    out = tmp_path / "r.html"
    res = run_cli("report", "--drift", dj, "--out", out)
    assert res.code == 0, res.err
    page = out.read_text()
    assert sections(page)[0] == "Summary" and sections(page)[-1] == "Inputs" and len(pictures(page)) == 1
    d = json.loads(dj.read_text())["position_m"]
    horizontal = np.hypot(d["north"]["sigma"][-1], d["east"]["sigma"][-1])
    assert f"horizontal position {horizontal:.4g} m (1 sigma)" in page
    res = run_cli("report", "--drift", aj, "--out", tmp_path / "no.html")  # an alignment is not a drift result
    assert res.code == 2 and "imu-align.drift" in res.err
