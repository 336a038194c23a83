"""The export writers (align.io.consumers) read back by their consumers: a C compiler, PyYAML, pandas."""

import shutil
import subprocess

import numpy as np
import pandas as pd
import pytest
import yaml

from align.errors import InputError
from align.io.consumers import c_array, c_file, c_float, csv_text, kalibr_yaml, lower_rotation, matrix_unit, yaml_float

CC = shutil.which("cc")
#: pandas before 3 parses floats with a fast, inexact parser unless asked; 3 deprecates the option (exact by default)
ROUND_TRIP = {"float_precision": "round_trip"} if int(pd.__version__.split(".")[0]) < 3 else {}
needs_cc = pytest.mark.skipif(CC is None, reason="no C compiler (cc) on this machine")


def _values(seed: int, n: int = 400) -> np.ndarray:
    """Awkward floats: many magnitudes, both signs, exact integers, values just off a float's midpoint."""
    rng = np.random.default_rng(seed)
    v = rng.normal(0, 1, n) * 10.0 ** rng.integers(-30, 30, n)
    return np.concatenate([v, [0.0, 1.0, -1.0, 123456789.0, 1e-5, 0.1, 3.4e38, 1.2e-38, 2.0 ** -149]])


@pytest.mark.parametrize("seed", range(5))
def test_c_literal_is_the_nearest_float_at_9_digits(seed):
    for x in _values(seed):
        text = c_float(x)
        assert text.endswith("f") and any(c in text for c in ".e"), text   # a float literal, never '1f'
        mantissa = text[:-1].split("e")[0].lstrip("-").replace(".", "").strip("0")
        assert len(mantissa) <= 9, text
        assert np.float32(text[:-1]) == np.float32(x), (x, text)


def test_c_literal_refuses_what_c_cannot_hold():
    for bad in (np.nan, np.inf, -np.inf):
        with pytest.raises(InputError, match="non-finite"):
            c_float(bad, "A")


@needs_cc
def test_c_compiler_reads_the_very_floats(tmp_path):
    """The compiler is the consumer: the header compiles warning-free and a program printing the arrays gives back
    numpy's float32 of every value."""
    v = _values(7, 60)
    m = np.random.default_rng(3).normal(0, 1, (3, 3))
    header = c_file("TEST_EXPORT", "a test header\nsecond line with */ inside", [
        c_array("TEST_EXPORT_V", v, "values"), c_array("TEST_EXPORT_M", m, "a matrix")])
    (tmp_path / "t.h").write_text(header)
    (tmp_path / "main.c").write_text(
        '#include <stdio.h>\n#include "t.h"\n'
        "int main(void) {\n"
        f"  for (int i = 0; i < {len(v)}; i++) printf(\"%.9g\\n\", (double)TEST_EXPORT_V[i]);\n"
        '  for (int i = 0; i < 3; i++) for (int j = 0; j < 3; j++) printf("%.9g\\n", (double)TEST_EXPORT_M[i][j]);\n'
        "  return 0;\n}\n")
    flags = ["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror"]
    subprocess.run([CC, *flags, "-c", "main.c", "-o", "main.o"], cwd=tmp_path, check=True, capture_output=True)
    subprocess.run([CC, "main.o", "-o", "main"], cwd=tmp_path, check=True, capture_output=True)
    out = subprocess.run([str(tmp_path / "main")], check=True, capture_output=True, text=True).stdout.split()
    got = np.array([np.float32(s) for s in out])
    assert np.array_equal(got, np.concatenate([v, m.ravel()]).astype(np.float32))


def test_c_file_refuses_a_name_that_is_not_an_identifier():
    with pytest.raises(InputError, match="not a C identifier") as exc:
        c_file("9LIVES", "x", [])
    assert exc.value.fields == ["name"]


@pytest.mark.parametrize("seed", range(3))
def test_yaml_floats_read_back_as_the_same_floats(seed):
    for x in _values(seed):
        text = yaml_float(x)
        back = yaml.safe_load(text)
        assert isinstance(back, float) and back == x, (x, text)   # PyYAML (YAML 1.1) reads '1e-05' as a string


def test_kalibr_yaml_reads_back_with_pyyaml():
    m = np.random.default_rng(1).normal(0, 1, (3, 3))
    text = kalibr_yaml("line one\nline two", [("rostopic", "/imu0", ""), ("update_rate", 200.0, "Hz"),
                                              ("gyroscope_noise_density", 1.5e-5, "rad/s/sqrt(Hz)")],
                       {"gyroscopes": {"M": m, "A": np.zeros((3, 3)), "C_gyro_i": np.eye(3)}})
    d = yaml.safe_load(text)
    assert d["rostopic"] == "/imu0" and d["update_rate"] == 200.0 and d["gyroscope_noise_density"] == 1.5e-5
    assert d["model"] == "scale-misalignment"
    assert np.array_equal(np.array(d["gyroscopes"]["M"]), m)
    assert all(line.startswith("#") for line in text.splitlines()[:2])


@pytest.mark.parametrize("seed", range(20))
def test_lower_rotation_splits_m_as_kalibr_models_it(seed):
    rng = np.random.default_rng(seed)
    m = np.diag(1 + rng.normal(0, 0.02, 3)) @ (np.eye(3) + rng.normal(0, 0.05, (3, 3)))
    if np.linalg.det(m) <= 0:
        pytest.skip("a reflection")
    low, rot = lower_rotation(m)
    assert np.allclose(low @ rot, m, atol=1e-14)
    assert np.all(np.triu(low, 1) == 0) and np.all(np.diag(low) > 0)
    assert np.allclose(rot @ rot.T, np.eye(3), atol=1e-14) and np.linalg.det(rot) > 0


def test_lower_rotation_refuses_a_reflection():
    with pytest.raises(InputError, match="det <= 0"):
        lower_rotation(np.diag([1.0, -1.0, 1.0]))


def test_csv_reads_back_with_pandas(tmp_path):
    rows = [["M", "gyroscope", "x", "y", 0.1 + 1e-17, float("nan"), "1"], ["bias", "gyroscope", "z", "", -2.5e-9, 1e-3, "deg/s"]]
    path = tmp_path / "t.csv"
    path.write_text(csv_text("a header\nwith units", ["quantity", "sensor", "row", "column", "value", "sigma_1", "unit"],
                             rows))
    df = pd.read_csv(path, comment="#", keep_default_na=False, na_values=[""], **ROUND_TRIP)
    assert list(df["value"]) == [rows[0][4], rows[1][4]] and np.isnan(df["sigma_1"][0])
    assert list(df["unit"]) == ["1", "deg/s"]


def test_matrix_unit_of_physical_readings_and_counts():
    assert matrix_unit("deg/s", "gyroscope") == "1" and matrix_unit("m/s^2", "accelerometer") == "1"
    assert matrix_unit("counts", "accelerometer") == "counts per m/s^2"
