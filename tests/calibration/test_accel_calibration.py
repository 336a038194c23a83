"""Accelerometer calibration: simulated truth with held-out positions, imu_tk's Xsens session against the datasheet."""

import json

import numpy as np
import pytest
from accelsim import six_faces
from support import SHARED

from align.calibration import accel_session, calibrate_accel
from align.errors import InputError, TestError

XSENS = SHARED / "data" / "multiposition" / "xsens_mti_imu_tk"


def test_accelerometer_multiposition_on_simulated_truth():
    rng = np.random.default_rng(0)
    m_true = np.eye(3) + rng.normal(0, 0.01, (3, 3))
    b_true = rng.normal(0, 0.1, 3)
    g = 9.80665
    ups = {f"{s}{a}": np.eye(3)[i] * (1 if s == "+" else -1) for i, a in enumerate("xyz") for s in "+-"}
    ups.update({"45 xz": np.array([1, 0, 1]) / np.sqrt(2), "45 -yz": np.array([0, -1, 1]) / np.sqrt(2)})  # seed 004
    means = {k: m_true @ (g * u) + b_true + rng.normal(0, 1e-3, 3) for k, u in ups.items()}
    cal = calibrate_accel(means, ups, g, holdout=("45 xz", "45 -yz"))
    assert np.all(np.abs(cal.M - m_true) < 5 * cal.sigma_M + 1e-4)
    assert np.abs(cal.bias - b_true).max() < 5e-3
    for k in ("45 xz", "45 -yz"):
        assert np.abs(cal.checks[k]).max() < 5e-3  # the held-out positions are predicted
    with pytest.raises(InputError, match="at least 6"):
        calibrate_accel({k: means[k] for k in list(means)[:5]}, ups, g)


def test_xsens_session_detected_and_calibrated_against_datasheet(tmp_path, run_cli):
    out = tmp_path / "xs.json"
    res = run_cli("calibrate", "accel", XSENS / "xsens_acc.mat", "--columns", "col0,col1,col2,col3", "--units", "counts",
                  "--gravity", "9.81744 m/s^2", "--init-static", "50 s", "--json", out)
    assert res.code == 0, res.err
    assert "38 static intervals detected" in res.out
    d = json.loads(out.read_text())["accelerometer"]
    scale = np.diag(np.array(d["M"]))
    assert np.allclose(scale, [415, 413, 415], rtol=0.01)  # SOURCE.txt: factory scale, counts per m/s^2
    assert np.allclose(d["bias"], [33123, 33276, 32360], atol=10)  # and nominal offsets, counts


def test_accel_units_that_are_not_an_acceleration(run_cli):
    res = run_cli("calibrate", "accel", XSENS / "xsens_acc.mat", "--columns", "col0,col1,col2,col3", "--units", "deg/s")
    assert res.code == 2 and "acceleration" in res.err


def test_accel_session_from_positions_and_its_errors():
    m_true, b_true, g, n = np.diag([1.01, 0.99, 1.0]), np.array([0.1, -0.2, 0.05]), 9.81, 200
    a, positions = six_faces(m_true, b_true, g, n)
    t = np.arange(len(a)) / 100.0
    intervals = [(k * n, (k + 1) * n) for k in range(6)]
    cal = accel_session(t, a, intervals, positions, g, "m/s^2")
    assert np.allclose(cal.M, m_true, atol=1e-3) and np.allclose(cal.bias, b_true, atol=1e-3)
    explicit = [{**p, "start": s, "end": e} for p, (s, e) in zip(positions, intervals, strict=True)]
    assert np.allclose(accel_session(t, a, [], explicit, g, "m/s^2").M, cal.M)
    with pytest.raises(TestError, match="5 static intervals detected but 6 positions") as exc:
        accel_session(t, a, intervals[:5], positions, g, "m/s^2")
    assert exc.value.fields == ["factor", "window_s"] and "--" not in str(exc.value)
    with pytest.raises(InputError, match="every position or for none"):
        accel_session(t, a, intervals, [explicit[0]] + positions[1:], g, "m/s^2", positions_file="pos.toml")
    with pytest.raises(InputError, match="up must be an axis"):
        accel_session(t, a, intervals, [{**positions[0], "up": 3}] + positions[1:], g, "m/s^2")


@pytest.mark.parametrize("counts_per_unit", [1.0, 1670.0])
def test_free_fit_uncertainty_scales_with_the_unit_and_covers_the_truth(counts_per_unit):
    """The |a| = g fit's sigmas must not depend on the unit of the readings (in raw counts the parameters span
    1e7 and an unscaled pseudo-inverse dropped directions: a bias sigma 500x too small); over seeds the bias
    lies inside 3 sigma."""
    from accelsim import attitudes

    from align.calibration.accel import calibrate_accel_free

    m_true = np.array([[1.01, 0.002, -0.003], [0.001, 0.99, 0.004], [0.0, 0.0, 1.005]])
    b_true = np.array([0.3, -0.2, 0.1])
    z = []
    for seed in range(20):  # 20 attitudes: 11 degrees of freedom for the residual scale
        means, _, _ = attitudes(m_true, b_true, 9.80665, k=20, seed=seed)
        rng = np.random.default_rng(seed)
        means = means + rng.normal(0, 0.01, means.shape)  # attitude-to-attitude scatter of 0.01 m/s^2
        ref = calibrate_accel_free(means)
        cal = calibrate_accel_free(means * counts_per_unit, units="counts")
        assert np.allclose(cal.sigma_bias, ref.sigma_bias * counts_per_unit, rtol=1e-4)
        z.append((ref.bias - b_true) / ref.sigma_bias)
    assert np.mean(np.abs(np.array(z)) < 3) > 0.95
