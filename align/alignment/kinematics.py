"""Orientation kinematics of a rate table, written for the simulator apart from the estimator.

Frames (see :mod:`align.alignment.geometry`): the local level frame ENU (east, north, up) and the
system frame. The orientation ``C`` (3, 3) holds the system x, y, z axes (columns) in ENU, so a
vector maps as ``v_ENU = C v_system``.

A table turning about its spin axis ``a`` (ENU unit vector) by ``theta(t)`` (the integral of its
rate) carries the system with it::

    C(t) = Rot(a, theta(t)) C_start                                     (K1)

and the system frame then turns at the body rate ``w = theta'(t) C_start^T a``; a step about system
axis ``u`` has ``C_start u = a``, so ``w = theta' u``. Earth's rate, ``Omega_ENU = Omega_e (0, cos L,
sin L)`` (L the latitude), reads in the system frame::

    w_earth(t) = C(t)^T Omega_ENU = C_start^T Rot(a, -theta(t)) Omega_ENU         (K2)

``Rot(a, phi) v = v cos(phi) + (a x v) sin(phi) + a (a . v) (1 - cos(phi))`` (Rodrigues).

Public names
------------
Piece, earth_rate_enu, rotate_about, axis_rotation, axis_rotations, smallest_rotation, first_orientation, step_orientation,
relative_rotation, piece_angles, body_rates, orientations
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.earth import EARTH_RATE


@dataclass(frozen=True)
class Piece:
    """One stretch of a simulated session: static, a plan step, or a move between steps.

    Attributes
    ----------
    kind : str
        ``"static"``, ``"step"`` or ``"move"``.
    start, end : int
        Samples (end exclusive).
    c_start : tuple of 3 tuples
        Orientation ``C`` (rows of the 3x3 matrix) at the start of the piece.
    axis : tuple of 3 float
        The spin axis in ENU (zero for a static piece).
    body_axis : tuple of 3 float
        The same axis in the system frame, ``C_start^T a`` (zero for a static piece).
    step : int or None
        Index of the plan step (0-based) of a ``"step"`` piece.
    """

    kind: str
    start: int
    end: int
    c_start: tuple[tuple[float, float, float], ...]
    axis: tuple[float, float, float] = (0.0, 0.0, 0.0)
    body_axis: tuple[float, float, float] = (0.0, 0.0, 0.0)
    step: int | None = None

    @property
    def c(self) -> np.ndarray:
        """``C`` at the start of the piece, (3, 3)."""
        return np.array(self.c_start, float)


def earth_rate_enu(latitude: float) -> np.ndarray:
    """Earth's rotation in the local level frame, ``Omega_e (0, cos L, sin L)``, rad/s, shape (3,)."""
    return EARTH_RATE * np.array([0.0, np.cos(latitude), np.sin(latitude)])


def rotate_about(axis: np.ndarray, angles: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``Rot(axis, angle) v`` for each angle (Rodrigues, K2).

    Parameters
    ----------
    axis : ndarray, shape (3,)
        Unit vector.
    angles : ndarray, shape (n,)
        rad, right-handed about ``axis``.
    v : ndarray, shape (3,)

    Returns
    -------
    ndarray, shape (n, 3)
    """
    a = np.asarray(axis, float)
    v = np.asarray(v, float)
    phi = np.asarray(angles, float)[:, None]
    return v * np.cos(phi) + np.cross(a, v) * np.sin(phi) + a * (a @ v) * (1.0 - np.cos(phi))


def axis_rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """The rotation matrix ``Rot(axis, angle)`` (3, 3); ``axis`` a unit vector, ``angle`` rad."""
    return axis_rotations(axis, np.array([angle]))[0]


def axis_rotations(axis: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """``Rot(axis, angle) = cos I + sin [a]x + (1 - cos) a a^T`` for each angle, shape (k, 3, 3); ``axis`` a unit
    vector, ``angles`` (k,) rad."""
    a = np.asarray(axis, float)
    cross = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    phi = np.asarray(angles, float)[:, None, None]
    return np.cos(phi) * np.eye(3) + np.sin(phi) * cross + (1.0 - np.cos(phi)) * np.outer(a, a)


def smallest_rotation(frm: np.ndarray, to: np.ndarray) -> np.ndarray:
    """The rotation (3, 3) of least angle that takes unit vector ``frm`` onto unit vector ``to``.

    Opposite vectors: half a turn about the axis perpendicular to ``frm`` that lies closest to the
    coordinate axis least aligned with ``frm`` (a fixed, documented choice).
    """
    frm, to = np.asarray(frm, float), np.asarray(to, float)
    cross, dot = np.cross(frm, to), float(frm @ to)
    s = float(np.linalg.norm(cross))
    if s < 1e-12:
        if dot > 0:
            return np.eye(3)
        helper = np.eye(3)[int(np.argmin(np.abs(frm)))]
        perp = np.cross(frm, helper)
        return axis_rotation(perp / np.linalg.norm(perp), np.pi)
    return axis_rotation(cross / s, float(np.arctan2(s, dot)))


def first_orientation(u: np.ndarray, a: np.ndarray, heading: float) -> np.ndarray:
    """``C`` for the first step without a stated rest: system axis ``u`` along table axis ``a``,
    then turned by ``heading`` (rad) about ``a``: ``C = Rot(a, heading) R(u -> a)``."""
    return axis_rotation(a, heading) @ smallest_rotation(u, a)


def step_orientation(current: np.ndarray, u: np.ndarray, a: np.ndarray, rest: np.ndarray | None) -> np.ndarray:
    """``C`` at the start of a step (system axis ``u`` along table axis ``a``), from the ``current`` one.

    ``rest`` when given; else ``current`` when ``current u`` already points along ``a`` (within 1e-9);
    else the smallest rotation that brings ``current u`` onto ``a``, applied to ``current``.
    """
    if rest is not None:
        return np.asarray(rest, float)
    along = current @ u
    if along @ a > 1.0 - 1e-9:
        return current
    return smallest_rotation(along, a) @ current


def relative_rotation(c_from: np.ndarray, c_to: np.ndarray) -> tuple[float, np.ndarray]:
    """Angle (rad, in [0, pi]) and ENU unit axis of the rotation ``c_to c_from^T`` (zero axis for no rotation)."""
    from scipy.spatial.transform import Rotation

    rotvec = Rotation.from_matrix(c_to @ c_from.T).as_rotvec()
    angle = float(np.linalg.norm(rotvec))
    return angle, (rotvec / angle if angle > 0 else np.zeros(3))


def piece_angles(rate: np.ndarray, dt: float) -> np.ndarray:
    """Table angle ``theta`` (rad) at each sample of a piece from its rate (rad/s): the rate is held over each
    sample interval centred on the sample, so ``theta_i = dt (sum_{j<=i} rate_j - rate_i / 2)``."""
    return (np.cumsum(rate) - 0.5 * rate) * dt


def body_rates(pieces: tuple[Piece, ...], rate: np.ndarray, dt: float, latitude: float | None) -> np.ndarray:
    """True angular rate of the system frame (n, 3), rad/s: ``rate * body_axis`` plus Earth's rate (K2).

    Parameters
    ----------
    pieces : tuple of Piece
        Covering samples 0..n in order.
    rate : ndarray, shape (n,)
        Signed rate of each piece's motion about its axis, rad/s (0 in static pieces).
    dt : float
        Sample interval, s.
    latitude : float or None
        rad; None leaves Earth's rate out.
    """
    w = np.zeros((len(rate), 3))
    omega = None if latitude is None else earth_rate_enu(latitude)
    for p in pieces:
        sl = slice(p.start, p.end)
        w[sl] = rate[sl, None] * np.array(p.body_axis)
        if omega is not None:
            if p.kind == "static":
                w[sl] += p.c.T @ omega
            else:
                w[sl] += rotate_about(np.array(p.axis), -piece_angles(rate[sl], dt), omega) @ p.c
    return w


def orientations(pieces: tuple[Piece, ...], rate: np.ndarray, dt: float, samples: np.ndarray) -> np.ndarray:
    """``C`` (k, 3, 3) at the given samples (K1)."""
    samples = np.asarray(samples, int)
    out = np.empty((len(samples), 3, 3))
    for p in pieces:
        inside = (samples >= p.start) & (samples < p.end)
        if not inside.any():
            continue
        if p.kind == "static":
            out[inside] = p.c
            continue
        theta = piece_angles(rate[p.start:p.end], dt)[samples[inside] - p.start]
        out[inside] = axis_rotations(np.array(p.axis), theta) @ p.c
    return out
