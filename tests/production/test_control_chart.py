"""The I-MR chart and its run rules: patterns built by hand fire at the unit that completes them, the in-control run
length matches the published one (Champ and Woodall 1987: 91.75 for rules 1-4, 370.4 for rule 1), and a drift starting
at a known unit is caught within a few units of it."""

from __future__ import annotations

import numpy as np
import pytest

from align.present.lot import lot_summary
from align.production import lot_statistics, read_spec
from align.production.control import control_chart

WE = ("1", "2", "3", "4")


def _first(values, rules=WE, **kw):
    sig = control_chart(np.asarray(values, float), centre=0.0, sigma=1.0, rules=rules, **kw).signals
    return [(s.rule, s.index, s.side) for s in sig]


@pytest.mark.parametrize("values, expected", [
    ([0.5, -0.5, 3.2, 0.1], [("1", 2, "above")]),
    ([0.5, -2.5, 0.3, -2.2, 0.1], [("2", 3, "below")]),  # 2 of 3 beyond 2 sigma, one side
    ([0.5, 2.5, -2.5, 0.1], []),  # beyond 2 sigma on two sides: nothing
    ([0.2, 1.5, 1.2, -0.3, 1.8, 1.1, -0.5], [("3", 5, "above")]),  # 4 of 5 beyond 1 sigma
    ([-0.1] + [0.3] * 8 + [-0.2], [("4", 8, "above")]),  # 8 in a row above
    ([-0.1] + [0.3] * 7 + [-0.2], []),  # 7 only
])
def test_each_rule_fires_at_the_point_that_completes_its_pattern(values, expected):
    assert _first(values) == expected


def test_the_moving_range_rule_and_the_signal_s_unit_name():
    chart = control_chart([0.0, 0.1, -0.1, 0.05, 0.0, 0.1, 2.0, 0.0], units=[f"SN{k}" for k in range(8)], reference=6)
    mr = [s for s in chart.signals if s.rule == "MR"]
    assert [(s.index, s.unit, s.count) for s in mr] == [(6, "SN6", 1)]  # |2.0 - 0.1| and |0.0 - 2.0|, one episode
    assert chart.mr == pytest.approx(np.mean([0.1, 0.2, 0.15, 0.05, 0.1])) and chart.mr_ucl == pytest.approx(3.267 * chart.mr)
    assert chart.sigma == pytest.approx(chart.mr / 1.128) and chart.reference == 6
    assert chart.first("1").describe() == "rule 1 (one point beyond 3 sigma, above) at unit SN6 (point 7 of the chart)"


def _run_length(rng, rules, length):
    x = rng.normal(size=length)
    sig = control_chart(x, centre=0.0, sigma=1.0, rules=rules).signals
    return sig[0].index + 1 if sig else length


def test_in_control_run_length_matches_champ_and_woodall():
    """Known limits: the average run length to a false signal is 91.75 for rules 1-4 (SE of 400 runs: about 4.6)."""
    rng = np.random.default_rng(11)
    arl = np.mean([_run_length(rng, WE, 1500) for _ in range(400)])
    assert 80 < arl < 104, arl
    arl1 = np.mean([_run_length(rng, ("1",), 3000) for _ in range(250)])  # SE about 23
    assert 320 < arl1 < 430, arl1


def test_an_in_control_lot_raises_false_signals_at_the_published_rate():
    """Lots of 50 units, limits from their own first units: rules 1-4 raise a false signal in about 1 - exp(-50/91.75)
    = 42 % of in-control lots (measured 46 %: estimated limits add a little); none in most lots."""
    rng = np.random.default_rng(12)
    alarms = np.mean([bool(control_chart(rng.normal(size=50), rules=WE).signals) for _ in range(400)])
    assert 0.33 < alarms < 0.56, alarms


@pytest.mark.parametrize("shape, within, rate", [("step", 5, 0.9), ("ramp", 10, 0.85)])
def test_a_drift_raises_a_rule_within_a_few_units_of_where_it_starts(shape, within, rate):
    """100 units, a drift from unit 60 (a 2 sigma step, or a ramp of 0.25 sigma per unit): the first signal at or after
    unit 60 comes within ``within`` units in at least ``rate`` of 200 lots (measured 0.95 and 0.93)."""
    rng = np.random.default_rng(13 if shape == "step" else 14)
    k = np.arange(100) - 60
    drift = 2.0 * (k >= 0) if shape == "step" else 0.25 * np.clip(k, 0, None)
    hit = 0
    for _ in range(200):
        sig = control_chart(rng.normal(size=100) + drift).signals
        after = [s.index for s in sig if s.index >= 60]
        hit += bool(after) and after[0] - 60 <= within
    assert hit / 200 >= rate


def test_the_lot_names_the_unit_where_a_rule_first_fires(tmp_path):
    (tmp_path / "s.toml").write_text('phi_xy = { abs_max = "0.5 deg" }\n')
    v = np.random.default_rng(21).normal(0.0, 1e-4, 120)
    v[80:] += 3e-4  # a 3 sigma step at U080
    rows = [{"serial": f"U{k:03d}", "job": "matrix", "order": k, "time": None, "status": "ok", "sensor": "gyroscope",
             "message": "", "phi_xy": float(x)} for k, x in enumerate(v)]
    stats = lot_statistics(rows, read_spec(tmp_path / "s.toml"))
    (fs,) = stats.figures
    after = [s for s in fs.chart.signals if s.index >= 80]
    assert after and after[0].index - 80 <= 3 and after[0].unit == f"U{after[0].index:03d}"
    text = lot_summary(stats, "lot.parquet")
    assert "control-chart signals (first unit per rule):" in text
    for rule in dict.fromkeys(s.rule for s in fs.chart.signals):  # each rule's first unit, named
        assert fs.chart.first(rule).describe() in text
    assert after[0].describe() in text or any((s.rule, s.side) == (after[0].rule, after[0].side)
                                              for s in fs.chart.signals if s.index < after[0].index)
