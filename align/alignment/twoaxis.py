"""The two-axis shortcut (Eq 35-36): ``M`` from turns about two axes, the third column inferred.

With turns about two system axes only, the third column of ``M`` is not
observed; assuming orthogonal gyros it follows from the two measured ones,
either as the source's cross product (Eq 36) or as the third column of the
nearest rotation (orthogonal Procrustes). The assumption's cost is bounded by
the datasheet's axis-to-axis spec (:func:`two_axis_error_bound`).

Public names
------------
two_axis, two_axis_error_bound
"""

from __future__ import annotations

import numpy as np

from align.alignment.estimate import Fit
from align.model import nearest_rotation


def two_axis(fit: Fit, missing: int, variant: str = "procrustes") -> np.ndarray:
    """Complete ``M`` from two measured columns, assuming orthogonal gyros (Eq 35-36).

    Parameters
    ----------
    fit : Fit
        A fit whose columns other than ``missing`` are measured (the third is NaN).
    missing : int
        The axis not turned about (0, 1, 2).
    variant : {"procrustes", "cross"}
        ``"cross"``: the source's cross product of the two measured columns (Eq 36, e.g.
        ``M11 = M22 M33 - M32 M23``). ``"procrustes"``: the third column of the nearest rotation to the
        two measured columns (SVD of ``C E^T``); unlike the cross product not scaled by the gyros' scale errors.

    Returns
    -------
    ndarray, shape (3, 3)
        ``M`` with column ``missing`` filled, dimensionless.
    """
    m = fit.M.copy()
    j, k = (missing + 1) % 3, (missing + 2) % 3
    if variant == "cross":
        m[:, missing] = np.cross(m[:, j], m[:, k])
    elif variant == "procrustes":
        e = np.eye(3)[:, [j, k]]
        c = m[:, [j, k]]
        r = nearest_rotation(c @ e.T)
        m[:, missing] = r[:, missing]
    else:
        raise ValueError(f"unknown two-axis variant {variant!r}")
    return m


def two_axis_error_bound(axis_to_axis: float) -> float:
    """Direction error of the column the two-axis shortcut infers (Eq 35-36), for an axis-to-axis spec.

    To first order each of its off-axis elements is off by the true ``delta_ij`` (Eq 32-34) of a gyro
    pair involving the missing axis, so its direction is off by up to ``sqrt(2) * spec``.

    Parameters
    ----------
    axis_to_axis : float
        The datasheet's axis-to-axis misalignment (largest ``delta_ij``), rad.

    Returns
    -------
    float
        rad.
    """
    return float(np.sqrt(2.0) * axis_to_axis)
