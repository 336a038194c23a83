"""The attitude integrator against motions whose attitude is known in closed form."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from support import coning

from align.attitude import increments, integrate, quat_from_rotvec, quat_multiply, quat_to_matrix, rotation

T = 2.0  # coning (conftest.coning): half-angle 0.05 rad about x, axis precessing at 5 Hz


def _cone_error(fs, order, jitter=0.0, seed=0):
    t = np.arange(int(T * fs) + 1) / fs
    if jitter:
        t[1:] += np.random.default_rng(seed).uniform(-jitter, jitter, len(t) - 1) / fs
    truth, w = coning(t)
    q = integrate(w, np.diff(t) if jitter else 1 / fs, truth[0], order=order)
    miss = quat_to_matrix(q[-1]).T @ quat_to_matrix(truth[-1])
    return Rotation.from_matrix(miss).magnitude()


def test_constant_rate_is_integrated_exactly():
    w = np.array([0.3, -1.2, 0.7])
    got = rotation(np.tile(w, (501, 1)), 0.01)
    assert np.allclose(got, Rotation.from_rotvec(w * 5.0).as_matrix(), atol=1e-12)


@pytest.mark.parametrize("order, ratio", [(4, 16.0), (2, 4.0)])
def test_coning_error_falls_at_the_stated_order(order, ratio):
    errors = [_cone_error(fs, order) for fs in (200, 400, 800)]
    assert 0.8 * ratio < errors[0] / errors[1] < 1.2 * ratio
    assert 0.8 * ratio < errors[1] / errors[2] < 1.2 * ratio
    if order == 4:
        assert errors[0] < 2e-5  # 100x closer than the trapezoid's 1.3e-3 rad at 200 Hz


def test_uneven_time_steps_keep_the_fourth_order():
    errors = [_cone_error(fs, 4, jitter=0.2, seed=fs) for fs in (200, 400)]
    assert errors[1] < errors[0] / 10 and errors[0] < 3e-5


def test_the_coning_term_is_what_cancels_the_drift():
    # without it the trapezoid's rotation vectors drift twice as far on the same coning motion
    t = np.arange(401) / 200
    truth, w = coning(t)
    plain = 0.5 / 200 * (w[:-1] + w[1:])
    q = truth[0]
    for p in quat_from_rotvec(plain):
        q = quat_multiply(q, p)
    drift = Rotation.from_matrix(quat_to_matrix(q).T @ quat_to_matrix(truth[-1])).magnitude()
    assert drift > 1.8 * _cone_error(200, 2)


def test_quaternion_helpers_agree_with_scipy():
    rng = np.random.default_rng(3)
    v = rng.normal(size=(20, 3))
    q = quat_from_rotvec(v)
    assert np.allclose(quat_to_matrix(q), Rotation.from_rotvec(v).as_matrix(), atol=1e-12)
    assert np.allclose(quat_to_matrix(quat_multiply(q[:10], q[10:])),
                       Rotation.from_rotvec(v[:10]).as_matrix() @ Rotation.from_rotvec(v[10:]).as_matrix(), atol=1e-12)
    assert np.allclose(quat_from_rotvec(np.full((1, 3), 1e-9))[0], [1, 5e-10, 5e-10, 5e-10])


@pytest.mark.parametrize("dt", [0.0, -0.01, np.nan])
def test_bad_steps_are_refused(dt):
    with pytest.raises(ValueError, match="intervals"):
        increments(np.zeros((5, 3)), dt)
