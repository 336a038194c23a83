"""Review 17's lot findings, against hand computations: counts never pooled with SI, populations per job,
overlapping and % scale limits, limits not checked, Wilson yield, outliers from 8 units, a foreign table,
the journal folded twice, the version in the content hash."""

from __future__ import annotations

import json
import math
from datetime import UTC, datetime, timedelta

import numpy as np
import pandas as pd
import pytest

import align
from align.errors import InputError
from align.production import lot_statistics, read_spec
from align.production.manifest import input_hash
from align.production.stats import wilson
from align.production.store import Journal, append_rows, read_table
from align.units import DEG

T0 = datetime(2026, 1, 1, tzinfo=UTC)


def _row(serial, job, sensor, order, bias_unit, **figures):
    return {"serial": serial, "job": job, "sensor": sensor, "order": order, "time": T0 + timedelta(minutes=order),
            "run": "r1", "status": "ok", "message": "", "bias_unit": bias_unit, **figures}


def _spec(tmp_path, text):
    (tmp_path / "s.toml").write_text(text)
    return read_spec(tmp_path / "s.toml")


def _mixed():
    """A calibration in counts (A-*: bias 33124 counts, M 400 counts per m/s^2) and Ferraris units in SI (F-*)."""
    rows = []
    for k in range(3):
        rows.append(_row(f"A-{k}", "calibrate accel", "accelerometer", k, "count", bias_x=33000.0 + 100 * k,
                         scale_x=400.0 + k, phi_xy=0.01 * DEG))
        rows.append(_row(f"F-{k}", "calibrate ferraris", "accelerometer", 3 + k, "m/s^2", bias_x=0.5 + 0.02 * k,
                         scale_x=1.0 + 1e-4 * k, phi_xy=0.02 * DEG))
    return rows


def test_counts_and_si_are_separate_populations_each_in_its_unit():
    stats = lot_statistics(_mixed())
    bias = {(fs.job, fs.reading_unit): fs for fs in stats.figures if fs.figure == "bias_x"}
    counts, si = bias[("calibrate accel", "count")], bias[("calibrate ferraris", "m/s^2")]
    assert counts.n == si.n == 3
    assert counts.unit == "count" and counts.shown(counts.mean) == pytest.approx(33100.0)  # (33000+33100+33200)/3
    assert si.unit == "m/s^2" and si.shown(si.mean) == pytest.approx(0.52)  # (0.50+0.52+0.54)/3
    scale = {fs.job: fs for fs in stats.figures if fs.figure == "scale_x"}
    assert scale["calibrate accel"].unit == "count/(m/s^2)" and scale["calibrate accel"].mean == pytest.approx(401.0)
    assert scale["calibrate ferraris"].unit == "1" and scale["calibrate ferraris"].mean == pytest.approx(1.0001)


def test_an_si_limit_is_not_applied_to_counts_and_the_unit_is_not_a_pass(tmp_path):
    spec = _spec(tmp_path, '[accelerometer]\nbias_x = { abs_max = "0.6 m/s^2" }\n')
    stats = lot_statistics(_mixed(), spec)
    verdict = {u.serial: u for u in stats.units}
    assert all(verdict[f"F-{k}"].verdict == "pass" for k in range(3))  # 0.50..0.54 m/s^2 within 0.6
    for k in range(3):  # 33000 counts is not 33000 m/s^2: not judged, and not a pass either
        assert verdict[f"A-{k}"].verdict == "unchecked" and "bias_x not checked (in counts)" in verdict[f"A-{k}"].reasons
    assert stats.passed == 3 and stats.count == 6
    assert len(stats.notes) == 1 and "3 of 6 units" in stats.notes[0] and "in counts" in stats.notes[0]
    counts = [fs for fs in stats.figures if fs.figure == "bias_x" and fs.reading_unit == "count"][0]
    assert counts.limit is None and math.isnan(counts.cpk)


def test_matrix_and_calibrate_gyro_are_not_pooled_and_a_serial_is_one_unit_over_its_jobs():
    rows = [_row("U1", "matrix", "gyroscope", 0, "rad/s", scale_x=1.001, bias_x=0.01),
            _row("U1", "allan", "gyroscope", 0, "rad/s", bias_x=0.02, arw_x=1e-4),
            _row("U2", "calibrate gyro", "gyroscope", 1, "rad/s", scale_x=0.998, bias_x=0.03)]
    stats = lot_statistics(rows)
    assert stats.count == 2 and {u.serial: u.job for u in stats.units}["U1"] == "matrix, allan"
    scale = {fs.job: fs.n for fs in stats.figures if fs.figure == "scale_x"}
    bias = {fs.job: fs.mean for fs in stats.figures if fs.figure == "bias_x"}
    assert scale == {"matrix": 1, "calibrate gyro": 1} and bias == {"matrix": 0.01, "allan": 0.02, "calibrate gyro": 0.03}


def test_a_serial_fails_when_any_of_its_jobs_fails(tmp_path):
    spec = _spec(tmp_path, '"phi_*" = { abs_max = "0.1 deg" }\n"arw_?" = { max = "1 deg/sqrt(h)" }\n')
    good = {f"phi_{p}": 0.0 for p in ("xy", "xz", "yx", "yz", "zx", "zy")}
    rows = [_row("U1", "matrix", "gyroscope", 0, "rad/s", **good),
            {**_row("U1", "allan", "gyroscope", 0, "rad/s"), "status": "failed", "message": "too short"},
            _row("U2", "matrix", "gyroscope", 1, "rad/s", **good),
            _row("U2", "allan", "gyroscope", 1, "rad/s", arw_x=0.1 * DEG / 60, arw_y=0.1 * DEG / 60,
                 arw_z=0.1 * DEG / 60)]
    stats = lot_statistics(rows, spec)
    verdict = {u.serial: u for u in stats.units}
    assert verdict["U1"].verdict == "failed" and verdict["U1"].reasons == ("allan: too short",)
    assert verdict["U2"].verdict == "pass" and stats.passed == 1


def test_overlapping_limits_are_refused_naming_both_keys(tmp_path):
    with pytest.raises(InputError) as exc:
        _spec(tmp_path, 'phi_xy = { abs_max = "1 deg" }\n"phi_*" = { abs_max = "0.01 deg" }\n')
    assert "phi_xy and phi_* both limit phi_xy" in str(exc.value)
    with pytest.raises(InputError) as exc:
        _spec(tmp_path, '"bias_?" = { abs_max = "1 deg/s" }\n[gyroscope]\nbias_x = { abs_max = "2 deg/s" }\n')
    assert "bias_? and gyroscope.bias_x both limit bias_x of the gyroscope" in str(exc.value)


def test_a_scale_limit_in_percent_is_the_deviation_from_1_and_one_excluding_1_is_refused(tmp_path):
    spec = _spec(tmp_path, '"scale_*" = { abs_max = "0.5 %" }\n')
    lim = spec.limits_for("scale_x", "gyroscope")[0]
    assert (lim.low, lim.high) == (pytest.approx(0.995), pytest.approx(1.005))
    assert lim.ok(1.004) and lim.ok(0.996) and not lim.ok(1.006) and not lim.ok(0.004)
    assert lim.describe() == "|scale_x - 1| <= 0.5 %"
    ppm = _spec(tmp_path, 'scale_y = { min = "-300 ppm", max = "500 ppm" }\n').limits[0]
    assert (ppm.low, ppm.high) == (pytest.approx(0.9997), pytest.approx(1.0005))
    for text in ('scale_x = { min = -0.005, max = 0.005 }', 'scale_x = { min = 1.01 }'):
        with pytest.raises(InputError) as exc:
            _spec(tmp_path, text + "\n")
        assert "scale_x: its range excludes 1" in str(exc.value)
    with pytest.raises(InputError, match="both bounds in %"):
        _spec(tmp_path, 'scale_x = { min = 0.995, max = "0.5 %" }\n')


def test_a_limit_no_unit_gives_or_a_nan_figure_is_not_checked_and_not_a_pass(tmp_path):
    spec = _spec(tmp_path, '[gyroscope]\n"arw_?" = { max = "0.3 deg/sqrt(h)" }\n')
    matrix = [_row(f"U{k}", "matrix", "gyroscope", k, "rad/s", scale_x=1.0) for k in range(4)]
    stats = lot_statistics(matrix, spec)
    assert stats.passed == 0 and all(u.verdict == "unchecked" for u in stats.units)
    assert len(stats.notes) == 3 and "not checked for 4 of 4 units" in stats.notes[0]
    ok = 0.1 * DEG / 60
    allan = [_row("N1", "allan", "gyroscope", 0, "rad/s", arw_x=ok, arw_y=ok, arw_z=ok),
             _row("N2", "allan", "gyroscope", 1, "rad/s", arw_x=ok, arw_y=math.nan, arw_z=ok)]
    stats = lot_statistics(allan, spec)
    verdict = {u.serial: u for u in stats.units}
    assert verdict["N1"].verdict == "pass" and verdict["N2"].verdict == "unchecked"
    assert verdict["N2"].reasons == ("arw_y not checked (not given)",) and stats.passed == 1


def test_the_yield_interval_is_wilson():
    # hand values (Wilson 1927, z = 1.96): 2 of 2 -> [0.3424, 1]; 0 of 2 -> [0, 0.6576]; 95 of 100 -> [0.8883, 0.9785]
    assert wilson(2, 2) == (pytest.approx(0.3424, abs=1e-4), 1.0)
    assert wilson(0, 2) == (0.0, pytest.approx(0.6576, abs=1e-4))
    lo, hi = wilson(95, 100)
    assert lo == pytest.approx(0.8883, abs=1e-4) and hi == pytest.approx(0.9785, abs=1e-4)


@pytest.mark.parametrize("n, named", [(3, False), (7, False), (8, True), (20, True)])
def test_outliers_are_named_from_8_units_on(n, named):
    rng = np.random.default_rng(n)
    values = list(1.0 + 1e-4 * rng.standard_normal(n - 1)) + [1.01]  # the last is 100 sigma off
    rows = [_row(f"U{k}", "matrix", "gyroscope", k, "rad/s", scale_x=v) for k, v in enumerate(values)]
    fs = [f for f in lot_statistics(rows).figures if f.figure == "scale_x"][0]
    assert (f"U{n - 1}" in fs.outliers) is named and (len(fs.outliers) <= 1)


def test_a_foreign_parquet_is_one_line(tmp_path):
    pd.DataFrame({"serial": ["a"], "M_xx": [1.0]}).to_parquet(tmp_path / "f.parquet")
    with pytest.raises(InputError) as exc:
        read_table(tmp_path / "f.parquet")
    assert "not an imu-align lot table" in str(exc.value) and "results.parquet of imu-align batch" in str(exc.value)


def test_folding_a_journal_twice_adds_its_rows_once(tmp_path):
    table = tmp_path / "results.parquet"
    rows = [_row(f"U{k}", "matrix", "gyroscope", k, "rad/s", scale_x=1.0) for k in range(3)]
    append_rows(table, rows[:1])
    journal = Journal(table)
    with open(journal.path, "w") as fh:  # a kill after the table's rewrite, before the journal's removal
        for r in rows:
            fh.write(json.dumps({**r, "time": r["time"].isoformat()}) + "\n")
    journal.fold()
    assert read_table(table).num_rows == 3
    with open(journal.path, "w") as fh:
        fh.write(json.dumps({**rows[2], "time": rows[2]["time"].isoformat()}) + "\n")
    journal.fold()
    assert read_table(table).num_rows == 3


def test_the_version_enters_the_content_hash(tmp_path, monkeypatch):
    (tmp_path / "log.csv").write_text("1,2,3\n")
    before = input_hash("matrix", ("--margin", "1 s"), [tmp_path / "log.csv"])
    assert input_hash("matrix", ("--margin", "1 s"), [tmp_path / "log.csv"]) == before
    monkeypatch.setattr(align, "__version__", align.__version__ + ".post1")
    assert input_hash("matrix", ("--margin", "1 s"), [tmp_path / "log.csv"]) != before


@pytest.mark.slow
def test_the_report_draws_every_figure_keeps_tables_in_the_page_and_no_spec_legend_without_a_spec():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from align.present.lot import MAX_PANELS, _legend, lot_report_html

    rng = np.random.default_rng(1)
    names = [f"scale_{a}" for a in "xyz"] + [f"phi_{p}" for p in ("xy", "xz", "yx", "yz", "zx", "zy")] \
        + [f"delta_{p}" for p in ("xy", "xz", "yz")] + [f"bias_{a}" for a in "xyz"]
    rows = [_row(f"U{k}", job, "gyroscope", k, "rad/s", **{n: float(rng.normal(1 if n[0] == "s" else 0, 1e-3))
                                                              for n in names})
            for k in range(10) for job in ("matrix", "calibrate gyro")]
    stats = lot_statistics(rows)
    n = len(stats.figures)
    assert n == 2 * len(names) > MAX_PANELS  # two jobs: two populations of each figure
    html = lot_report_html(stats, "t.parquet")
    pictures = 2 * math.ceil(n / MAX_PANELS)  # histograms and control charts, every figure
    assert html.count("data:image/png;base64,") == pictures and f"All {n} figures" in html
    assert 'overflow-x' not in html and html.split("Statistics")[1].count('<table class="fit">') == 2
    fig, ax = plt.subplots()
    _legend(ax, stats.figures[0], False, ("mean", "k", "-"))
    assert "outside the spec" not in [t.get_text() for t in ax.get_legend().get_texts()]
    _legend(ax, stats.figures[0], True, ("mean", "k", "-"))
    assert "outside the spec" in [t.get_text() for t in ax.get_legend().get_texts()]
    plt.close(fig)


@pytest.mark.parametrize("text, words", [
    ('[gyro]\nphi_xy = { abs_max = "1 deg" }\n', "gyro: neither a figure nor a sensor table (did you mean gyroscope?)"),
    ('[test]\nrate_accuracy = 0.01\n', "test: neither a figure nor a sensor table"),
])
def test_a_table_that_is_not_a_sensor_says_so(tmp_path, text, words):
    with pytest.raises(InputError) as exc:
        _spec(tmp_path, text)
    assert words in str(exc.value), str(exc.value)
