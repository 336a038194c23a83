"""Real logger files through every command: --skip-rows, --comment, --delimiter, --time-units, count sizes.

Truth from outside the code under test: numpy reads the MPU-6050 records of ../shared/data as their
SOURCE.txt says (4 preamble lines, 131 LSB/(deg/s), 16384 LSB/g, 100 Hz) and computes the figures
by their textbook formulas; the authors' own calibration of that sensor; the bundled alignment
session (time in s) against copies of it written by this test in ms, us, ns, with ';', tabs,
blanks, comments and a preamble.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from support import ROOT, SHARED

MPU = SHARED / "data" / "static" / "mpu6050_tomisuarez2" / "imu_static_test.csv"
MPU_MULTI = SHARED / "data" / "multiposition" / "mpu6050_tomisuarez2"
needs_mpu = pytest.mark.skipif(not MPU.is_file(), reason="../shared/data not present")
SESSION = ROOT / "examples" / "alignment" / "session.csv"
PLAN = ROOT / "examples" / "alignment" / "plan.toml"
FORMAT_OPTIONS = ("--skip-rows", "--comment", "--delimiter")


def _one_line(res, code: int = 2) -> str:
    assert res.code == code, (res.code, res.err, res.out)
    assert len(res.err.strip().splitlines()) == 1, res.err
    return res.err


def _session_text() -> tuple[list[str], list[str]]:
    lines = SESSION.read_text().replace('"', "").splitlines()
    return lines[0].split(","), lines[1:]


def _write_session(path, sep=",", time_factor: float | None = None, before: str = "", comment_every: int = 0) -> None:
    header, rows = _session_text()
    out = [before + sep.join(header)]
    for k, row in enumerate(rows):
        cells = row.split(",")
        if time_factor is not None:
            cells[0] = repr(round(float(cells[0]) * time_factor, 9))
        out.append(sep.join(cells) + (" # mark" if comment_every and k % comment_every == 3 else ""))
        if comment_every and k % comment_every == 7:
            out.append("# a note between samples")
    path.write_text("\n".join(out) + "\n")


def _matrix(run_cli, log, *args):
    out = log.with_suffix(".json")
    res = run_cli("matrix", log, "--plan", PLAN, "--json", out, *args)
    assert res.code == 0, res.err
    return json.loads(out.read_text())


# ---------------------------------------------------------------- the MPU-6050 records

@needs_mpu
@pytest.mark.parametrize("units", ["131 LSB/(deg/s)", "0.0076336 deg/s"])
def test_mpu6050_allan_with_skip_rows_and_a_count_size_matches_numpy(run_cli, tmp_path, units):
    out = tmp_path / "allan.json"
    res = run_cli("allan", MPU, "--skip-rows", "4", "--columns", "gx,gy,gz", "--rate-hz", "100", "--gyro-units", units,
                  "--json", out)
    assert res.code == 0, res.err
    d = json.loads(out.read_text())
    counts = np.loadtxt(MPU, delimiter=",", skiprows=5)[:, 3:]          # header on line 5
    deg_s = counts / 131.0
    rel = 1e-12 if units.startswith("131") else 2e-5                    # 0.0076336 = 1/131 to 5e-6
    assert d["units"]["adev"] == "deg/s" and d["fs_hz"] == 100 and d["samples"] == 9986
    for j, ch in enumerate(("gx", "gy", "gz")):
        assert d["figures"][ch]["bias"] == pytest.approx(deg_s[:, j].mean(), rel=rel)
        # ADEV at tau0 = sqrt(mean(diff^2) / 2)  (IEEE 952)
        assert d["tau"][0] == pytest.approx(0.01)
        assert d["adev"][ch][0] == pytest.approx(np.sqrt(0.5 * np.mean(np.diff(deg_s[:, j]) ** 2)), rel=rel)
        blocks = deg_s[: 99 * 100, j].reshape(99, 100).mean(axis=1)     # consecutive 1 s means
        assert d["figures"][ch]["bias_stability"]["1 s"] == pytest.approx(blocks.std(ddof=1), rel=max(rel, 1e-9))
    assert [d["figures"][c]["bias"] for c in ("gx", "gy", "gz")] == pytest.approx([-3.26826, 1.11757, -0.50384], abs=1e-4)


@needs_mpu
def test_mpu6050_without_skip_rows_names_the_rows_to_skip(run_cli):
    err = _one_line(run_cli("allan", MPU, "--columns", "gx,gy,gz", "--rate-hz", "100", "--gyro-units", "131 LSB/(deg/s)"))
    assert "--skip-rows 4" in err and "Expected 2 columns" not in err and "imu_static_test.csv" in err, err


@needs_mpu
def test_mpu6050_gyro_in_plain_counts_is_refused_with_the_count_size_to_give(run_cli):
    err = _one_line(run_cli("allan", MPU, "--skip-rows", "4", "--columns", "gx,gy,gz", "--rate-hz", "100",
                            "--gyro-units", "counts"))
    assert "--gyro-units '131 LSB/(deg/s)'" in err and "MPU-6050" in err, err


@needs_mpu
def test_mpu6050_accelerometer_calibration_agrees_with_the_authors(run_cli, tmp_path):
    """The multi-position session in counts per g against the authors' own calibration of this sensor
    (acc = T K (raw + b): scale 1/K in counts per m/s^2, bias -b in counts)."""
    log = MPU_MULTI / "example_data_calibration.csv"
    authors = np.loadtxt(MPU_MULTI / "authors_result_params_acc.csv")
    out = {}
    for units in ("counts", "16384 LSB/g"):
        out[units] = tmp_path / f"{units[:3]}.json"
        res = run_cli("calibrate", "accel", log, "--skip-rows", "4", "--columns", "ax,ay,az", "--rate-hz", "100",
                      "--accel-units", units, "--init-static", "36.5 s", "--json", out[units])
        # ten poses fix the angles poorly (+/- 247 deg): NOT USABLE by the default limits, exit 4, the file written
        assert res.code == 4 and "NOT USABLE: accelerometer phi_xy" in res.out, (res.out[-600:], res.err)
    counts = json.loads(out["counts"].read_text())
    si = json.loads(out["16384 LSB/g"].read_text())
    m_counts = np.diag(counts["accelerometer"]["M"])                      # counts per m/s^2
    np.testing.assert_allclose(m_counts, 1 / authors[3:6], rtol=3e-3)
    np.testing.assert_allclose(counts["accelerometer"]["bias"], -authors[6:9], atol=25)   # counts (0.15 % of 16384)
    # the same fit through the count size (to the fit's convergence): M dimensionless, bias in m/s^2
    lsb = 9.80665 / 16384
    np.testing.assert_allclose(np.diag(si["accelerometer"]["M"]), m_counts * lsb, rtol=1e-5)
    np.testing.assert_allclose(si["accelerometer"]["bias"], np.array(counts["accelerometer"]["bias"]) * lsb, rtol=1e-5)
    assert si["inputs"]["skip_rows"] == 4 and si["inputs"]["accel_units"] == "16384 LSB/g"


# ---------------------------------------------------------------- time units

@pytest.mark.parametrize("unit, factor", [("ms", 1e3), ("us", 1e6), ("ns", 1e9)])
def test_time_in_ms_us_ns_is_detected_and_gives_the_seconds_result(run_cli, tmp_path, unit, factor):
    base = tmp_path / "s.csv"
    _write_session(base)
    ref = _matrix(run_cli, base)
    log = tmp_path / f"{unit}.csv"
    _write_session(log, time_factor=factor)
    got = _matrix(run_cli, log)
    np.testing.assert_allclose(got["M"], ref["M"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(got["bias"], ref["bias"], rtol=0, atol=1e-9)
    assert got["inputs"]["time_units"] == unit and got["inputs"]["time_units_detected"] is True
    assert ref["inputs"]["time_units"] == "s"
    assert any(f"time column read in {unit}" in n for n in got["notes"]), got["notes"]
    given = _matrix(run_cli, log, "--time-units", unit)
    assert given["inputs"]["time_units_detected"] is False and given["M"] == got["M"]


@pytest.mark.parametrize("unit, wrong, fix", [("ms", "s", "ms"), ("ms", "ns", "ms"), (None, "us", "s")])
def test_a_wrong_time_unit_is_one_line_naming_the_time_column(run_cli, tmp_path, unit, wrong, fix):
    log = tmp_path / "log.csv"
    _write_session(log, time_factor={"ms": 1e3, None: None}[unit])
    err = _one_line(run_cli("matrix", log, "--plan", PLAN, "--time-units", wrong))
    assert "time column 'time'" in err and f"--time-units {fix}" in err and "log.csv" in err, err


def test_apply_writes_the_time_column_back_in_its_unit(run_cli, tmp_path):
    log = tmp_path / "ms.csv"
    _write_session(log, time_factor=1e3)
    result = tmp_path / "r.json"
    assert run_cli("matrix", log, "--plan", PLAN, "--json", result).code == 0
    res = run_cli("apply", log, "--alignment", result, "--out", tmp_path / "c.csv")
    assert res.code == 0 and "time column read in ms" in res.out, res.err
    assert "units: time=ms, " in (tmp_path / "c.csv").read_text().splitlines()[0]   # the stated time unit
    written = np.loadtxt(tmp_path / "c.csv", delimiter=",", skiprows=2)
    np.testing.assert_allclose(written[:, 0], np.loadtxt(log, delimiter=",", skiprows=1)[:, 0], rtol=1e-12)


# ---------------------------------------------------------------- delimiters, comments, preamble

@pytest.mark.parametrize("name, write, args", [
    ("semi.csv", {"sep": ";"}, ("--delimiter", ";")),
    ("tab.csv", {"sep": "\t"}, ("--delimiter", "tab")),
    ("tab2.csv", {"sep": "\t"}, ("--delimiter", "\\t")),
    ("blank.txt", {"sep": "  "}, ("--delimiter", "space")),
    ("comments.csv", {"before": "# exported by logger 1.0\n# units deg/s\n", "comment_every": 500}, ("--comment", "#")),
    ("preamble.csv", {"before": "Fs;100\nLogging Type;1\nInitialization time;-1\n", "sep": ";"},
     ("--skip-rows", "3", "--delimiter", ";")),
])
def test_matrix_reads_a_logger_file_like_the_plain_csv(run_cli, tmp_path, name, write, args):
    base = tmp_path / "plain.csv"
    _write_session(base)
    ref = _matrix(run_cli, base)
    log = tmp_path / name
    _write_session(log, **write)
    got = _matrix(run_cli, log, *args)
    assert got["M"] == ref["M"] and got["bias"] == ref["bias"]
    rec = got["inputs"]
    assert {k: rec[k] for k in ("skip_rows", "comment", "delimiter")} != {"skip_rows": 0, "comment": None,
                                                                           "delimiter": None}
    refused = run_cli("matrix", log, "--plan", PLAN)                   # the same file without the options
    err = _one_line(refused)
    assert any(flag in err for flag in args if flag.startswith("--")), err


def test_a_count_size_gives_the_result_of_the_unit(run_cli, tmp_path):
    header, rows = _session_text()
    data = np.array([[float(c) for c in r.split(",")] for r in rows])
    counts = np.column_stack([data[:, 0], np.round(data[:, 1:] * 131)])
    log = tmp_path / "counts.csv"
    np.savetxt(log, counts, delimiter=",", header="time,gx,gy,gz", comments="", fmt="%.10g")
    ref_log = tmp_path / "quantized.csv"
    np.savetxt(ref_log, np.column_stack([counts[:, 0], counts[:, 1:] / 131]), delimiter=",",
               header="time,gx,gy,gz", comments="", fmt="%.17g")
    ref = _matrix(run_cli, ref_log, "--columns", "time,gx,gy,gz")
    got = _matrix(run_cli, log, "--columns", "time,gx,gy,gz", "--gyro-units", "131 LSB/(deg/s)")
    np.testing.assert_allclose(got["M"], ref["M"], atol=1e-9)
    np.testing.assert_allclose(got["bias"], ref["bias"], atol=1e-9)
    assert got["units"]["bias"] == "deg/s" and got["inputs"]["gyro_units"] == "131 LSB/(deg/s)"
    err = _one_line(run_cli("matrix", log, "--plan", PLAN, "--columns", "time,gx,gy,gz", "--gyro-units", "counts"))
    assert "dimensionless" in err and "--gyro-units '0.0076336 deg/s'" in err, err


# ---------------------------------------------------------------- the options themselves

COMMANDS = [("matrix",), ("apply",), ("allan",), ("calibrate", "accel"), ("calibrate", "ferraris"),
            ("calibrate", "mag")]


@pytest.mark.parametrize("path", COMMANDS, ids=" ".join)
def test_every_command_that_reads_a_log_has_the_options(run_cli, path):
    shown = run_cli(*path, "--help").out
    for flag in FORMAT_OPTIONS:
        assert flag in shown, (path, flag)
    has_time = path not in (("calibrate", "ferraris"), ("calibrate", "mag"))   # those read no time column
    assert ("--time-units" in shown) == has_time, path


@pytest.mark.parametrize("flag, bad", [("--skip-rows", "-1"), ("--skip-rows", "two"), ("--skip-rows", "1.5"),
                                       ("--comment", "ab"), ("--comment", "1"), ("--comment", ""),
                                       ("--delimiter", "ab"), ("--delimiter", "7"), ("--delimiter", ""),
                                       ("--time-units", "h"), ("--time-units", "sec")])
def test_a_bad_option_value_is_one_line_naming_the_option(run_cli, flag, bad):
    err = _one_line(run_cli("matrix", SESSION, "--plan", PLAN, f"{flag}={bad}"))
    assert flag in err, err


def test_a_comment_equal_to_the_delimiter_and_text_options_on_npy_are_refused(run_cli, tmp_path):
    err = _one_line(run_cli("matrix", SESSION, "--plan", PLAN, "--comment", ";", "--delimiter", ";"))
    assert "--comment" in err
    header, rows = _session_text()
    np.save(tmp_path / "s.npy", np.array([[float(c) for c in r.split(",")] for r in rows]))
    err = _one_line(run_cli("matrix", tmp_path / "s.npy", "--plan", PLAN, "--skip-rows", "2"))
    assert "--skip-rows" in err and ".npy" in err, err
    err = _one_line(run_cli("matrix", SESSION, "--plan", PLAN, "--rate-hz", "100", "--columns", "gyro_x,gyro_y,gyro_z",
                            "--time-units", "s"))
    assert "--time-units" in err and "--rate-hz" in err, err


def test_calibrate_mag_with_semicolons_and_a_preamble(run_cli, tmp_path):
    rng = np.random.default_rng(3)
    v = rng.normal(size=(600, 3))
    m = 48.0 * v / np.linalg.norm(v, axis=1)[:, None] @ np.diag([1.05, 0.97, 1.0]) + [10.0, -5.0, 3.0]
    plain, fancy = tmp_path / "mag.csv", tmp_path / "mag_fancy.csv"
    np.savetxt(plain, m, delimiter=",", header="mag_x,mag_y,mag_z", comments="", fmt="%.12g")
    fancy.write_text("device;HMC\nrate;50 Hz\n" + plain.read_text().replace(",", ";"))
    ref, got = tmp_path / "ref.json", tmp_path / "got.json"
    assert run_cli("calibrate", "mag", plain, "--json", ref).code == 0
    res = run_cli("calibrate", "mag", fancy, "--skip-rows", "2", "--delimiter", ";", "--json", got)
    assert res.code == 0, res.err
    a, b = json.loads(ref.read_text()), json.loads(got.read_text())
    assert a["hard_iron"] == b["hard_iron"] and b["inputs"]["delimiter"] == ";" and b["inputs"]["skip_rows"] == 2


@pytest.mark.slow
def test_report_reads_a_logger_file_with_its_options(tmp_path, run_cli):
    """The report's rate-table log goes through the same reader options as matrix (issue 12)."""
    src = ROOT / "examples/alignment"
    rows = (src / "session.csv").read_text().splitlines()
    log = tmp_path / "logger.csv"
    log.write_text("logger v2\nsample rate,100\n" + "\n".join(r.replace(",", ";") for r in rows) + "\n")
    out = tmp_path / "r.html"
    args = ("report", "--mount", ROOT / "examples/budget/example1.toml", "--manoeuvre",
            ROOT / "examples/sensitivity/example2.toml", "--log", log, "--plan", src / "plan.toml", "--out", out,
            "--monte-carlo", "1000")
    res = run_cli(*args)
    assert res.code == 2 and "--skip-rows 2" in res.err and not out.exists()
    res = run_cli(*args, "--skip-rows", "2", "--delimiter", ";")
    assert res.code == 0, res.err
    plain = run_cli("matrix", src / "session.csv", "--plan", src / "plan.toml")
    psi = next(line for line in plain.out.splitlines() if "psi (axis-frame)" in line)
    assert "alignment: psi" in res.out and psi.split()[2][2:7] in res.out


def test_allan_on_raw_gyro_counts_without_their_size_is_refused(run_cli):
    """The MPU-6050 static record holds raw counts: read as deg/s its x gyro would sit at -428 deg/s, which no gyro
    at rest reads (a user study found the figures accepted silently)."""
    log = SHARED / "data/static/mpu6050_tomisuarez2/imu_static_test.csv"
    res = run_cli("allan", log, "--skip-rows", "4", "--columns", "gx,gy,gz", "--rate-hz", "100")
    assert res.code == 3 and "channel gx reads -428 deg/s" in res.err and "--gyro-units" in res.err
    assert res.err.count("\n") == 1 and "Traceback" not in res.err
