"""Sensitivity, symbolic: the sympy response and its Jacobian against finite differences and Eq 5."""

import numpy as np
import pytest

from align.errors import InputError
from align.sensitivity.symbolic import ELEMENTS, matrix_from_angles, response, sensitivity, symbolic, symbolic_text


def test_symbolic_and_numeric_sensitivities_agree():
    rng = np.random.default_rng(0)
    ang = rng.normal(0, 0.05, 9)
    w = rng.normal(0, 1.0, 3)
    jac = sensitivity(w, ang)
    h = 1e-7
    for k in range(9):
        dp, dm = ang.copy(), ang.copy()
        dp[k] += h
        dm[k] -= h
        fd = (response(w, dp) - response(w, dm)) / (2 * h)
        assert np.allclose(jac[:, k], fd, atol=1e-7)
    # Eq 5: g_x = w_x cos(psi_x) + w_y sin(phi_xy) + w_z sin(phi_xz)
    a = dict(zip(ELEMENTS, ang))
    gx = w[0] * np.cos(a["psi_x"]) + w[1] * np.sin(a["phi_xy"]) + w[2] * np.sin(a["phi_xz"])
    assert response(w, ang)[0] == pytest.approx(gx, rel=1e-14)
    s = symbolic()
    assert s.jacobian.shape == (3, 9)
    assert "psi_x" in symbolic_text("pretty") and "\\cos" in symbolic_text("latex")


def test_matrix_from_angles_by_name_and_refusals_name_the_input():
    m = matrix_from_angles({"phi_yz": 0.01, "psi_x": 0.02})
    assert m[1, 2] == pytest.approx(np.sin(0.01), rel=1e-15) and m[0, 0] == pytest.approx(np.cos(0.02), rel=1e-15)
    assert m[2, 1] == 0.0 and m[1, 1] == 1.0
    with pytest.raises(InputError) as bad:
        matrix_from_angles({"phi_xx": 0.01})
    assert bad.value.fields == ["angles"] and "phi_xx" in str(bad.value)
    with pytest.raises(InputError) as style:
        symbolic_text("html")
    assert style.value.fields == ["style"] and "--" not in str(style.value)
