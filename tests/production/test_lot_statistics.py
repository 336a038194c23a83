"""The spec (units at the edge) and the lot's statistics, against populations of known truth over many seeds."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats as sst

from align.errors import InputError
from align.production import lot_statistics, read_spec
from align.production.stats import cpk, robust_z, trend
from align.units import DEG

# ---------------------------------------------------------------- the spec


def test_limits_are_parsed_in_their_units_and_patterns_expand(tmp_path):
    (tmp_path / "s.toml").write_text('''
"phi_*" = { abs_max = "0.1 deg" }
scale_x = { min = 0.995, max = 1.005 }
arw_x = { max = "0.3 deg/sqrt(h)" }
bias_y = { abs_max = "0.05 m/s^2" }
[magnetometer]
heading_error = { max = "1 deg" }
''')
    spec = read_spec(tmp_path / "s.toml")
    phis = [lim for lim in spec.limits if lim.figure.startswith("phi_")]
    assert len(phis) == 6 and all(lim.sensor == "" and lim.symmetric for lim in phis)
    assert phis[0].high == pytest.approx(0.1 * DEG) and phis[0].low == pytest.approx(-0.1 * DEG)
    assert phis[0].describe() == "|phi_xy| <= 0.1 deg"
    scale = spec.limits_for("scale_x", "gyroscope")[0]
    assert (scale.low, scale.high) == (0.995, pytest.approx(1.005)) and scale.describe() == "0.995 <= scale_x <= 1.005"
    arw = spec.limits_for("arw_x", "gyroscope")
    assert len(arw) == 1 and arw[0].high == pytest.approx(0.3 * DEG / 60) and not spec.limits_for("arw_x", "accelerometer")
    assert [lim.sensor for lim in spec.limits if lim.figure == "bias_y"] == ["accelerometer"]  # by its dimension
    assert spec.limits_for("heading_error", "magnetometer") and not spec.limits_for("heading_error", "gyroscope")


@pytest.mark.parametrize("text, words", [
    ('phi_xx = { abs_max = "0.1 deg" }', "phi_xx: no figure is named so"),
    ('phy_xy = { abs_max = "0.1 deg" }', "(did you mean phi_xy?)"),
    ('phi_xy = { abs_max = "0.1 mm" }', "phi_xy: 'mm' is not a unit of phi_xy; write it like 'deg'"),
    ('phi_xy = { abs_max = 0.1 }', "phi_xy: '1' is not a unit of phi_xy"),
    ('bias_x = { max = "2 s" }', "bias_x: 's' is not a unit of bias_x; write it like "),
    ('scale_x = { min = 1.01, max = 0.99 }', "scale_x: min is above max"),
    ('scale_x = { low = 0.99 }', "scale_x: unknown bound 'low'; use min, max or abs_max"),
    ('scale_x = { abs_max = 1, max = 2 }', "give abs_max, or min and/or max, not both"),
    ('scale_x = 1.0', "scale_x: give its limits as a table"),
    ('[gyroscope]\nfield = { max = "60 uT" }', "gyroscope.field: 'uT' is not a unit of field for the gyroscope"),
    ('phi_xy = { abs_max = "x deg" }', "phi_xy.abs_max: 'x deg' does not start with a number"),
])
def test_a_bad_spec_is_one_error_naming_the_key(tmp_path, text, words):
    (tmp_path / "s.toml").write_text(text + "\n")
    with pytest.raises(InputError) as exc:
        read_spec(tmp_path / "s.toml")
    assert words in str(exc.value), str(exc.value)

# ---------------------------------------------------------------- the statistics, against known populations


def test_cpk_and_its_standard_error_cover_the_population_s_cpk():
    """Normal samples of known mean and sigma: Cpk_true = min(USL - mu, mu - LSL) / (3 sigma); the estimate
    lands within 2 of its standard errors in about 95 % of 400 lots."""
    rng = np.random.default_rng(0)
    mu, sigma, low, high, n = 0.2, 1.0, -3.0, 4.0, 60
    true = min(high - mu, mu - low) / (3 * sigma)
    hits = 0
    for _ in range(400):
        c, se = cpk(rng.normal(mu, sigma, n), low, high)
        hits += abs(c - true) < 2 * se
    assert 0.91 < hits / 400 < 0.985
    one_sided, _ = cpk(np.array([1.0, 2.0, 3.0]), None, 5.0)
    assert one_sided == pytest.approx((5 - 2) / 3)
    assert math.isnan(cpk(np.array([1.0]), -1, 1)[0])


def test_robust_z_flags_planted_outliers_and_few_clean_points():
    rng = np.random.default_rng(1)
    false = 0
    for _ in range(200):
        x = rng.normal(0, 1, 100)
        x[:2] = [9.0, -8.0]
        z = robust_z(x)
        assert abs(z[0]) > 3.5 and abs(z[1]) > 3.5
        false += int(np.sum(np.abs(z[2:]) > 3.5))
    assert false / (200 * 98) < 0.002  # |z| > 3.5 of a normal: 0.05 %, a little more for the estimated scale
    assert np.all(robust_z(np.ones(5)) == 0)


def test_the_trend_s_slope_and_its_uncertainty_cover_the_true_slope():
    rng = np.random.default_rng(2)
    x = np.arange(80.0)
    hits = 0
    for _ in range(400):
        b, se = trend(x, 0.3 + 0.01 * x + rng.normal(0, 0.5, len(x)))
        hits += abs(b - 0.01) < se * sst.t.ppf(0.975, len(x) - 2)
    assert 0.92 < hits / 400 < 0.98


def _rows(values, figure="phi_xy", sensor="gyroscope", status="ok"):
    return [{"serial": f"U{k}", "job": "matrix", "order": k, "time": None, "status": status, "sensor": sensor,
             "message": "", figure: float(v)} for k, v in enumerate(values)]


def test_lot_statistics_of_a_known_population(tmp_path):
    (tmp_path / "s.toml").write_text('phi_xy = { abs_max = "0.1 deg" }\n')
    rng = np.random.default_rng(3)
    v = rng.normal(0.01, 0.03, 300) * DEG
    v[7] = 0.5 * DEG  # out of spec and an outlier
    rows = _rows(v) + [{"serial": "BAD", "job": "matrix", "order": 300, "time": None, "status": "failed",
                        "sensor": None, "message": "imu-align: error: x.csv: file not found"}]
    stats = lot_statistics(rows, read_spec(tmp_path / "s.toml"))
    (fs,) = stats.figures
    assert fs.n == 300 and fs.unit == "deg"
    assert fs.mean == pytest.approx(v.mean()) and fs.std == pytest.approx(v.std(ddof=1))
    within = np.abs(v) <= 0.1 * DEG
    assert fs.passed == within.sum() and fs.yield_ == pytest.approx(within.mean())
    assert "U7" in fs.outliers and "U7" in fs.out_of_control
    assert stats.count == 301 and stats.passed == within.sum()  # the failed unit counts as not passing
    assert stats.units[0].verdict in ("fail", "failed") and stats.units[-1].verdict == "pass"
    bad = {u.serial: u for u in stats.units if u.verdict != "pass"}
    assert bad["BAD"].reasons == ("imu-align: error: x.csv: file not found",)
    assert bad["U7"].reasons == ("phi_xy = 0.5 deg, outside |phi_xy| <= 0.1 deg",)
    assert abs(fs.slope) < 4 * fs.slope_sigma  # no drift planted


def test_a_unit_of_two_sensors_takes_the_worse_verdict(tmp_path):
    (tmp_path / "s.toml").write_text('bias_x = { abs_max = "0.5 m/s^2" }\n')
    rows = [{"serial": "F1", "job": "calibrate ferraris", "order": 0, "time": None, "status": "ok",
             "sensor": "gyroscope", "message": "", "bias_x": 3.0},  # rad/s: no acceleration limit applies
            {"serial": "F1", "job": "calibrate ferraris", "order": 0, "time": None, "status": "ok",
             "sensor": "accelerometer", "message": "", "bias_x": 0.7}]
    stats = lot_statistics(rows, read_spec(tmp_path / "s.toml"))
    assert [(u.serial, u.verdict) for u in stats.units] == [("F1", "fail")]
    assert [(f.figure, f.sensor) for f in stats.figures] == [("bias_x", "accelerometer")]


def test_the_trend_over_time_is_per_day(tmp_path):
    from datetime import UTC, datetime, timedelta

    (tmp_path / "s.toml").write_text('scale_x = { min = 0.99, max = 1.01 }\n')
    t0 = datetime(2026, 1, 5, tzinfo=UTC)
    rows = [{"serial": f"U{k}", "job": "matrix", "order": 0, "time": t0 + timedelta(hours=6 * k), "status": "ok",
             "sensor": "gyroscope", "message": "", "scale_x": 1.0 + 1e-4 * (k / 4)} for k in range(40)]
    (fs,) = lot_statistics(rows, read_spec(tmp_path / "s.toml"), "time").figures
    assert fs.slope == pytest.approx(1e-4) and fs.x[-1] == pytest.approx(39 / 4)  # 1e-4 per day over 10 days
