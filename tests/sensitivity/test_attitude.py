"""Sensitivity, attitude: propagation equals Eq 11-13 for one fixed axis, and departs from it for sequences."""

import numpy as np
from scipy.spatial.transform import Rotation

from align.sensitivity.manoeuvre import manoeuvre_from_dict
from align.sensitivity.propagation import attitudes, closed_form_errors, output_errors
from align.sensitivity.symbolic import matrix_from_angles
from align.units import DEG


def test_propagation_equals_eq11_13_for_fixed_axis_rotations():
    rng = np.random.default_rng(1)
    for _ in range(20):
        m = matrix_from_angles(rng.normal(0, 0.03, 9))
        axis = "xyz"[rng.integers(3)]
        angle = rng.uniform(-170, 170)
        man = manoeuvre_from_dict({"rotation": [{"axis": axis, "angle": f"{angle} deg"}], "limits": {"x": "1 deg"}})
        hist = output_errors(man, m, history=True)
        prop = np.array([hist[a][-1] for a in "xyz"])
        assert np.allclose(prop, closed_form_errors(man, m), atol=1e-12)


def test_sequences_are_where_the_formulas_stop_agreeing():
    m = matrix_from_angles({"phi_yz": 2 * DEG, "phi_xy": 1 * DEG, "psi_z": 3 * DEG})
    man = manoeuvre_from_dict({"rotation": [{"axis": "z", "angle": "90 deg"}, {"axis": "x", "angle": "90 deg"}],
                               "limits": {"x": "1 deg", "y": "1 deg", "z": "1 deg"}})
    hist = output_errors(man, m, history=True)
    prop = np.array([hist[a][-1] for a in "xyz"])
    # independent truth: compose the two measured fixed-axis rotations with scipy
    r_true = Rotation.from_rotvec([0, 0, np.pi / 2]) * Rotation.from_rotvec([np.pi / 2, 0, 0])
    r_meas = Rotation.from_rotvec(m @ [0, 0, np.pi / 2]) * Rotation.from_rotvec(m @ [np.pi / 2, 0, 0])
    assert np.allclose(prop, r_meas.as_rotvec() - r_true.as_rotvec(), atol=1e-12)
    assert np.max(np.abs(prop - closed_form_errors(man, m))) > 0.5 * DEG


def test_prefix_product_equals_sequential_composition():
    rng = np.random.default_rng(2)
    inc = rng.normal(0, 0.3, (37, 3))
    r = Rotation.identity()
    want = []
    for v in inc:
        r = r * Rotation.from_rotvec(v)
        want.append(r)
    got = Rotation.from_quat(attitudes(inc))
    assert all(g.approx_equal(w, atol=1e-12) for g, w in zip(got, want))
