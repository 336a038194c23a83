"""The g-sensitivity of a gyro's bias, ``K_ga`` in ``raw = M w + K_ga f + b`` ((rad/s) per (m/s^2)), and its 1-sigma.

``calibrate gyro --g-sensitivity`` estimates ``K_ga`` with the bias from every static pose's mean reading,
``g_k = b + K_ga f_k`` (ordinary least squares per gyro axis, ``f_k`` the pose's specific force); this module gives
that estimate's 1-sigma, with the part Earth's rate can put in it when no latitude models it.

Public names
------------
EARTH_K, EARTH_NOTE, g_sensitivity_sigma
"""

from __future__ import annotations

import numpy as np

__all__ = ["EARTH_K", "EARTH_NOTE", "g_sensitivity_sigma"]


#: the most Earth's rate can put into ``K_ga`` when it is not modelled: its vertical part ``Omega sin(lat)`` turns
#: with gravity from pose to pose and reads as ``K_ga = Omega sin(lat) / g I``; at most Omega / g
EARTH_K = 7.2921150e-5 / 9.80665
EARTH_NOTE = (f"K_ga's 1-sigma: the least-squares one (the poses' scatter) with {EARTH_K:.3g} (rad/s)/(m/s^2) "
              f"({EARTH_K * 180 / np.pi * 3600 * 9.80665:.2g} deg/h/g) added on its diagonal, the most Earth's rate "
              "(not modelled: no latitude) can put there")


def g_sensitivity_sigma(s2: np.ndarray, xtxi: np.ndarray) -> np.ndarray:
    """1-sigma of ``K_ga`` (3, 3) from the per-axis least squares ``g_k = b + K_ga f_k`` (the residual variances
    ``s2`` (3,) and ``(X^T X)^-1`` (4, 4) of ``X = [1, f_k]``), with :data:`EARTH_K` on the diagonal in quadrature:
    ``sigma_ij^2 = s2_i (X^T X)^-1_{j+1,j+1} + [i = j] EARTH_K^2``.

    Parameters
    ----------
    s2 : ndarray, shape (3,)
        Residual variance of each gyro axis' fit, (rad/s)^2.
    xtxi : ndarray, shape (4, 4)
        ``(X^T X)^-1`` of the design ``X = [1, f_k]`` (f in m/s^2).

    Returns
    -------
    ndarray, shape (3, 3)
        (rad/s) per (m/s^2).

    Examples
    --------
    >>> x = np.column_stack([np.ones(6), np.vstack([np.eye(3), -np.eye(3)]) * 9.8])
    >>> s = g_sensitivity_sigma(np.full(3, 1e-8), np.linalg.inv(x.T @ x))
    >>> bool(np.allclose(s[0, 1], 1e-4 / (9.8 * np.sqrt(2))))
    True
    """
    var = np.outer(s2, np.diag(xtxi)[1:]) + np.eye(3) * EARTH_K ** 2
    return np.sqrt(var)
