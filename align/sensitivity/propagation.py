"""Attitude propagation: what a misalignment does to the outputs over a manoeuvre.

The true increments of a :class:`~align.sensitivity.manoeuvre.Manoeuvre` and the
increments the misaligned gyros report (``M`` applied to each) are chained into
attitudes (scalar-last quaternions, scipy's convention) and compared:

* ``x``, ``y``, ``z``: each gyro's integrated angle, the rotation vector of the
  reported attitude minus the true one; for a fixed-axis rotation exactly
  ``(M - I) theta`` (Eq 11-13, :func:`closed_form_errors`);
* ``azimuth``, ``elevation``, ``roll``: Z-Y-X Euler angles of the reported
  attitude minus the true one, wrapped to ``(-pi, pi]``.

Public names
------------
output_errors, closed_form_errors, attitudes
"""

from __future__ import annotations

import numpy as np

from align.sensitivity.manoeuvre import Manoeuvre
from align.sensitivity.symbolic import AXIS_INDEX, OUTPUTS

_EULER = ("azimuth", "elevation", "roll")


def _qmul(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product of scalar-last quaternions (scipy's convention), arrays (..., 4)."""
    px, py, pz, pw = np.moveaxis(p, -1, 0)
    qx, qy, qz, qw = np.moveaxis(q, -1, 0)
    return np.stack([pw * qx + px * qw + py * qz - pz * qy,
                     pw * qy - px * qz + py * qw + pz * qx,
                     pw * qz + px * qy - py * qx + pz * qw,
                     pw * qw - px * qx - py * qy - pz * qz], axis=-1)


def attitudes(increments: np.ndarray) -> np.ndarray:
    """Attitude after each body-frame increment: ``R_k = R_(k-1) exp(dtheta_k)``.

    An inclusive prefix product by doubling (log2 n vectorised steps).

    Parameters
    ----------
    increments : ndarray, shape (n, 3)
        Body-frame rotation vectors, rad.

    Returns
    -------
    ndarray, shape (n, 4)
        Scalar-last quaternions.
    """
    from scipy.spatial.transform import Rotation

    q = Rotation.from_rotvec(np.array(increments, dtype=float)).as_quat()   # a writable copy (scipy needs one)
    step = 1
    while step < len(q):
        q = np.concatenate([q[:step], _qmul(q[:-step], q[step:])])
        step *= 2
    return q


def _euler(q: np.ndarray) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return Rotation.from_quat(q).as_euler("ZYX")             # azimuth, elevation, roll


def output_errors(man: Manoeuvre, m: np.ndarray, history: bool = False) -> dict:
    """Largest |error| of every limited output over the manoeuvre, by attitude propagation.

    Parameters
    ----------
    man : Manoeuvre
        Its ``increments`` (n, 3), rad, body-frame rotation vectors, and its
        ``limits`` (output name -> rad), which name the outputs computed.
    m : array_like, shape (3, 3)
        The misaligned response ``M`` (Eq 5-10), dimensionless.
    history : bool
        Return the full time histories of every output instead.

    Returns
    -------
    dict
        Output name -> largest |error|, rad (the limited outputs), or with
        ``history`` output name -> ndarray, shape (n,), rad (every output).
    """
    from scipy.spatial.transform import Rotation

    q_true = attitudes(man.increments)
    q_meas = attitudes(man.increments @ np.asarray(m).T)
    out = {}
    need = set(man.limits) if not history else set(OUTPUTS)
    if need & set(AXIS_INDEX):
        d = Rotation.from_quat(q_meas).as_rotvec() - Rotation.from_quat(q_true).as_rotvec()
        for name, k in AXIS_INDEX.items():
            out[name] = d[:, k]
    if need & set(_EULER):
        e = _euler(q_meas) - _euler(q_true)
        e = (e + np.pi) % (2 * np.pi) - np.pi
        for k, name in enumerate(_EULER):
            out[name] = e[:, k]
    if history:
        return out
    return {name: float(np.max(np.abs(out[name]))) for name in man.limits}


def closed_form_errors(man: Manoeuvre, m: np.ndarray) -> np.ndarray:
    """Eq 11-13 applied step by step and summed: ``sum_k (M - I) theta_k``.

    Parameters
    ----------
    man : Manoeuvre
        Its ``increments`` (n, 3), rad, each taken as a fixed-axis rotation.
    m : array_like, shape (3, 3)
        The misaligned response ``M`` (Eq 5-10), dimensionless.

    Returns
    -------
    ndarray, shape (3,)
        Integrated-angle error of each gyro, rad.
    """
    return (man.increments @ (np.asarray(m) - np.eye(3)).T).sum(axis=0)
