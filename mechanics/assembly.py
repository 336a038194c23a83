"""The assembled pose: where the gyro axes point once the package rests, skewed, on its ledges.

Shared by the deterministic worst case (:mod:`mechanics.budget`) and the Monte
Carlo (:mod:`mechanics.montecarlo`): the rest-plane slopes of ledge heights, the
skew limit of the screws in their holes, and the 3-D composition of skew and
tilt applied to the package-frame gyro axes.

Public names
------------
rotate_axes, skew_limit, rest_slopes, worst_case_per_axis
"""

from __future__ import annotations

from itertools import product

import numpy as np

from align.errors import InputError
from mechanics.formulas import screw_radius
from mechanics.mount import Mount
from mechanics.rest import corner_geometry, rest_plane_hull, rest_planes


def rotate_axes(a: np.ndarray, b: np.ndarray, skew: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """Rotate package-frame gyro axes into the system frame and return their misalignment (section 2).

    The package is turned by ``skew`` about z, then tilted by the rotation that
    takes ``e_z`` to the rest-plane normal ``n ~ (-a, -b, 1)`` (Rodrigues, axis
    ``e_z x n`` in the x-y plane).

    Parameters
    ----------
    a, b : ndarray, shape (N,)
        Rest-plane slopes along x and y (``z = a x + b y + c``), dimensionless.
    skew : ndarray, shape (N,)
        Rotation about z (Eq 4), rad.
    axes : ndarray, shape (N, 3, 3)
        Row ``i``: gyro ``i``'s axis in the package frame (normalised here).

    Returns
    -------
    ndarray, shape (N, 3)
        Angle between each gyro axis and its system axis, rad.
    """
    vx, vy, vz = axes[:, :, 0], axes[:, :, 1], axes[:, :, 2]           # (N, 3): component of each axis
    inv = 1.0 / np.sqrt(vx * vx + vy * vy + vz * vz)
    cz, sz = np.cos(skew)[:, None], np.sin(skew)[:, None]
    x = (cz * vx - sz * vy) * inv
    y = (sz * vx + cz * vy) * inv
    z = vz * inv
    r = np.sqrt(a * a + b * b)
    c = (1.0 / np.sqrt(1.0 + r * r))[:, None]                          # cos of the tilt
    s = (r[:, None] * c)                                               # sin of the tilt
    safe = np.where(r > 0, r, 1.0)
    kx, ky = (b / safe)[:, None], (np.where(r > 0, -a, 0.0) / safe)[:, None]  # unit (e_z x n) = (b, -a, 0) / r
    kv = (kx * x + ky * y) * (1.0 - c)
    rx = x * c + ky * z * s + kx * kv                                  # v cos + (k x v) sin + k (k.v)(1 - cos)
    ry = y * c - kx * z * s + ky * kv
    rz = z * c + (kx * y - ky * x) * s
    along = np.column_stack([rx[:, 0], ry[:, 1], rz[:, 2]])
    across = np.column_stack([np.hypot(ry[:, 0], rz[:, 0]), np.hypot(rx[:, 1], rz[:, 1]), np.hypot(rx[:, 2], ry[:, 2])])
    return np.arctan2(across, along)


def skew_limit(m: Mount) -> float:
    """Largest skew about z with each screw at the edge of its clearance and position tolerance (Eq 4).

    ``asin((c + t / 2) / R_S)``: the radial clearance ``c = (D_H - D_M) / 2``
    widened by the radius of the screw's position tolerance zone (diameter
    ``t``), capped at 90 deg.

    Parameters
    ----------
    m : Mount
        The mounting: ``spacing_x``, ``spacing_y`` (for ``R_S``), the screw and
        hole diameters and ``position_tolerance``, m.

    Returns
    -------
    float
        rad.
    """
    r = screw_radius(m.spacing_x, m.spacing_y)
    return float(np.arcsin(min(1.0, (m.clearance + m.position_tolerance / 2) / r)))


def rest_slopes(m: Mount, heights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rest-plane slopes: closed form for four corner ledges, the trimesh hull otherwise (Eq 2-3).

    Parameters
    ----------
    m : Mount
        The mounting; ``m.pads`` (P, V, 2), m, gives the ledge layout.
    heights : ndarray, shape (N, P)
        Ledge-top heights of ``N`` configurations, m (in :data:`~mechanics.rest.CORNERS`
        order for four corner ledges).

    Returns
    -------
    a, b : ndarray, shape (N,)
        Slopes of each resting plane along x and y, dimensionless.
    """
    try:
        geo = corner_geometry(m.pads)
    except InputError:
        planes = np.array([rest_plane_hull(m.pads, h)[:2] for h in heights])
        return planes[:, 0], planes[:, 1]
    a, b, _ = rest_planes(geo, heights)
    return a, b


def worst_case_per_axis(m: Mount) -> np.ndarray:
    """Every tolerance at its extreme, composed in 3-D, plus the datasheet and extra terms.

    The corners of the ledge-height box go through the rest model, with the
    skew at either limit (:func:`skew_limit`); the largest angle of each gyro
    axis is added to its datasheet term and the extras (the worst case of Eq 1:
    the plain sum).

    Parameters
    ----------
    m : Mount
        The mounting: ledges, heights and their tolerance (m), screws (m), the
        datasheet axis-to-package term (3,) and extra terms (rad).

    Returns
    -------
    ndarray, shape (3,)
        Worst-case misalignment of each gyro axis, rad.
    """
    skew_w = skew_limit(m)
    corners = np.array(list(product((0.0, m.height_tolerance), repeat=len(m.pads)))) + m.pad_heights[None, :]
    a, b = rest_slopes(m, corners)
    aa, bb = np.repeat(a, 2), np.repeat(b, 2)
    ss = np.tile([-skew_w, skew_w], len(a))
    mount_angles = rotate_axes(aa, bb, ss, np.broadcast_to(np.eye(3), (len(aa), 3, 3))).max(axis=0)
    return mount_angles + m.axis_to_package + sum(m.extras.values())
