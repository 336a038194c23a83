"""Logger files as they come: preamble, comments, delimiters, time units, count sizes (align.io).

Truth from outside the readers: numpy/pandas parse the same files, the time stamps and rates are
the ones written, the MPU-6050 records in ../shared/data are read by pandas as their SOURCE.txt says.
"""

from __future__ import annotations

import gzip
import math

import numpy as np
import pandas as pd
import pytest
from support import SHARED

from align.errors import InputError, UnitError
from align.io import (
    LogFormat,
    read_columns,
    read_log,
    read_sensor_log,
    read_static,
    read_static_log,
    sensor_scale,
)
from align.io.formats import csv_source, delimiter_char, time_unit
from align.units import DEG, STANDARD_GRAVITY, parse_scale

MPU_STATIC = SHARED / "data" / "static" / "mpu6050_tomisuarez2" / "imu_static_test.csv"
MPU_MULTI = SHARED / "data" / "multiposition" / "mpu6050_tomisuarez2" / "example_data_calibration.csv"
needs_mpu = pytest.mark.skipif(not MPU_STATIC.is_file(), reason="../shared/data not present")
GYRO = ["gx", "gy", "gz"]


def _session(n: int = 400, fs: float = 200.0, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    g = np.column_stack([np.sin(t), np.cos(2 * t), 0.1 * t]) * 50 + rng.normal(0, 0.2, (n, 3))
    return t, g


def _write(path, header: list[str], rows: np.ndarray, sep: str = ",", before: str = "", fmt: str = "%.12g") -> None:
    body = "\n".join(sep.join(fmt % v for v in row) for row in rows)
    path.write_text(before + sep.join(header) + "\n" + body + "\n")


# ---------------------------------------------------------------- LogFormat and its values

@pytest.mark.parametrize("kwargs, field", [
    ({"skip_rows": -1}, "skip_rows"), ({"skip_rows": 1.5}, "skip_rows"), ({"skip_rows": True}, "skip_rows"),
    ({"comment": "ab"}, "comment"), ({"comment": "1"}, "comment"), ({"comment": " "}, "comment"),
    ({"comment": ","}, "comment"), ({"comment": ";", "delimiter": ";"}, "comment"),
    ({"delimiter": "ab"}, "delimiter"), ({"delimiter": "5"}, "delimiter"), ({"delimiter": "\n"}, "delimiter"),
    ({"time_units": "h"}, "time_units"), ({"time_units": "sec"}, "time_units"),
])
def test_a_bad_format_value_is_refused_naming_its_field(kwargs, field):
    with pytest.raises(InputError) as err:
        LogFormat(**kwargs)
    assert field in err.value.fields and "\n" not in str(err.value)


def test_delimiter_names_and_the_format_as_results_record_it():
    assert [delimiter_char(x) for x in ("tab", "\\t", "\t", "space", ";", "|", "comma")] == ["\t", "\t", "\t", " ", ";",
                                                                                             "|", ","]
    fmt = LogFormat(skip_rows=4, comment="#", delimiter="tab", time_units="ms")
    assert fmt.delimiter == "\t" and not fmt.plain and LogFormat().plain
    assert fmt.to_dict() == {"skip_rows": 4, "comment": "#", "delimiter": "tab", "time_units": "ms"}


# ---------------------------------------------------------------- time units

@pytest.mark.parametrize("fs", [12.5, 50.0, 100.0, 200.0, 1000.0, 2000.0, 4000.0, 8000.0])
@pytest.mark.parametrize("unit, size", [("s", 1.0), ("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9)])
def test_the_time_unit_is_detected_for_every_usual_imu_rate(fs, unit, size):
    """Detected when one unit alone gives 1 Hz - 10 kHz; from 1 kHz up a step in ms, us or ns also reads as 1-10 Hz
    in the next larger unit: then refused with both readings (a guess would be a silent factor of 1000), unless
    the time stamps are a Unix epoch."""
    step = 1.0 / fs / size   # the step as the file holds it
    if unit == "s" or fs < 1000:
        assert time_unit(step, "time", "log") == (unit, True)
    else:
        with pytest.raises(InputError, match="the unit cannot be told from the file") as err:
            time_unit(step, "time", "log")
        assert err.value.fields == ["time_units", "time_units"] and f"{fs:g} Hz in {unit}" in str(err.value)
    epoch = 1.7e9 / size  # 2023 in the file's unit
    assert time_unit(step, "time", "log", first=epoch) == (unit, True)


def test_seconds_up_to_100_khz_and_nanoseconds_down_to_1_hz():
    assert time_unit(1e-5, "t", "log")[0] == "s"
    assert time_unit(1e9, "t", "log")[0] == "ns"
    for step in (5e-6, 5e9):
        with pytest.raises(InputError, match=r"time column 't': its median step .* is no IMU sample interval") as err:
            time_unit(step, "t", "log")
        assert set(err.value.fields) == {"columns", "rate_hz"}


def test_a_given_time_unit_is_checked_and_the_fix_named():
    assert time_unit(0.5, "time", "log", "ms") == ("ms", False)
    assert time_unit(0.5, "time", "log", "s") == ("s", False)       # 2 Hz in seconds: slow but an IMU rate
    with pytest.raises(InputError) as err:
        time_unit(5.0, "stamp", "log.csv", "s")                       # 0.2 Hz
    msg = err.value.render(lambda n, v: f"--{n.replace('_', '-')}" + (f" {v}" if v else ""))
    assert msg.startswith("log.csv: time column 'stamp' in s:") and "--time-units ms" in msg, msg
    with pytest.raises(InputError, match="time column 'time' in us: .* 1e\\+08 Hz"):
        time_unit(0.01, "time", "log", "us")


@pytest.mark.parametrize("unit, factor, integer", [("ms", 1e3, False), ("us", 1e6, True), ("ns", 1e9, True)])
def test_a_log_timed_in_ms_us_ns_reads_like_the_one_in_seconds(tmp_path, unit, factor, integer):
    t, g = _session(fs=500.0)
    _write(tmp_path / "s.csv", ["time", *GYRO], np.column_stack([t, g]), fmt="%.17g")
    stamps = np.round(t * factor) if integer else t * factor
    _write(tmp_path / "u.csv", ["time", *GYRO], np.column_stack([stamps, g]), fmt="%.17g")
    ref = read_sensor_log(tmp_path / "s.csv", GYRO, "deg/s")
    got = read_sensor_log(tmp_path / "u.csv", GYRO, "deg/s")
    assert (ref.time_units, got.time_units, got.time_detected) == ("s", unit, True)
    np.testing.assert_allclose(got.t, t, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(got.data, ref.data)
    assert got.rate_hz == pytest.approx(500.0) and got.inputs()["time_units"] == unit
    assert unit in got.time_note() and ref.time_note() is None
    t2, _ = read_log(tmp_path / "u.csv", GYRO, "deg/s", log_format=LogFormat(time_units=unit))
    np.testing.assert_allclose(t2, t, atol=1e-12)


def test_a_time_unit_with_a_sample_rate_is_refused(tmp_path):
    t, g = _session()
    _write(tmp_path / "s.csv", ["time", *GYRO], np.column_stack([t, g]))
    with pytest.raises(InputError, match="applies to a time column") as err:
        read_log(tmp_path / "s.csv", GYRO, "deg/s", None, 200.0, log_format=LogFormat(time_units="s"))
    assert set(err.value.fields) == {"time_units", "rate_hz"}


def test_static_record_in_ms_gives_its_rate(tmp_path):
    t, g = _session(n=3000, fs=100.0)
    _write(tmp_path / "static.csv", ["time", "gyro_x", "gyro_y", "gyro_z"], np.column_stack([t * 1e3, g]), fmt="%.17g")
    got = read_static_log(tmp_path / "static.csv", ["gyro_x", "gyro_y", "gyro_z"], None)
    assert got.rate_hz == pytest.approx(100.0) and (got.time_units, got.time_detected) == ("ms", True)
    data, fs = read_static(tmp_path / "static.csv", ["gyro_x", "gyro_y", "gyro_z"], None)
    assert fs == pytest.approx(100.0)
    np.testing.assert_allclose(data, g, rtol=1e-11)


# ---------------------------------------------------------------- preamble, comments, delimiters

@needs_mpu
def test_mpu6050_record_with_skip_rows_is_what_pandas_reads():
    ref = pd.read_csv(MPU_STATIC, skiprows=4)                    # as SOURCE.txt says
    names, data = read_columns(MPU_STATIC, ["ax", "ay", "az", *GYRO], log_format=LogFormat(skip_rows=4))
    np.testing.assert_array_equal(data, ref[names].to_numpy(float))
    assert len(data) == 9986


@needs_mpu
def test_mpu6050_gyro_in_counts_per_deg_s_has_pandas_mean_and_std():
    raw = np.loadtxt(MPU_STATIC, delimiter=",", skiprows=5)[:, 3:]   # header at line 5
    got = read_sensor_log(MPU_STATIC, GYRO, "131 LSB/(deg/s)", None, 100.0, log_format=LogFormat(skip_rows=4))
    deg_s = got.data / DEG
    np.testing.assert_allclose(deg_s.mean(axis=0), raw.mean(axis=0) / 131, rtol=1e-12)
    np.testing.assert_allclose(deg_s.std(axis=0), raw.std(axis=0) / 131, rtol=1e-12)
    assert deg_s.mean(axis=0) == pytest.approx([-3.26826, 1.11757, -0.50384], abs=1e-5)
    assert got.shown == "deg/s" and got.units == "131 LSB/(deg/s)" and got.time_units is None
    size = read_sensor_log(MPU_STATIC, GYRO, "0.0076336 deg/s", None, 100.0, log_format=LogFormat(skip_rows=4))
    np.testing.assert_allclose(size.data, got.data, rtol=2e-5)   # 1/131 = 0.00763359


@needs_mpu
@pytest.mark.parametrize("path", [MPU_STATIC, MPU_MULTI], ids=["static", "multiposition"])
def test_a_preamble_left_out_is_named_with_the_rows_to_skip(path):
    for skip in (0, 2):
        with pytest.raises(InputError) as err:
            read_columns(path, GYRO, log_format=LogFormat(skip_rows=skip))
        msg = err.value.message
        assert "{skip_rows=4}" in msg and "Expected" not in msg and "\n" not in msg, msg
        assert "first 4 lines hold 2 fields" in msg and "line 5 on hold 6" in msg, msg


def test_comments_semicolons_tabs_blanks_and_gzip_read_like_the_plain_csv(tmp_path):
    t, g = _session()
    rows = np.column_stack([t, g])
    header = ["time", *GYRO]
    _write(tmp_path / "plain.csv", header, rows)
    ref = read_columns(tmp_path / "plain.csv", header)[1]
    _write(tmp_path / "semi.csv", header, rows, ";")
    _write(tmp_path / "tab.csv", header, rows, "\t")
    _write(tmp_path / "blank.txt", header, rows, "   ")
    lines = (tmp_path / "plain.csv").read_text().splitlines()
    commented = ["# logger 1.2", "#", lines[0], *[f"{x}  # note" if i == 3 else x for i, x in enumerate(lines[1:])]]
    commented.insert(50, "   # a comment line between samples")
    (tmp_path / "comments.csv").write_text("\n".join(commented) + "\n")
    (tmp_path / "comments.csv.gz").write_bytes(gzip.compress((tmp_path / "comments.csv").read_bytes()))
    preamble = "Fs;200\nLogging Type;1\n\n" + (tmp_path / "semi.csv").read_text()
    (tmp_path / "preamble.csv").write_text(preamble)
    for name, fmt in [("semi.csv", LogFormat(delimiter=";")), ("tab.csv", LogFormat(delimiter="tab")),
                      ("blank.txt", LogFormat(delimiter="space")), ("comments.csv", LogFormat(comment="#")),
                      ("comments.csv.gz", LogFormat(comment="#")), ("plain.csv", LogFormat(comment="%")),
                      ("preamble.csv", LogFormat(skip_rows=3, delimiter=";"))]:
        np.testing.assert_array_equal(read_columns(tmp_path / name, header, log_format=fmt)[1], ref, err_msg=name)


def test_the_plain_format_hands_the_file_to_pyarrow_untouched(tmp_path):
    t, g = _session()
    _write(tmp_path / "plain.csv", ["time", *GYRO], np.column_stack([t, g]))
    for fmt in (LogFormat(), LogFormat(skip_rows=3), LogFormat(delimiter=";"), LogFormat(comment="#")):
        source, _, _ = csv_source(tmp_path / "plain.csv", fmt)
        assert source() == tmp_path / "plain.csv"   # no copy: the path itself (the comment is not in the file)


@pytest.mark.parametrize("text, fix", [
    ("time;gx;gy;gz\n0;1;2;3\n0.01;1;2;3\n", "delimiter=;"),
    ("time\tgx\tgy\tgz\n0\t1\t2\t3\n0.01\t1\t2\t3\n", "delimiter=tab"),
    ("time gx gy gz\n0 1 2 3\n0.01 1 2 3\n", "delimiter=space"),
    ("# exported by logger\ntime,gx,gy,gz\n0,1,2,3\n# pause\n0.01,1,2,3\n", "comment=#"),
    ("Fs,100\nLogging Type,1\ntime,gx,gy,gz\n0,1,2,3\n0.01,1,2,3\n0.02,1,2,3\n", "skip_rows=2"),
])
def test_a_delimiter_or_comment_left_out_is_named(tmp_path, text, fix):
    (tmp_path / "log.csv").write_text(text)
    with pytest.raises(InputError) as err:
        read_columns(tmp_path / "log.csv", ["time", *GYRO])
    assert "{" + fix + "}" in err.value.message, err.value.message


@pytest.mark.parametrize("suffix", [".npy", ".parquet"])
def test_text_options_on_a_binary_log_are_refused(tmp_path, suffix):
    t, g = _session()
    data = np.column_stack([t, g])
    path = tmp_path / f"log{suffix}"
    if suffix == ".npy":
        np.save(path, data)
    else:
        pd.DataFrame(data, columns=["time", *GYRO]).to_parquet(path)
    with pytest.raises(InputError) as err:
        read_log(path, GYRO, "deg/s", log_format=LogFormat(skip_rows=2, comment="#"))
    assert set(err.value.fields) == {"skip_rows", "comment"} and suffix in str(err.value)
    assert read_log(path, GYRO, "deg/s", log_format=LogFormat(time_units="s"))[0] == pytest.approx(t)


def test_a_headerless_blank_table_with_a_preamble_and_comments(tmp_path):
    t, g = _session()
    body = "\n".join(" ".join(f"{v:.12g}" for v in row) for row in np.column_stack([t, g]))
    (tmp_path / "log.txt").write_text("logger v2\nstart 12:00\n% first\n" + body + "\n% end\n")
    _, data = read_columns(tmp_path / "log.txt", log_format=LogFormat(skip_rows=2, comment="%"))
    np.testing.assert_allclose(data, np.column_stack([t, g]), rtol=1e-11)


# ---------------------------------------------------------------- count sizes

@pytest.mark.parametrize("text, expect, size", [
    ("131 LSB/(deg/s)", "angular_rate", DEG / 131), ("0.0076336 deg/s", "angular_rate", 0.0076336 * DEG),
    ("0.0076336 deg/s/LSB", "angular_rate", 0.0076336 * DEG), ("16384 LSB/g", "acceleration", STANDARD_GRAVITY / 16384),
    ("0.061035 mg", "acceleration", 0.061035e-3 * STANDARD_GRAVITY), ("1090 LSB/gauss", "magnetic_field", 1e-4 / 1090),
    ("0.92 mG", "magnetic_field", 0.92e-7),
])
def test_a_count_size_or_a_datasheet_sensitivity(text, expect, size):
    factor, shown = parse_scale(text, expect)
    assert factor == pytest.approx(size, rel=1e-12) and shown in ("deg/s", "m/s^2", "uT")


@pytest.mark.parametrize("text", ["0 LSB/(deg/s)", "-0.0076 deg/s", "131 LSB/g", "5", "1e999 deg/s"])
def test_a_count_size_that_is_no_count_size_is_refused(text):
    with pytest.raises(UnitError):
        parse_scale(text, "angular_rate", "{gyro_units}")


def test_raw_counts_of_a_gyro_are_refused_with_the_count_size_to_give():
    with pytest.raises(UnitError) as err:
        sensor_scale("counts", "angular_rate", "gyro_units")
    msg = err.value.message
    assert "{gyro_units=0.0076336 deg/s}" in msg and "{gyro_units=131 LSB/(deg/s)}" in msg and "MPU-6050" in msg
    assert "dimensionless" in msg
    assert sensor_scale("counts", "acceleration", counts=True) == (1.0, "counts")
    assert sensor_scale("deg/s", "angular_rate") == (pytest.approx(DEG), "deg/s")


def test_a_count_size_scales_npy_chunks_read_in_bounded_memory(tmp_path):
    counts = np.arange(3000 * 3, dtype=float).reshape(3000, 3) % 97 - 48
    np.save(tmp_path / "static.npy", counts)
    got = read_static_log(tmp_path / "static.npy", ["x", "y", "z"], 100.0, scale=1 / 131)
    block = np.vstack(list(got.data.chunks(rows=1000)))
    np.testing.assert_allclose(block, counts / 131, rtol=1e-15)
    assert math.isclose(got.rate_hz, 100.0)


@pytest.mark.parametrize("eol", ["\n", "\r\n"])
def test_comments_and_blank_runs_keep_line_ends_and_drop_what_they_should(tmp_path, eol):
    from align.io.formats import _blanks_to_commas, _strip_comments

    text = eol.join(["# head", "t,x  # why", "   # indented", "1,2", "3,4 #"]) + "#tail"
    assert _strip_comments(text.encode(), "#").decode() == eol.join(["", "t,x", "", "1,2", "3,4"])
    blanks = eol.join(["  t \tx ", "1   2", "\t", "3 4  "])
    assert _blanks_to_commas(blanks.encode()).decode() == eol.join(["t,x", "1,2", "", "3,4"])
    (tmp_path / "log.csv").write_bytes(text.encode())
    _, data = read_columns(tmp_path / "log.csv", ["t", "x"], log_format=LogFormat(comment="#"))
    np.testing.assert_array_equal(data, [[1, 2], [3, 4]])


def test_a_clock_coarser_than_the_samples_points_to_the_sample_rate(tmp_path):
    """Integer milliseconds at 2 kHz: every other stamp repeats; the fix is to read at the sample rate, not to sort."""
    n = 4000
    t_ms = np.floor(np.arange(n) / 2.0)  # 2 kHz, ms clock
    f = tmp_path / "coarse.csv"
    f.write_text("time,gyro_x,gyro_y,gyro_z\n" + "\n".join(f"{a:.0f},0.1,0.2,0.3" for a in t_ms) + "\n")
    with pytest.raises(InputError, match="the clock is coarser than the sample interval") as err:
        read_log(f, ["gyro_x", "gyro_y", "gyro_z"], "deg/s")
    assert err.value.fields == ["rate_hz"]
    t, _ = read_log(f, ["gyro_x", "gyro_y", "gyro_z"], "deg/s", time_column=None, rate_hz=2000.0)
    assert t[-1] == pytest.approx((n - 1) / 2000.0)
