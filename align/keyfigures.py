"""The names, kinds and units of the figures every result gives: one vocabulary for results, limits and the lot.

The figures share one vocabulary across jobs, in the convention ``raw = M true + bias`` (rows of ``M`` are
sensor axes):

* ``M_ij`` and ``M_ij_sigma`` (1-sigma): the whole matrix; for a magnetometer ``M = soft_iron^-1``;
* ``scale_i``, ``phi_ij``, ``delta_ij``, ``rotation_i`` (the mounting rotation vector): the decomposition of
  ``M`` (reference section 1, :func:`align.model.angles`), for an alignment relative to its nominal mounting
  (``M N^T``), with their 1-sigma by first-order propagation (:func:`angle_sigmas`);
* ``bias_i`` and ``bias_i_sigma``; ``arw_i``, ``bi_i``, ``rrw_i`` (the noise terms ``N``, ``B``, ``K``);
* ``field``, ``coverage``, ``heading_error``, ``spread`` (a magnetometer);
* the figures of the test series (issue 26): ``nonlinearity_i``, ``asymmetry_i`` (ratios), ``warmup_i`` (s),
  ``bias_repeatability_i`` (a reading), ``gsens_ij`` (a reading per m/s^2), and the residuals ``verify``
  reports (``residual_scale_i``, ``residual_phi_ij``, ``residual_norm_rms``).

Values are SI: angles in rad, readings in rad/s, m/s^2 or T (counts for a calibration in counts).
:func:`si_unit` and :func:`shown_unit` give a figure's unit for a sensor; :data:`TITLES` its standard name.

Public names
------------
FIGURES, KIND, TITLES, AXES, si_unit, shown_unit, title, matrix_figures, vector_figures, angle_vector, angle_sigmas,
ANGLE_NAMES
"""

from __future__ import annotations

import numpy as np

from align.model import angles

AXES = "xyz"
_PAIRS = ("xy", "xz", "yz")
_CROSS = tuple(f"{a}{b}" for a in AXES for b in AXES if a != b)

#: figure -> its kind: "1" (a ratio), "angle", "reading" (the sensor's quantity), "white", "flicker", "walk", "time",
#: "gsens" (a gyro bias per m/s^2)
KIND: dict[str, str] = {
    **{f"M_{a}{b}": "1" for a in AXES for b in AXES},
    **{f"M_{a}{b}_sigma": "1" for a in AXES for b in AXES},
    **{f"scale_{a}": "1" for a in AXES},
    **{f"phi_{p}": "angle" for p in _CROSS},
    **{f"delta_{p}": "angle" for p in _PAIRS},
    **{f"rotation_{a}": "angle" for a in AXES},
    **{f"bias_{a}": "reading" for a in AXES},
    **{f"bias_{a}_sigma": "reading" for a in AXES},
    **{f"arw_{a}": "white" for a in AXES},
    **{f"bi_{a}": "flicker" for a in AXES},
    **{f"rrw_{a}": "walk" for a in AXES},
    "field": "reading", "coverage": "1", "heading_error": "angle", "spread": "1",
    **{f"nonlinearity_{a}": "1" for a in AXES},
    **{f"asymmetry_{a}": "1" for a in AXES},
    **{f"warmup_{a}": "time" for a in AXES},
    **{f"bias_repeatability_{a}": "reading" for a in AXES},
    **{f"gsens_{a}{b}": "gsens" for a in AXES for b in AXES},
    **{f"residual_scale_{a}": "1" for a in AXES},
    **{f"residual_phi_{p}": "angle" for p in _CROSS},
    "residual_norm_rms": "reading", "residual_norm_max": "reading", "residual_rate_rms": "reading",
    **{f"hysteresis_{a}": "reading" for a in AXES},
    **{f"thermal_residual_{a}": "reading" for a in AXES},
}
#: every figure, in the table's column order
FIGURES: tuple[str, ...] = tuple(KIND)

#: kind -> sensor -> (SI unit, the unit a figure is shown in when no limit states one)
_UNITS: dict[str, dict[str, tuple[str, str]]] = {
    "1": {"": ("1", "1")},
    "angle": {"": ("rad", "deg")},
    "reading": {"gyroscope": ("rad/s", "deg/s"), "accelerometer": ("m/s^2", "m/s^2"), "magnetometer": ("T", "uT")},
    "white": {"gyroscope": ("rad/sqrt(s)", "deg/sqrt(h)"), "accelerometer": ("m/s/sqrt(s)", "m/s/sqrt(h)")},
    "flicker": {"gyroscope": ("rad/s", "deg/h"), "accelerometer": ("m/s^2", "ug")},
    "walk": {"gyroscope": ("rad/s/sqrt(s)", "deg/h/sqrt(h)"), "accelerometer": ("m/s^2/sqrt(s)", "ug/sqrt(h)")},
    "time": {"": ("s", "s")},
    "gsens": {"gyroscope": ("rad/s/(m/s^2)", "deg/h/g")},
}

_TITLE_OF = {"M": "matrix element", "scale": "scale factor", "phi": "cross-axis misalignment",
             "delta": "non-orthogonality", "rotation": "mounting rotation", "bias": "bias",
             "arw": "angle (velocity) random walk N", "bi": "bias instability B", "rrw": "rate random walk K",
             "field": "field strength", "coverage": "coverage of directions", "heading_error": "heading error (1-sigma)",
             "spread": "field-magnitude spread", "nonlinearity": "scale-factor nonlinearity (of full scale)",
             "asymmetry": "scale-factor asymmetry", "warmup": "warm-up time", "bias_repeatability":
             "bias repeatability (turn-on to turn-on)", "gsens": "g-sensitivity of the bias",
             "residual_scale": "residual scale error after correction", "residual_phi":
             "residual misalignment after correction", "residual_norm": "residual of |reading| after correction",
             "residual_rate": "residual rate error after correction",
             "hysteresis": "thermal hysteresis of the bias (heating minus cooling)",
             "thermal_residual": "bias residual after thermal compensation (rms)"}
#: figure -> its standard name
TITLES: dict[str, str] = {}
for _f in KIND:
    _stem = _f.removesuffix("_sigma")
    _base = next((k for k in sorted(_TITLE_OF, key=len, reverse=True) if _stem == k or _stem.startswith(k + "_")), _stem)
    TITLES[_f] = _TITLE_OF.get(_base, _stem) + (" (1-sigma)" if _f.endswith("_sigma") else "")


def title(figure: str) -> str:
    """The standard name of ``figure`` (its own name for one this vocabulary does not know)."""
    return TITLES.get(figure, figure)


def _units_of(figure: str, sensor: str) -> tuple[str, str] | tuple[None, None]:
    units = _UNITS[KIND[figure]]
    return units.get("", units.get(sensor)) or (None, None)


def si_unit(figure: str, sensor: str) -> str | None:
    """The SI unit of ``figure`` for ``sensor`` (``"rad"``, ``"rad/s"``, ``"1"``); None: the sensor has no such figure."""
    return _units_of(figure, sensor)[0]


def shown_unit(figure: str, sensor: str) -> str:
    """The unit ``figure`` is shown in for ``sensor`` when no limit states one (``"deg"``, ``"deg/sqrt(h)"``)."""
    return _units_of(figure, sensor)[1] or "1"


def matrix_figures(m: np.ndarray, sigma: np.ndarray | None, mounting: np.ndarray | None = None, *,
                   angle_sigmas_too: bool = False) -> dict:
    """``M_ij``, their sigmas and the decomposition of ``M N^T`` (``N`` the nominal mounting, identity when None).

    With ``sigma`` (the elements' 1-sigma) and ``angle_sigmas_too``, the decomposition's 1-sigma too
    (``scale_x_sigma``, ``phi_xy_sigma``, ``delta_xy_sigma``, ``rotation_x_sigma``): the scale's
    ``sqrt(sum_j (M_ij / |M_i|)^2 sigma_ij^2)``, the angles' by :func:`angle_sigmas`.
    """
    out = {f"M_{a}{b}": float(m[i, j]) for i, a in enumerate(AXES) for j, b in enumerate(AXES)}
    if sigma is not None:
        out |= {f"M_{a}{b}_sigma": float(sigma[i, j]) for i, a in enumerate(AXES) for j, b in enumerate(AXES)}
    ang = angles(m if mounting is None else m @ mounting.T)
    if sigma is not None and angle_sigmas_too:
        sig = angle_sigmas(m, sigma, mounting)
        out |= {f"scale_{a}_sigma": float(np.sqrt(np.sum((m[i] / np.linalg.norm(m[i]) * sigma[i]) ** 2)))
                for i, a in enumerate(AXES)}
        out |= {f"{k}_sigma": v for k, v in sig.items() if k.startswith(("phi_", "delta_"))}
        out |= {f"rotation_{a}_sigma": sig[f"rot_{a}"] for a in AXES}
    out |= {f"scale_{a}": float(ang.scale[i]) for i, a in enumerate(AXES)}
    out |= {f"phi_{a}{b}": float(ang.phi[i, j]) for i, a in enumerate(AXES) for j, b in enumerate(AXES) if i != j}
    out |= {f"delta_{p}": float(v) for p, v in zip(_PAIRS, ang.delta)}
    out |= {f"rotation_{a}": float(v) for a, v in zip(AXES, ang.mounting_rotvec)}
    return out


def vector_figures(name: str, v, sigma=None) -> dict:
    """``name_x, name_y, name_z`` (and ``name_x_sigma`` ... with ``sigma``) of a 3-vector."""
    out = {f"{name}_{a}": float(x) for a, x in zip(AXES, np.asarray(v, float))}
    if sigma is not None:
        out |= {f"{name}_{a}_sigma": float(x) for a, x in zip(AXES, np.asarray(sigma, float))}
    return out


#: the angles :func:`angle_vector` returns, in order
ANGLE_NAMES = ("psi_x", "psi_y", "psi_z", "phi_xy", "phi_xz", "phi_yx", "phi_yz", "phi_zx", "phi_zy",
               "delta_xy", "delta_xz", "delta_yz", "rot_x", "rot_y", "rot_z")


def angle_vector(m: np.ndarray) -> np.ndarray:
    """The angles of reference section 1 read from ``M`` (already relative to the nominal mounting), rad.

    ``psi_i = atan2(|u_i x e_i|, u_i . e_i)`` (equal to ``acos(u_i . e_i)``, well conditioned near 0),
    ``phi_ij = asin(u_i . e_j)``, ``delta_ij = asin(u_i . u_j)``, and the rotation vector of the mounting
    rotation ``R`` with ``R^T`` the nearest proper rotation to ``M`` (:func:`align.model.angles`).

    Returns
    -------
    ndarray, shape (15,)
        In :data:`ANGLE_NAMES` order.
    """
    m = np.asarray(m, float)
    u = m / np.linalg.norm(m, axis=1, keepdims=True)
    psi = [np.arctan2(np.linalg.norm(np.cross(u[i], np.eye(3)[i])), u[i, i]) for i in range(3)]
    phi = [np.arcsin(np.clip(u[i, j], -1, 1)) for i in range(3) for j in range(3) if i != j]
    delta = [np.arcsin(np.clip(u[i] @ u[j], -1, 1)) for i, j in ((0, 1), (0, 2), (1, 2))]
    return np.concatenate([psi, phi, delta, angles(m).mounting_rotvec])


def angle_sigmas(m: np.ndarray, sigma_m: np.ndarray, mounting: np.ndarray | None = None) -> dict:
    """1-sigma of every angle of ``M N^T`` by first-order propagation of the elements' 1-sigma.

    ``sigma_a^2 = sum_kl (d a / d M_kl)^2 sigma_M,kl^2`` (the elements taken independent, as the result
    states no covariance), the derivatives by central differences of :func:`angle_vector`.

    Parameters
    ----------
    m, sigma_m : ndarray, shape (3, 3)
        The measured ``M`` and its 1-sigma (NaN: unknown, giving NaN sigmas).
    mounting : ndarray, shape (3, 3), optional
        Nominal mounting ``N`` (rows: gyro axes in the system frame); the identity when None.

    Returns
    -------
    dict of str -> float
        :data:`ANGLE_NAMES` -> 1-sigma, rad.
    """
    n = np.eye(3) if mounting is None else np.asarray(mounting, float)
    m = np.asarray(m, float)
    h = 1e-7
    jac = np.zeros((len(ANGLE_NAMES), 9))
    for k in range(9):
        flat = np.zeros(9)
        flat[k] = h
        d = flat.reshape(3, 3)
        jac[:, k] = (angle_vector((m + d) @ n.T) - angle_vector((m - d) @ n.T)) / (2 * h)
    var = (jac**2) @ np.square(np.asarray(sigma_m, float)).ravel()
    return dict(zip(ANGLE_NAMES, np.sqrt(var).tolist()))


def figures_from(values: dict, sensor: str, *, test: str = "", method: str = "", counts: bool = False) -> tuple:
    """The :class:`~align.merit.Figure` of every figure of ``values`` (``{name: value, name_sigma: 1-sigma}``, SI).

    Parameters
    ----------
    values : dict
        Figures by name (:data:`KIND`), their 1-sigma under ``name_sigma``; names this vocabulary does not know
        are left out.
    sensor : str
    test, method : str
        The test (job) and the method the figures came from.
    counts : bool
        A calibration in counts: the readings and the scale are in counts (the figure's unit ``"count"``).

    Returns
    -------
    tuple of Figure
        In ``values``' order, ``_sigma`` entries folded into their figure.
    """
    from align.merit import Figure

    out = []
    for name, value in values.items():
        if name.endswith("_sigma") or name not in KIND:
            continue
        unit = "count" if counts and (KIND[name] == "reading" or name.startswith("scale_")) else \
            (si_unit(name, sensor) or "1")
        out.append(Figure(name, sensor, float(value), float(values.get(f"{name}_sigma", np.nan)), unit, title(name),
                          method, test))
    return tuple(out)
