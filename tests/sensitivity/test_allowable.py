"""Sensitivity, allowable: Example 2, closed forms vs root finding, the check against Example 1's budget,
and the result files."""

import json

import numpy as np
import pytest
from support import ROOT

from align.io import read_toml
from align.results import load_result, save_result
from align.sensitivity.allowable import Allowable, allowable
from align.sensitivity.manoeuvre import Manoeuvre, manoeuvre_from_dict
from align.sensitivity.margins import Margin, MarginTable, check_margins
from align.sensitivity.symbolic import ELEMENTS
from align.units import DEG
from align.values import approx_equal
from mechanics.budget import budget
from mechanics.mount import mount_from_dict

EXAMPLE2 = ROOT / "examples" / "sensitivity" / "example2.toml"
EXAMPLE1 = ROOT / "examples" / "budget" / "example1.toml"


@pytest.fixture(scope="module")
def example2() -> Allowable:
    return allowable(manoeuvre_from_dict(read_toml(EXAMPLE2), str(EXAMPLE2)))


def _tight(tmp_path):
    """Example 2 with the y gyro's limit cut to 0.3 deg (phi_yz fails against Example 1)."""
    tight = tmp_path / "tight.toml"
    tight.write_text(EXAMPLE2.read_text().replace('y = "1 deg"', 'y = "0.3 deg"'))
    return tight


def test_example2_allowable_and_binding(example2):
    a = example2
    assert a.allowable["phi_yz"] / DEG == pytest.approx(1.9102, abs=5e-5)
    assert a.allowable["psi_z"] / DEG == pytest.approx(14.835, abs=5e-4)
    assert np.degrees(np.arcsin(1 / 30)) == pytest.approx(a.allowable["phi_yz"] / DEG, rel=1e-12)
    assert a.binding == "phi_yz"
    assert not np.isfinite(a.allowable["phi_xz"])  # no limit on the x gyro
    assert a.cone / DEG == pytest.approx(1.9102, abs=1e-4)  # a rigid rotation about x: the same element


def test_numeric_root_finding_equals_closed_forms():
    man = manoeuvre_from_dict(read_toml(EXAMPLE2))
    closed, numeric = allowable(man), allowable(man.replace(fixed_axis=False))
    assert numeric.method["phi_yz"].startswith("numeric")
    for e in ELEMENTS:
        c, n = closed.allowable[e], numeric.allowable[e]
        assert (c == n == np.inf) or c == pytest.approx(n, rel=1e-9)


def test_allowable_and_check_commands(tmp_path, run_cli):
    out = tmp_path / "a.json"
    res = run_cli("allowable", EXAMPLE2, "--json", out, "--symbolic", "pretty")
    assert res.code == 0, res.err
    d = json.loads(out.read_text())
    assert d["binding"] == "phi_yz" and d["binding_deg"] == pytest.approx(1.9102, abs=5e-5)
    assert set(d["allowable_deg"]) == set(ELEMENTS)
    ok = run_cli("check", EXAMPLE1, EXAMPLE2)
    assert ok.code == 0 and "PASS" in ok.out
    tight = _tight(tmp_path)
    res = run_cli("check", EXAMPLE1, tight, "--json", tmp_path / "c.json")
    assert res.code == 4 and "FAIL (phi_yz)" in res.out
    c = json.loads((tmp_path / "c.json").read_text())
    assert c["pass"] is False
    row = next(r for r in c["elements"] if r["element"] == "phi_yz")
    # predicted phi_yz: RSS of the tilt about x and the y gyro's datasheet term (Eq 1 per element)
    assert row["predicted_deg"] == pytest.approx(np.hypot(0.30155, 1.0), abs=1e-4)
    assert row["allowed_deg"] == pytest.approx(np.degrees(np.arcsin(0.3 / 30)), rel=1e-9)


def test_check_margins_passes_and_fails_as_the_check_command(example2, tmp_path):
    """Example 1's mount against Example 2's manoeuvre passes; with the y limit cut to 0.3 deg only phi_yz fails."""
    b = budget(mount_from_dict(read_toml(EXAMPLE1), str(EXAMPLE1), EXAMPLE1.parent))
    table = check_margins(b.elements("rss"), example2, "rss")
    assert table.passed and table.failed == [] and len(table) == len(ELEMENTS)
    assert [r.element for r in table] == list(ELEMENTS)
    tight = allowable(manoeuvre_from_dict(read_toml(_tight(tmp_path))))
    fail = check_margins(b.elements("rss"), tight, "rss")
    assert not fail.passed and fail.failed == ["phi_yz"]
    d = fail.to_dict()
    assert d["format"] == "imu-align.check" and d["pass"] is False and d["basis"] == "rss"
    assert d["units"] == {"angles": "deg"}
    assert set(d) >= {"format", "version", "convention", "units", "basis", "pass", "elements"}
    row = next(r for r in d["elements"] if r["element"] == "phi_yz")
    assert set(row) == {"element", "predicted_deg", "allowed_deg", "margin_deg", "pass"}
    assert row["pass"] is False
    assert row["predicted_deg"] == pytest.approx(np.hypot(0.30155, 1.0), abs=1e-4)
    assert row["allowed_deg"] == pytest.approx(np.degrees(np.arcsin(0.3 / 30)), rel=1e-9)
    assert row["margin_deg"] == pytest.approx(row["allowed_deg"] - row["predicted_deg"], rel=1e-12)
    free = next(r for r in d["elements"] if r["element"] == "phi_xz")   # no limit on the x gyro
    assert free["allowed_deg"] is None and free["margin_deg"] is None and free["pass"] is True
    # the worst-case basis adds the terms: still within Example 2's allowance
    assert check_margins(b.elements("worst"), example2, "worst").passed


def test_allowable_round_trips_through_a_file(example2, tmp_path):
    a = example2.replace(inputs={"manoeuvre": str(EXAMPLE2)})
    assert approx_equal(Allowable.from_dict(a.to_dict()), a, rtol=1e-12)   # deg and back may round the last bit
    save_result(tmp_path / "a.json", a)
    back = load_result(tmp_path / "a.json")
    assert type(back) is Allowable and approx_equal(back, a, rtol=1e-12)
    assert back.inputs == {"manoeuvre": str(EXAMPLE2)} and back.allowable["phi_xz"] == np.inf
    # today's keys are all kept
    d = json.loads((tmp_path / "a.json").read_text())
    for key in ("format", "version", "generator", "convention", "units", "manoeuvre", "limits_deg", "allowable_deg",
                "method", "binding", "binding_deg", "cone_deg", "cone_worst_direction", "agreement"):
        assert key in d
    assert d["format"] == "imu-align.allowable" and d["allowable_deg"]["phi_xz"] is None


def test_allowable_without_manoeuvre_detail_still_reads(example2):
    d = example2.to_dict()
    del d["manoeuvre_detail"]
    back = Allowable.from_dict(d)
    assert back.manoeuvre.description == example2.manoeuvre.description
    assert back.manoeuvre.limits == pytest.approx(example2.manoeuvre.limits, rel=1e-12)
    assert back.binding == "phi_yz"


def test_margin_table_round_trips_through_a_file(tmp_path):
    table = MarginTable("worst", (Margin("psi_x", 0.01, 0.02), Margin("phi_yz", 0.03, 0.02), Margin("phi_xz", 0.01, np.inf)),
                        {"mount": "m.toml"})
    assert not table.passed and table.failed == ["phi_yz"]
    assert approx_equal(MarginTable.from_dict(table.to_dict()), table, rtol=1e-12)
    save_result(tmp_path / "c.json", table)
    back = load_result(tmp_path / "c.json")
    assert type(back) is MarginTable and approx_equal(back, table, rtol=1e-12)
    assert back.rows[2].allowed == np.inf and back.inputs == {"mount": "m.toml"}


def test_rotation_manoeuvre_keeps_its_increments_in_the_file(example2):
    d = example2.to_dict()["manoeuvre_detail"]
    assert example2.series is None and "series" not in d
    assert np.allclose(d["increments_deg"], [[0.0, 0.0, 30.0]], rtol=1e-12)


def _series_manoeuvre(tmp_path):
    """A 300-sample rate series: a smooth 38 deg turn about z with some x (changing axis)."""
    t = np.arange(0, 3.0, 0.01)
    rate = 20.0 * np.sin(np.pi * t / 3.0)
    (tmp_path / "rates.csv").write_text("time,wx,wy,wz\n" + "\n".join(
        f"{a:.6f},{0.2 * r:.9f},0,{r:.9f}" for a, r in zip(t, rate)) + "\n")
    return manoeuvre_from_dict({"series": {"file": "rates.csv"}, "limits": {"y": "1 deg", "z": "1 deg"}}, "m", tmp_path)


@pytest.mark.slow
def test_series_allowable_writes_a_summary_not_the_samples_and_round_trips(tmp_path):
    man = _series_manoeuvre(tmp_path)
    a = allowable(man, directions=20).replace(inputs={"manoeuvre": "m.toml"})
    d = a.to_dict()
    detail = d["manoeuvre_detail"]
    assert "increments_deg" not in detail
    assert set(detail) >= {"description", "limits_deg", "fixed_axis", "segments", "series"}
    assert detail["limits_deg"] == pytest.approx({"y": 1.0, "z": 1.0}, rel=1e-12) and detail["segments"] == []
    s = detail["series"]
    assert s["samples"] == 300 and s["increments"] == 299 and len(s["increments_sha256"]) == 64
    assert s["increments_sum_deg"] == pytest.approx(man.increments.sum(axis=0) / DEG, rel=1e-12)
    assert a.series == s
    # read back: everything but the samples; the file it writes again is the file it was read from
    back = Allowable.from_dict(d)
    assert back.manoeuvre.increments.shape == (0, 3) and back.series == a.series
    assert approx_equal(back, a.replace(manoeuvre=man.replace(increments=np.empty((0, 3)))), rtol=1e-12)
    assert approx_equal(back.to_dict(), d, rtol=1e-12)
    save_result(tmp_path / "a.json", a)
    loaded = load_result(tmp_path / "a.json")
    assert type(loaded) is Allowable and approx_equal(loaded, back, rtol=1e-12)
    assert approx_equal(loaded.to_dict(), json.loads((tmp_path / "a.json").read_text()), rtol=1e-12)


def test_a_long_series_stays_a_small_file():
    """200 000 samples used to be written one by one (11 MB); the summary is a few hundred bytes."""
    inc = np.random.default_rng(0).normal(0.0, 1e-4, (200_000, 3))
    man = Manoeuvre(inc, {"y": 1 * DEG}, description="rate series long.csv: 200001 samples")
    a = Allowable({e: 0.01 for e in ELEMENTS}, {e: "numeric (attitude propagation)" for e in ELEMENTS}, "psi_x", 0.01,
                  0.02, np.array([0.0, 0.0, 1.0]), {}, man)
    text = json.dumps(a.to_dict())
    assert len(text) < 4000
    other = a.replace(manoeuvre=man.replace(increments=inc[::-1]))   # the same numbers in another order
    assert other.to_dict()["manoeuvre_detail"]["series"]["increments_sha256"] != json.loads(text)[
        "manoeuvre_detail"]["series"]["increments_sha256"]
