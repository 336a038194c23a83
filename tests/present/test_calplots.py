"""Pictures of calibrations: the geometry they draw checked against sampling, the heading errors against closed
forms and Monte Carlo, and every picture decoding (real captures where the repository has them)."""

import io

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from support import SHARED

from align.calibration import calibrate_magnetometer
from align.errors import InputError
from align.present.calplots import (
    accel_statics_png,
    apply_traces_png,
    ellipse_outline,
    heading_errors,
    magnetometer_png,
)
from align.units import DEG, STANDARD_GRAVITY


def decoded(png: bytes):
    from PIL import Image

    img = Image.open(io.BytesIO(png))
    img.load()
    assert img.format == "PNG" and img.size[0] > 600 and img.size[1] > 300
    pixels = np.asarray(img.convert("L"), float)
    assert pixels.std() > 10  # something was drawn
    return img


@pytest.mark.slow
def test_ellipse_outline_is_the_shadow_of_the_ellipsoid():
    rng = np.random.default_rng(0)
    for _ in range(5):
        a = rng.normal(size=(3, 3))
        shape = a @ a.T + 0.5 * np.eye(3)   # any ellipsoid centre + shape u, |u| = 1
        centre = rng.normal(size=3)
        u = rng.normal(size=(200_000, 3))
        pts = centre + (u / np.linalg.norm(u, axis=1, keepdims=True)) @ shape.T
        for plane in ((0, 1), (0, 2), (1, 2)):
            line = ellipse_outline(centre, shape, plane, 721)
            proj = pts[:, list(plane)]
            for k in range(0, 360, 15):  # support function: the outline's and the points' extent in each direction
                d = np.array([np.cos(np.radians(k)), np.sin(np.radians(k))])
                assert (line @ d).max() == pytest.approx((proj @ d).max(), rel=2e-3, abs=2e-3)


def _mag_cal(soft, hard, field=50e-6, dip=60 * DEG, sigma=(0.2e-6, 0.3e-6, 0.1e-6)):
    from align.calibration.magnetometer import MagCalibration

    return MagCalibration(np.array(hard, float), np.array(soft, float), field, "symmetric", "uT", np.array(sigma),
                          0.1, 0.001, 0.3, 0.2 * DEG, dip)


def test_heading_error_without_calibration_matches_the_closed_form_of_a_hard_iron():
    # hard iron h along x only, no soft iron: the level reading is (H cos psi + h, -H sin psi)
    h, dip = 10e-6, 60 * DEG
    cal = _mag_cal(np.eye(3), [h, 0, 0], dip=dip)
    psi = np.radians(np.arange(0, 360, 5.0))
    before, _ = heading_errors(cal, psi)
    big_h = 50e-6 * np.cos(dip)
    expected = np.arctan2(big_h * np.sin(psi), big_h * np.cos(psi) + h) - psi
    assert np.allclose(before, np.angle(np.exp(1j * expected)), atol=1e-12)
    assert np.abs(before).max() == pytest.approx(np.arcsin(h / big_h), rel=1e-3)  # the known peak asin(h / H)


def test_heading_error_after_calibration_matches_monte_carlo_of_the_hard_iron():
    rng = np.random.default_rng(1)
    a = rng.normal(0, 0.05, (3, 3))
    soft = np.eye(3) + 0.5 * (a + a.T)
    cal = _mag_cal(soft, [20e-6, -15e-6, 30e-6])
    psi = np.radians(np.arange(0, 360, 30.0))
    _, after = heading_errors(cal, psi)
    # simulate: the true level field read through the true distortion, corrected with a hard iron off by its sigma
    dip, f = cal.dip, cal.field
    body = np.column_stack([f * np.cos(dip) * np.cos(psi), -f * np.cos(dip) * np.sin(psi), np.full(len(psi), f * np.sin(dip))])
    raw = np.linalg.solve(soft, body.T).T + cal.hard_iron
    draws = rng.normal(0, 1, (20_000, 3)) * cal.sigma_hard_iron
    errs = []
    for dh in draws[:4000]:
        m = (raw - (cal.hard_iron + dh)) @ soft.T
        errs.append(np.angle(np.exp(1j * (np.arctan2(-m[:, 1], m[:, 0]) - psi))))
    assert np.allclose(np.std(errs, axis=0), after, rtol=0.06)


@pytest.mark.slow
def test_magnetometer_picture_of_a_real_capture():
    import pandas as pd

    d = pd.read_csv(SHARED / "data" / "magnetometer" / "hmc5883l_sunsided" / "hmc5883l_compass.csv")
    raw = d[["mag_x_gauss", "mag_y_gauss", "mag_z_gauss"]].to_numpy(float) * 1e-4
    cal = calibrate_magnetometer(raw, "gauss")
    png = magnetometer_png(raw, cal)
    decoded(png)
    assert png == magnetometer_png(raw, cal)  # deterministic
    with pytest.raises(InputError):
        magnetometer_png(raw[:, :2], cal)


@pytest.mark.slow
def test_accel_statics_picture_of_a_simulated_session_and_its_refusals():
    rng = np.random.default_rng(2)
    fs, ups = 100.0, Rotation.random(8, random_state=3).apply([0, 0, STANDARD_GRAVITY])
    parts, intervals, n = [], [], 0
    for k, up in enumerate(ups):
        still = np.tile(up, (400, 1)) + rng.normal(0, 0.01, (400, 3))
        move = np.linspace(up, ups[(k + 1) % len(ups)], 150) + rng.normal(0, 0.5, (150, 3))
        parts += [still, move]
        intervals.append((n + 20, n + 380))
        n += 550
    acc = np.vstack(parts)
    t = np.arange(len(acc)) / fs
    for units in ("m/s^2", "g", "16384 LSB/g", "counts"):
        decoded(accel_statics_png(t, acc, intervals, units))
    with pytest.raises(InputError, match="outside"):
        accel_statics_png(t, acc, [(0, len(t) + 1)], "m/s^2")
    with pytest.raises(InputError):
        accel_statics_png(t[:-1], acc, intervals, "m/s^2")


@pytest.mark.slow
def test_apply_traces_picture_short_and_long():
    for n in (500, 300_000):  # a long log is drawn as its min/max envelope
        t = np.arange(n) / 100.0
        raw = np.column_stack([np.sin(t), np.cos(t), 0.1 * t]) * DEG
        decoded(apply_traces_png(t, raw, raw * 1.01 + 0.001, "deg/s"))
    with pytest.raises(InputError):
        apply_traces_png(t, raw, raw[:10], "deg/s")
