"""The misaligned-gyro response in angles, derived with sympy (Eq 5-13).

The response of misaligned gyros to a rotation ``w`` is ``g = M w`` with ``M``
written in the nine misalignment angles (Eq 5-10)::

    g_x = w_x cos(psi_x) + w_y sin(phi_xy) + w_z sin(phi_xz)     (and likewise y, z)

and for a rotation about a fixed axis the integrated outputs obey the same
matrix, ``theta_G = M theta`` (Eq 11-13). sympy derives the response and its
Jacobian with respect to each angle (:func:`symbolic`); numbers come from the
lambdified forms (:func:`matrix_from_angles`, :func:`response`,
:func:`sensitivity`).

Public names
------------
ELEMENTS, OUTPUTS, AXIS_INDEX, Symbolic, symbolic, symbolic_text, matrix_from_angles, response, sensitivity
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import numpy.typing as npt

from align.errors import InputError
from align.values import Value

#: the nine misalignment angles of ``M`` (Eq 5-10): ``psi_i`` on the diagonal, ``phi_ij`` off it
ELEMENTS = ("psi_x", "psi_y", "psi_z", "phi_xy", "phi_xz", "phi_yx", "phi_yz", "phi_zx", "phi_zy")
#: outputs a requirement can limit: each gyro's integrated angle, and the Z-Y-X Euler angles
OUTPUTS = ("x", "y", "z", "azimuth", "elevation", "roll")
#: gyro / axis name -> index
AXIS_INDEX = {"x": 0, "y": 1, "z": 2}
#: how :func:`symbolic_text` prints: sympy's ASCII pretty printer or LaTeX
STYLES = ("pretty", "latex")


@dataclass(frozen=True, eq=False)
class Symbolic(Value):
    """The sympy model: ``M`` in angles, ``g = M w``, ``theta_G = M theta`` and the Jacobians.

    Attributes
    ----------
    angles : tuple of sympy.Symbol
        The nine angles, in :data:`ELEMENTS` order.
    w, theta : sympy.Matrix, shape (3, 1)
        Body rate and fixed-axis rotation angle.
    M : sympy.Matrix, shape (3, 3)
        Eq 5-10.
    g, theta_G : sympy.Matrix, shape (3, 1)
        ``M w`` (Eq 5-10) and ``M theta`` (Eq 11-13).
    jacobian : sympy.Matrix, shape (3, 9)
        ``d g / d angles``.
    """

    angles: tuple
    w: Any
    theta: Any
    M: Any
    g: Any
    theta_G: Any
    jacobian: Any


@lru_cache(maxsize=1)
def symbolic() -> Symbolic:
    """Derive Eq 5-13 and their sensitivities with sympy (cached).

    Returns
    -------
    Symbolic
        ``M`` in the nine angles (Eq 5-10), ``g = M w``, ``theta_G = M theta``
        (Eq 11-13) and the Jacobian ``d g / d angles`` (3, 9).
    """
    import sympy as sp

    ang = sp.symbols(" ".join(ELEMENTS), real=True)
    a = dict(zip(ELEMENTS, ang))
    w = sp.Matrix(sp.symbols("omega_x omega_y omega_z", real=True))
    th = sp.Matrix(sp.symbols("theta_x theta_y theta_z", real=True))
    m = sp.Matrix(3, 3, lambda i, j: sp.cos(a[f"psi_{'xyz'[i]}"]) if i == j else sp.sin(a[f"phi_{'xyz'[i]}{'xyz'[j]}"]))
    g = m * w
    return Symbolic(ang, w, th, m, g, m * th, g.jacobian(sp.Matrix(ang)))


def symbolic_text(style: str = "pretty") -> str:
    """Eq 5-10, Eq 11-13 and the sensitivity matrix as text.

    Parameters
    ----------
    style : {"pretty", "latex"}
        sympy's ASCII pretty printer or LaTeX.

    Returns
    -------
    str
        The three equations, each after a heading line, separated by blank lines.

    Raises
    ------
    InputError
        For a style other than ``"pretty"`` or ``"latex"`` (names ``{style}``).
    """
    import sympy as sp

    if style not in STYLES:
        raise InputError(f"choose pretty or latex (got {style!r})", "{style}")
    s = symbolic()
    show = (lambda e: sp.latex(e)) if style == "latex" else (lambda e: sp.pretty(e, use_unicode=False))
    return "\n\n".join([
        "Gyro response g = M w (Eq 5-10):", show(sp.Eq(sp.Symbol("g"), s.g, evaluate=False)),
        "Integrated, fixed-axis rotation theta_G = M theta (Eq 11-13):",
        show(sp.Eq(sp.Symbol("theta_G"), s.theta_G, evaluate=False)),
        f"Sensitivity d g / d ({', '.join(ELEMENTS)}):", show(s.jacobian),
    ])


@lru_cache(maxsize=1)
def _lambdified():
    import sympy as sp

    s = symbolic()
    m_fn = sp.lambdify([s.angles], s.M, "numpy")
    j_fn = sp.lambdify([s.angles, list(s.w)], s.jacobian, "numpy")
    return m_fn, j_fn


def _angle_vector(angles) -> np.ndarray:
    if isinstance(angles, dict):
        unknown = set(angles) - set(ELEMENTS)
        if unknown:
            raise InputError(f"unknown element(s) {', '.join(sorted(unknown))}; elements are {', '.join(ELEMENTS)}",
                             "{angles}")
        return np.array([float(angles.get(e, 0.0)) for e in ELEMENTS])
    return np.asarray(angles, dtype=float).reshape(9)


def matrix_from_angles(angles: dict[str, float] | npt.ArrayLike) -> np.ndarray:
    """``M`` of Eq 5-10 from the nine angles, via the lambdified sympy form.

    Parameters
    ----------
    angles : dict or array_like, shape (9,)
        Element name -> angle (missing ones zero), or the nine angles in
        :data:`ELEMENTS` order, rad.

    Returns
    -------
    ndarray, shape (3, 3)
        ``M_ii = cos(psi_i)``, ``M_ij = sin(phi_ij)``, dimensionless.

    Raises
    ------
    InputError
        For a dict naming an element not in :data:`ELEMENTS`.
    """
    return np.array(_lambdified()[0](tuple(_angle_vector(angles))), dtype=float)


def response(w: npt.ArrayLike, angles: dict[str, float] | npt.ArrayLike) -> np.ndarray:
    """Gyro outputs ``g = M w`` (Eq 5-10).

    Parameters
    ----------
    w : array_like, shape (3,) or (n, 3)
        True body rate (any unit; ``g`` is in the same).
    angles : dict or array_like, shape (9,)
        As :func:`matrix_from_angles`, rad.

    Returns
    -------
    ndarray, shape like ``w``
        The gyro outputs, in the unit of ``w``.
    """
    return np.asarray(w, float) @ matrix_from_angles(angles).T


def sensitivity(w: npt.ArrayLike, angles: dict[str, float] | npt.ArrayLike) -> np.ndarray:
    """Jacobian ``d g / d angles`` of Eq 5-10 at rate ``w`` (lambdified sympy).

    Parameters
    ----------
    w : array_like, shape (3,)
        True body rate (any unit; the Jacobian is in the same per rad).
    angles : dict or array_like, shape (9,)
        As :func:`matrix_from_angles`, rad.

    Returns
    -------
    ndarray, shape (3, 9)
        Columns in :data:`ELEMENTS` order, unit of ``w`` per rad.

    Examples
    --------
    Aligned axes (all angles 0) and a unit rate about z: only the x and y gyros' cross-axis
    angles toward z (``phi_xz``, ``phi_yz``) change the readings to first order (Eq 5-10).

    >>> import numpy as np
    >>> J = sensitivity([0.0, 0.0, 1.0], np.zeros(9))
    >>> J.shape, [ELEMENTS[j] for j in np.flatnonzero(np.abs(J).max(axis=0) > 1e-12)]
    ((3, 9), ['phi_xz', 'phi_yz'])
    """
    return np.array(_lambdified()[1](tuple(_angle_vector(angles)), list(np.asarray(w, float))), dtype=float)
