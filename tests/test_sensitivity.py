"""Sensitivity: Example 2, symbolic vs numeric, closed forms vs attitude propagation, checks."""

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from align.errors import InputError
from align.io import read_toml
from align.sensitivity.allowable import (ELEMENTS, allowable, closed_form_errors, manoeuvre_from_dict, matrix_from_angles,
                               output_errors, response, sensitivity, symbolic, symbolic_text)
from align.units import DEG

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE2 = ROOT / "examples" / "sensitivity" / "example2.toml"
EXAMPLE1 = ROOT / "examples" / "budget" / "example1.toml"


def test_example2_allowable_and_binding():
    a = allowable(manoeuvre_from_dict(read_toml(EXAMPLE2)))
    assert a.allowable["phi_yz"] / DEG == pytest.approx(1.9102, abs=5e-5)
    assert a.allowable["psi_z"] / DEG == pytest.approx(14.835, abs=5e-4)
    assert np.degrees(np.arcsin(1 / 30)) == pytest.approx(a.allowable["phi_yz"] / DEG, rel=1e-12)
    assert a.binding == "phi_yz"
    assert not np.isfinite(a.allowable["phi_xz"])  # no limit on the x gyro
    assert a.cone / DEG == pytest.approx(1.9102, abs=1e-4)  # a rigid rotation about x: the same element


def test_numeric_root_finding_equals_closed_forms():
    from dataclasses import replace

    man = manoeuvre_from_dict(read_toml(EXAMPLE2))
    closed, numeric = allowable(man), allowable(replace(man, fixed_axis=False))
    assert numeric.method["phi_yz"].startswith("numeric")
    for e in ELEMENTS:
        c, n = closed.allowable[e], numeric.allowable[e]
        assert (c == n == np.inf) or c == pytest.approx(n, rel=1e-9)


def test_symbolic_and_numeric_sensitivities_agree():
    rng = np.random.default_rng(0)
    ang = rng.normal(0, 0.05, 9)
    w = rng.normal(0, 1.0, 3)
    jac = sensitivity(w, ang)
    h = 1e-7
    for k in range(9):
        dp, dm = ang.copy(), ang.copy()
        dp[k] += h
        dm[k] -= h
        fd = (response(w, dp) - response(w, dm)) / (2 * h)
        assert np.allclose(jac[:, k], fd, atol=1e-7)
    # Eq 5: g_x = w_x cos(psi_x) + w_y sin(phi_xy) + w_z sin(phi_xz)
    a = dict(zip(ELEMENTS, ang))
    gx = w[0] * np.cos(a["psi_x"]) + w[1] * np.sin(a["phi_xy"]) + w[2] * np.sin(a["phi_xz"])
    assert response(w, ang)[0] == pytest.approx(gx, rel=1e-14)
    s = symbolic()
    assert s.jacobian.shape == (3, 9)
    assert "psi_x" in symbolic_text("pretty") and "\\cos" in symbolic_text("latex")


def test_propagation_equals_eq11_13_for_fixed_axis_rotations():
    rng = np.random.default_rng(1)
    for _ in range(20):
        m = matrix_from_angles(rng.normal(0, 0.03, 9))
        axis = "xyz"[rng.integers(3)]
        angle = rng.uniform(-170, 170)
        man = manoeuvre_from_dict({"rotation": [{"axis": axis, "angle": f"{angle} deg"}], "limits": {"x": "1 deg"}})
        hist = output_errors(man, m, history=True)
        prop = np.array([hist[a][-1] for a in "xyz"])
        assert np.allclose(prop, closed_form_errors(man, m), atol=1e-12)


def test_sequences_are_where_the_formulas_stop_agreeing():
    m = matrix_from_angles({"phi_yz": 2 * DEG, "phi_xy": 1 * DEG, "psi_z": 3 * DEG})
    man = manoeuvre_from_dict({"rotation": [{"axis": "z", "angle": "90 deg"}, {"axis": "x", "angle": "90 deg"}],
                               "limits": {"x": "1 deg", "y": "1 deg", "z": "1 deg"}})
    hist = output_errors(man, m, history=True)
    prop = np.array([hist[a][-1] for a in "xyz"])
    # independent truth: compose the two measured fixed-axis rotations with scipy
    r_true = Rotation.from_rotvec([0, 0, np.pi / 2]) * Rotation.from_rotvec([np.pi / 2, 0, 0])
    r_meas = Rotation.from_rotvec(m @ [0, 0, np.pi / 2]) * Rotation.from_rotvec(m @ [np.pi / 2, 0, 0])
    assert np.allclose(prop, r_meas.as_rotvec() - r_true.as_rotvec(), atol=1e-12)
    assert np.max(np.abs(prop - closed_form_errors(man, m))) > 0.5 * DEG


def test_rate_series_fixed_axis_matches_and_gap_is_refused(tmp_path):
    t = np.arange(0, 3.0, 0.01)
    rate = 20.0 * np.sin(np.pi * t / 3.0)  # deg/s about z, a smooth 38 deg turn
    csv = tmp_path / "rates.csv"
    csv.write_text("time,wx,wy,wz\n" + "\n".join(f"{a:.6f},0,0,{r:.9f}" for a, r in zip(t, rate)) + "\n")
    man = manoeuvre_from_dict({"series": {"file": "rates.csv"}, "limits": {"y": "1 deg", "z": "1 deg"}}, "m", tmp_path)
    total = man.increments.sum(axis=0)
    a = allowable(man, directions=50)
    theta = abs(total[2])
    assert a.allowable["phi_yz"] == pytest.approx(np.arcsin(1 * DEG / theta), rel=1e-6)
    rows = csv.read_text().splitlines()
    del rows[100:110]
    csv.write_text("\n".join(rows) + "\n")
    with pytest.raises(InputError, match="gap in the time series at t=0.98"):
        manoeuvre_from_dict({"series": {"file": "rates.csv"}, "limits": {"y": "1 deg"}}, "m", tmp_path)


@pytest.mark.parametrize("text,words", [
    ('[limits]\ny = "1 deg"\n', "no [[rotation]]"),
    ('[[rotation]]\naxis = "z"\nangle = "30 deg"\n[limits]\ny = "0 deg"\n', "limits.y"),
    ('[[rotation]]\naxis = "w"\nangle = "30 deg"\n[limits]\ny = "1 deg"\n', "rotation 1.axis"),
    ('[[rotation]]\naxis = "z"\nangle = "30 mm"\n[limits]\ny = "1 deg"\n', "rotation 1.angle"),
])
def test_bad_manoeuvre_gets_one_line_naming_the_field(tmp_path, run_cli, text, words):
    f = tmp_path / "m.toml"
    f.write_text(text)
    res = run_cli("allowable", f, "--json", tmp_path / "never.json")
    assert res.code == 2 and words in res.err and res.err.strip().count("\n") == 0
    assert not (tmp_path / "never.json").exists()


def test_allowable_and_check_commands(tmp_path, run_cli):
    out = tmp_path / "a.json"
    res = run_cli("allowable", EXAMPLE2, "--json", out, "--symbolic", "pretty")
    assert res.code == 0, res.err
    d = json.loads(out.read_text())
    assert d["binding"] == "phi_yz" and d["binding_deg"] == pytest.approx(1.9102, abs=5e-5)
    assert set(d["allowable_deg"]) == set(ELEMENTS)
    ok = run_cli("check", EXAMPLE1, EXAMPLE2)
    assert ok.code == 0 and "PASS" in ok.out
    tight = tmp_path / "tight.toml"
    tight.write_text(EXAMPLE2.read_text().replace('y = "1 deg"', 'y = "0.3 deg"'))
    res = run_cli("check", EXAMPLE1, tight, "--json", tmp_path / "c.json")
    assert res.code == 4 and "FAIL (phi_yz)" in res.out
    c = json.loads((tmp_path / "c.json").read_text())
    assert c["pass"] is False
    row = next(r for r in c["elements"] if r["element"] == "phi_yz")
    # predicted phi_yz: RSS of the tilt about x and the y gyro's datasheet term (Eq 1 per element)
    assert row["predicted_deg"] == pytest.approx(np.hypot(0.30155, 1.0), abs=1e-4)
    assert row["allowed_deg"] == pytest.approx(np.degrees(np.arcsin(0.3 / 30)), rel=1e-9)
