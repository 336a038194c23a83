"""Magnetometer hard- and soft-iron 1-sigma that holds on partial coverage (issue 15).

Truth from an independent simulator (magtruth.py: field 45-55 uT, hard iron ~20 uT, symmetric soft
iron, isotropic noise 0.2-1 uT, 400-2000 samples). Over many seeds the hard iron (all three
components) and the soft iron (all six) must fall inside their reported 3-sigma at least 97 % of the
time for every capture the gates accept, full-sphere and hemisphere alike, and the normalised errors
must have a spread near 1 (a 1-sigma inflated to pass would show as a spread well below 1).
"""

import numpy as np
import pytest
from magtruth import draw_truth, tumble
from scipy.spatial.transform import Rotation

from align.calibration import calibrate_magnetometer
from align.errors import TestError

SEEDS = 200
IU = np.triu_indices(3)


def normalised_errors(raw, truth, known: bool):
    """(hard-iron z (3,), soft-iron z (6,)) of one capture, or None when the gates refuse it."""
    try:
        c = calibrate_magnetometer(raw, "uT", field=truth.field if known else None)
    except TestError:
        return None
    w = truth.w_true(unit_det=not known)  # a fitted field scales W to unit determinant
    zh = (c.hard_iron - truth.hard) / c.sigma_hard_iron
    zw = (c.soft_iron[IU] - w[IU]) / c.sigma_soft_iron[IU]
    assert np.allclose(c.sigma_hard_iron, np.sqrt(np.diag(c.covariance)[:3]))
    return zh, zw


def coverage_run(kind: str, seeds: int = SEEDS):
    zh, zw, refused = [], [], 0
    for seed in range(seeds):
        rng = np.random.default_rng(5000 + seed)
        truth = draw_truth(rng, mount_deg=0.0)
        n = int(rng.choice([400, 1000, 2000]))
        raw = tumble(truth, rng, n, kind, noise=rng.uniform(0.2e-6, 1.0e-6))
        got = normalised_errors(raw, truth, known=bool(seed % 2))
        if got is None:
            refused += 1
            continue
        zh.append(got[0])
        zw.append(got[1])
    return np.array(zh), np.array(zw), refused


@pytest.mark.parametrize("kind", ["sphere", "hemisphere"])
@pytest.mark.slow
def test_hard_and_soft_iron_inside_their_3_sigma(kind):
    zh, zw, refused = coverage_run(kind)
    assert refused <= 0.05 * SEEDS, f"the gates refused {refused} of {SEEDS} {kind} captures"
    hard_in = np.mean(np.all(np.abs(zh) < 3, axis=1))
    soft_in = np.mean(np.all(np.abs(zw) < 3, axis=1))
    # measured (200 seeds): sphere 0.995 / 0.985, hemisphere 0.995 / 0.99; before the fix hemisphere 0.745
    assert hard_in >= 0.97 and soft_in >= 0.97, (hard_in, soft_in)
    # honest, not inflated: the normalised errors spread like N(0, 1)
    for z in (zh, zw):
        assert 0.8 < np.std(z) < 1.2, np.std(z, axis=0)
        assert np.all(np.abs(np.mean(z, axis=0)) < 0.3), np.mean(z, axis=0)


def hand_held(truth, rng, n, max_tilt_deg, noise=0.5e-6):
    """Every heading, tilted by at most ``max_tilt_deg`` (a device never turned over)."""
    yaw = Rotation.from_euler("z", rng.uniform(0, 360, n)[:, None], degrees=True)
    d = np.column_stack([rng.normal(size=(n, 2)), np.zeros(n)])
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    tilt = Rotation.from_rotvec(d * np.radians(rng.uniform(0, max_tilt_deg, n))[:, None])
    return truth.readings(yaw * tilt, rng, noise)[0]


@pytest.mark.slow
def test_tilted_captures_accepted_only_with_an_honest_sigma():
    """Hand-held captures tilted at most 45 deg: the gates accept some (the hard iron then known to
    < 2 % of the field); those they accept are covered like full ones. At most 20 deg: all refused."""
    zh, zw = [], []
    for seed in range(80):
        rng = np.random.default_rng(7000 + seed)
        truth = draw_truth(rng, mount_deg=0.0)
        got = normalised_errors(hand_held(truth, rng, 1000, 45), truth, known=bool(seed % 2))
        if got is not None:
            zh.append(got[0])
            zw.append(got[1])
        if seed < 10:
            with pytest.raises(TestError, match="coverage too small|planar or near-level"):
                calibrate_magnetometer(hand_held(truth, rng, 1000, 20), "uT")
    assert 20 <= len(zh) <= 75  # some accepted, some refused: the gate is at work
    zh, zw = np.array(zh), np.array(zw)
    assert np.mean(np.all(np.abs(zh) < 3, axis=1)) >= 0.95  # a small sample: 0.95 allows one miss in 20+
    assert np.mean(np.all(np.abs(zw) < 3, axis=1)) >= 0.95
    assert 0.7 < np.std(zh) < 1.3 and 0.7 < np.std(zw) < 1.3


def test_sigma_falls_with_noise_and_samples():
    """The reported 1-sigma follows the data: half the noise, half the sigma; four times the samples, half."""
    rng = np.random.default_rng(11)
    truth = draw_truth(rng, mount_deg=0.0)
    sig = {}
    for noise, n in ((1e-6, 1000), (0.5e-6, 1000), (1e-6, 4000)):
        raw = tumble(truth, np.random.default_rng(3), n, "sphere", noise)
        sig[noise, n] = calibrate_magnetometer(raw, "uT").sigma_hard_iron
    assert np.allclose(sig[0.5e-6, 1000] / sig[1e-6, 1000], 0.5, rtol=0.1)
    assert np.allclose(sig[1e-6, 4000] / sig[1e-6, 1000], 0.5, rtol=0.2)
