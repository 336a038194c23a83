"""Digits follow the uncertainty (issue 28: "1-sigma 0.0000" and "margin/sigma +169067.7"): a 1-sigma is shown with a
significant digit and the value to its decimal place; a margin in sigmas has two significant digits, is capped where
more say nothing, and is not shown against a zero 1-sigma."""

import html
import re

import numpy as np
import pytest

from align.present.angles import angle_rows
from align.present.measured import MeasuredMargin, OutputMargin, measured_section
from align.units import DEG


def _cells(page: str) -> list[list[str]]:
    return [[html.unescape(c) for c in re.findall(r"<td[^>]*>(.*?)</td>", row)]
            for row in re.findall(r"<tr>(.*?)</tr>", page) if "<td" in row]


@pytest.mark.parametrize("sigma_deg", [4.2e-6, 3.7e-5, 8.8e-4, 2.5e-3])
def test_the_one_sigma_is_shown_with_a_significant_digit_and_the_value_to_its_place(sigma_deg):
    out = OutputMargin("z", 0.0015449 * DEG, sigma_deg * DEG, 1.0 * DEG)
    row = _cells(measured_section([out], []).body)[0]
    error, sigma, margin = row[1], row[2], row[4]
    assert float(sigma) > 0 and sigma != "0.0000"
    assert float(sigma) == pytest.approx(sigma_deg, rel=0.15)  # one or two significant digits of it
    decimals = len(sigma.split(".")[1])
    assert len(error.split(".")[1]) == decimals and len(margin.split(".")[1]) == decimals
    assert abs(float(error) - 0.0015449) <= 0.5 * 10**-decimals + 1e-15
    from align.present.measured import headline  # the terminal's line, the same digits

    assert headline(out).startswith(f"output z: error {error} ± {sigma} deg")


def test_a_margin_in_sigmas_has_two_digits_and_no_more_than_the_guard_band_needs():
    outs = [OutputMargin("y", 0.1559 * DEG, 0.00042 * DEG, 1.0 * DEG),     # 2010 sigmas
            OutputMargin("z", 0.0015 * DEG, 4.0e-6 * DEG, 1.0 * DEG),      # 249625 sigmas (the issue's +169067.7)
            OutputMargin("x", 0.9958 * DEG, 0.0021 * DEG, 1.0 * DEG),      # 2.0 sigmas
            OutputMargin("w", 1.0300 * DEG, 0.0020 * DEG, 1.0 * DEG)]      # -15 sigmas
    ratios = [r[5] for r in _cells(measured_section(outs, []).body)]
    assert ratios == ["> +1000", "> +1000", "+2.0", "-15"]


def test_no_ratio_to_a_zero_sigma():
    out = OutputMargin("z", 0.0015 * DEG, 0.0, 1.0 * DEG)
    row = _cells(measured_section([out], [MeasuredMargin("phi_yz", 0.3 * DEG, 0.0, 1.9 * DEG)]).body)
    for cells in row:
        assert cells[2] == "0" and cells[5] == "- (sigma 0)"
        assert not re.search(r"[0-9]{4,}\.[0-9]", cells[5])


def test_structural_zeros_of_an_upper_triangular_fit_are_not_shown_as_0_0000():
    """The |a| = g fit's M is upper triangular: its z row lies on z by construction, with a zero 1-sigma."""
    m = np.array([[1649.3, -0.75, 28.0], [0.0, 1660.2, 19.2], [0.0, 0.0, 1671.2]])
    sigma = np.array([[0.14, 0.2, 0.21], [0.0, 0.12, 0.18], [0.0, 0.0, 0.15]])
    cells = [c for row in angle_rows(m, sigma) for c in row.text()]
    assert not any("± 0.0000" in c for c in cells), cells
    psi = next(row for row in angle_rows(m, sigma) if row.key == "psi")
    assert psi.text()[2] == "z=0.0000 ± 0" and psi.sigmas[2] == 0.0
    # a small but known 1-sigma is given its digits (value and sigma), not rounded away
    tiny = angle_rows(np.eye(3) + 1e-7, np.full((3, 3), 2e-8))
    shown = next(row for row in tiny if row.key == "phi").text()[0]
    value, sig = re.fullmatch(r"xy=([-+0-9.]+) ± ([0-9.e-]+)", shown).groups()
    assert float(sig) == pytest.approx(next(row for row in tiny if row.key == "phi").sigmas[0], rel=0.1)
    assert len(value.split(".")[1]) >= 6
