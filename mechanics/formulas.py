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

    Returns
    -------
    float
        rad; Example 1: ``atan(0.2 mm / 38 mm) = 0.30155 deg``.
    """
    return float(np.arctan2(height_difference, span - ledge_size))


def screw_radius(spacing_x: float, spacing_y: float) -> float:
    """``R_S`` of Eq 4: half the distance between screws at opposite corners.

    Parameters
    ----------
    spacing_x, spacing_y : float
        Distances between the mounting holes along x and along y, m.

    Returns
    -------
    float
        ``0.5 hypot(spacing_x, spacing_y)``, m; Example 1: 39.6 mm and 42.6 mm
        give 29.0814 mm.
    """
    return 0.5 * float(np.hypot(spacing_x, spacing_y))


def skew_from_screws(hole_diameter: float, screw_diameter: float, radius: float) -> float:
    """Eq 4: skew about z, ``theta_Z = asin((D_H - D_M) / (2 R_S))``.

    The package turns until each screw meets its hole's wall: the radial
    clearance is half the diametral one.

    Parameters
    ----------
    hole_diameter : float
        Through-hole diameter ``D_H``, m.
    screw_diameter : float
        Screw diameter ``D_M``, m.
    radius : float
        ``R_S``, half the distance between screws at opposite corners
        (:func:`screw_radius`), m.

    Returns
    -------
    float
        rad; Example 1: 2.85 mm holes, 2 mm screws and ``R_S = 29.0814 mm`` give 0.83736 deg.
    """
    return float(np.arcsin((hole_diameter - screw_diameter) / (2.0 * radius)))


def rss(*terms: float) -> float:
    """Eq 1: root sum of squares of independent misalignment terms.

    Parameters
    ----------
    *terms : float
        Misalignment angles, rad (e.g. ``theta_IMU`` and ``theta_SYS``).

    Returns
    -------
    float
        ``sqrt(sum(terms^2))``, rad; Example 1: 1 deg and 0.83736 deg give 1.3043 deg.
    """
    return float(np.sqrt(np.sum(np.square(terms))))
