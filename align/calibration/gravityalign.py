"""A magnetometer against gravity: the dip angle and the rotation to the accelerometer frame.

With an accelerometer read at the same instants as a tumbling magnetometer capture, the angle between
the calibrated field direction ``m_hat`` and the accelerometer's vector ``a_hat`` is constant when
both are in one frame. :func:`dip_from_accelerometer` reads the dip from it;
:func:`alignment_to_gravity` finds the rotation that makes it constant and :func:`with_gravity_alignment`
adds that rotation to a :class:`~align.calibration.magnetometer.MagCalibration`.

The dip (inclination) is the field's angle below the horizontal: ``90 deg - theta`` with ``theta`` the
angle between the field and gravity (down). An accelerometer at rest reads the specific force, which
points up; then ``90 deg - angle(m, a)`` is minus the dip. The sign follows the accelerometer's vector;
the heading-error prediction uses ``cos(dip)`` and does not depend on it.

Public names
------------
dip_from_accelerometer, alignment_to_gravity, with_gravity_alignment
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from align.calibration.magnetometer import MagCalibration


def dip_from_accelerometer(u: np.ndarray, acc: np.ndarray) -> tuple[float, str]:
    """``90 deg - median(angle(m_hat, a_hat))``, rad, and the note that says so.

    Parameters
    ----------
    u : ndarray, shape (n, 3)
        Calibrated field directions (unit vectors).
    acc : ndarray, shape (n, 3)
        Simultaneous accelerometer readings (any unit).

    Returns
    -------
    dip : float
        rad: the dip when ``acc`` points along gravity (down), its negative when it is the specific force (up).
    note : str
    """
    a = np.asarray(acc, float)
    cosang = np.sum(u * a, axis=1) / (np.linalg.norm(u, axis=1) * np.linalg.norm(a, axis=1))
    theta = float(np.median(np.arccos(np.clip(cosang, -1, 1))))
    dip = float(np.pi / 2 - theta)
    note = (f"dip {np.degrees(dip):.2f} deg from the accelerometer: 90 deg minus the median angle between the field "
            f"and the accelerometer's vector ({np.degrees(theta):.2f} deg); the dip below the horizontal if that "
            "vector is gravity, its negative if it is the specific force (up at rest)")
    return dip, note


def alignment_to_gravity(m_cal: np.ndarray, acc: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Rotation ``R`` (mag frame to accelerometer frame) making the field-gravity angle constant.

    Minimises the scatter of ``asin(a_hat . R m_hat)`` (90 deg minus the angle between the field and the
    accelerometer's vector: the dip, see the module docstring) over a tumbling capture; returns ``R``,
    that angle (rad) and the remaining scatter (rad).
    """
    from scipy.optimize import least_squares
    from scipy.spatial.transform import Rotation

    mh = m_cal / np.linalg.norm(m_cal, axis=1, keepdims=True)
    ah = acc / np.linalg.norm(acc, axis=1, keepdims=True)

    def resid(p):
        r = Rotation.from_rotvec(p[:3]).as_matrix()
        return np.arcsin(np.clip(np.sum(ah * (mh @ r.T), axis=1), -1, 1)) - p[3]

    p0 = np.array([0.0, 0.0, 0.0, float(np.median(np.arcsin(np.clip(np.sum(ah * mh, axis=1), -1, 1))))])
    sol = least_squares(resid, p0)
    return Rotation.from_rotvec(sol.x[:3]).as_matrix(), float(sol.x[3]), float(np.std(sol.fun))


def with_gravity_alignment(cal: MagCalibration, m: np.ndarray, acc: np.ndarray) -> MagCalibration:
    """``cal`` with its rotation to the accelerometer frame, found from gravity (:func:`alignment_to_gravity`).

    Parameters
    ----------
    cal : MagCalibration
        A calibration of the capture ``m``.
    m : ndarray, shape (n, 3)
        The raw magnetometer readings ``cal`` was fitted to, SI or counts.
    acc : ndarray, shape (n, 3)
        Simultaneous accelerometer readings (any unit).

    Returns
    -------
    MagCalibration
        ``cal`` with ``misalignment`` set (``m_body = misalignment m_cal``) and a note
        giving the fitted dip and the remaining scatter.
    """
    rot, dip_fit, scatter = alignment_to_gravity(cal.correct(m), np.asarray(acc, float))
    note = (f"rotation to the accelerometer frame from gravity: after it, 90 deg minus the field-accelerometer angle "
            f"is {np.degrees(dip_fit):.2f} deg with a scatter of {np.degrees(scatter):.2f} deg")
    return cal.replace(misalignment=rot, misalignment_method="gravity", notes=cal.notes + (note,))
