"""A multi-position calibration turned into the system frame, from a rate-table result or a mounting.

The multi-position calibration (:mod:`align.calibration.gyro`) finds both sensors relative to the
accelerometer frame ``c``: ``g = M_g w_c + b_g``, ``a = M_a f_c + b_a`` with ``M_a`` upper triangular, so that
``c`` has its z axis along the accelerometer's z axis and its y axis in the accelerometer's y-z plane (row 3 of
``M_a`` is ``(0, 0, u33)``, row 2 ``(0, u22, u23)``; with a non-orthogonal accelerometer this is not the frame
with x along the accelerometer's x axis). The system frame ``s`` is
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

The two calibrations must describe one gyro: the part of ``X = M_g^-1 M_t`` that is not a rotation or
a common scale, ``D = R^T X / det(X)^(1/3) - I`` (symmetric), is compared with its 1-sigma (propagated
from both results' ``sigma_M``, numerically): beyond :data:`WARN_SIGMA` a warning note, beyond
:data:`REFUSE_SIGMA` a refusal (another unit's table, or one of the two calibrations wrong).

The 1-sigma of ``M_g,s`` and ``M_a,s`` include ``R``'s: ``d(M R) = dM R + M dR``, ``dR`` from both
``M_g``'s and ``M_t``'s errors (first order, numerical derivatives; a table without uncertainty counts
as exact). With a mounting ``R = N`` is exact: ``sigma(M R)_ij = sqrt(sum_k sigma_ik^2 R_kj^2)``.

Public names
------------
in_system_frame, rotation_from_table, frame_consistency, WARN_SIGMA, REFUSE_SIGMA
"""

from __future__ import annotations

import numpy as np

from align.calibration.results import Calibration
from align.errors import TestError
from align.units import DEG

#: the two calibrations' difference beyond a rotation: a warning note above this many sigma
WARN_SIGMA = 3.0
#: and a refusal above this many
REFUSE_SIGMA = 10.0
_IU = np.triu_indices(3)


def _polar(m_g: np.ndarray, m_t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``R`` nearest to ``X = M_g^-1 M_t`` and ``D = R^T X / det(X)^(1/3) - I``."""
    x = np.linalg.solve(m_g, m_t)
    det = float(np.linalg.det(x))
    u, _, vt = np.linalg.svd(x)
    r = u @ vt
    return r, r.T @ x / np.cbrt(det) - np.eye(3)


def rotation_from_table(m_g: np.ndarray, m_t: np.ndarray, where: str = "{frame}") -> tuple[np.ndarray, float]:
    """``R`` nearest to ``M_g^-1 M_t`` and the largest element of the disagreement beyond a rotation.

    Raises
    ------
    TestError
        ``M_g^-1 M_t`` is singular or mirrored (the two calibrations do not describe one gyro).
    """
    m_g, m_t = np.asarray(m_g, float), np.asarray(m_t, float)
    det = float(np.linalg.det(np.linalg.solve(m_g, m_t)))
    if not np.isfinite(det) or det <= 0:
        raise TestError("the rate-table result and this calibration do not describe one gyro (M_g^-1 M_t is singular "
                        "or mirrored): check that both come from the same unit", where)
    r, d = _polar(m_g, m_t)
    return r, float(np.abs(d).max())


def _jacobian(f, theta: np.ndarray, steps: np.ndarray) -> np.ndarray:
    """Central differences of ``f`` (-> flat array) over ``theta``, shape (len(f), len(theta))."""
    cols = []
    for i, h in enumerate(steps):
        e = np.zeros_like(theta)
        e[i] = h
        cols.append((f(theta + e) - f(theta - e)) / (2 * h))
    return np.stack(cols, axis=1)


def frame_consistency(m_g: np.ndarray, sigma_g: np.ndarray, m_t: np.ndarray, sigma_t: np.ndarray | None) -> dict:
    """``R``, the difference beyond a rotation ``D`` and its significance, and the derivatives of ``R``.

    Parameters
    ----------
    m_g, sigma_g : ndarray, shape (3, 3)
        The multi-position gyro (accelerometer frame) and its 1-sigma.
    m_t, sigma_t : ndarray, shape (3, 3)
        The rate-table result's ``M`` (system frame) and its 1-sigma (None or NaN: exact).

    Returns
    -------
    dict
        ``r`` (3, 3); ``d`` (6,) the upper elements of ``D``, ``sigma`` (6,) their 1-sigma, ``z`` (6,)
        ``d / sigma``; ``dr`` (9, 18) the derivative of ``vec R`` over ``(vec M_g, vec M_t)``; ``var`` (18,) the
        variances of those.
    """
    m_g, m_t = np.asarray(m_g, float), np.asarray(m_t, float)
    st = np.zeros((3, 3)) if sigma_t is None else np.nan_to_num(np.asarray(sigma_t, float), nan=0.0)
    theta = np.concatenate([m_g.ravel(), m_t.ravel()])
    var = np.concatenate([np.nan_to_num(np.asarray(sigma_g, float), nan=0.0).ravel() ** 2, st.ravel() ** 2])
    steps = 1e-6 * np.concatenate([np.full(9, np.abs(m_g).max()), np.full(9, np.abs(m_t).max())])

    def parts(th):
        return _polar(th[:9].reshape(3, 3), th[9:].reshape(3, 3))

    r, d = parts(theta)
    jd = _jacobian(lambda th: parts(th)[1][_IU], theta, steps)
    sd = np.sqrt((jd ** 2) @ var)
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.where(sd > 0, d[_IU] / sd, np.where(d[_IU] == 0, 0.0, np.inf))
    return {"r": r, "d": d[_IU], "sigma": sd, "z": z, "dr": _jacobian(lambda th: parts(th)[0].ravel(), theta, steps),
            "var": var}


def _turned(cal: Calibration, r: np.ndarray, note: str, dr: np.ndarray | None = None,
            var: np.ndarray | None = None, own: slice | None = None) -> Calibration:
    """``M R`` with its 1-sigma: ``dM R`` from the calibration's own sigma, plus ``M dR`` (``dr`` over the
    parameters of variances ``var``; ``own``: those that are this calibration's ``M``, whose ``dM R`` and
    ``M dR`` are correlated)."""
    if dr is None:
        sigma = np.sqrt((cal.sigma_M ** 2) @ (r ** 2))
    else:
        m = np.asarray(cal.M, float)
        jac = np.einsum("ik,kjp->ijp", m, dr.reshape(3, 3, -1)).reshape(9, -1)      # M dR
        total = np.nan_to_num(np.asarray(cal.sigma_M, float), nan=0.0) ** 2
        if own is not None:                                                          # + dM R on M's own slots
            own_jac = np.einsum("ia,bj->ijab", np.eye(3), r).reshape(9, 9)
            jac[:, own] += own_jac
            sigma = np.sqrt((jac ** 2) @ var).reshape(3, 3)
        else:
            sigma = np.sqrt((jac ** 2) @ var + ((total @ (r ** 2)).ravel())).reshape(3, 3)
    return cal.replace(M=cal.M @ r, sigma_M=sigma, notes=tuple(n for n in cal.notes if not n.startswith("relative to "))
                       + (note,))


def in_system_frame(acc: Calibration, gyr: Calibration, table_m: np.ndarray | None = None,
                    mounting: np.ndarray | None = None, source: str = "",
                    table_sigma: np.ndarray | None = None) -> tuple[Calibration, Calibration, np.ndarray]:
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
    table_sigma : ndarray, shape (3, 3), optional
        The 1-sigma of ``table_m`` (default: exact).

    Returns
    -------
    acc, gyr : Calibration
        ``M R`` each, with a note stating the combination (and a warning when the two gyros differ beyond a
        rotation by more than :data:`WARN_SIGMA`).
    r : ndarray, shape (3, 3)
        The rotation ``R`` (``w_c = R w_s``).

    Raises
    ------
    TestError
        The two gyros differ beyond a rotation by more than :data:`REFUSE_SIGMA` (or by a mirror).
    """
    if (table_m is None) == (mounting is None):
        raise ValueError("give a rate-table M or a mounting, not both")
    if table_m is not None:
        r, rest = rotation_from_table(gyr.M, table_m)
        got = frame_consistency(gyr.M, gyr.sigma_M, table_m, table_sigma)
        worst = float(np.abs(got["z"]).max())
        if worst > REFUSE_SIGMA:
            raise TestError(f"the rate-table result and this calibration differ beyond a rotation by {rest:.2g} (largest "
                            f"element of R^T M_g^-1 M_t / det^(1/3) - I), {worst:.3g} times its 1-sigma: not the same "
                            "gyro, or one of the two calibrations is wrong", "{frame}")
        how = (f"the frame from the rate-table result {source}: R nearest to M_g^-1 M_t (the two differ beyond a "
               f"rotation by {rest:.2g} at most, {worst:.2g} sigma); the 1-sigma include R's, from both")
        if worst > WARN_SIGMA:
            how += (f"; warning: that difference is {worst:.3g} sigma (more than {WARN_SIGMA:g}): the two calibrations "
                    "disagree beyond their uncertainty (another model, temperature, or not one gyro)")
        acc_args: tuple[np.ndarray | None, np.ndarray | None, slice | None] = (got["dr"], got["var"], None)
        gyr_args: tuple[np.ndarray | None, np.ndarray | None, slice | None] = (got["dr"], got["var"], slice(0, 9))
    else:
        r = np.asarray(mounting, float)
        how = f"the frame from the mounting {source}: R = N, the accelerometer frame taken as the sensor axes"
        acc_args = gyr_args = (None, None, None)
    from scipy.spatial.transform import Rotation

    turn = Rotation.from_matrix(r).magnitude() / DEG
    note = (f"in the system frame: M = M_c R (M_c relative to the accelerometer frame, w_c = R w_s, a {turn:.3g} deg "
            f"rotation); {how}")
    return _turned(acc, r, note, *acc_args), _turned(gyr, r, note, *gyr_args), r
