"""The measured misalignment's verdict: propagated through the manoeuvre (errors of several elements add), its
1-sigma by the same propagation, and the guard band. The truth is an attitude computation written here with scipy's
rotations (one rotation composed after another, in the body frame), independent of align.sensitivity.propagation."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from align.present.measured import GUARD_K, MeasuredMargin, OutputMargin, guard, output_margins
from align.sensitivity import allowable, manoeuvre_from_dict
from align.sensitivity.symbolic import matrix_from_angles
from align.units import DEG

#: the reviewer's manoeuvre: y 60 deg then z 60 deg, the x gyro's integrated angle held within 0.1 deg
TWO = {"rotation": [{"axis": "y", "angle": "60 deg"}, {"axis": "z", "angle": "60 deg"}], "limits": {"x": "0.1 deg"}}


def _x_error(d: np.ndarray, steps: list[np.ndarray]) -> float:
    """Largest |x| of rotvec(measured attitude) - rotvec(true attitude) after each step, each step a fixed-axis turn
    applied in the body frame after the previous ones; the gyros read ``d`` times each true increment."""
    true, meas, worst = Rotation.identity(), Rotation.identity(), 0.0
    for theta in steps:
        true, meas = true * Rotation.from_rotvec(theta), meas * Rotation.from_rotvec(d @ theta)
        worst = max(worst, abs((meas.as_rotvec() - true.as_rotvec())[0]))
    return worst


def _unit_rows(m):
    return m / np.linalg.norm(m, axis=1, keepdims=True)


STEPS = [np.array([0, 60 * DEG, 0]), np.array([0, 0, 60 * DEG])]


def test_the_reviewers_unit_fails_although_each_element_alone_passes():
    man = manoeuvre_from_dict(TWO, "two")
    m = matrix_from_angles({"phi_xy": 0.085 * DEG, "phi_xz": 0.095 * DEG})
    sigma = np.full((3, 3), 1e-6)
    (x,) = output_margins(m, sigma, None, man)
    truth = _x_error(_unit_rows(m), STEPS)
    assert truth / DEG == pytest.approx(0.170, abs=0.0005)  # the review's number
    assert x.error == pytest.approx(truth, rel=1e-6)
    assert x.limit == pytest.approx(0.1 * DEG) and x.status == "FAIL"
    # each element alone is within its allowance (0.0955 and 0.1057 deg): the per-element table cannot decide
    allow = allowable(man).allowable
    for name, v in (("phi_xy", 0.085), ("phi_xz", 0.095)):
        assert MeasuredMargin(name, v * DEG, 1e-6, allow[name]).status == "PASS"


@pytest.mark.parametrize("seed", range(3))
def test_output_error_and_its_sigma_against_an_independent_monte_carlo(seed):
    """A misaligned unit (random small rotation and skew) through the reviewer's manoeuvre: the error matches the
    scipy composition; the linear 1-sigma matches the spread over draws of M from sigma(M)."""
    rng = np.random.default_rng(seed)
    man = manoeuvre_from_dict(TWO, "two")
    m = Rotation.from_rotvec(rng.normal(0, 0.05 * DEG, 3)).as_matrix().T + rng.normal(0, 3e-4, (3, 3))
    sigma = rng.uniform(1e-5, 4e-5, (3, 3))
    (x,) = output_margins(m, sigma, None, man)
    assert x.error == pytest.approx(_x_error(_unit_rows(m), STEPS), rel=1e-6, abs=1e-12)
    draws = [_x_error(_unit_rows(m + rng.normal(size=(3, 3)) * sigma), STEPS) for _ in range(1500)]
    assert x.sigma == pytest.approx(np.std(draws), rel=0.1)


def test_a_nominal_mounting_is_taken_out_first():
    """With the IMU mounted turned 90 deg about z (N), the same directions relative to N give the same error."""
    man = manoeuvre_from_dict(TWO, "two")
    d = matrix_from_angles({"phi_xy": 0.05 * DEG, "phi_xz": 0.04 * DEG})
    n = Rotation.from_rotvec([0, 0, np.pi / 2]).as_matrix().round()
    (a,) = output_margins(d, np.zeros((3, 3)), None, man)
    (b,) = output_margins(d @ n * 1.003, np.zeros((3, 3)), n, man)  # M = D N (M N^T = D), scale errors left out
    assert b.error == pytest.approx(a.error, rel=1e-9)
    assert a.error == pytest.approx(_x_error(_unit_rows(d), STEPS), rel=1e-6)


@pytest.mark.parametrize(("margin_sigmas", "status"), [(3.0, "PASS"), (0.5, "WARN"), (-0.5, "WARN"), (-3.0, "FAIL")])
def test_guard_band(margin_sigmas, status):
    """PASS above k sigma, FAIL below -k sigma, WARN within (k = 2, stated on the page)."""
    sigma, limit = 0.001 * DEG, 0.1 * DEG
    out = OutputMargin("x", limit - margin_sigmas * sigma, sigma, limit)
    assert GUARD_K == 2 and out.status == status and out.sigmas == pytest.approx(margin_sigmas)
    row = MeasuredMargin("phi_xz", -(limit - margin_sigmas * sigma), sigma, limit)
    assert row.status == status and row.ok == (status != "FAIL")
    assert guard(np.inf, sigma) == "-" and MeasuredMargin("psi_x", 0.01, sigma, np.inf).status == "-"
