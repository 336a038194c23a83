"""Issue 27: ``imu-align lot --json`` writes the lot's statistics as a versioned JSON document (SI, units stated);
read back, its numbers match statistics computed here with numpy/scipy from the simulated lot's values."""

from __future__ import annotations

import json
import math
import warnings
from datetime import UTC, datetime, timedelta

import numpy as np
import pytest
from _lots import cli
from scipy import stats as sst

from align.errors import InputError
from align.production import append_rows
from align.production.lotjson import read_lot_json

N = 90
SPEC = 'phi_xy = { abs_max = "0.1 deg" }\nscale_x = { min = 0.995, max = 1.01 }\n'


def _lot(tmp_path):
    rng = np.random.default_rng(11)
    phi = rng.normal(0.0, np.radians(0.02), N)
    phi[70] = np.radians(0.15)  # out of spec, an outlier, a rule-1 signal at SN070
    scale = 0.998 + 0.002 * rng.lognormal(0.0, 0.6, N)  # skewed: the percentile Cpk
    t0 = datetime(2026, 11, 3, 7, 0, tzinfo=UTC)
    rows = [{"serial": f"SN{k:03d}", "order": k, "run": "r1", "time": t0 + timedelta(minutes=k), "job": "matrix",
             "sensor": "gyroscope", "status": "ok", "verdict": "pass", "message": "", "phi_xy": float(phi[k]),
             "scale_x": float(scale[k])} for k in range(N)]
    store = tmp_path / "out" / "results.parquet"
    append_rows(store, rows)
    (tmp_path / "spec.toml").write_text(SPEC)
    return store, phi, scale


def test_the_json_statistics_match_an_independent_computation(tmp_path):
    store, phi, scale = _lot(tmp_path)
    code, out, err = cli("lot", store, "--spec", tmp_path / "spec.toml", "--json", tmp_path / "lot.json")
    assert code == 4, err
    doc = read_lot_json(tmp_path / "lot.json")
    assert (doc["format"], doc["version"]) == ("imu-align.lot-statistics", 1)
    assert doc["lot"]["count"] == N and doc["lot"]["passed"] == N - 1 and doc["lot"]["yield"] == pytest.approx(89 / 90)
    assert doc["units"][0]["serial"] == "SN070" and doc["units"][0]["verdict"] == "fail"
    figs = {f["figure"]: f for f in doc["figures"]}
    p = figs["phi_xy"]
    assert (p["unit"], p["shown_unit"], p["title"]) == ("rad", "deg", "cross-axis misalignment")
    assert p["limit"]["high"] == pytest.approx(math.radians(0.1)) and p["limit"]["low"] == pytest.approx(-math.radians(0.1))
    assert p["n"] == N and p["mean"] == pytest.approx(phi.mean()) and p["std"] == pytest.approx(phi.std(ddof=1))
    assert (p["min"], p["max"]) == pytest.approx((phi.min(), phi.max()))
    assert p["passed"] == N - 1
    z = 0.6745 * (phi - np.median(phi)) / np.median(np.abs(phi - np.median(phi)))
    assert p["outliers"] == [f"SN{k:03d}" for k in np.flatnonzero(np.abs(z) > 3.5)] and "SN070" in p["outliers"]
    # the control chart: limits from the first max(20, n // 3) units, sigma = mean moving range / 1.128
    ref = phi[:max(20, N // 3)]
    ch = p["control_chart"]
    sigma = np.mean(np.abs(np.diff(ref))) / 1.128
    assert ch["centre"] == pytest.approx(ref.mean()) and ch["sigma"] == pytest.approx(sigma)
    assert ch["ucl"] == pytest.approx(ref.mean() + 3 * sigma) and ch["reference"] == len(ref)
    rule1 = [s for s in ch["signals"] if s["rule"] == "1"]
    assert {"unit": "SN070", "index": 70, "side": "above"}.items() <= rule1[0].items()
    # the capability: the skewed scale shows the percentile Cpk, because the Anderson-Darling test rejects normality
    c = figs["scale_x"]["capability"]
    assert figs["scale_x"]["unit"] == "1"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        assert c["normality"]["statistic"] == pytest.approx(float(sst.anderson(scale).statistic), rel=1e-9)
    assert c["normality"]["p"] < c["normality"]["alpha"] == 0.05 and c["shown"] == "percentile"
    lo, med, hi = c["percentile"]["quantiles"]
    assert med == pytest.approx(np.median(scale))
    assert c["cpk"] == pytest.approx(min((1.01 - med) / (hi - med), (med - 0.995) / (med - lo)))
    a, b = c["percentile"]["interval"]
    assert a < c["cpk"] < b and c["percentile"]["level"] == 0.95
    m, s = scale.mean(), scale.std(ddof=1)
    assert c["normal"]["cpk"] == pytest.approx(min(1.01 - m, m - 0.995) / (3 * s))
    assert c["normal"]["applicable"] is False and "not applicable" in c["normal"]["note"]
    assert "Anderson-Darling p" in c["why"]
    json.loads((tmp_path / "lot.json").read_text(), parse_constant=lambda name: pytest.fail(f"{name} in the JSON"))


def test_a_json_that_is_not_a_lots_is_refused(tmp_path):
    (tmp_path / "x.json").write_text('{"format": "something else"}')
    with pytest.raises(InputError, match="not a lot's JSON statistics"):
        read_lot_json(tmp_path / "x.json")
    (tmp_path / "y.json").write_text('{"format": "imu-align.lot-statistics", "version": 9}')
    with pytest.raises(InputError, match="this release reads version 1"):
        read_lot_json(tmp_path / "y.json")
