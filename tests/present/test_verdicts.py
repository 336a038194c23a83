"""The report's verdicts: angle 1-sigma against Monte Carlo, the measured misalignment against a simulation's known
truth and the reference's allowance formula, and the summary's wording."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from align.model import SensorModel
from align.present.measured import measured_margins
from align.present.verdicts import (
    ANGLE_NAMES,
    FAIL,
    INFO,
    PASS,
    WARN,
    Verdict,
    angle_sigmas,
    angle_vector,
    summary_section,
)
from align.units import DEG


def _reference_angles(m):
    """Reference section 1, written out here: psi_i = acos(u_i . e_i), phi_ij = asin(u_i . e_j)."""
    u = m / np.linalg.norm(m, axis=1, keepdims=True)
    psi = np.arccos(np.clip(np.diag(u), -1, 1))
    phi = {f"phi_{'xyz'[i]}{'xyz'[j]}": np.arcsin(u[i, j]) for i in range(3) for j in range(3) if i != j}
    return psi, phi


def test_angle_vector_is_reference_section_1():
    rng = np.random.default_rng(0)
    for _ in range(20):
        m = Rotation.from_rotvec(rng.normal(0, 0.02, 3)).as_matrix().T * (1 + rng.normal(0, 3e-3, (3, 1)))
        v = dict(zip(ANGLE_NAMES, angle_vector(m)))
        psi, phi = _reference_angles(m)
        assert np.allclose([v["psi_x"], v["psi_y"], v["psi_z"]], psi, atol=1e-9)
        assert all(v[k] == pytest.approx(phi[k], abs=1e-12) for k in phi)


@pytest.mark.slow
def test_angle_sigmas_match_monte_carlo():
    rng = np.random.default_rng(1)
    m = Rotation.from_rotvec([0.004, -0.007, 0.01]).as_matrix().T * np.array([[1.002], [0.999], [1.001]])
    sigma = np.full((3, 3), 2e-5) + rng.uniform(0, 2e-5, (3, 3))
    lin = angle_sigmas(m, sigma)
    draws = np.array([angle_vector(m + rng.normal(size=(3, 3)) * sigma) for _ in range(4000)])
    mc = dict(zip(ANGLE_NAMES, draws.std(axis=0)))
    for k in ANGLE_NAMES:
        assert lin[k] == pytest.approx(mc[k], rel=0.08), k


@pytest.mark.parametrize("seed", range(3))
def test_measured_margins_against_truth_and_the_allowance_formula(seed):
    from align.alignment.job import align
    from align.alignment.plan import Plan
    from align.alignment.simulate import SessionSpec, simulate_session
    from align.sensitivity import allowable, manoeuvre_from_dict
    from align.units import parse_quantity as q

    beta = -(0.40 + 0.02 * seed) * DEG  # a tilt about y: phi_xz = -beta to first order
    truth = SensorModel.from_rotation(Rotation.from_rotvec([0.05 * DEG, beta, 0.1 * DEG]))
    plan = Plan.standard_rate(100 * DEG)
    t, g, _ = simulate_session(plan, truth, SessionSpec(noise_density=q("0.3 deg/sqrt(h)", "angle_random_walk")), seed)
    r = align(t, g, plan, units="deg/s")
    man = manoeuvre_from_dict({"rotation": [{"axis": "z", "angle": "30 deg"}],
                               "limits": {"x": "0.1667 deg", "y": "1 deg", "z": "1 deg"}}, "test")
    rows = {x.element: x for x in measured_margins(r, allowable(man))}
    # the reference's closed forms (section 3): phi_max = asin(E / Theta), psi_max = acos(1 - E / Theta)
    assert rows["phi_xz"].allowed == pytest.approx(np.arcsin((0.1667 * DEG) / (30 * DEG)), rel=1e-6)
    assert rows["psi_z"].allowed == pytest.approx(np.arccos(1 - 1 / 30), rel=1e-6)
    _, phi = _reference_angles(truth.M)
    for name, row in rows.items():
        if name.startswith("phi"):
            assert abs(row.measured - phi[name]) < 5 * row.sigma + 1e-6, name
        assert row.margin == pytest.approx(row.allowed - abs(row.measured))
    assert not rows["phi_xz"].ok and rows["phi_yz"].ok and rows["psi_z"].ok
    assert [k for k, x in rows.items() if not x.ok] == ["phi_xz"]


def test_summary_banner_and_statuses():
    fail = Verdict("a", FAIL, "x margin -0.1 deg", -0.1)
    page = summary_section([Verdict("b", PASS, "1"), fail, Verdict("c", WARN, "2"), Verdict("d", INFO, "3")]).body
    assert page.index("FAIL: 1 of 3 checks failed (a).") < page.index("<table")
    assert "1 WARN (c)" in page
    assert 'class="l fail">FAIL' in page and 'class="l warn">WARN' in page
    assert "PASS: the one check passed" in summary_section([Verdict("b", PASS, "1")]).body
    assert "without a verdict" in summary_section([Verdict("d", INFO, "3")]).body
    assert fail.failed and not Verdict("c", WARN, "2").failed
    # a report whose only checks are WARN says so (not "no requirement was given")
    warn_only = summary_section([Verdict("c", WARN, "2"), Verdict("d", INFO, "3")]).body
    assert warn_only.startswith('<p class="banner warn">WARN: none of 1 check failed; 1 WARN (c)')


def test_a_design_check_does_not_govern_when_the_unit_is_measured():
    design = Verdict("mounting budget (rss) vs allowance", FAIL, "psi_x margin -0.1 deg", -0.1, design=True,
                     governs=False)
    page = summary_section([design, Verdict("measured misalignment vs allowance", PASS, "x margin +0.01 deg")]).body
    assert page.startswith('<p class="banner pass">PASS: the one check passed.</p>')
    assert "FAIL (design check)" in page and "the measurement governs" in page
    assert not design.failed and Verdict("b", FAIL, "1", design=True).failed  # alone, a design check governs
