"""imu-align export: each format read back by its consumer's own reader (PyYAML as Kalibr reads, a C compiler,
pandas, imucal's loader) to the numbers of the result file, and every refusal one line with no output."""

import contextlib
import io
import json
import math
import re
import shutil
import subprocess

import numpy as np
import pandas as pd
import pytest
import yaml
from support import ROOT, SHARED

from align.calibration import Calibration, CalibrationSet, MagCalibration
from align.noise.sim import NoiseSpec, simulate_noise
from align.results import save_result
from align.units import DEG

CC = shutil.which("cc")
#: pandas before 3 parses floats with a fast, inexact parser unless asked; 3 deprecates the option (exact by default)
ROUND_TRIP = {"float_precision": "round_trip"} if int(pd.__version__.split(".")[0]) < 3 else {}
FERRARIS = SHARED / "data" / "multiposition" / "imucal_ferraris"
HMC = SHARED / "data" / "magnetometer" / "hmc5883l_sunsided" / "hmc5883l_compass.csv"
FS = 100.0
#: the simulated truth: gyro N 0.3 deg/sqrt(h), K 300 deg/h/sqrt(h); accelerometer N 60 ug/sqrt(Hz), K 1e-3 m/s^3/sqrt(Hz)
N_GYRO, K_GYRO = 0.3 * DEG / 60, 300 * DEG / 3600 / 60
N_ACC, K_ACC = 60e-6 * 9.80665, 1e-3


def _cli(*args) -> tuple[int, str, str]:
    from align.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            main([str(a) for a in args])
            code = 0
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else 0
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """Result files as the commands write them: two Allan records of known noise, an alignment, a Ferraris calibration,
    a magnetometer calibration and a budget."""
    d = tmp_path_factory.mktemp("results")
    n = int(FS * 1800)
    gyro = simulate_noise(n, FS, NoiseSpec(white=N_GYRO, random_walk=K_GYRO), channels=3, seed=11) / DEG
    acc = simulate_noise(n, FS, NoiseSpec(white=N_ACC, random_walk=K_ACC), channels=3, seed=12)
    np.save(d / "gyro.npy", gyro)
    np.save(d / "acc.npy", acc)
    runs = [("allan", d / "gyro.npy", "--rate-hz", FS, "--json", d / "allan.json"),
            ("allan", d / "acc.npy", "--rate-hz", FS, "--units", "m/s^2", "--columns", "acc_x,acc_y,acc_z",
             "--json", d / "allan_acc.json"),
            ("matrix", ROOT / "examples" / "alignment" / "session.csv", "--plan", ROOT / "examples" / "alignment" /
             "plan.toml", "--json", d / "align.json", "--c-header", d / "matrix.h"),
            ("calibrate", "ferraris", FERRARIS / "example_ferraris_session.csv", "--sections",
             FERRARIS / "example_ferraris_session_list.json", "--rate-hz", "102.4", "--json", d / "cal.json"),
            ("calibrate", "mag", HMC, "--columns", "mag_x_gauss,mag_y_gauss,mag_z_gauss", "--mag-units", "gauss",
             "--json", d / "mag.json"),
            ("budget", ROOT / "examples" / "budget" / "example1.toml", "--json", d / "budget.json")]
    for args in runs:
        code, _, err = _cli(*args)
        assert code == 0, (args, err)
    return d


def _export(*args):
    code, out, err = _cli("export", *args)
    assert code == 0, err
    return out


def _refused(folder, *args, words=()):
    out = folder / "refused.out"
    code, stdout, err = _cli("export", *args, "--out", out)
    assert code == 2, (stdout, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    for w in words:
        assert w in lines[0], (w, lines[0])
    assert not out.exists()


# ---------------------------------------------------------------- Kalibr

def _largest(d: dict, key: str, factor: float) -> float:
    """The largest over the channels of a fitted term (its 95 % upper bound where not identified), SI."""
    vals = []
    for fit in d["fit"].values():
        t = fit["terms"][key]
        vals.append((t["value"] if t["identifiable"] else t["upper_bound"]) * factor)
    return max(vals)


def test_kalibr_noise_reads_back_to_the_allan_numbers_and_the_truth(results, tmp_path):
    out = tmp_path / "imu.yaml"
    _export(results / "allan.json", results / "allan_acc.json", "--to", "kalibr", "--out", out, "--rostopic", "/imu/data")
    y = yaml.safe_load(out.read_text())
    g, a = (json.loads((results / n).read_text()) for n in ("allan.json", "allan_acc.json"))
    assert y["rostopic"] == "/imu/data" and y["update_rate"] == FS and "model" not in y
    # the numbers of the result files, in Kalibr's SI units (conversions written out here, not the tool's)
    assert g["fit"]["gyro_x"]["terms"]["angle_random_walk"]["unit"] == "deg/sqrt(h)"
    assert g["fit"]["gyro_x"]["terms"]["rate_random_walk"]["unit"] == "deg/h/sqrt(h)"
    assert a["fit"]["acc_x"]["terms"]["velocity_random_walk"]["unit"] == "m/s/sqrt(h)"
    assert a["fit"]["acc_x"]["terms"]["acceleration_random_walk"]["unit"] == "ug/sqrt(h)"
    expect = {"gyroscope_noise_density": _largest(g, "angle_random_walk", DEG / 60),
              "gyroscope_random_walk": _largest(g, "rate_random_walk", DEG / 3600 / 60),
              "accelerometer_noise_density": _largest(a, "velocity_random_walk", 1 / 60),
              "accelerometer_random_walk": _largest(a, "acceleration_random_walk", 9.80665e-6 / 60)}
    for key, v in expect.items():
        assert y[key] == pytest.approx(v, rel=1e-12), key
    # and the simulated truth (the largest of three channels: a little above it)
    assert y["gyroscope_noise_density"] == pytest.approx(N_GYRO, rel=0.03)
    assert y["accelerometer_noise_density"] == pytest.approx(N_ACC, rel=0.03)
    assert y["gyroscope_random_walk"] == pytest.approx(K_GYRO, rel=0.5)
    assert y["accelerometer_random_walk"] == pytest.approx(K_ACC, rel=0.5)
    text = out.read_text()
    for words in ("imu-align 0.", "m/s^2/sqrt(Hz)", "rad/s^2/sqrt(Hz)", "frame", "convention"):
        assert words in text, words


def test_kalibr_intrinsics_of_an_alignment_in_kalibrs_direction(results):
    y = yaml.safe_load(_export(results / "align.json", results / "allan.json", results / "allan_acc.json", "--to",
                               "kalibr"))
    m = np.array(json.loads((results / "align.json").read_text())["M"])
    low, c = np.array(y["gyroscopes"]["M"]), np.array(y["gyroscopes"]["C_gyro_i"])
    assert y["model"] == "scale-misalignment" and np.all(np.triu(low, 1) == 0)
    assert np.allclose(c @ c.T, np.eye(3), atol=1e-12) and np.linalg.det(c) > 0
    # Kalibr's w_meas = M_gyro C_gyro_i w (modelling, like imu-align's M; not A = M^-1)
    w = np.random.default_rng(0).normal(0, 1, (3, 50))
    assert np.allclose(low @ c @ w, m @ w, atol=1e-12)
    assert np.array_equal(np.array(y["gyroscopes"]["A"]), np.zeros((3, 3)))
    assert y["update_rate"] == FS and y["gyroscope_noise_density"] > 0 and y["accelerometer_random_walk"] > 0


def test_kalibr_of_an_alignment_alone_is_refused_it_has_no_noise_figures(results, tmp_path):
    """Issue 28: an imu.yaml without the noise keys Kalibr reads is not written (Kalibr's ImuParameters raises on a
    missing key): one line, exit 2, saying what to give."""
    _refused(tmp_path, results / "align.json", "--to", "kalibr",
             words=["align.json", "no noise figures", "gyroscope_noise_density", "allan"])
    _refused(tmp_path, results / "cal.json", "--to", "kalibr", words=["cal.json", "no noise figures"])


@pytest.mark.parametrize("seed", range(4))
def test_kalibr_intrinsics_of_a_calibration_reproduce_its_model(results, tmp_path, seed):
    """raw_a = M_a a + b_a and raw_g = M_g w + K_ga a + b_g (imu-align) equal Kalibr's a_meas = M_accel a_i and
    w_meas = M_gyro C_gyro_i w_i + A C_gyro_i a_i, in the frame i = R (calibration frame) the file defines."""
    rng = np.random.default_rng(seed)

    def cal(sensor, units, kga):
        m = np.diag(1 + rng.normal(0, 0.01, 3)) @ (np.eye(3) + rng.normal(0, 0.01, (3, 3)))
        return Calibration(sensor, m, rng.normal(0, 0.1, 3), np.full((3, 3), 1e-4), np.full(3, 1e-3), units, "test",
                           g_sensitivity=rng.normal(0, 1e-4, (3, 3)) if kga else None)

    cs = CalibrationSet({"accelerometer": cal("accelerometer", "m/s^2", False), "gyroscope": cal("gyroscope", "deg/s", True)})
    path = tmp_path / "cal.json"
    save_result(path, cs)
    d = json.loads(path.read_text())
    y = yaml.safe_load(_export(path, results / "allan.json", results / "allan_acc.json", "--to", "kalibr"))
    ma, mg = np.array(d["accelerometer"]["M"]), np.array(d["gyroscope"]["M"])
    kga = np.array(d["gyroscope"]["g_sensitivity"]) * DEG          # deg/s per m/s^2 -> (rad/s) per (m/s^2)
    la, lg = np.array(y["accelerometers"]["M"]), np.array(y["gyroscopes"]["M"])
    c, ak = np.array(y["gyroscopes"]["C_gyro_i"]), np.array(y["gyroscopes"]["A"])
    assert np.all(np.triu(la, 1) == 0) and np.all(np.triu(lg, 1) == 0)
    r = np.linalg.solve(la, ma)                                     # the frame i the file's accelerometer defines
    assert np.allclose(r @ r.T, np.eye(3), atol=1e-12) and np.linalg.det(r) > 0
    w, a = rng.normal(0, 1, (3, 20)), rng.normal(0, 9.8, (3, 20))
    assert np.allclose(la @ (r @ a), ma @ a, atol=1e-12)
    assert np.allclose(lg @ c @ (r @ w) + ak @ c @ (r @ a), mg @ w + kga @ a, atol=1e-12)


def test_kalibr_refuses_what_it_cannot_take(results, tmp_path):
    _refused(tmp_path, results / "budget.json", "--to", "kalibr",
             words=["budget.json", "imu-align.budget", "no Kalibr", "allan, alignment, calibration"])
    _refused(tmp_path, results / "mag.json", "--to", "kalibr", words=["mag.json", "magnetometer"])
    _refused(tmp_path, results / "allan.json", results / "allan.json", "--to", "kalibr", words=["second gyroscope Allan"])
    counts = CalibrationSet({"accelerometer": Calibration("accelerometer", np.eye(3) * 1600, np.zeros(3), np.zeros((3, 3)),
                                                          np.zeros(3), "counts", "test")})
    save_result(tmp_path / "counts.json", counts)
    _refused(tmp_path, tmp_path / "counts.json", "--to", "kalibr", words=["counts", "dimensionless"])


# ---------------------------------------------------------------- C headers

def _literals(header: str, name: str) -> np.ndarray:
    body = header.split(f"{name}")[1].split(";")[0]
    return np.array([np.float32(s) for s in re.findall(r"(-?[0-9][0-9.e+-]*)f\b", body.split("=", 1)[1])])


def _compiled_values(folder, header: str, arrays: dict[str, int]) -> dict[str, np.ndarray]:
    """Compile the header with a program that prints each array (``cc -c``, warnings as errors), run it and read back."""
    (folder / "x.h").write_text(header)
    prints = "\n".join(f'  for (int i = 0; i < {n}; i++) printf("{name} %.9g\\n", (double)((const float *){name})[i]);'
                       for name, n in arrays.items())
    (folder / "main.c").write_text(f'#include <stdio.h>\n#include "x.h"\nint main(void) {{\n{prints}\n  return 0;\n}}\n')
    subprocess.run([CC, "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-c", "main.c", "-o", "main.o"],
                   cwd=folder, check=True, capture_output=True)
    subprocess.run([CC, "main.o", "-o", "main"], cwd=folder, check=True, capture_output=True)
    out = subprocess.run([str(folder / "main")], check=True, capture_output=True, text=True).stdout.splitlines()
    got: dict[str, list] = {}
    for line in out:
        name, v = line.split()
        got.setdefault(name, []).append(np.float32(v))
    return {k: np.array(v) for k, v in got.items()}


needs_cc = pytest.mark.skipif(CC is None, reason="no C compiler (cc) on this machine")


def _f32(values) -> np.ndarray:
    return np.asarray(values, dtype=float).astype(np.float32).ravel()


@needs_cc
def test_c_header_of_an_alignment_compiles_and_its_a_is_the_jsons_to_float_precision(results, tmp_path):
    d = json.loads((results / "align.json").read_text())
    header = _export(results / "align.json", "--to", "c")
    got = _compiled_values(tmp_path, header, {"IMU_ALIGN_A": 9, "IMU_ALIGN_BIAS": 3})
    assert np.array_equal(got["IMU_ALIGN_A"], _f32(d["A"])) and np.array_equal(got["IMU_ALIGN_BIAS"], _f32(d["bias"]))
    assert np.array_equal(_literals(header, "IMU_ALIGN_A[3][3]"), _f32(d["A"]))
    for words in ("correcting", "w = A (g - b)", "frame", "deg/s", "imu-align 0."):
        assert words in header, words
    # 'matrix --c-header' is the same writer: the same arrays, only the first line (the source) differs
    old = (results / "matrix.h").read_text()
    assert old.splitlines()[1:] == header.splitlines()[1:]


@needs_cc
def test_c_header_of_a_calibration_compiles_with_every_sensor(results, tmp_path):
    d = json.loads((results / "cal.json").read_text())
    header = _export(results / "cal.json", "--to", "c", "--name", "MY_CAL")
    got = _compiled_values(tmp_path, header, {"MY_CAL_ACCEL_A": 9, "MY_CAL_ACCEL_BIAS": 3, "MY_CAL_GYRO_A": 9,
                                              "MY_CAL_GYRO_BIAS": 3, "MY_CAL_GYRO_G_SENSITIVITY": 9})
    for key, sensor in (("ACCEL", "accelerometer"), ("GYRO", "gyroscope")):
        assert np.array_equal(got[f"MY_CAL_{key}_A"], _f32(d[sensor]["A"]))
        assert np.array_equal(got[f"MY_CAL_{key}_BIAS"], _f32(d[sensor]["bias"]))
    assert np.array_equal(got["MY_CAL_GYRO_G_SENSITIVITY"], _f32(d["gyroscope"]["g_sensitivity"]))
    assert "m/s^2" in header and "deg/s" in header and "correcting" in header


@needs_cc
def test_c_header_of_a_magnetometer_compiles(results, tmp_path):
    d = json.loads((results / "mag.json").read_text())
    header = _export(results / "mag.json", "--to", "c")
    got = _compiled_values(tmp_path, header, {"IMU_MAG_A": 9, "IMU_MAG_HARD_IRON": 3})
    assert np.array_equal(got["IMU_MAG_A"], _f32(d["soft_iron"]))       # no rotation found: A is the soft iron
    assert np.array_equal(got["IMU_MAG_HARD_IRON"], _f32(d["hard_iron"]))
    assert "gauss" in header
    # with a rotation to the accelerometer: A = misalignment soft_iron
    rot = np.array([[math.cos(0.1), -math.sin(0.1), 0], [math.sin(0.1), math.cos(0.1), 0], [0, 0, 1]])
    mag = MagCalibration(np.zeros(3), np.array(d["soft_iron"]), 50e-6, "symmetric", "uT", np.zeros(3), 0.1, 0.01, 0.3,
                         0.01, 1.0, misalignment=rot)
    save_result(tmp_path / "magrot.json", mag)
    header = _export(tmp_path / "magrot.json", "--to", "c")
    got = _compiled_values(tmp_path, header, {"IMU_MAG_A": 9, "IMU_MAG_SOFT_IRON": 9, "IMU_MAG_MISALIGNMENT": 9})
    assert np.array_equal(got["IMU_MAG_A"], _f32(rot @ np.array(d["soft_iron"])))


def test_c_header_refusals(results, tmp_path):
    _refused(tmp_path, results / "allan.json", "--to", "c", words=["allan.json", "no C header", "alignment, calibration"])
    _refused(tmp_path, results / "align.json", results / "cal.json", "--to", "c", words=["one result", "--to kalibr"])
    _refused(tmp_path, tmp_path / "none.json", "--to", "c", words=["none.json"])
    singular = json.loads((results / "cal.json").read_text())
    singular["accelerometer"]["M"][2] = [0.0, 0.0, 0.0]
    (tmp_path / "singular.json").write_text(json.dumps(singular))
    for to in ("c", "csv", "imucal", "kalibr"):
        _refused(tmp_path, tmp_path / "singular.json", "--to", to, words=["singular.json: accelerometer.M"])
    code, _, err = _cli("export", results / "cal.json", "--to", "c", "--out", results / "cal.json")
    assert code == 2 and "--out" in err and json.loads((results / "cal.json").read_text())["format"]   # input untouched


# ---------------------------------------------------------------- CSV, imucal

def test_csv_of_the_allan_curve_reads_back_with_pandas(results, tmp_path):
    out = tmp_path / "allan.csv"
    _export(results / "allan.json", "--to", "csv", "--out", out)
    d = json.loads((results / "allan.json").read_text())
    df = pd.read_csv(out, comment="#", **ROUND_TRIP)
    u = d["units"]["adev"]
    assert list(df.columns)[:4] == ["tau [s]", f"gyro_x adev [{u}]", f"gyro_x ci_low [{u}]", f"gyro_x ci_high [{u}]"]
    assert np.array_equal(df["tau [s]"].to_numpy(), np.array(d["tau"]))
    for ch in ("gyro_x", "gyro_y", "gyro_z"):
        assert np.array_equal(df[f"{ch} adev [{u}]"].to_numpy(), np.array(d["adev"][ch]))
        assert np.array_equal(df[f"{ch} ci_high [{u}]"].to_numpy(), np.array(d["ci_high"][ch]))


def test_csv_of_m_a_and_the_angles_reads_back_with_pandas(results, tmp_path):
    for name in ("align.json", "cal.json", "mag.json"):
        out = tmp_path / f"{name}.csv"
        _export(results / name, "--to", "csv", "--out", out)
        d = json.loads((results / name).read_text())
        df = pd.read_csv(out, comment="#", keep_default_na=False, na_values=[""], **ROUND_TRIP)
        assert list(df.columns) == ["quantity", "sensor", "row", "column", "value", "sigma_1", "unit"]
        text = out.read_text()
        assert "modelling" in text and "correcting" in text and "frame" in text and "imu-align 0." in text

        def table(q, sensor, df=df):
            rows = df[(df.quantity == q) & (df.sensor == sensor)]
            return rows.value.to_numpy().reshape(3, 3) if len(rows) == 9 else rows.value.to_numpy()

        if name == "align.json":
            assert np.array_equal(table("M", "gyroscope"), np.array(d["M"]))
            assert np.array_equal(table("A", "gyroscope"), np.array(d["A"]))
            psi = df[(df.quantity == "psi")].set_index("row").value
            assert all(psi[a] == pytest.approx(d["angles"]["psi_deg"][f"psi_{a}"], rel=1e-12) for a in "xyz")
            phi = df[df.quantity == "phi"]
            for _, r in phi.iterrows():
                assert r.value == pytest.approx(d["angles"]["phi_deg"][f"phi_{r.row}{r.column}"], rel=1e-12)
            assert set(df[df.quantity == "psi"].unit) == {"deg"}
        elif name == "cal.json":
            for s in ("accelerometer", "gyroscope"):
                assert np.array_equal(table("M", s), np.array(d[s]["M"]))
                assert np.array_equal(table("A", s), np.array(d[s]["A"]))
                assert np.array_equal(table("bias", s), np.array(d[s]["bias"]))
        else:
            assert np.array_equal(table("A", "magnetometer"), np.array(d["soft_iron"]))
            assert np.array_equal(table("hard_iron", "magnetometer"), np.array(d["hard_iron"]))


def test_imucal_export_loads_with_imucals_own_loader(results, tmp_path):
    from imucal.management import load_calibration_info

    out = tmp_path / "imucal.json"
    _export(results / "cal.json", "--to", "imucal", "--out", out)
    info = load_calibration_info(out)
    d = json.loads((results / "cal.json").read_text())
    assert np.allclose(info.K_a @ info.R_a, np.array(d["accelerometer"]["M"]), rtol=0, atol=1e-12)
    assert np.allclose(info.K_g @ info.R_g, np.array(d["gyroscope"]["M"]), rtol=0, atol=1e-12)
    assert np.allclose(info.b_g, d["gyroscope"]["bias"], atol=1e-12) and d["units"]["gyroscope"] == "deg/s"
    assert "imu-align 0." in info.comment and "raw = K R true + b" in info.comment
    one = CalibrationSet({"accelerometer": Calibration("accelerometer", np.eye(3), np.zeros(3), np.zeros((3, 3)),
                                                       np.zeros(3), "m/s^2", "test")})
    save_result(tmp_path / "acc.json", one)
    _refused(tmp_path, tmp_path / "acc.json", "--to", "imucal", words=["acc.json", "no gyroscope"])
    _refused(tmp_path, results / "align.json", "--to", "imucal", words=["align.json", "no imucal"])


def test_export_prints_when_no_out_is_given_and_names_what_it_wrote(results, tmp_path):
    text = _export(results / "allan.json", "--to", "csv")
    assert text.startswith("# Allan deviation curve from allan.json (imu-align.allan); written by imu-align ")
    code, out, _ = _cli("export", results / "allan.json", "--to", "csv", "--out", tmp_path / "a.csv")
    assert code == 0 and out.startswith(f"wrote {tmp_path / 'a.csv'}") and (tmp_path / "a.csv").read_text() == text
