"""Mechanics, formulas: the reference's Example 1 (Eq 1-4), by hand and through the budget."""

import numpy as np
import pytest
from mounts import example1

from mechanics.budget import budget
from mechanics.formulas import rss, screw_radius, skew_from_screws, tilt_from_ledges


def test_example1_source_numbers():
    # reference section 2, Example 1 (recomputed values; the source prints 1.28 for the total)
    assert np.degrees(tilt_from_ledges(0.2e-3, 44e-3, 6e-3)) == pytest.approx(0.30155, abs=5e-6)
    assert np.degrees(tilt_from_ledges(0.2e-3, 47e-3, 6e-3)) == pytest.approx(0.27949, abs=5e-6)
    assert screw_radius(39.6e-3, 42.6e-3) * 1e3 == pytest.approx(29.0814, abs=5e-5)
    assert np.degrees(skew_from_screws(2.85e-3, 2e-3, screw_radius(39.6e-3, 42.6e-3))) == pytest.approx(0.83736, abs=5e-6)
    d = budget(example1()).to_dict()
    assert d["tilt_x_deg"] == pytest.approx(0.30155, abs=5e-6)
    assert d["tilt_y_deg"] == pytest.approx(0.27949, abs=5e-6)
    assert d["skew_z_deg"] == pytest.approx(0.83736, abs=5e-6)
    assert d["mounting_deg"] == pytest.approx(0.83736, abs=5e-6)
    assert d["total_deg"] == pytest.approx(1.3043, abs=5e-5)
    assert d["total_deg"] != pytest.approx(1.28, abs=0.01)  # the source's printed value does not follow
    assert rss(1.0, 0.83) == pytest.approx(1.2996, abs=1e-4)
