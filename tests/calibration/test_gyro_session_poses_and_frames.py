"""calibrate gyro after review 15/16, on simulated sessions of known truth (align.calibration.posesim):
pose 1 stays inside the true rest, a gyro turned or mirrored relative to the accelerometer, the rotation
table in the file, residuals beyond the noise, and the system frame's consistency and uncertainty."""

import re

import numpy as np
import pytest

from align.calibration import CalibrationSet
from align.calibration.accel import StaticDetector
from align.calibration.gyro import calibrate_gyro_session, detect_poses
from align.calibration.gyroframe import frame_consistency, in_system_frame
from align.calibration.posesim import PoseSessionSpec, accel_frame_truth, random_sensors, simulate_poses
from align.calibration.statics import initial_static_period
from align.errors import TestError

QUICK = {"fs": 50.0, "init_s": 20.0}


def _session(seed, k_ga=None, **spec):
    rng = np.random.default_rng(seed)
    m_a, b_a, m_g, b_g = random_sensors(rng)
    run = simulate_poses(PoseSessionSpec(**{**QUICK, **spec}), m_a, b_a, m_g, b_g, rng, k_ga)
    return run, *accel_frame_truth(m_a, m_g)


@pytest.mark.slow
def test_pose_1_never_runs_into_the_first_turn():
    """400 starts at 200 Hz: the detected pose 1 (the gyro bias) ends inside the true rest every time, although the
    accelerometer alone puts the end of the rest after the turn has begun in some (a turn about the vertical)."""
    late = 0
    for seed in range(900, 1300):
        run = _session(seed, fs=200.0, init_s=30.0, poses=3)[0]
        rest = run.poses[0][1]
        late += initial_static_period(run.acc, 200.0) * 200.0 > rest
        poses, init, _ = detect_poses(run.t, run.acc, run.gyr, 200.0, StaticDetector(), None)
        assert poses[0][1] <= rest and init * 200.0 <= rest, seed
    assert late >= 5, late


@pytest.mark.parametrize("columns", ["y,-x,z", "z,x,y", "-x,-y,z"])
@pytest.mark.slow
def test_a_gyro_turned_relative_to_the_accelerometer_is_fitted(columns):
    """Two chips, or gyro columns in another order: the fit starts from the 24 axis-to-axis rotations and finds
    M = P M_c (P the columns' rotation), inside its 3 sigma, with a note."""
    run, _, g_acc, _ = _session(6)
    p = np.zeros((3, 3))
    for i, c in enumerate(columns.split(",")):
        p[i, "xyz".index(c[-1])] = -1.0 if c.startswith("-") else 1.0
    got = calibrate_gyro_session(run.t, run.acc, run.gyr @ p.T, "m/s^2", "rad/s").gyroscope
    assert np.abs((got.M - p @ g_acc) / got.sigma_M).max() < 3.5
    turn = np.degrees(np.arccos((np.trace(p) - 1) / 2))                  # 90, 120 or 180 deg, and the small
    note = next(n for n in got.notes if "gyro's axes are turned by" in n)   # misalignments of the two triads
    assert abs(float(re.search(r"turned by ([\d.]+) deg relative to the accelerometer's", note)[1]) - turn) < 5


@pytest.mark.parametrize("columns", [[0, 1, 2, -1], [1, 0, 2, 1]])
def test_a_gyro_mirrored_relative_to_the_accelerometer_is_named(columns):
    """One column's sign flipped, or two columns swapped: one line saying so, not a false 'do not span 3-D'."""
    run = _session(6)[0]
    order, sign = columns[:3], np.array([1.0, 1.0, float(columns[3])])
    with pytest.raises(TestError) as exc:
        calibrate_gyro_session(run.t, run.acc, run.gyr[:, order] * sign, "m/s^2", "rad/s", where="s.csv")
    assert str(exc.value).startswith("s.csv: gyro axes mirrored relative to the accelerometer")
    assert exc.value.fields == ["gyro_columns", "accel_columns"] and "\n" not in str(exc.value)


def test_the_rotation_table_is_in_the_file_and_the_largest_residual_is_the_tables():
    run, _, g_acc, _ = _session(3)
    s = calibrate_gyro_session(run.t, run.acc, run.gyr, "m/s^2", "rad/s")
    rows = s.gyroscope.rotations
    assert [r["rotation"] for r in rows] == list(range(1, 20)) and all(r["used"] for r in rows)
    for r, (a, _), (b, _) in zip(rows, run.poses[:-1], run.poses[1:]):     # each turn is the simulated one
        true = run.attitude[a].T @ run.attitude[b]
        assert abs(np.degrees(np.arccos(np.clip((np.trace(true) - 1) / 2, -1, 1))) - r["turn_deg"]) < 0.5
    big = max(rows, key=lambda r: r["residual_deg"])
    note = next(n for n in s.gyroscope.notes if "rms residual" in n)
    assert f"largest {big['residual_deg']:.3g} deg, rotation {big['rotation']})" in note
    back = CalibrationSet.from_dict(CalibrationSet(s.sensors()).to_dict()).sensors["gyroscope"]
    assert back.rotations == rows and back.level == s.gyroscope.level and "29 degrees of freedom" in back.level


@pytest.mark.slow
def test_residuals_beyond_the_noise_point_to_the_g_sensitivity_model():
    """A g-sensitive gyro fitted without K_ga leaves residuals ~50x the noise's: a note says so and names the model;
    with K_ga modelled, or without g-sensitivity in the data, no such note."""
    k_true = np.random.default_rng(99).normal(0, 3e-4, (3, 3))
    run = _session(0, k_ga=k_true)[0]
    plain = calibrate_gyro_session(run.t, run.acc, run.gyr, "m/s^2", "rad/s").gyroscope
    assert any("what the sensors' noise explains" in n and "g-sensitivity model" in n for n in plain.notes)
    modelled = calibrate_gyro_session(run.t, run.acc, run.gyr, "m/s^2", "rad/s", g_sensitivity=True).gyroscope
    clean = _session(0)[0]
    quiet = calibrate_gyro_session(clean.t, clean.acc, clean.gyr, "m/s^2", "rad/s").gyroscope
    assert not any("noise explains" in n for n in modelled.notes + quiet.notes)


@pytest.mark.slow
def test_system_frame_1_sigma_includes_the_tables_and_disagreement_is_flagged():
    """Rate-table results of the same gyro with an error of known sigma: the system-frame M of both sensors
    inside 3 sigma for >= 99 % of the elements over 4 sessions x 25 tables (with R taken as exact: far fewer).
    A table of another gyro is refused; one that differs by ~5 sigma beyond a rotation is warned of."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(1)
    z_new, z_exact, warned = [], [], 0
    for seed in range(4):
        run, _, _, _ = _session(seed)
        s = calibrate_gyro_session(run.t, run.acc, run.gyr, "m/s^2", "rad/s")
        p = Rotation.from_rotvec(rng.normal(0, 0.5, 3)).as_matrix()           # w_body = P w_sys
        sigma_t = np.full((3, 3), 3.0 * np.median(s.gyroscope.sigma_M))
        for _ in range(25):
            table = run.M_g @ p + rng.normal(0, 1, (3, 3)) * sigma_t
            acc, gyr, r = in_system_frame(s.accelerometer, s.gyroscope, table_m=table, table_sigma=sigma_t)
            for cal, truth, own in ((gyr, run.M_g @ p, s.gyroscope), (acc, run.M_a @ p, s.accelerometer)):
                z_new.append(((cal.M - truth) / cal.sigma_M).ravel())
                z_exact.append(((cal.M - truth) / np.sqrt(own.sigma_M ** 2 @ r ** 2)).ravel())
            warned += any("warning" in n for n in gyr.notes)
    inside, inside_exact = np.mean(np.abs(z_new) < 3), np.mean(np.abs(z_exact) < 3)
    assert inside >= 0.99 and inside_exact < 0.9, (inside, inside_exact)
    assert warned <= 10, warned   # the largest of six |z| beyond 3: ~2 % of consistent pairs
    other = _session(50)[0]
    with pytest.raises(TestError, match="differ beyond a rotation by .* not the same gyro") as exc:
        in_system_frame(s.accelerometer, s.gyroscope, table_m=other.M_g)
    assert exc.value.fields == ["frame"]
    d = frame_consistency(s.gyroscope.M, s.gyroscope.sigma_M, run.M_g, None)
    shear = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]) * 5.0 * d["sigma"][1]
    bent = run.M_g @ (np.eye(3) + shear)                                   # D_xy moved by 5 sigma
    _, gyr, _ = in_system_frame(s.accelerometer, s.gyroscope, table_m=bent)
    assert any("warning: that difference is" in n for n in gyr.notes)
