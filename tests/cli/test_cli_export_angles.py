"""One layout of the misalignment angles (align.present.angles): the terminal text and the CSV give the same numbers,
and those are reference section 1's definitions applied here to M (written out below, not the tool's code); the
scale's 1-sigma matches a Monte Carlo over sigma(M); no negative zeros."""

import json
import re

import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation
from support import ROOT, SHARED

from align.calibration import Calibration, CalibrationSet
from align.present.angles import angle_rows, number
from align.present.text import calibration_summary
from align.results import save_result

HMC = SHARED / "data" / "magnetometer" / "hmc5883l_sunsided" / "hmc5883l_compass.csv"
SESSION, PLAN = ROOT / "examples" / "alignment" / "session.csv", ROOT / "examples" / "alignment" / "plan.toml"


def _reference(m: np.ndarray) -> dict[str, float]:
    """Reference section 1: u_i = M_i/|M_i|; psi_i = acos(u_i . e_i), phi_ij = asin(u_i . e_j), delta_ij =
    asin(u_i . u_j) in deg; the scale |M_i|; the mounting rotation: R^T the nearest proper rotation to M (polar)."""
    u = m / np.linalg.norm(m, axis=1)[:, None]
    out = {f"scale_{a}": float(np.linalg.norm(m[i])) for i, a in enumerate("xyz")}
    out |= {f"psi_{a}": float(np.degrees(np.arccos(u[i, i]))) for i, a in enumerate("xyz")}
    out |= {f"phi_{'xyz'[i]}{'xyz'[j]}": float(np.degrees(np.arcsin(u[i, j]))) for i in range(3) for j in range(3)
            if i != j}
    out |= {f"delta_{p}": float(np.degrees(np.arcsin(u["xyz".index(p[0])] @ u["xyz".index(p[1])])))
            for p in ("xy", "xz", "yz")}
    w, _, vt = np.linalg.svd(m)
    r = (w @ np.diag([1, 1, np.linalg.det(w @ vt)]) @ vt).T                # R^T = nearest proper rotation to M
    out |= {f"rotation_{a}": float(v) for a, v in zip("xyz", np.degrees(Rotation.from_matrix(r).as_rotvec()))}
    return out


def _csv(text: str, tmp_path, sensor: str) -> dict[str, float]:
    (tmp_path / "x.csv").write_text(text)
    df = pd.read_csv(tmp_path / "x.csv", comment="#", keep_default_na=False, na_values=[""])
    df = df[df.sensor == sensor]
    names = {"mounting_rotation": "rotation"}
    return {f"{names.get(r.quantity, r.quantity)}_{r.row}{'' if pd.isna(r.column) else r.column}": r.value
            for r in df.itertuples()
            if r.quantity in ("scale", "psi", "phi", "delta", "mounting_rotation")}


def _text(block: str) -> dict[str, float]:
    got = {}
    for key, label in (("psi", "psi (axis-frame)"), ("phi", "phi (cross-axis)"), ("delta", "delta (axis-axis)"),
                       ("rotation", "mounting rotation")):
        line = next(t for t in block.splitlines() if label in t)
        got |= {f"{key}_{k}": float(v) for k, v in re.findall(r"([xyz]{1,2})=([+-]?[0-9.]+)", line)}
    line = re.sub(r" ± \S+|\([a-z/^ 0-9]+\)", "", next(t for t in block.splitlines() if "scale factors" in t))
    got |= {f"scale_{a}": float(v) for a, v in zip("xyz", line.split()[2:5])}
    return got


def test_text_and_csv_lay_out_the_same_reference_angles(run_cli, tmp_path):
    rng = np.random.default_rng(7)
    m = 1668.0 * (np.eye(3) + rng.normal(0, 0.01, (3, 3)))                 # counts per m/s^2
    cs = CalibrationSet({"accelerometer": Calibration("accelerometer", m, np.zeros(3), np.full((3, 3), 0.4),
                                                      np.zeros(3), "counts", "test")})
    save_result(tmp_path / "c.json", cs)
    res = run_cli("export", tmp_path / "c.json", "--to", "csv")
    assert res.code == 0, res.err
    csv, text, want = _csv(res.out, tmp_path, "accelerometer"), _text(calibration_summary(cs.sensors)), _reference(m)
    assert set(csv) == set(want) == set(text)
    for k, v in want.items():
        assert csv[k] == pytest.approx(v, rel=1e-9, abs=1e-12), k
        assert abs(text[k] - v) <= (0.0006 if k.startswith("scale") else 6e-5), (k, text[k], v)
    assert "(counts per m/s^2)" in next(t for t in calibration_summary(cs.sensors).splitlines() if "scale factors" in t)


def test_alignment_text_csv_and_json_agree(run_cli, tmp_path):
    res = run_cli("matrix", SESSION, "--plan", PLAN, "--json", tmp_path / "a.json")
    assert res.code == 0, res.err
    d = json.loads((tmp_path / "a.json").read_text())
    csv = _csv(run_cli("export", tmp_path / "a.json", "--to", "csv").out, tmp_path, "gyroscope")
    text = _text(res.out)
    want = _reference(np.array(d["M"]))   # identity mounting in this example
    for k, v in want.items():
        assert csv[k] == pytest.approx(v, rel=1e-9, abs=1e-12), k
        assert abs(text[k] - v) <= (6e-6 if k.startswith("scale") else 6e-5), k


def test_scale_sigma_matches_monte_carlo():
    rng = np.random.default_rng(1)
    m = np.eye(3) + rng.normal(0, 0.02, (3, 3))
    sig = rng.uniform(1e-4, 1e-3, (3, 3))
    rows = {r.key: r for r in angle_rows(m, sig)}
    draws = np.array([np.linalg.norm(m + rng.normal(size=(3, 3)) * sig, axis=1) for _ in range(20000)])
    assert np.allclose(rows["scale"].sigmas, draws.std(axis=0), rtol=0.03)
    assert angle_rows(m)[0].sigmas is None


def test_no_negative_zeros(run_cli, tmp_path):
    assert number(-1e-9) == "+0.0000" and number(-0.00004, 4, False) == "0.0000" and number(-0.00006) == "-0.0001"
    res = run_cli("calibrate", "mag", HMC, "--columns", "mag_x_gauss,mag_y_gauss,mag_z_gauss", "--mag-units", "gauss")
    assert res.code == 0, res.err
    assert "mounting rotation  x=+0.0000  y=+0.0000  z=+0.0000" in res.out    # the soft iron is symmetric: no turn
    assert not re.search(r"-0\.0+(?![0-9])", res.out), res.out
