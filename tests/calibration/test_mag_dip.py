"""The dip note says what it computes (90 deg minus the median field-accelerometer angle) and equals the simulated
dip (its sign following the accelerometer's vector); MagCalibration.correcting maps raw readings to the field in the
accelerometer's frame (simulated truth), and the summary's angles are those of its inverse."""

import re

import numpy as np
import pytest
from magsim import F, capture, dip, truth
from scipy.spatial.transform import Rotation

from align.calibration import calibrate_magnetometer, with_gravity_alignment
from align.present.text import magnetometer_summary
from align.units import DEG


@pytest.mark.parametrize("seed", range(3))
def test_dip_note_and_number_agree_with_the_simulated_dip(seed):
    s, h = truth(seed)
    m, acc = capture("sphere", s, h, seed=seed + 20)      # acc: specific force (up at rest); the field 60 deg below
    for a, want in ((acc, -dip), (-acc, dip)):            # -acc points along gravity (down)
        c = calibrate_magnetometer(m, "uT", acc=a)
        assert c.dip == pytest.approx(want, abs=0.5 * DEG)
        note = next(n for n in c.notes if n.startswith("dip "))
        shown, angle = (float(v) for v in re.match(r"dip ([+-]?[0-9.]+) deg .*\(([0-9.]+) deg\)", note).groups())
        assert "90 deg minus the median angle between the field and the accelerometer's vector" in note
        assert shown == pytest.approx(90 - angle, abs=0.011)   # the words and the number agree
        assert shown == pytest.approx(np.degrees(want), abs=0.5)


def test_correcting_maps_raw_to_the_field_in_the_accelerometer_frame():
    s, h = truth(4)
    m, acc = capture("sphere", s, h, seed=31, noise=0.1e-6)
    q = Rotation.from_rotvec(np.radians([2.0, -1.5, 3.0])).as_matrix()   # magnetometer axes turned from the body's
    body = (m - h) @ np.linalg.inv(s).T                                  # the field in the body frame (truth)
    raw = body @ q.T @ s.T + h                                           # the magnetometer reads S q m_body + h
    c = with_gravity_alignment(calibrate_magnetometer(raw, "uT", field=F, acc=acc), raw, acc)
    assert np.allclose(c.correcting, c.misalignment @ c.soft_iron)
    got = (raw - c.hard_iron) @ c.correcting.T
    assert np.sqrt(np.mean(np.sum((got - body) ** 2, axis=1))) < 0.01 * F
    assert np.allclose(c.model_matrix @ c.correcting, np.eye(3), atol=1e-12)
    text = magnetometer_summary(c)
    want = np.degrees(np.arcsin(c.model_matrix[0, 1] / np.linalg.norm(c.model_matrix[0])))   # phi_xy of M
    line = next(t for t in text.splitlines() if "phi (cross-axis)" in t)
    assert float(re.search(r"xy=([+-][0-9.]+)", line).group(1)) == pytest.approx(want, abs=6e-5)
