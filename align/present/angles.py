"""The one layout of a matrix's scale factors and misalignment angles, shared by every presentation.

``matrix``/``calibrate`` text (:func:`align.present.text.angle_lines`), the CSV export
(:mod:`align.present.exportable`) and the report's sections all lay the angles out from :func:`angle_rows`:
five rows, each a label, its elements, the values in the display unit and (when ``sigma(M)`` is known)
their 1-sigma.

The angles are those of reference section 1, read from the rows ``u_i = M_i / |M_i|`` of ``M N^T``
(``N`` the nominal mounting, the identity when there is none; rows of ``M`` are sensor axes):

========  ====================  =======================================  ==============  ===========
key       label                 definition                               elements        unit
========  ====================  =======================================  ==============  ===========
scale     scale factors         ``s_i = |M_i|``                          x, y, z         M's unit
psi       psi (axis-frame)      ``psi_i = acos(u_i . e_i)``              x, y, z         deg
phi       phi (cross-axis)      ``phi_ij = asin(u_i . e_j)``             xy xz yx yz..   deg
delta     delta (axis-axis)     ``delta_ij = asin(u_i . u_j)``           xy, xz, yz      deg
rotation  mounting rotation     rotation vector of ``R``, ``R^T`` the    x, y, z         deg
                                nearest proper rotation to ``M N^T``
========  ====================  =======================================  ==============  ===========

M's unit is :func:`align.io.consumers.matrix_unit` (``1`` for readings in a physical unit, ``counts per
m/s^2`` etc. for readings in counts). The 1-sigma are first-order propagations of ``sigma(M)`` with the
elements taken independent (:func:`align.present.verdicts.angle_sigmas`; for the scale,
``sigma_s_i^2 = sum_j (M_ij / s_i)^2 sigma_M,ij^2``).

Use
---
``for row in angle_rows(M, sigma_M, N, unit): row.key, row.label, row.names, row.values, row.sigmas, row.unit``;
``row.text()`` gives the cells as the terminal prints them (``xy=+0.0123 ± 0.0004``).

Public names
------------
AngleRow, angle_rows, number, DEFINITIONS
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.model import angles
from align.present.digits import with_sigma
from align.units import DEG

#: each row's definition, for a file's header or a report's note
DEFINITIONS = {
    "scale": "scale s_i = |M_i| (row i of M, in M's unit)",
    "psi": "psi_i = acos(u_i . e_i)",
    "phi": "phi_ij = asin(u_i . e_j)",
    "delta": "delta_ij = asin(u_i . u_j)",
    "rotation": "mounting rotation: rotation vector of R, R^T the nearest proper rotation to M",
}
_PAIRS = ("xy", "xz", "yz")
_OFF = tuple((i, j) for i in range(3) for j in range(3) if i != j)


@dataclass(frozen=True)
class AngleRow:
    """One row of the layout.

    Attributes
    ----------
    key : {"scale", "psi", "phi", "delta", "rotation"}
    label : str
        ``"scale factors"``, ``"psi (axis-frame)"``, ``"phi (cross-axis)"``, ``"delta (axis-axis)"``,
        ``"mounting rotation"``.
    names : tuple of str
        The elements: sensor axes ``"x", "y", "z"`` (scale, psi; the rotation: about x, y, z) or pairs ``"xy"``
        (phi: axis i toward frame axis j; delta: axes i and j).
    values : tuple of float
        In ``unit``.
    sigmas : tuple of float or None
        1-sigma in ``unit`` (NaN for an element whose sigma is unknown); None when no ``sigma(M)`` was given.
    unit : str
        ``"deg"``, or M's unit for the scale (``"1"``: dimensionless).
    assumed : int or None
        Index of a value that was assumed, not measured (the scale of the two-axis shortcut's axis).
    """

    key: str
    label: str
    names: tuple[str, ...]
    values: tuple[float, ...]
    sigmas: tuple[float, ...] | None
    unit: str
    assumed: int | None = None

    def text(self, digits: int = 4) -> list[str]:
        """Each element as ``x=+0.0123`` (``± 0.0004`` when known, the value's decimals following it: ``± 0.0000042``
        with 7, ``± 0`` for a 1-sigma of exactly zero; ``(assumed)``); no negative zeros."""
        sign = self.key not in ("scale", "psi")
        out = []
        for k, (n, v) in enumerate(zip(self.names, self.values)):
            s = self.sigmas[k] if self.sigmas is not None and np.isfinite(self.sigmas[k]) else None
            if self.key == "scale":  # 6 decimals of a dimensionless M; 7 significant digits in counts
                cell = number(v, 6, False) if self.unit == "1" else f"{v:.7g}"
                cell += "" if s is None else f" ± {s:.2g}"
            elif s is None:
                cell = f"{n}={number(v, digits, sign)}"
            else:  # the angle to the decimal place its 1-sigma is shown to (never "± 0.0000")
                value, sigma = with_sigma(v, s, digits, sign)
                cell = f"{n}={value} ± {sigma}"
            out.append(cell + ("(assumed)" if k == self.assumed else ""))
        return out


def number(v: float, digits: int = 4, sign: bool = True) -> str:
    """``v`` with ``digits`` decimals, signed when ``sign``; a value that rounds to zero prints as ``0`` (never
    ``-0.0000``)."""
    v = round(float(v), digits) + 0.0  # + 0.0 turns -0.0 into 0.0
    return f"{v:+.{digits}f}" if sign else f"{v:.{digits}f}"


def _scale_sigma(m: np.ndarray, sigma_m: np.ndarray) -> np.ndarray:
    s = np.linalg.norm(m, axis=1)
    return np.sqrt(np.sum((m / s[:, None]) ** 2 * np.square(sigma_m), axis=1))


def angle_rows(m: np.ndarray, sigma_m: np.ndarray | None = None, mounting: np.ndarray | None = None,
               unit: str = "1", assumed: int | None = None) -> list[AngleRow]:
    """The five rows (scale, psi, phi, delta, mounting rotation) of ``M N^T``.

    Parameters
    ----------
    m : ndarray, shape (3, 3)
        ``M`` of ``raw = M true + bias`` (rows: sensor axes), in ``unit``.
    sigma_m : ndarray, shape (3, 3), optional
        1-sigma of ``M``'s elements (NaN: unknown); None: no sigmas on the rows.
    mounting : ndarray, shape (3, 3), optional
        Nominal mounting ``N`` (rows: sensor axes in the reference frame); the angles are relative to it.
    unit : str
        M's unit (:func:`align.io.consumers.matrix_unit`), the scale row's unit.
    assumed : int, optional
        The axis whose scale was assumed (marked on the scale row).

    Returns
    -------
    list of AngleRow
        Keys ``scale, psi, phi, delta, rotation`` in that order; angles in degrees.
    """
    m = np.asarray(m, float)
    n = np.eye(3) if mounting is None else np.asarray(mounting, float)
    ang = angles(m @ n.T)
    sig = None
    if sigma_m is not None:
        from align.present.verdicts import angle_sigmas  # same layer; imported here: verdicts is the larger module

        sig = {k: v / DEG for k, v in angle_sigmas(m, np.asarray(sigma_m, float), n).items()}
        s_scale = tuple(float(v) for v in _scale_sigma(m, np.asarray(sigma_m, float)))

    def sigmas(prefix: str, names) -> tuple[float, ...] | None:
        return None if sig is None else tuple(float(sig[f"{prefix}_{k}"]) for k in names)

    xyz = ("x", "y", "z")
    phi_names = tuple("xyz"[i] + "xyz"[j] for i, j in _OFF)
    return [
        AngleRow("scale", "scale factors", xyz, tuple(float(v) for v in ang.scale),
                 None if sig is None else s_scale, unit, assumed),
        AngleRow("psi", "psi (axis-frame)", xyz, tuple(float(v / DEG) for v in ang.psi), sigmas("psi", xyz), "deg"),
        AngleRow("phi", "phi (cross-axis)", phi_names, tuple(float(ang.phi[i, j] / DEG) for i, j in _OFF),
                 sigmas("phi", phi_names), "deg"),
        AngleRow("delta", "delta (axis-axis)", _PAIRS, tuple(float(v / DEG) for v in ang.delta),
                 sigmas("delta", _PAIRS), "deg"),
        AngleRow("rotation", "mounting rotation", xyz, tuple(float(v / DEG) for v in ang.mounting_rotvec),
                 sigmas("rot", xyz), "deg"),
    ]
