"""The strapdown integrator against trajectories known in closed form, to its stated order."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from support import coning

from align.attitude import quat_from_rotvec, quat_multiply, quat_to_matrix
from align.navigation.strapdown import (
    earth_rate_ned,
    euler_from_quat,
    level_attitude,
    navigate,
    normal_gravity,
    quat_from_euler,
    rotate,
)

G = 9.8

# ---- a coordinated turn: level, on a circle of radius R at angular speed W, body x along the velocity ----
R, W = 50.0, 0.4


def _turn(t):
    """Position, velocity, acceleration (NED) and the body-to-NED quaternions of the turn, exactly."""
    p = R * np.stack([np.sin(W * t), 1 - np.cos(W * t), 0 * t], -1)
    v = R * W * np.stack([np.cos(W * t), np.sin(W * t), 0 * t], -1)
    a = R * W**2 * np.stack([-np.sin(W * t), np.cos(W * t), 0 * t], -1)
    q = np.stack([np.cos(W * t / 2), 0 * t, 0 * t, np.sin(W * t / 2)], -1)  # heading W t
    return p, v, a, q


def _turn_errors(fs, duration=20.0, step=1):
    t = np.arange(int(duration * fs) + 1) / fs
    p, v, a, q = _turn(t)
    f = rotate(q * np.array([1, -1, -1, -1]), a - np.array([0, 0, G]))  # f = C^T (a - g)
    w = np.tile([0.0, 0.0, W], (len(t), 1))
    tr = navigate(w, f, 1 / fs, q[0], v[0], p[0], step=step, gravity=G)
    k = np.arange(len(tr.t)) * step
    return (np.abs(tr.p - p[k]).max(), np.abs(tr.v - v[k]).max(),
            Rotation.from_matrix(quat_to_matrix(tr.q[-1]).T @ quat_to_matrix(q[k[-1]])).magnitude())


def test_constant_rates_at_rest_keep_the_attitude_exact_and_the_body_still():
    w = np.array([0.3, -0.2, 0.5])
    t = np.arange(1001) / 100
    q_true = quat_multiply(quat_from_euler(0.1, 0.2, 0.3), quat_from_rotvec(np.outer(t, w)))
    f = rotate(q_true * np.array([1, -1, -1, -1]), np.array([0, 0, -G]))
    tr = navigate(np.tile(w, (len(t), 1)), f, 0.01, q_true[0], gravity=G)
    miss = Rotation.from_matrix(quat_to_matrix(tr.q[-1]).T @ quat_to_matrix(q_true[-1])).magnitude()
    assert miss < 1e-12
    # the specific force turns with the body: the trapezoid of C f leaves an h^2 velocity error only
    assert np.abs(tr.v).max() < 2e-3 and np.abs(tr.p).max() < 1e-2


def test_a_coordinated_turn_converges_at_second_order():
    errs = [_turn_errors(fs) for fs in (25, 50, 100)]
    for i in (0, 1):  # position and velocity: trapezoid rules, h^2
        assert 3.4 < errs[0][i] / errs[1][i] < 4.6 and 3.4 < errs[1][i] / errs[2][i] < 4.6
    assert errs[2][0] < 0.05 and errs[2][1] < 0.01
    assert max(e[2] for e in errs) < 1e-10  # the rate is constant: the attitude is exact


def test_two_speed_steps_keep_the_attitude_and_the_order():
    # 10 samples per navigation step: the attitude is the same (each step's rotation composed from the samples)
    fine, coarse = _turn_errors(100), _turn_errors(100, step=10)
    assert coarse[2] < 1e-10
    assert coarse[1] < 0.05 and coarse[0] < 0.5  # h = 0.1 s now
    assert _turn_errors(200, step=10)[0] < coarse[0] / 3.4 and fine[0] < coarse[0]


# ---- coning at rest (the attitude module's test motion) ----
T = 2.0  # coning (conftest.coning)


def _cone_errors(fs, order=4):
    t = np.arange(int(T * fs) + 1) / fs
    q, w = coning(t)
    f = rotate(q * np.array([1, -1, -1, -1]), np.array([0, 0, -G]))
    tr = navigate(w, f, 1 / fs, q[0], gravity=G, order=order)
    att = Rotation.from_matrix(quat_to_matrix(tr.q[-1]).T @ quat_to_matrix(q[-1])).magnitude()
    return att, np.abs(tr.v).max(), np.abs(tr.p).max()


@pytest.mark.parametrize("order, ratio", [(4, 16.0), (2, 4.0)])
def test_coning_at_rest_converges_at_the_attitude_order(order, ratio):
    # at rest C f is constant in NED (its trapezoid is exact): velocity and position err only through the
    # attitude (gravity leaking through the tilt error), so all three fall at the attitude's order
    errs = [_cone_errors(fs, order) for fs in (200, 400, 800)]
    for i in (0, 1, 2):
        assert 0.8 * ratio < errs[0][i] / errs[1][i] < 1.2 * ratio
        assert 0.8 * ratio < errs[1][i] / errs[2][i] < 1.2 * ratio
    if order == 4:
        assert errs[2][2] < 1e-6  # 1 um after 2 s of 5 Hz coning at 800 Hz


def test_at_rest_on_the_rotating_earth_nothing_moves():
    lat = np.radians(47.0)
    g = normal_gravity(lat)
    q0 = quat_from_euler(0.02, -0.01, 1.0)
    conj = q0 * np.array([1, -1, -1, -1])
    n = 3601
    w = np.tile(rotate(conj, earth_rate_ned(lat)), (n, 1))  # what the gyros read at rest: the Earth rate
    f = np.tile(rotate(conj, np.array([0, 0, -g])), (n, 1))
    tr = navigate(w, f, 1.0, q0, latitude=lat, earth_rate=True, step=1)
    assert np.abs(euler_from_quat(tr.q) - euler_from_quat(q0)).max() < 1e-9
    assert np.abs(tr.v).max() < 1e-6 and np.abs(tr.p).max() < 1e-3
    # left out, the same readings make the attitude turn with the Earth: 15 deg in the hour
    off = navigate(w, f, 1.0, q0, latitude=lat, earth_rate=False)
    turned = Rotation.from_matrix(quat_to_matrix(off.q[-1]).T @ quat_to_matrix(q0)).magnitude()
    assert abs(np.degrees(turned) - 15.04) < 0.05


def test_levelling_recovers_roll_and_pitch():
    q = quat_from_euler(0.2, -0.3, 0.7)
    f = rotate(q * np.array([1, -1, -1, -1]), np.array([0, 0, -G]))
    assert np.allclose(euler_from_quat(level_attitude(f, 0.7)), [0.2, -0.3, 0.7], atol=1e-12)
