"""The refusals of a multi-position gyro session: each one line naming the pose or rotation, on simulated
sessions whose fault is known (too few poses, short or moving poses, clipped rotations, no rest at the start)."""

import numpy as np
import pytest

from align.calibration.gyro import calibrate_gyro_session
from align.calibration.gyrochecks import parse_intervals, saturated_samples
from align.calibration.posesim import PoseSessionSpec, random_sensors, simulate_poses
from align.errors import InputError, TestError
from align.units import DEG

LSB = 131.0 / DEG  # counts per rad/s


def _run(seed=0, **spec):
    rng = np.random.default_rng(seed)
    m_a, b_a, m_g, b_g = random_sensors(rng)
    return simulate_poses(PoseSessionSpec(**{"fs": 50.0, "init_s": 20.0, **spec}), m_a, b_a, m_g, b_g, rng)


def _one_line(exc):
    text = str(exc.value)
    assert "\n" not in text
    return text


def test_too_few_poses_are_refused_with_the_number_needed():
    run = _run(poses=8)
    with pytest.raises(TestError) as exc:
        calibrate_gyro_session(run.t, run.acc, run.gyr, "m/s^2", "rad/s")
    assert "only 8 static poses" in _one_line(exc) and "at least 10" in str(exc.value)


def test_given_poses_too_short_or_moving_are_named():
    run = _run(1)
    poses = [list(p) for p in run.poses]
    short = [tuple(p) for p in poses]
    short[3] = (short[3][0], short[3][0] + 20)           # 0.4 s
    with pytest.raises(TestError) as exc:
        calibrate_gyro_session(run.t, run.acc, run.gyr, "m/s^2", "rad/s", intervals=short)
    assert _one_line(exc).startswith("log: pose 4 (t=") and "shorter than 1 s" in str(exc.value)
    moving = [tuple(p) for p in poses]
    moving[5] = (moving[5][0] - 100, moving[5][1])        # starts 2 s early: inside the rotation before it
    with pytest.raises(TestError) as exc:
        calibrate_gyro_session(run.t, run.acc, run.gyr, "m/s^2", "rad/s", intervals=moving)
    assert "pose 6 (t=" in _one_line(exc) and "is not static" in str(exc.value)
    text = ",".join(f"{a}:{b}" for a, b in run.poses)
    got = calibrate_gyro_session(run.t, run.acc, run.gyr, "m/s^2", "rad/s", intervals=text)
    assert got.poses == tuple(run.poses)


def test_malformed_intervals():
    assert parse_intervals("0:10, 20-30 40..50", 100) == [(0, 10), (20, 30), (40, 50)]
    with pytest.raises(InputError, match="'a:b' is not a sample range"):
        parse_intervals("0:10,a:b", 100)
    with pytest.raises(InputError, match="pose 2: samples 90:120 are not a range inside the log's 100 samples"):
        parse_intervals("0:10,90:120", 100)
    with pytest.raises(InputError, match="start before pose 1 ends"):
        parse_intervals("0:10,5:20", 100)


@pytest.mark.slow
def test_a_clipped_rotation_is_refused_by_name_and_can_be_left_out():
    run = _run(2)
    raw = np.round(run.gyr * LSB + 40.0)
    peak = np.abs(raw[run.poses[3][1]:run.poses[4][0]]).max(axis=0)   # rotation 4's peaks
    rail = float(np.sort(peak)[-1] * 0.9)                              # clips rotation 4 (and maybe others)
    clipped = np.clip(raw, -rail, rail)
    hit = [k for k in range(1, len(run.poses))
           if (np.abs(clipped[run.poses[k - 1][1] - 1:run.poses[k][0] + 1]) >= rail).any()]
    assert 4 in hit
    with pytest.raises(TestError) as exc:
        calibrate_gyro_session(run.t, run.acc, clipped, "m/s^2", "counts")
    assert f"rotation {hit[0]} (t=" in _one_line(exc) and "at the gyro's range" in str(exc.value)
    assert f"drop_rotations='{hit[0]}'" in str(exc.value)  # the CLI spells it --drop-rotations N
    got = calibrate_gyro_session(run.t, run.acc, clipped, "m/s^2", "counts", drop=tuple(hit)).gyroscope
    assert {f"rotation {k}" for k in hit} == set(got.checks)
    assert len(got.residuals) == len(run.poses) - 1 - len(hit)
    # the full scale given: samples at it count, the flat tops are not needed
    with pytest.raises(TestError, match=f"rotation {hit[0]} "):
        calibrate_gyro_session(run.t, run.acc, clipped, "m/s^2", "counts", gyro_range=rail)
    with pytest.raises(InputError, match="no rotation 40: the session has rotations 1 to 19"):
        calibrate_gyro_session(run.t, run.acc, clipped, "m/s^2", "counts", drop=(40,))


def test_smooth_peaks_and_quantised_readings_are_not_saturation():
    t = np.arange(2000) / 100.0
    g = np.round(np.column_stack([3000 * np.sin(t), 2000 * np.cos(0.7 * t), 100 * np.sin(3 * t)]))
    assert not saturated_samples(g, np.zeros(3), np.ones(3), None, counts=True).any()
    rails = g.copy()
    rails[500:503, 0] = 32767.0  # a 16-bit rail, reached
    assert saturated_samples(rails, np.zeros(3), np.ones(3), None, counts=True)[500:503, 0].all()


def test_a_record_that_starts_moving_is_refused():
    run = _run(3, init_s=0.0)
    with pytest.raises(TestError) as exc:
        calibrate_gyro_session(run.t, run.acc, run.gyr, "m/s^2", "rad/s")
    assert "does not start at rest" in _one_line(exc) and "init_static_s" in str(exc.value)


@pytest.mark.slow
def test_a_unit_mix_up_is_refused():
    run = _run(4)
    with pytest.raises(TestError, match="scale factor .* is outside 1 \\+/- 0.2: wrong {gyro_units}|outside 1"):
        calibrate_gyro_session(run.t, run.acc, run.gyr / DEG, "m/s^2", "rad/s")   # deg/s read as rad/s
