"""The source's first-order mounting formulas (reference section 2, Eq 1-4), SI units.

Public names
------------
tilt_from_ledges, screw_radius, skew_from_screws, rss
"""

from __future__ import annotations

import numpy as np


def tilt_from_ledges(height_difference: float, span: float, ledge_size: float) -> float:
    """Eq 2 / Eq 3: tilt (rad) from a ledge-height difference across a span.

    ``theta = atan((H2 - H1) / (W - W1))``: the package rocks on the inner edge
    of the high ledge and the outer edge of the low one.

    Parameters
    ----------
    height_difference : float
        ``H2 - H1``, m.
    span : float
        Package width ``W`` (tilt about x) or length ``L`` (tilt about y), m.
    ledge_size : float
        Ledge width ``W1`` along the span, m.
    """
    return float(np.arctan2(height_difference, span - ledge_size))


def screw_radius(spacing_x: float, spacing_y: float) -> float:
    """``R_S``: half the distance between screws at opposite corners, m."""
    return 0.5 * float(np.hypot(spacing_x, spacing_y))


def skew_from_screws(hole_diameter: float, screw_diameter: float, radius: float) -> float:
    """Eq 4: skew about z (rad), ``asin((D_H - D_M) / (2 R_S))``."""
    return float(np.arcsin((hole_diameter - screw_diameter) / (2.0 * radius)))


def rss(*terms: float) -> float:
    """Eq 1: root sum of squares of independent misalignment terms."""
    return float(np.sqrt(np.sum(np.square(terms))))
