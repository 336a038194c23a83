"""Magnetometer hard- and soft-iron calibration from tumbling data (seed 004), with gates.

Hard iron ``h`` (an offset) and soft iron turn the sphere ``|m| = F`` of the
field into an ellipsoid; the calibration maps it back:
``m_cal = W (m_raw - h)`` with ``W`` symmetric positive definite (``soft_iron``).

Steps: centre and scale the data (conditioning only); fit the ellipsoid
algebraically (:mod:`align.calibration.ellipsoid`: Li and Griffiths 2004,
ellipsoid-specific ``4J - I^2 = 1``, or a sphere, or an axis-aligned ellipsoid);
refine ``h`` and ``W`` geometrically to a known field strength or to the fitted
one (``det W = 1`` scale), by the first-order distance of each reading from the
ellipsoid in the readings' own space (:func:`~align.calibration.ellipsoid.sampson`).
Minimising ``sum (|W (m - h)| - F)^2`` instead, as before version 2, is biased on
partial coverage: that residual's noise gain ``|W y| / |y|`` depends on ``W``,
and the fit shrinks it along the poorly covered direction, an error of order
``sigma^2`` that does not fall with more samples (on simulated hemisphere
captures at 1 % noise the hard iron fell inside its 3-sigma 75 % of the time).
The 1-sigma of ``h`` and ``W`` (``covariance``) is the refinement's Gauss-Newton
covariance scaled by the residual variance, carried through the ``det W = 1``
scaling. Gates refuse, with a clear message, data that cannot give a trustworthy answer:
too few samples, planar or clustered captures (the hard iron's 1-sigma from the
refinement exceeds 2 % of the field), a quadric that is not an ellipsoid, a
reflected solution. With simultaneous accelerometer data,
:func:`with_gravity_alignment` (:mod:`align.calibration.gravityalign`, re-exported here) adds the rotation to
the accelerometer frame;
:func:`align.calibration.axisdown.with_axis_down` the rotation to the body axes
from axis-down turns (seed 004).
:class:`MagCalibration` is the registered result ``imu-align.magnetometer``.

Public names
------------
MagCalibration, calibrate_magnetometer, with_gravity_alignment, alignment_to_gravity (both re-exported from
:mod:`align.calibration.gravityalign`), misalignment_from_axes_down,
MODELS, FORMAT, CONVENTION, ANGLES_ARE, COVARIANCE_IS
"""

from __future__ import annotations

from dataclasses import field as dataclass_field

import numpy as np

from align.calibration.ellipsoid import MODELS, algebraic_fit, full_params, refine, unpack
from align.calibration.gravityalign import alignment_to_gravity, dip_from_accelerometer, with_gravity_alignment
from align.errors import InputError, TestError, literal
from align.io import check_finite
from align.plausible import check_dip, check_field_strength, check_known_field, check_positive_definite
from align.results import Result, file_unit
from align.units import DEG, to_unit
from align.wellformed import array_field, malformed

FORMAT = "imu-align.magnetometer"
CONVENTION = "m_cal = soft_iron (m_raw - hard_iron)"
#: the keys of a magnetometer file after the envelope (unknown keys are refused: a misspelled key is not ignored)
FILE_KEYS = ("sensor", "model", "hard_iron", "soft_iron", "field", "uncertainty", "quality", "notes", "misalignment",
             "misalignment_convention", "misalignment_method", "misalignment_angles", "inputs")
#: what the rotation angles of ``misalignment`` are (``angles_deg`` in the file)
ANGLES_ARE = ("rotation vector of misalignment (alpha, beta, gamma about x, y, z): the magnetometer's calibrated axes "
              "turned by it from the body axes, m_cal ~ [[1, gamma, -beta], [-gamma, 1, alpha], [beta, -alpha, 1]] m_body")
COVARIANCE_IS = ("covariance of (hard_iron x, y, z; soft_iron xx, xy, xz, yy, yz, zz), hard iron in the file's unit")


class MagCalibration(Result, format=FORMAT, convention=CONVENTION, version=2):
    """A magnetometer calibration, ``m_cal = soft_iron (m_raw - hard_iron)``.

    Attributes
    ----------
    hard_iron, sigma_hard_iron : ndarray, shape (3,)
        Offset and its 1-sigma, SI (tesla) or counts.
    soft_iron : ndarray, shape (3, 3)
        Symmetric positive definite ``W``, dimensionless.
    field : float
        Field strength after calibration, same unit as ``hard_iron``.
    model : str
        One of :data:`MODELS`.
    units : str
        File and display unit of the readings (``"uT"``, ``"gauss"``, ``"counts"``).
    spread_before, spread_after : float
        ``std(|m|) / mean(|m|)`` of the raw and calibrated readings.
    coverage : float
        Smallest eigenvalue of ``mean(u u^T)`` of the calibrated directions (1/3 for a full sphere).
    heading_error : float
        Predicted heading error, rad (1 sigma).
    dip : float or None
        Magnetic dip used for the prediction, rad.
    notes : tuple of str
    misalignment : ndarray, shape (3, 3), optional
        Rotation to the body (accelerometer or fixture) frame: ``m_body = misalignment m_cal``.
    inputs : dict
        The files and settings the calibration came from.
    covariance : ndarray, shape (9, 9), optional
        Covariance of ``(hard_iron, soft_iron upper triangle)`` (:data:`~align.calibration.ellipsoid.FULL`),
        SI (or counts) squared for the hard iron; absent in files written before version 2.
    misalignment_method : str, optional
        How ``misalignment`` was found (``"gravity"``, ``"axis-down"``); None in older files.
    sigma_misalignment : ndarray, shape (3,), optional
        1-sigma of the rotation angles of ``misalignment`` (:attr:`misalignment_angles`), rad.
    """

    hard_iron: np.ndarray
    soft_iron: np.ndarray
    field: float
    model: str
    units: str
    sigma_hard_iron: np.ndarray
    spread_before: float
    spread_after: float
    coverage: float
    heading_error: float
    dip: float | None
    notes: tuple = ()
    misalignment: np.ndarray | None = None
    inputs: dict = dataclass_field(default_factory=dict)
    covariance: np.ndarray | None = None
    misalignment_method: str | None = None
    sigma_misalignment: np.ndarray | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "notes", tuple(self.notes))
        object.__setattr__(self, "inputs", dict(self.inputs))

    @property
    def sensor(self) -> str:
        """The sensor this result corrects: always ``"magnetometer"``."""
        return "magnetometer"

    @property
    def sigma_soft_iron(self) -> np.ndarray | None:
        """1-sigma of each element of ``soft_iron``, shape (3, 3), from :attr:`covariance` (None without it)."""
        if self.covariance is None:
            return None
        sd = np.sqrt(np.diag(self.covariance)[3:])
        out = np.zeros((3, 3))
        out[np.triu_indices(3)] = sd
        return out + np.triu(out, 1).T

    @property
    def misalignment_angles(self) -> np.ndarray | None:
        """Rotation vector of ``misalignment`` (alpha, beta, gamma about x, y, z), rad (:data:`ANGLES_ARE`)."""
        if self.misalignment is None:
            return None
        from scipy.spatial.transform import Rotation

        u, _, vt = np.linalg.svd(self.misalignment)  # the nearest rotation (the matrix is one up to rounding)
        return Rotation.from_matrix(u @ vt).as_rotvec()

    @property
    def correcting(self) -> np.ndarray:
        """The whole correcting matrix, dimensionless, shape (3, 3): ``misalignment soft_iron`` (``soft_iron``
        without a misalignment), so that ``m = correcting (m_raw - hard_iron)`` in the body frame."""
        return self.soft_iron if self.misalignment is None else self.misalignment @ self.soft_iron

    @property
    def model_matrix(self) -> np.ndarray:
        """``M = correcting^-1`` of the model ``m_raw = M m + hard_iron`` (rows: the magnetometer axes), shape (3, 3)."""
        return np.linalg.inv(self.correcting)

    def correction(self, sensor: str | None = None, where: str = "magnetometer") -> MagCalibration:
        """This calibration, which corrects magnetometer logs (see :class:`align.results.Correction`).

        Refuses (naming ``where``) a soft iron that is not finite, singular, ``det <= 0`` or not
        positive definite (:func:`align.plausible.check_positive_definite`).
        """
        self._only_sensor("magnetometer", sensor, where, "soft_iron")
        check_positive_definite(self.soft_iron, where)
        return self

    def correct(self, raw: np.ndarray) -> np.ndarray:
        """``m_cal = W (raw - h)`` for readings of shape (n, 3), SI or counts."""
        return (np.asarray(raw) - self.hard_iron) @ self.soft_iron.T

    def figures_of_merit(self) -> tuple:
        """``M = soft_iron^-1`` and its decomposition (their 1-sigma from :attr:`covariance` by ``dM = -M dW M`` when
        the file has it), the hard iron with its 1-sigma, the field, coverage, heading error and spread
        (:mod:`align.keyfigures`)."""
        from align.keyfigures import figures_from, matrix_figures, vector_figures

        m = np.linalg.inv(np.asarray(self.soft_iron, float))
        sigma_m = None
        if self.covariance is not None:  # dM = -M dW M over the upper triangle of W (FULL's order), first order
            jac = []
            for k, c in ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)):
                dw = np.zeros((3, 3))
                dw[k, c] = dw[c, k] = 1.0
                jac.append((-m @ dw @ m).ravel())
            j = np.array(jac).T                                                  # (9, 6)
            sigma_m = np.sqrt(np.clip(np.diag(j @ np.asarray(self.covariance)[3:, 3:] @ j.T), 0, None)).reshape(3, 3)
        values = (matrix_figures(m, sigma_m, angle_sigmas_too=True)
                  | vector_figures("bias", self.hard_iron, self.sigma_hard_iron)
                  | {"field": float(self.field), "coverage": float(self.coverage),
                     "heading_error": float(self.heading_error), "spread": float(self.spread_after)})
        return figures_from(values, "magnetometer", method=f"ellipsoid fit ({self.model})",
                            counts=self.units.strip().lower() in ("count", "counts"))

    def to_dict(self) -> dict:
        """The versioned JSON form: field quantities in ``self.units``, angles in deg."""
        u = self.units
        d = {
            **self.envelope({"hard_iron": u, "field": u, "soft_iron": "1", "angles": "deg"}),
            "sensor": "magnetometer", "model": self.model,
            "hard_iron": to_unit(self.hard_iron, u).tolist(), "soft_iron": self.soft_iron.tolist(),
            "field": float(to_unit(self.field, u)),
            "uncertainty": {"level": "1 sigma", "hard_iron": to_unit(self.sigma_hard_iron, u).tolist()},
            "quality": {"field_spread_before": self.spread_before, "field_spread_after": self.spread_after,
                        "spread_is": "std(|m|) / mean(|m|)", "coverage": self.coverage,
                        "coverage_is": "smallest eigenvalue of mean(u u^T) of the calibrated directions (1/3 for a full sphere)",
                        "predicted_heading_error_deg": self.heading_error / DEG,
                        "dip_deg": None if self.dip is None else self.dip / DEG},
            "notes": list(self.notes),
        }
        if self.covariance is not None:
            k = np.r_[np.full(3, to_unit(1.0, u)), np.ones(6)]
            sigma_soft = self.sigma_soft_iron
            assert sigma_soft is not None  # given with the covariance
            d["uncertainty"]["soft_iron"] = sigma_soft.tolist()
            d["uncertainty"]["covariance"] = (self.covariance * np.outer(k, k)).tolist()
            d["uncertainty"]["covariance_is"] = COVARIANCE_IS
        if self.misalignment is not None:
            angles = self.misalignment_angles
            assert angles is not None  # given with the misalignment
            d["misalignment"] = self.misalignment.tolist()
            d["misalignment_convention"] = "m_body = misalignment m_cal"
            d["misalignment_method"] = self.misalignment_method
            d["misalignment_angles"] = {
                "angles_deg": (angles / DEG).tolist(),
                "sigma_deg": None if self.sigma_misalignment is None else (self.sigma_misalignment / DEG).tolist(),
                "angles_are": ANGLES_ARE}
        d["inputs"] = self.inputs
        return d

    @classmethod
    def from_dict(cls, d: dict, where: str = "magnetometer") -> MagCalibration:
        """Read the form written by :meth:`to_dict` (any version up to the current one)."""
        cls.check_envelope(d, where, keys=FILE_KEYS)
        try:
            u, f = file_unit(d, "hard_iron", None, where)
            q = d["quality"]
            mis = d.get("misalignment")
            what = "magnetometer calibration"
            hard, soft = array_field(d, "hard_iron", (3,), what, where, f), array_field(d, "soft_iron", (3, 3), what, where)
            mis = None if mis is None else array_field(d, "misalignment", (3, 3), what, where)
            unc, angles = d["uncertainty"], d.get("misalignment_angles") or {}
            if not isinstance(unc, dict) or not isinstance(angles, dict):
                raise ValueError("uncertainty and misalignment_angles must be objects")
            cov = None
            if "covariance" in unc:
                k = np.r_[np.full(3, f), np.ones(6)]
                cov = array_field(unc, "covariance", (9, 9), what, where) * np.outer(k, k)
            sig_mis = angles.get("sigma_deg")
            sig_mis = None if sig_mis is None else array_field(angles, "sigma_deg", (3,), what, where, DEG)
            return cls(
                hard_iron=hard, soft_iron=soft,
                field=float(d["field"]) * f, model=d["model"], units=u,
                sigma_hard_iron=np.array(d["uncertainty"]["hard_iron"], float).reshape(3) * f,
                spread_before=q["field_spread_before"], spread_after=q["field_spread_after"], coverage=q["coverage"],
                heading_error=q["predicted_heading_error_deg"] * DEG,
                dip=None if q["dip_deg"] is None else q["dip_deg"] * DEG,
                notes=tuple(d.get("notes", [])),
                misalignment=mis,
                inputs=dict(d.get("inputs") or {}),
                covariance=cov, misalignment_method=d.get("misalignment_method"), sigma_misalignment=sig_mis,
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"malformed magnetometer calibration ({malformed(exc)}); regenerate it", where) from None


def calibrate_magnetometer(m: np.ndarray, units: str = "uT", field: float | None = None, model: str = "symmetric",
                           acc: np.ndarray | None = None, dip: float | None = None,
                           max_hard_iron_sigma: float = 0.02, where: str = "magnetometer") -> MagCalibration:
    """Hard and soft iron from a tumbling capture (see module docstring).

    Parameters
    ----------
    m : ndarray, shape (n, 3)
        Raw readings, SI (tesla) or counts.
    units : str
        Unit of the readings, for the result's file form (``"uT"``, ``"counts"``).
    field : float, optional
        Known field strength (same unit as ``m``); otherwise the fitted one (``det W = 1``).
    model : {"sphere", "diagonal", "symmetric"}
    acc : ndarray, shape (n, 3), optional
        Simultaneous accelerometer readings: give the dip angle for the heading-error prediction.
    dip : float, optional
        Magnetic dip (rad) when no accelerometer is given; default 60 deg, said in the notes.
    max_hard_iron_sigma : float
        Refuse when the hard iron's 1-sigma exceeds this fraction of the field.
    where : str
        The capture (its file name), for errors.

    Returns
    -------
    MagCalibration
        ``m_cal = W (m_raw - h)`` (seed 004, the sphere ``|m_cal| = F``): ``hard_iron`` ``h`` (3,) and ``field``
        ``F`` in the unit of ``m``, ``soft_iron`` ``W`` (3, 3) dimensionless, ``heading_error`` rad.

    Raises
    ------
    TestError
        The capture cannot give a trustworthy answer (planar, poor coverage, not an ellipsoid), or its
        field strength is not Earth's in ``units`` (a unit mix-up, named with its fix ``{units=gauss}``).
    InputError
        Not three columns, NaN rows, too few samples, a known ``field`` that is not Earth's,
        a ``dip`` outside [-90, 90] deg.

    Examples
    --------
    A 48 uT field on a sphere offset by a hard iron of (10, -5, 3) uT:

    >>> import numpy as np
    >>> v = np.random.default_rng(3).normal(size=(600, 3))
    >>> m = (48.0 * v / np.linalg.norm(v, axis=1)[:, None] + [10.0, -5.0, 3.0]) * 1e-6
    >>> cal = calibrate_magnetometer(m)
    >>> np.round(np.asarray(cal.hard_iron) * 1e6, 3).tolist()
    [10.0, -5.0, 3.0]
    """
    if model not in MODELS:
        raise InputError(f"unknown model '{literal(model)}'; choose {', '.join(MODELS)}", "{model}")
    if dip is not None:
        dip = check_dip(dip)
    m = np.asarray(m, float)
    if m.ndim != 2 or m.shape[1] != 3:
        raise InputError(f"a magnetometer capture has 3 columns (x, y, z), not {m.shape[-1] if m.ndim else 0}; "
                         "give three {columns}", where)
    if acc is not None and np.shape(acc) != m.shape:
        raise InputError(f"the accelerometer needs 3 columns and one row per magnetometer row, not {np.shape(acc)}; "
                         "give three {accel_columns}", where)
    check_finite(m, where)
    n_par = {"sphere": 4, "diagonal": 6, "symmetric": 9}[model]
    if len(m) < 3 * n_par:
        raise InputError(f"only {len(m)} samples; the {model} model needs at least {3 * n_par}", where)
    # centre and scale (conditioning only; the hard iron comes from the fit, not from the sample mean)
    c0 = 0.5 * (m.min(axis=0) + m.max(axis=0))
    s0 = float(np.sqrt(np.mean(np.sum((m - c0) ** 2, axis=1))))
    if not s0 > 0:
        raise TestError("all samples are equal: the sensor did not move", where)
    x = (m - c0) / s0
    sv = np.linalg.svd(x - x.mean(axis=0), compute_uv=False)
    if sv[2] < 0.15 * sv[0]:
        raise TestError(f"planar or near-level capture: the samples barely leave a plane (thickness {sv[2] / sv[0]:.2f} of "
                        "their width); tilt the device through all orientations (a figure-eight in every direction)",
                        where)
    try:
        centre, w = algebraic_fit(x, model)
    except TestError as exc:
        raise TestError(exc.message, where) from None
    strength = s0 / float(np.linalg.det(w)) ** (1 / 3)  # the readings' own field: the ellipsoid's mean radius
    check_field_strength(strength, units, where=where)
    if field is not None:
        check_known_field(field, strength, units)
    target = None if field is None else field / s0
    p, cov_p, _, at_bound = refine(x, centre, w, model, target)
    if at_bound:
        raise TestError("coverage too small: the fit runs away along the poorly covered direction (the geometric "
                        "refinement reached its bound); rotate the device through more orientations", where)
    notes_refine = ("geometric refinement (Sampson distance: first-order distance of each reading from the "
                    "ellipsoid) from the algebraic Li-Griffiths fit; 1-sigma from its Gauss-Newton covariance "
                    "scaled by the residual variance")
    if not np.linalg.det(unpack(p[3:], model)) > 0:
        raise TestError("the fit came out reflected or singular (det <= 0)", where)

    def final(q):  # (hard iron SI, upper triangle of W) from the normalised parameters
        wq = unpack(q[3:], model)
        if target is None:  # the fitted field: W scaled to unit determinant, |m_cal| is then the field
            wq = wq / np.linalg.det(wq) ** (1 / 3)
        return full_params(c0 + q[:3] * s0, wq)

    step = np.array([1e-6 * max(1.0, abs(v)) for v in p])
    t_jac = np.column_stack([(final(p + dv) - final(p - dv)) / (2 * dv[k]) for k, dv in enumerate(np.diag(step))])
    cov = t_jac @ cov_p @ t_jac.T
    hard, w = c0 + p[:3] * s0, unpack(final(p)[3:], "symmetric")
    field_si = s0 / np.linalg.det(unpack(p[3:], model)) ** (1 / 3) if field is None else field  # target None: field None
    if not np.all(np.linalg.eigvalsh(w) > 0) or np.linalg.det(w) <= 0:
        raise TestError("the soft-iron matrix is not positive definite (a reflected or degenerate solution); "
                        "the capture does not determine it", where)
    sig_c = np.sqrt(np.diag(cov)[:3])
    cal = (m - hard) @ w.T
    norms = np.linalg.norm(cal, axis=1)
    u = cal / norms[:, None]
    coverage = float(np.linalg.eigvalsh(u.T @ u / len(u))[0])
    size = min(field_si, s0)  # a runaway fit inflates the fitted field; the data's own radius does not
    if np.max(sig_c) > max_hard_iron_sigma * size or coverage < 0.05:
        raise TestError(f"coverage too small: the hard iron is uncertain by {to_unit(np.max(sig_c), units):.3g} {units} "
                        f"(limit {100 * max_hard_iron_sigma:g} % of the field) and the calibrated directions cover "
                        f"{coverage:.3f} (0.333 for a full sphere); rotate the device through more orientations",
                        where)
    raw_norm = np.linalg.norm(m, axis=1)
    notes = [f"{model} model, {len(m)} samples; " + ("field fixed at the value given" if field is not None else
                                                      "field fitted (soft iron scaled to unit determinant)"), notes_refine]
    if acc is not None:
        dip, note = dip_from_accelerometer(u, acc)
        notes.append(note)
    elif dip is None:
        dip = 60 * DEG
        notes.append("dip not measured: heading error predicted for 60 deg (mid latitudes); "
                     "give accelerometer data for the real one")
    horizontal = field_si * np.cos(dip)
    heading = float(np.arctan2(np.std(norms - field_si), horizontal))
    notes.append("predicted heading error: the residual field-magnitude scatter seen across the horizontal field (1 sigma)")
    return MagCalibration(hard, w * 1.0, field_si, model, units, sig_c, float(np.std(raw_norm) / np.mean(raw_norm)),
                          float(np.std(norms) / np.mean(norms)), coverage, heading, dip, tuple(notes), covariance=cov)


def misalignment_from_axes_down(down: dict) -> np.ndarray:
    """Seed 004: rows are the normalised mean calibrated field with the x, y, z axes pointing down in turn.

    ``down`` maps ``"x"``, ``"y"``, ``"z"`` to a mean vector (3,) over a full turn about that (downward)
    axis. This is the seed's equation as written, valid where the field points down (northern
    hemisphere) and for headings spread evenly over a full turn; the command uses
    :func:`align.calibration.axisdown.with_axis_down`, which fits each turn's plane instead and
    gives the uncertainty.
    """
    rows = [np.asarray(down[a], float) for a in "xyz"]
    return np.array([r / np.linalg.norm(r) for r in rows])


__all__ = ["MagCalibration", "calibrate_magnetometer", "with_gravity_alignment", "alignment_to_gravity",
           "misalignment_from_axes_down", "MODELS", "FORMAT", "CONVENTION", "ANGLES_ARE", "COVARIANCE_IS"]
