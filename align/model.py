"""The measurement model ``g = M w + b`` and the angles engineers read from ``M``.

Row ``i`` of ``M`` is gyro ``i``'s sensitive axis in the system frame times its
scale factor (reference section 1). A package rotated by ``R`` relative to the
system frame has ``M = R^T`` (first order ``M ~ I - [r]x``, Eq 14-15); scale
errors scale rows; non-orthogonality tilts rows against each other.

Public names
------------
SensorModel, Angles, angles, nearest_rotation, rotation_vector, small_rotation_matrix,
non_orthogonal_axes, check_handedness, AXES
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from align.errors import HandednessError
from align.values import Value, frozen_array

AXES = ("x", "y", "z")


def small_rotation_matrix(alpha: float, beta: float, gamma: float) -> np.ndarray:
    """First-order ``M`` for a package rotated by small angles (reference section 1).

    ``M ~ [[1, gamma, -beta], [-gamma, 1, alpha], [beta, -alpha, 1]]`` with
    ``alpha, beta, gamma`` (rad) about x, y, z.
    """
    return np.array([[1.0, gamma, -beta], [-gamma, 1.0, alpha], [beta, -alpha, 1.0]])


def non_orthogonal_axes(delta_xy: float, delta_xz: float, delta_yz: float) -> np.ndarray:
    """Unit gyro axes (rows) in the package frame with given axis-to-axis angles.

    Triangular convention: x is the package x axis, y lies in the package x-y
    plane, z completes the set; ``u_i . u_j = sin(delta_ij)`` (Eq 32-34).

    Parameters
    ----------
    delta_xy, delta_xz, delta_yz : float
        Axis-to-axis (non-orthogonality) angles, rad.

    Returns
    -------
    ndarray, shape (3, 3)
    """
    ux = np.array([1.0, 0.0, 0.0])
    uy = np.array([np.sin(delta_xy), np.cos(delta_xy), 0.0])
    a = np.sin(delta_xz)
    b = (np.sin(delta_yz) - np.sin(delta_xy) * a) / np.cos(delta_xy)
    uz = np.array([a, b, np.sqrt(1.0 - a * a - b * b)])
    return np.vstack([ux, uy, uz])


def nearest_rotation(m: np.ndarray) -> np.ndarray:
    """Nearest proper rotation to ``m`` in the Frobenius norm (polar decomposition).

    ``m = U P``; the orthogonal factor ``U = W V^T`` from the SVD ``m = W S V^T``,
    with the last singular vector flipped when ``det < 0`` so that ``det = +1``.
    """
    w, _, vt = np.linalg.svd(m)
    d = np.sign(np.linalg.det(w @ vt)) or 1.0
    return w @ np.diag([1.0, 1.0, d]) @ vt


def rotation_vector(r: np.ndarray) -> np.ndarray:
    """Rotation vector (axis times angle, rad) of a proper rotation matrix.

    Via the unit quaternion (largest-component branch, stable for every angle),
    ``rotvec = 2 atan2(|v|, w) v / |v|``; the same as scipy's
    ``Rotation.from_matrix(r).as_rotvec()`` without importing scipy.spatial.
    """
    tr = np.trace(r)
    diag = np.diag(r)
    k = int(np.argmax(np.append(diag, tr)))
    if k == 3:
        w = 0.5 * np.sqrt(1.0 + tr)
        v = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]) / (4.0 * w)
    else:
        i, j, n = k, (k + 1) % 3, (k + 2) % 3
        v = np.empty(3)
        v[i] = 0.5 * np.sqrt(1.0 + 2.0 * r[i, i] - tr)
        w = (r[n, j] - r[j, n]) / (4.0 * v[i])
        v[j] = (r[j, i] + r[i, j]) / (4.0 * v[i])
        v[n] = (r[n, i] + r[i, n]) / (4.0 * v[i])
    if w < 0:
        w, v = -w, -v
    norm = np.linalg.norm(v)
    if norm < 1e-300:
        return np.zeros(3)
    return 2.0 * np.arctan2(norm, w) * v / norm


def check_handedness(m: np.ndarray, where: str | None = None) -> None:
    """Raise :class:`HandednessError` when ``det(M) <= 0`` (reference section 1)."""
    det = float(np.linalg.det(m))
    if not det > 0:
        raise HandednessError(
            f"det(M) = {det:.4g} <= 0: an axis is wired, mounted or signed backwards; "
            "check the gyro axis signs and the plan's axis directions (the tool does not 'fix' this)",
            where,
        )


@dataclass(frozen=True, eq=False)
class Angles(Value):
    """Angles read from ``M`` (reference section 1), all in radians.

    Attributes
    ----------
    scale : ndarray, shape (3,)
        Scale factor of each gyro, ``|M[i, :]|``.
    psi : ndarray, shape (3,)
        Axis-to-frame misalignment ``psi_i = acos(u_i . e_i)``.
    phi : ndarray, shape (3, 3)
        Signed cross-axis angles ``phi_ij = asin(u_i . e_j)``; NaN on the diagonal.
    delta : ndarray, shape (3,)
        Axis-to-axis angles ``delta_xy, delta_xz, delta_yz = asin(u_i . u_j)``.
    mounting_rotvec : ndarray, shape (3,)
        Rotation vector of the mounting rotation ``R`` (package relative to system)
        where ``R^T`` is the nearest proper rotation to ``M``.
    """

    scale: np.ndarray
    psi: np.ndarray
    phi: np.ndarray
    delta: np.ndarray
    mounting_rotvec: np.ndarray


def angles(m: np.ndarray) -> Angles:
    """Decompose ``M`` into scale factors and misalignment angles.

    Implements the definitions of reference section 1 and Eq 32-34.
    """
    m = np.asarray(m, dtype=float)
    scale = np.linalg.norm(m, axis=1)
    u = m / scale[:, None]
    psi = np.arccos(np.clip(np.diag(u), -1.0, 1.0))
    phi = np.arcsin(np.clip(u, -1.0, 1.0))
    np.fill_diagonal(phi, np.nan)
    pairs = ((0, 1), (0, 2), (1, 2))
    delta = np.array([np.arcsin(np.clip(u[i] @ u[j], -1.0, 1.0)) for i, j in pairs])
    return Angles(scale, psi, phi, delta, rotation_vector(nearest_rotation(m).T))


@dataclass(frozen=True, eq=False)
class SensorModel(Value):
    """The linear sensor model ``g = M w + b`` (Eq 14-15).

    Immutable; build it with the ``from_*`` constructors, convert with the
    methods. ``M`` is dimensionless, ``bias`` is in SI (rad/s for a gyro).

    Attributes
    ----------
    M : ndarray, shape (3, 3)
    bias : ndarray, shape (3,)
    """

    M: np.ndarray
    bias: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        object.__setattr__(self, "M", frozen_array(self.M, (3, 3)))
        object.__setattr__(self, "bias", frozen_array(self.bias, (3,)))

    @classmethod
    def identity(cls) -> SensorModel:
        return cls(np.eye(3))

    @classmethod
    def from_rotation(
        cls,
        rotation,
        scale=(1.0, 1.0, 1.0),
        delta=(0.0, 0.0, 0.0),
        bias=(0.0, 0.0, 0.0),
    ) -> SensorModel:
        """Build ``M = diag(scale) N R^T``.

        Parameters
        ----------
        rotation : scipy.spatial.transform.Rotation
            Package orientation relative to the system frame (mounting error).
        scale : array_like, shape (3,)
            Gyro scale factors.
        delta : array_like, shape (3,)
            Axis-to-axis angles ``delta_xy, delta_xz, delta_yz`` (rad), see
            :func:`non_orthogonal_axes`.
        bias : array_like, shape (3,)
            rad/s.
        """
        n = non_orthogonal_axes(*delta)
        m = np.diag(np.asarray(scale, float)) @ n @ rotation.as_matrix().T
        return cls(m, bias)

    @classmethod
    def from_angles(cls, psi, phi, bias=(0.0, 0.0, 0.0)) -> SensorModel:
        """Eq 5-10: ``M_ii = cos(psi_i)``, ``M_ij = sin(phi_ij)``.

        Parameters
        ----------
        psi : array_like, shape (3,)
            Axis-to-frame angles, rad.
        phi : array_like, shape (3, 3)
            Cross-axis angles ``phi_ij`` (rad); the diagonal is ignored.
        """
        m = np.sin(np.nan_to_num(np.asarray(phi, dtype=float)))
        np.fill_diagonal(m, np.cos(np.asarray(psi, dtype=float)))
        return cls(m, bias)

    @classmethod
    def from_small_angles(cls, alpha: float, beta: float, gamma: float, bias=(0.0, 0.0, 0.0)) -> SensorModel:
        """First-order model of a package rotated by ``alpha, beta, gamma`` (rad)."""
        return cls(small_rotation_matrix(alpha, beta, gamma), bias)

    def alignment(self) -> np.ndarray:
        """The alignment matrix ``A = M^-1`` (Eq 15)."""
        return np.linalg.inv(self.M)

    def measure(self, w: np.ndarray) -> np.ndarray:
        """Gyro output ``g = M w + b`` for true rates ``w`` of shape (3,) or (n, 3)."""
        return np.asarray(w) @ self.M.T + self.bias

    def correct(self, g: np.ndarray) -> np.ndarray:
        """Aligned rate ``w = A (g - b)`` for readings of shape (3,) or (n, 3)."""
        return np.linalg.solve(self.M, (np.asarray(g) - self.bias).T).T

    def angles(self) -> Angles:
        return angles(self.M)
