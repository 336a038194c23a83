"""The field -> flag table, old spellings, the sample rate and quantity types."""

import json

import numpy as np
import pytest

from align.cli.options import hertz, quantity, rewrite_aliases, spell, speller
from align.errors import InputError, UnitError
from align.units import DEG


@pytest.mark.parametrize("name,value,command,expected", [
    ("rate_hz", None, None, "--rate-hz"),
    ("gyro_units", "deg/s", None, "--gyro-units deg/s"),
    ("json_out", None, None, "--json"),
    ("min_dwell", "2 s", "matrix", "--min-dwell '2 s'"),
    ("method", "two-axis", "matrix", "--method two-axis"),
    ("earth_correction", "false", "matrix", "--no-earth"),
    ("fs", None, "simulate", "--rate-hz"),
    ("units", None, "apply", "--units"),
    ("units", None, "calibrate accel", "--accel-units"),
    ("acc_units", None, "calibrate ferraris", "--accel-units"),
    ("log", None, "matrix", "LOG"),
    ("log", None, "report", "--log"),
    ("table_rate", None, "report", "--rate"),
])
def test_spell(name, value, command, expected):
    assert spell(name, value, command) == expected


def test_library_errors_render_with_flags():
    err = UnitError("'mm' is not an angular rate", "{gyro_units}")
    assert err.render(speller("matrix")) == "--gyro-units: 'mm' is not an angular rate"
    err = InputError("measured rates are 57.3x the plan's: set {gyro_units=deg/s}", "log.csv")
    assert err.render(speller("matrix")).endswith("set --gyro-units deg/s")
    assert str(err).endswith("set gyro_units='deg/s'")  # the library's own spelling is unchanged


def test_aliases_are_rewritten_per_command():
    assert rewrite_aliases("simulate session", ["out", "--fs", "100 Hz"]) == ["out", "--rate-hz", "100 Hz"]
    assert rewrite_aliases("simulate session", ["out", "--fs=100"]) == ["out", "--rate-hz=100"]
    assert rewrite_aliases("matrix", ["log", "--fs", "100"]) == ["log", "--fs", "100"]  # not an option of matrix
    assert rewrite_aliases("calibrate accel", ["x", "--units", "counts", "--", "--units"]) == \
        ["x", "--accel-units", "counts", "--", "--units"]
    assert rewrite_aliases("report", ["--allan-units", "rad/s", "--allan-columns", "a,b,c", "--allan-rate-hz", "10"]) == \
        ["--units", "rad/s", "--columns", "a,b,c", "--rate-hz", "10"]


@pytest.mark.parametrize("text,hz", [("100", 100.0), ("102.4", 102.4), ("100 Hz", 100.0), ("2 kHz", 2000.0), (50, 50.0)])
def test_sample_rate_accepts_a_bare_number_or_a_frequency(text, hz):
    assert hertz(text) == pytest.approx(hz)


@pytest.mark.parametrize("text", ["fast", "100 deg", "0", "-5 Hz"])
def test_sample_rate_refuses(text):
    with pytest.raises(ValueError):
        hertz(text)


def test_quantity_is_si():
    assert quantity("angle")("0.05 deg") == pytest.approx(0.05 * DEG)
    assert quantity("dimensionless")("10 %") == pytest.approx(0.1)
    with pytest.raises(ValueError, match="not a time"):
        quantity("time")("2 mm")


def test_old_spellings_still_work(tmp_path, run_cli):
    """--fs on simulate (and '100 Hz' or a bare number on --rate-hz) give the same session."""
    runs = {}
    for flag, rate in (("--fs", "100 Hz"), ("--rate-hz", "100"), ("--rate-hz", "100 Hz")):
        out = tmp_path / flag.strip("-") / rate.replace(" ", "")
        res = run_cli("simulate", out, flag, rate, "--dwell", "2 s", "--gap", "1 s")
        assert res.code == 0, res.err
        runs[(flag, rate)] = (out / "session.csv").read_text()
        t = np.loadtxt(out / "session.csv", delimiter=",", skiprows=1, usecols=0)
        assert np.median(np.diff(t)) == pytest.approx(0.01)
    assert len(set(runs.values())) == 1
    truth = json.loads((out / "truth.json").read_text())
    assert truth["format"] == "imu-align.truth" and truth["version"] == 1 and {"M", "A", "bias", "seed"} <= set(truth)
