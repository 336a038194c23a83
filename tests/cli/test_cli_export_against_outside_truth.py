"""Review 14's export findings, each checked against a truth outside the writer: a compiled C program run on
simulated readings of known truth, Kalibr's own source, imucal's own calibrate(), the bytes of an input file."""

import hashlib
import json
import re
import shutil
import subprocess

import numpy as np
import pandas as pd
import pytest
import yaml
from support import ROOT, SHARED

from align.calibration import Calibration, CalibrationSet
from align.noise.sim import NoiseSpec, simulate_noise
from align.results import save_result
from align.units import DEG

CC = shutil.which("cc")
needs_cc = pytest.mark.skipif(CC is None, reason="no C compiler (cc) on this machine")
FERRARIS = SHARED / "data" / "multiposition" / "imucal_ferraris"
HMC = SHARED / "data" / "magnetometer" / "hmc5883l_sunsided" / "hmc5883l_compass.csv"
SESSION, PLAN = ROOT / "examples" / "alignment" / "session.csv", ROOT / "examples" / "alignment" / "plan.toml"


def _one_line(res, *words):
    assert res.code == 2, (res.out, res.err)
    lines = res.err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in res.err, res.err
    for w in words:
        assert w in lines[0], (w, lines[0])


def _md5(path) -> str:
    return hashlib.md5(path.read_bytes()).hexdigest()


# ---------------------------------------------------------------- bug 1: an --out that a result names

def test_export_refuses_to_overwrite_a_data_file_the_result_names(run_cli, tmp_path):
    capture = tmp_path / "c.csv"
    shutil.copyfile(HMC, capture)
    res = run_cli("calibrate", "mag", capture, "--columns", "mag_x_gauss,mag_y_gauss,mag_z_gauss", "--mag-units", "gauss",
                  "--json", tmp_path / "m.json")
    assert res.code == 0, res.err
    before = _md5(capture)
    for to in ("csv", "c"):
        _one_line(run_cli("export", tmp_path / "m.json", "--to", to, "--out", capture), "--out", "m.json")
        assert _md5(capture) == before
    res = run_cli("matrix", SESSION, "--plan", PLAN, "--json", tmp_path / "a.json")
    assert res.code == 0, res.err
    plan = tmp_path / "plan.toml"
    plan.write_bytes(PLAN.read_bytes())
    for named in (SESSION, PLAN):
        sums = _md5(named)
        _one_line(run_cli("export", tmp_path / "a.json", "--to", "csv", "--out", named), "--out", "a.json")
        assert _md5(named) == sums


# ---------------------------------------------------------------- bug 6: the unit of the corrected values

def _run_c(folder, header: str, body: str) -> np.ndarray:
    (folder / "cal.h").write_text(header)
    (folder / "main.c").write_text('#include <stdio.h>\n#include "cal.h"\nint main(void) {\n' + body + "\n  return 0;\n}\n")
    subprocess.run([CC, "-std=c99", "-Wall", "-Wextra", "-Werror", "main.c", "-o", "main"], cwd=folder, check=True,
                   capture_output=True)
    out = subprocess.run([str(folder / "main")], check=True, capture_output=True, text=True).stdout
    return np.array([[float(v) for v in line.split()] for line in out.splitlines()])


def _correct_in_c(folder, header: str, prefix: str, raw: np.ndarray) -> np.ndarray:
    """A firmware loop: true = A (raw - bias), in float, with the header's arrays."""
    rows = ",\n".join("{" + ", ".join(f"{v:.9g}f" for v in r) + "}" for r in raw)
    body = (f"  static const float raw[{len(raw)}][3] = {{\n{rows}\n}};\n"
            f"  for (int n = 0; n < {len(raw)}; n++) {{\n"
            "    for (int i = 0; i < 3; i++) {\n      float s = 0.0f;\n"
            f"      for (int j = 0; j < 3; j++) s += {prefix}_A[i][j] * (raw[n][j] - {prefix}_BIAS[j]);\n"
            '      printf("%.9g ", (double)s);\n    }\n    printf("\\n");\n  }')
    return _run_c(folder, header, body)


@needs_cc
def test_c_header_corrected_values_are_in_the_unit_it_states(run_cli, tmp_path):
    """Readings simulated as raw = M true + bias: in deg/s the header's A (raw - bias) gives deg/s (not rad/s); in
    counts it gives m/s^2, and the header says so."""
    rng = np.random.default_rng(3)
    m_g = np.eye(3) + rng.normal(0, 0.01, (3, 3))
    m_a = 1670.0 * (np.eye(3) + rng.normal(0, 0.01, (3, 3)))          # counts per m/s^2
    b_g, b_a = np.array([0.5, -0.3, 0.2]), np.array([120.0, -80.0, 40.0])  # deg/s, counts
    cs = CalibrationSet({
        "accelerometer": Calibration("accelerometer", m_a, b_a, np.zeros((3, 3)), np.zeros(3), "counts", "test"),
        "gyroscope": Calibration("gyroscope", m_g, b_g * DEG, np.zeros((3, 3)), np.zeros(3), "deg/s", "test")})
    save_result(tmp_path / "cal.json", cs)
    res = run_cli("export", tmp_path / "cal.json", "--to", "c")
    assert res.code == 0, res.err
    header = res.out
    w = rng.uniform(-200, 200, (5, 3))                                   # deg/s
    a = rng.uniform(-15, 15, (5, 3))                                     # m/s^2
    got_w = _correct_in_c(tmp_path, header, "IMU_CAL_GYRO", w @ m_g.T + b_g)
    got_a = _correct_in_c(tmp_path, header, "IMU_CAL_ACCEL", a @ m_a.T + b_a)
    assert np.allclose(got_w, w, rtol=0, atol=2e-4 * 200)                 # float precision of deg/s values
    assert np.allclose(got_a, a, rtol=0, atol=2e-4 * 15)
    units = next(line for line in header.splitlines() if line.startswith("/* units:"))
    assert "gyroscope readings and bias in deg/s, true values in deg/s" in units
    assert "accelerometer readings and bias in counts, true values in m/s^2" in units
    assert "rad/s" not in units and "SI (m/s^2, rad/s)" not in header


# ---------------------------------------------------------------- bug 10: one preamble

def test_alignment_c_header_states_the_tool_and_the_convention_once(run_cli, tmp_path):
    res = run_cli("matrix", SESSION, "--plan", PLAN, "--json", tmp_path / "a.json", "--c-header", tmp_path / "m.h")
    assert res.code == 0, res.err
    exported = run_cli("export", tmp_path / "a.json", "--to", "c")
    for header in (exported.out, (tmp_path / "m.h").read_text()):
        comments = [ln for ln in header.splitlines() if ln.startswith("/*") and not ln.startswith("/* alignment")
                    and not ln.startswith("/* gyro bias")]
        assert sum("written by" in ln for ln in comments) == 1, comments
        assert sum("w = A (g - b)" in ln for ln in comments) == 1, comments
        assert comments[0].startswith("/* imu-align alignment from ") and "written by imu-align" in comments[0]


# ---------------------------------------------------------------- bug 8 and the CSV's first line

def test_csv_scale_rows_carry_ms_unit(run_cli, tmp_path):
    m = np.diag([1670.0, 1672.0, 1668.0]) + np.array([[0, 3.0, 0], [0, 0, -2.0], [1.0, 0, 0]])
    cs = CalibrationSet({"accelerometer": Calibration("accelerometer", m, np.zeros(3), np.full((3, 3), 0.5), np.zeros(3),
                                                      "counts", "test")})
    save_result(tmp_path / "c.json", cs)
    res = run_cli("export", tmp_path / "c.json", "--to", "csv")
    assert res.code == 0, res.err
    first = res.out.splitlines()[0]
    assert first.count("calibration") == 1, first                        # the format named once
    (tmp_path / "c.csv").write_text(res.out)
    df = pd.read_csv(tmp_path / "c.csv", comment="#", keep_default_na=False, na_values=[""])
    scale = df[df.quantity == "scale"].set_index("row")
    assert set(scale.unit) == {"counts per m/s^2"}
    for i, a in enumerate("xyz"):
        assert scale.value[a] == pytest.approx(float(np.sqrt(np.sum(m[i] ** 2))), rel=1e-12)   # |row of M|


# ---------------------------------------------------------------- bug 11: the Kalibr random walk

@pytest.fixture(scope="module")
def rest(tmp_path_factory):
    """Allan results of 3-minute white-noise records at rest: a gyroscope (g.json) and an accelerometer reading
    gravity (acc.json); neither identifies a bias random walk."""
    from align.cli import run

    d, fs = tmp_path_factory.mktemp("rest"), 100.0
    gyro = simulate_noise(int(fs * 180), fs, NoiseSpec(white=0.3 * DEG / 60), channels=3, seed=5) / DEG
    acc = simulate_noise(int(fs * 180), fs, NoiseSpec(white=6e-4), channels=3, seed=6) + np.array([0.2, -0.1, 9.8])
    np.save(d / "g.npy", gyro)
    np.save(d / "acc.npy", acc)
    assert run(["allan", str(d / "g.npy"), "--rate-hz", str(fs), "--json", str(d / "g.json")]) == 0
    assert run(["allan", str(d / "acc.npy"), "--rate-hz", str(fs), "--units", "m/s^2", "--columns",
                "acc_x,acc_y,acc_z", "--json", str(d / "acc.json")]) == 0
    return d


def test_kalibr_says_which_numbers_are_upper_bounds_and_that_it_ignores_the_intrinsics(run_cli, rest, tmp_path):
    """A 3-minute white-noise record cannot identify a bias random walk: the Allan JSON gives its 95 % upper bound
    (terms.*.upper_bound), and imu.yaml writes that same number with a comment saying it is an upper bound.

    The intrinsics: in ethz-asl/kalibr (commit 0230eed, aslam_offline_calibration/kalibr/python/
    kalibr_imu_camera_calibration/IccSensors.py) IccScaledMisalignedImu.addDesignVariables starts q_gyro_i at the
    identity quaternion, M_accel_Dv and M_gyro_Dv at np.eye(3) and M_accel_gyro_Dv at np.zeros((3,3)); the
    imu.yaml's accelerometers/gyroscopes are only printed (printDetails) and written back (setIntrisicsMatrices).
    """
    res = run_cli("export", rest / "g.json", rest / "acc.json", "--to", "kalibr")
    assert res.code == 0, res.err
    d = json.loads((rest / "g.json").read_text())
    terms = {ch: f["terms"]["rate_random_walk"] for ch, f in d["fit"].items()}
    assert not any(t["identifiable"] for t in terms.values())
    assert {t["unit"] for t in terms.values()} == {"deg/h/sqrt(h)"}
    bound = max(t["upper_bound"] for t in terms.values()) * DEG / 3600 / 60       # deg/h/sqrt(h) -> rad/s^2/sqrt(Hz)
    y = yaml.safe_load(res.out)
    assert y["gyroscope_random_walk"] == pytest.approx(bound, rel=1e-12)
    line = next(ln for ln in res.out.splitlines() if ln.startswith("gyroscope_random_walk:"))
    assert "UPPER BOUND" in line and "not a fitted value" in line
    noise = next(ln for ln in res.out.splitlines() if ln.startswith("gyroscope_noise_density:"))
    assert "fitted" in noise and "UPPER BOUND" not in noise
    res = run_cli("matrix", SESSION, "--plan", PLAN, "--json", tmp_path / "a.json")
    text = run_cli("export", tmp_path / "a.json", rest / "g.json", rest / "acc.json", "--to", "kalibr").out
    assert re.search(r"Kalibr does not read accelerometers/gyroscopes from its input imu.yaml .*M = I, C = I, A = 0",
                     text)


# ---------------------------------------------------------------- bug 13, --name and --rostopic

def test_a_file_that_is_not_a_result_gets_one_line_saying_what_to_give(run_cli, tmp_path):
    (tmp_path / "x.json").write_text('{"a": 1}')
    (tmp_path / "e.json").write_text("")
    for path in (SESSION, tmp_path / "x.json", tmp_path / "e.json"):
        _one_line(run_cli("export", path, "--to", "c"), "not a result file", "--json", path.name)
    _one_line(run_cli("export", tmp_path / "none.json", "--to", "c"), "file not found")


def test_name_and_rostopic_are_refused_where_they_mean_nothing(run_cli, rest, tmp_path):
    res = run_cli("matrix", SESSION, "--plan", PLAN, "--json", tmp_path / "a.json")
    assert res.code == 0, res.err
    _one_line(run_cli("export", tmp_path / "a.json", "--to", "csv", "--name", "X"), "--name", "--to c")
    _one_line(run_cli("export", tmp_path / "a.json", "--to", "c", "--rostopic", "/imu"), "--rostopic", "--to kalibr")
    assert run_cli("export", tmp_path / "a.json", "--to", "c", "--name", "X").code == 0
    assert "rostopic: \"/imu\"" in run_cli("export", tmp_path / "a.json", rest / "g.json", rest / "acc.json", "--to",
                                           "kalibr", "--rostopic", "/imu").out


# ---------------------------------------------------------------- imucal's own calibrate()

def test_imucal_calibrate_reproduces_a_times_raw_minus_bias(run_cli, tmp_path):
    """imucal's FerrarisCalibrationInfo.calibrate on the real Ferraris session equals A (raw - b) (gyro: minus K_ga
    times the corrected acceleration) computed here from the result file's own A, bias and g-sensitivity."""
    from imucal.management import load_calibration_info

    res = run_cli("calibrate", "ferraris", FERRARIS / "example_ferraris_session.csv", "--sections",
                  FERRARIS / "example_ferraris_session_list.json", "--rate-hz", "102.4", "--json", tmp_path / "f.json")
    assert res.code == 0, res.err
    assert run_cli("export", tmp_path / "f.json", "--to", "imucal", "--out", tmp_path / "i.json").code == 0
    d = json.loads((tmp_path / "f.json").read_text())
    assert d["units"] == {"accelerometer": "m/s^2", "gyroscope": "deg/s"}
    raw = pd.read_csv(FERRARIS / "example_ferraris_session.csv")
    acc, gyr = raw[["acc_x", "acc_y", "acc_z"]].to_numpy(), raw[["gyr_x", "gyr_y", "gyr_z"]].to_numpy()
    a_acc, b_acc = np.array(d["accelerometer"]["A"]), np.array(d["accelerometer"]["bias"])
    a_gyr, b_gyr, kga = (np.array(d["gyroscope"][k]) for k in ("A", "bias", "g_sensitivity"))
    assert d["gyroscope"]["units"]["g_sensitivity"] == "deg/s per m/s^2"     # K_ga acts on m/s^2, gives deg/s
    want_acc = (acc - b_acc) @ a_acc.T
    want_gyr = (gyr - b_gyr - want_acc @ kga.T) @ a_gyr.T
    info = load_calibration_info(tmp_path / "i.json")
    got_acc, got_gyr = info.calibrate(acc, gyr, "m/s^2", "deg/s")
    assert np.max(np.abs(got_acc - want_acc)) < 1e-12 * np.max(np.abs(want_acc))
    assert np.max(np.abs(got_gyr - want_gyr)) < 1e-12 * np.max(np.abs(want_gyr))
    counts = CalibrationSet({s: Calibration(s, np.eye(3) * 1600, np.zeros(3), np.zeros((3, 3)), np.zeros(3), "counts",
                                            "test") for s in ("accelerometer", "gyroscope")})
    save_result(tmp_path / "counts.json", counts)
    _one_line(run_cli("export", tmp_path / "counts.json", "--to", "imucal", "--out", tmp_path / "o.json"),
              "counts", "imucal")
