"""The rate-table simulator's physics against truth computed by hand (and by scipy's rotations), not by the
simulator's own kinematics nor the estimator's Earth-rate code."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from align.alignment.plan import Plan, Step
from align.alignment.simulate import (
    SessionSpec,
    SimulationTruth,
    mount_model,
    mounting_from_rotation,
    random_model,
    simulate_run,
    simulate_session,
)
from align.errors import InputError
from align.model import SensorModel
from align.results import result_from_dict
from align.units import DEG
from align.values import approx_equal

OMEGA = 7.2921150e-5  # rad/s, Earth's rate (WGS-84)
QUIET = dict(noise_density=0.0, fs=100.0, static_s=1.0, dwell_s=2.0)
EAST, NORTH, UP = np.eye(3)


def _plan(text_steps, **test) -> Plan:
    return Plan.from_dict({"test": test, "step": text_steps})


def test_static_at_a_known_rest_reads_earth_rate_in_system_axes_before_and_after_a_quarter_turn():
    lat = 45 * DEG
    plan = _plan([{"axis": "+z", "angle": "90 deg"}], latitude="45 deg", rest=["north", "west", "up"])
    run = simulate_run(plan, SensorModel.identity(), SessionSpec(**QUIET), 0)
    head, tail = run.pieces[0], run.pieces[-1]
    assert head.kind == tail.kind == "static" and run.latitude == pytest.approx(lat)
    # x north, y west, z up: w = Omega (cos L, 0, sin L) at every static sample
    assert np.allclose(run.w[head.start:head.end], OMEGA * np.array([np.cos(lat), 0, np.sin(lat)]), rtol=0, atol=1e-18)
    # after +90 deg about up: x points west, y south -> w = Omega (0, -cos L, sin L)
    assert np.allclose(run.w[tail.start:tail.end], OMEGA * np.array([0, -np.cos(lat), np.sin(lat)]), rtol=0, atol=1e-18)
    # during the turn, z stays up: its rate is the table's plus Omega sin L; the table's integrates to 90 deg
    s, e = run.steps[0]
    assert np.sum(run.w[s:e, 2] - OMEGA * np.sin(lat)) / 100.0 == pytest.approx(np.pi / 2, rel=1e-12)
    assert np.array_equal(run.rests[0], np.column_stack([NORTH, -EAST, UP]))


def test_table_axis_north_dwell_sees_the_north_component_along_the_axis_and_the_vertical_one_turning():
    lat = 30 * DEG
    # x north, y up, z east; the table spins about north at 50 deg/s
    plan = _plan([{"axis": "+x", "rate": "50 deg/s"}], latitude="30 deg", table_axis="north", rest=["north", "up", "east"])
    run = simulate_run(plan, SensorModel.identity(), SessionSpec(**{**QUIET, "dwell_s": 8.0}), 0)
    s, e = run.steps[0]
    dwell = slice(s + 60, e - 60)  # the ramps take 50 samples
    assert np.allclose(run.w[dwell, 0], 50 * DEG + OMEGA * np.cos(lat), rtol=0, atol=1e-15)
    # y and z turn in the east-up plane, where Earth's rate is Omega sin L (up)
    assert np.allclose(np.hypot(run.w[dwell, 1], run.w[dwell, 2]), OMEGA * np.sin(lat), rtol=1e-9)
    assert np.ptp(run.w[dwell, 1]) > 1.9 * OMEGA * np.sin(lat)  # it really turns (more than a turn)


def test_a_turn_integrates_to_its_planned_angle_and_turns_the_orientation_about_the_table_axis():
    plan = _plan([{"axis": "-y", "angle": "-270 deg", "table_axis": "east"}])
    run = simulate_run(plan, SensorModel.identity(), SessionSpec(**QUIET), 4)
    s, e = run.steps[0]
    u = np.array([0.0, -1.0, 0.0])
    assert np.sum(run.w[s:e] @ u) / 100.0 == pytest.approx(-1.5 * np.pi, rel=1e-12)
    assert np.abs(run.w[s:e] - np.outer(run.w[s:e] @ u, u)).max() == 0  # nothing off the axis
    c0, c1 = run.rests[0], run.orientation(e)[0]
    assert np.allclose(c0 @ u, EAST, atol=1e-12)  # the step's axis along the table axis
    assert np.allclose(run.orientation(s)[0], c0, atol=1e-3)  # half a sample of the first ramp in (1e-4 rad)
    # scipy's rotation about east by the planned angle takes the start orientation to the end one
    assert np.allclose(Rotation.from_rotvec(EAST * -1.5 * np.pi).as_matrix() @ c0, c1, atol=1e-12)


def test_reorientation_moves_are_in_the_log_with_the_relative_rotation_between_the_steps():
    plan = Plan.standard_rate(100 * DEG)  # +x, +x, +y, +y, +z, +z on a vertical table
    spec = SessionSpec(**QUIET, reorient=True)
    run = simulate_run(plan, SensorModel.identity(), spec, 2)
    assert len(run.moves) == 2
    # x up -> y up: a quarter turn about -z; y up -> z up: a quarter turn about -x (by hand: u_new x u_old)
    for move, axis in zip(run.moves, ([0, 0, -1], [-1, 0, 0])):
        assert move.angle == pytest.approx(np.pi / 2, abs=1e-12)
        assert np.allclose(move.axis, axis, atol=1e-12)
        assert move.rate == pytest.approx(20 * DEG, rel=0.01)  # scaled by a fraction of a sample to the exact angle
        assert np.allclose(run.w[move.start:move.end].sum(axis=0) / 100.0, np.pi / 2 * np.array(axis), atol=1e-12)
        before, after = run.orientation([move.start - 1, move.end])
        rel = Rotation.from_matrix(after @ before.T)
        assert rel.magnitude() == pytest.approx(np.pi / 2, abs=1e-9)
        assert np.allclose(before.T @ rel.as_rotvec(), np.pi / 2 * np.array(axis), atol=1e-9)
    # static between every step and move: six steps and two moves are the only motions
    moving = np.abs(run.w).max(axis=1) > 0
    assert np.sum(np.diff(moving.astype(int)) == 1) + moving[0] == 8
    # without reorient the orientation switches and nothing else moves
    flat = simulate_run(plan, SensorModel.identity(), SessionSpec(**QUIET), 2)
    assert flat.moves == () and len(flat.t) < len(run.t)
    flat_moving = np.abs(flat.w).max(axis=1) > 0
    assert np.sum(np.diff(flat_moving.astype(int)) == 1) + flat_moving[0] == 6


def test_a_move_between_stated_rests_is_their_relative_rotation():
    # z up (x north) then x up (y west, z south): a quarter turn about east, i.e. about system -y
    plan = _plan([{"axis": "+z", "angle": "360 deg", "rest": ["north", "west", "up"]},
                  {"axis": "+x", "angle": "360 deg", "rest": ["up", "west", "south"]}])
    run = simulate_run(plan, SensorModel.identity(), SessionSpec(**QUIET, reorient=True), 0)
    (move,) = run.moves
    assert move.angle == pytest.approx(np.pi / 2, abs=1e-12) and np.allclose(move.axis, [0, -1, 0], atol=1e-12)
    assert np.allclose(run.rests[1], np.column_stack([UP, -EAST, -NORTH]), atol=0)


def test_mounting_makes_ideal_gyros_read_n_w():
    n = mounting_from_rotation(30 * DEG, [1, 1, 0])
    axis = np.array([1, 1, 0]) / np.sqrt(2)
    # row i: gyro i's axis in the system frame, the IMU turned by 30 deg about (1, 1, 0)
    assert np.allclose(n, Rotation.from_rotvec(axis * 30 * DEG).as_matrix().T, atol=1e-15)
    plan = _plan([{"axis": "+x", "rate": "100 deg/s"}, {"axis": "+y", "angle": "90 deg"},
                  {"axis": "+z", "rate": "-40 deg/s"}], latitude="50 deg")
    run = simulate_run(plan, mount_model(SensorModel.identity(), n), SessionSpec(**QUIET, reorient=True), 1)
    assert np.allclose(run.g, run.w @ n.T, rtol=0, atol=1e-15)
    m = random_model(np.random.default_rng(5), 0.5 * DEG, mounting=n).M
    assert np.abs(m @ n.T - np.eye(3)).max() < 0.03 and np.linalg.det(m) > 0
    with pytest.raises(InputError, match="rotation"):
        mount_model(SensorModel.identity(), np.diag([1.0, 1.0, -1.0]))


def test_head_zero_starts_moving_at_sample_zero_and_the_bias_path_is_what_the_gyros_add():
    plan = Plan.standard_angle(180 * DEG)
    run = simulate_run(plan, SensorModel(np.eye(3), [0.01, -0.02, 0.03]),
                       SessionSpec(**{**QUIET, "static_s": 0.5}, head_s=0.0, bias_walk=1e-4), 3)
    assert run.pieces[0].kind == "step" and run.w[0, 0] > 0
    assert np.allclose(run.g - run.w, run.bias, rtol=0, atol=1e-15)  # M = I, no white noise
    assert np.allclose(run.bias[0], [0.01, -0.02, 0.03], atol=1e-4) and np.ptp(run.bias[:, 0]) > 0


def test_latitude_comes_from_the_plan_and_a_disagreeing_spec_is_refused():
    plan = _plan([{"axis": "+z", "rate": "10 deg/s"}], latitude="45 deg")
    run = simulate_run(plan, SensorModel.identity(), SessionSpec(**QUIET), 0)
    assert np.allclose(run.w[:50, 2], OMEGA * np.sin(45 * DEG), rtol=1e-12)  # z up: the vertical component
    same = simulate_run(plan, SensorModel.identity(), SessionSpec(**QUIET, latitude=45 * DEG), 0)
    assert np.array_equal(same.w, run.w)
    with pytest.raises(InputError, match="latitude") as err:
        simulate_run(plan, SensorModel.identity(), SessionSpec(**QUIET, latitude=40 * DEG), 0)
    assert "\n" not in str(err.value)
    t, g, w = simulate_session(plan, SensorModel.identity(), SessionSpec(**QUIET), 0)
    assert np.array_equal(t, run.t) and np.array_equal(g, run.g) and np.array_equal(w, run.w)


@pytest.mark.slow
def test_flicker_gives_the_allan_floor_of_its_coefficient():
    from align.noise.allan import allan

    b = 0.01 * DEG
    plan = Plan((Step(2, 1, rate=10 * DEG),))
    run = simulate_run(plan, SensorModel.identity(), SessionSpec(fs=100.0, noise_density=0.0, flicker=b, head_s=600.0,
                                                                 dwell_s=1.0, static_s=0.0), 1)
    res = allan(run.bias[:60_000], 100.0, grid="octave")
    floor = np.median(res.adev[:, (res.tau >= 0.5) & (res.tau <= 30)], axis=1)
    assert np.all(np.abs(floor / (0.664 * b) - 1) < 0.15)  # IEEE 952: the flicker floor is 0.664 B


def test_truth_keeps_mounting_and_moves_and_reads_files_without_them():
    n = mounting_from_rotation(90 * DEG, [0, 0, 1])
    run = simulate_run(Plan.standard_rate(100 * DEG), SensorModel.identity(), SessionSpec(**QUIET, reorient=True), 0)
    truth = SimulationTruth(random_model(np.random.default_rng(1), 0.1 * DEG, mounting=n), "deg/s", 1, {}, n, run.moves)
    back = result_from_dict(truth.to_dict())
    assert approx_equal(back, truth, rtol=1e-12, atol=1e-15) and len(back.moves) == 2
    assert np.array_equal(back.mounting, n)
    old = truth.to_dict()
    del old["mounting"], old["moves"]
    legacy = result_from_dict(old)
    assert legacy.mounting is None and legacy.moves == ()
