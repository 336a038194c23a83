"""Calibration summaries state M's unit and the misalignment angles in degrees, as 'matrix' does: the printed angles
are the reference's definitions (section 1) applied here to the M of the result file."""

import json
import re

import numpy as np
from support import SHARED

from align.calibration import Calibration, CalibrationSet
from align.present.text import calibration_summary

FERRARIS = SHARED / "data" / "multiposition" / "imucal_ferraris"
HMC = SHARED / "data" / "magnetometer" / "hmc5883l_sunsided" / "hmc5883l_compass.csv"


def _reference_angles(m: np.ndarray) -> dict[str, float]:
    """psi_i = acos(u_i . e_i), phi_ij = asin(u_i . e_j), delta_ij = asin(u_i . u_j), deg; scale |M[i, :]|."""
    u = m / np.linalg.norm(m, axis=1)[:, None]
    out = {f"scale_{i}": float(np.linalg.norm(m[i])) for i in range(3)}
    out |= {f"psi_{'xyz'[i]}": float(np.degrees(np.arccos(u[i, i]))) for i in range(3)}
    out |= {f"phi_{'xyz'[i]}{'xyz'[j]}": float(np.degrees(np.arcsin(u[i, j]))) for i in range(3) for j in range(3) if i != j}
    out |= {f"delta_{p}": float(np.degrees(np.arcsin(u["xyz".index(p[0])] @ u["xyz".index(p[1])]))) for p in ("xy", "xz", "yz")}
    return out


def _printed_angles(block: str) -> dict[str, float]:
    found = {}
    for key, line in (("psi", "psi (axis-frame)"), ("phi", "phi (cross-axis)"), ("delta", "delta (axis-axis)")):
        text = next(t for t in block.splitlines() if line in t)
        found |= {f"{key}_{k}": float(v) for k, v in re.findall(r"([xyz]{1,2})=([+-]?[0-9.]+)", text)}
    text = re.sub(r" ± \S+|\(assumed\)|\([a-z/^ 0-9]+\)", "", next(t for t in block.splitlines() if "scale factors" in t))
    found |= {f"scale_{i}": float(v) for i, v in enumerate(text.split()[2:5])}
    return found


def _check(block: str, m: np.ndarray) -> None:
    got, want = _printed_angles(block), _reference_angles(m)
    assert set(got) == set(want)
    for k, v in want.items():
        assert abs(got[k] - v) <= (6e-6 if k.startswith("scale") else 6e-5), (k, got[k], v)


def test_ferraris_summary_states_m_unit_and_the_angles(run_cli, tmp_path):
    out = tmp_path / "cal.json"
    res = run_cli("calibrate", "ferraris", FERRARIS / "example_ferraris_session.csv", "--sections",
                  FERRARIS / "example_ferraris_session_list.json", "--rate-hz", "102.4", "--json", out)
    assert res.code == 0, res.err
    d = json.loads(out.read_text())
    blocks = res.out.split("\n\n")
    for sensor in ("accelerometer", "gyroscope"):
        block = next(b for b in blocks if b.startswith(sensor))
        assert "M [dimensionless] (1-sigma):" in block and "[deg]:" in block
        _check(block, np.array(d[sensor]["M"]))


def test_magnetometer_summary_states_the_angles_of_its_m(run_cli, tmp_path):
    out = tmp_path / "mag.json"
    res = run_cli("calibrate", "mag", HMC, "--columns", "mag_x_gauss,mag_y_gauss,mag_z_gauss", "--mag-units", "gauss",
                  "--json", out)
    assert res.code == 0, res.err
    d = json.loads(out.read_text())
    assert "soft iron [dimensionless] (± 1 sigma):" in res.out and "angles of M = (soft_iron)^-1" in res.out
    _check(res.out, np.linalg.inv(np.array(d["soft_iron"])))      # m_raw = M m + h: M = soft_iron^-1


def test_a_calibration_in_counts_states_its_m_in_counts():
    m = np.diag([1670.0, 1672.0, 1668.0])
    cal = Calibration("accelerometer", m, np.zeros(3), np.zeros((3, 3)), np.zeros(3), "counts", "test")
    text = calibration_summary(CalibrationSet({"accelerometer": cal}).sensors)
    assert "M [counts per m/s^2] (1-sigma):" in text
    _check(text, m)
