import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from align.errors import HandednessError
from align.model import SensorModel, angles, check_handedness, nearest_rotation, non_orthogonal_axes, small_rotation_matrix
from align.units import DEG


def test_small_rotation_matches_exact_rotation_to_first_order():
    a, b, c = 1e-4, -2e-4, 3e-4
    exact = Rotation.from_rotvec([a, b, c]).as_matrix().T  # M = R^T for a package rotated by R
    assert np.allclose(small_rotation_matrix(a, b, c), exact, atol=1e-7)


def test_angles_of_known_model():
    d = np.array([0.05, -0.03, 0.02]) * DEG
    scale = np.array([1.01, 0.98, 1.002])
    rot = Rotation.from_rotvec([0.2 * DEG, -0.1 * DEG, 0.7 * DEG])
    m = SensorModel.from_rotation(rot, scale=scale, delta=d)
    ang = m.angles()
    assert np.allclose(ang.scale, scale, rtol=1e-12)
    assert np.allclose(ang.delta, d, atol=1e-12)  # axis-to-axis is invariant to the mounting rotation
    u = m.M / scale[:, None]
    assert np.allclose(np.cos(ang.psi), np.diag(u))
    assert ang.phi[0, 1] == pytest.approx(np.arcsin(u[0, 1]))
    assert np.isnan(ang.phi[1, 1])


def test_mounting_rotation_recovered_for_orthogonal_gyros():
    rot = Rotation.from_rotvec([0.3, -0.2, 0.5])
    m = SensorModel.from_rotation(rot)
    assert np.allclose(angles(m.M).mounting_rotvec, rot.as_rotvec(), atol=1e-12)


def test_non_orthogonal_axes_dot_products():
    n = non_orthogonal_axes(0.01, -0.02, 0.015)
    assert np.allclose(np.linalg.norm(n, axis=1), 1)
    assert np.allclose([n[0] @ n[1], n[0] @ n[2], n[1] @ n[2]], np.sin([0.01, -0.02, 0.015]))


def test_nearest_rotation_is_proper_and_idempotent():
    rng = np.random.default_rng(1)
    m = np.eye(3) + 0.05 * rng.normal(size=(3, 3))
    r = nearest_rotation(m)
    assert np.allclose(r @ r.T, np.eye(3)) and np.linalg.det(r) == pytest.approx(1)
    assert np.allclose(nearest_rotation(r), r)


def test_correct_inverts_measure():
    m = SensorModel.from_rotation(Rotation.from_rotvec([0.01, 0.02, -0.01]), scale=[1.01, 0.99, 1], bias=[0.1, 0, -0.2])
    w = np.random.default_rng(0).normal(size=(50, 3))
    assert np.allclose(m.correct(m.measure(w)), w)
    assert np.allclose(m.alignment() @ m.M, np.eye(3))


def test_handedness_error_on_reflected_matrix():
    with pytest.raises(HandednessError, match="det"):
        check_handedness(np.diag([1.0, 1.0, -1.0]))
    check_handedness(np.eye(3))


def test_model_is_immutable():
    m = SensorModel.identity()
    with pytest.raises(ValueError):
        m.M[0, 0] = 2.0


def test_rotation_vector_matches_scipy():
    from align.model import rotation_vector

    rng = np.random.default_rng(3)
    for rv in list(rng.normal(size=(20, 3))) + [np.array([np.pi - 1e-3, 0, 0]), np.zeros(3), np.array([0, 0, 1e-9])]:
        r = Rotation.from_rotvec(rv).as_matrix()
        assert np.allclose(rotation_vector(r), Rotation.from_matrix(r).as_rotvec(), atol=1e-9)


@pytest.mark.slow
def test_from_angles_matches_the_sympy_form():
    from align.sensitivity import ELEMENTS, matrix_from_angles

    rng = np.random.default_rng(4)
    vals = dict(zip(ELEMENTS, rng.normal(0, 0.05, 9)))
    psi = [vals["psi_x"], vals["psi_y"], vals["psi_z"]]
    phi = np.full((3, 3), np.nan)
    for i, a in enumerate("xyz"):
        for j, b in enumerate("xyz"):
            if i != j:
                phi[i, j] = vals[f"phi_{a}{b}"]
    assert np.allclose(SensorModel.from_angles(psi, phi).M, matrix_from_angles(vals), atol=1e-15)
