"""A multi-position calibration turned into the system frame, from a rate-table result or a mounting.

The multi-position calibration (:mod:`align.calibration.gyro`) finds both sensors relative to the
accelerometer frame ``c``: ``g = M_g w_c + b_g``, ``a = M_a f_c + b_a``. The system frame ``s`` is
related to ``c`` by a rotation ``R`` (``w_c = R w_s``), which gravity cannot give. Combining means::

    M_g,s = M_g R,   M_a,s = M_a R   (biases unchanged)                              (F1)

so that ``g = M_g,s w_s + b_g`` and ``a = M_a,s f_s + b_a``: scale factors and axis-to-axis angles from
the multi-position session, the frame from the other source. ``R`` comes from

* a rate-table alignment (``g = M_t w_s + b``, an ``imu-align.alignment`` result, or a calibration
  file's gyroscope): ``R`` is the rotation nearest to ``M_g^-1 M_t`` (the orthogonal factor of its polar
  decomposition; a common scale, e.g. counts against rad/s, drops out). What is left,
  ``M_g^-1 M_t / det^(1/3) - R``, is the two calibrations' disagreement beyond a rotation, reported;
* a mounting ``N`` (rows: the sensor axes in the system frame): ``R = N`` (the accelerometer frame taken
  as the sensor axes).

The 1-sigma are propagated with ``R`` taken as exact: ``sigma(M R)_ij = sqrt(sum_k sigma_ik^2 R_kj^2)``.

Public names
------------
in_system_frame, rotation_from_table
"""

from __future__ import annotations

import numpy as np

from align.calibration.results import Calibration
from align.errors import TestError
from align.units import DEG


def rotation_from_table(m_g: np.ndarray, m_t: np.ndarray, where: str = "{frame}") -> tuple[np.ndarray, float]:
    """``R`` nearest to ``M_g^-1 M_t`` and the largest element of the disagreement beyond a rotation.

    Raises
    ------
    TestError
        ``M_g^-1 M_t`` is singular or mirrored (the two calibrations do not describe one gyro).
    """
    x = np.linalg.solve(np.asarray(m_g, float), np.asarray(m_t, float))
    det = float(np.linalg.det(x))
    if not np.isfinite(det) or det <= 0:
        raise TestError("the rate-table result and this calibration do not describe one gyro (M_g^-1 M_t is singular "
                        "or mirrored): check that both come from the same unit", where)
    u, _, vt = np.linalg.svd(x)
    r = u @ vt
    return r, float(np.abs(x / det ** (1.0 / 3.0) - r).max())


def _turned(cal: Calibration, r: np.ndarray, note: str) -> Calibration:
    sigma = np.sqrt((cal.sigma_M ** 2) @ (r ** 2))
    return cal.replace(M=cal.M @ r, sigma_M=sigma, notes=tuple(n for n in cal.notes if not n.startswith("relative to "))
                       + (note,))


def in_system_frame(acc: Calibration, gyr: Calibration, table_m: np.ndarray | None = None,
                    mounting: np.ndarray | None = None, source: str = "") -> tuple[Calibration, Calibration, np.ndarray]:
    """Both sensors in the system frame (F1).

    Parameters
    ----------
    acc, gyr : Calibration
        The multi-position calibration (accelerometer frame).
    table_m : ndarray, shape (3, 3), optional
        ``M`` of a rate-table alignment of the same gyro (system frame).
    mounting : ndarray, shape (3, 3), optional
        The nominal mounting ``N``; one of ``table_m`` and ``mounting``.
    source : str
        Where ``table_m`` or ``mounting`` came from, for the notes.

    Returns
    -------
    acc, gyr : Calibration
        ``M R`` each, with a note stating the combination.
    r : ndarray, shape (3, 3)
        The rotation ``R`` (``w_c = R w_s``).
    """
    if (table_m is None) == (mounting is None):
        raise ValueError("give a rate-table M or a mounting, not both")
    if table_m is not None:
        r, rest = rotation_from_table(gyr.M, table_m)
        how = (f"the frame from the rate-table result {source}: R nearest to M_g^-1 M_t (the two differ beyond a "
               f"rotation by {rest:.2g} at most)")
    else:
        r = np.asarray(mounting, float)
        how = f"the frame from the mounting {source}: R = N, the accelerometer frame taken as the sensor axes"
    from scipy.spatial.transform import Rotation

    turn = Rotation.from_matrix(r).magnitude() / DEG
    note = (f"in the system frame: M = M_c R (M_c relative to the accelerometer frame, w_c = R w_s, a {turn:.3g} deg "
            f"rotation); {how}")
    return _turned(acc, r, note), _turned(gyr, r, note), r
