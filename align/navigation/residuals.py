"""The residual sensor errors a navigation mission is run with: what is left after compensation.

For each sensor (gyroscope, accelerometer) and axis, the model of the compensated reading is::

    y = (I + dM) x + b + r t + n_white + n_flicker + n_walk                           (R1)

with ``x`` the true rate (specific force), ``dM`` the residual scale (diagonal) and misalignment
(off-diagonal) error, ``b`` the residual turn-on bias, ``r`` a rate ramp, and the noise of the
IEEE five-term model (reference section 6): white (``N``, angle/velocity random walk), flicker
(bias instability ``B``, PSD ``B^2 / (pi f)``), random walk (``K``). Every term is zero-mean
and drawn per run: ``b ~ N(0, sigma_b^2)``, ``dM_ij ~ N(0, sigma_M,ij^2)``, ``r ~ N(0, R^2)``.

A mounting budget (the angle ``P_i`` between each axis of the IMU and its system axis; its per-axis
RSS, taken as the **rms** angle, i.e. a 1-sigma figure of a zero-mean draw) is one of two things
(:data:`MOUNT_ERRORS`):

* ``"attitude"`` (default): the whole IMU (gyros and accelerometers together) is turned by a rigid
  rotation ``r`` relative to the vehicle, ``r_k ~ N(0, s_k^2)`` about body axis ``k``, with ``s``
  chosen so that each axis' rms misalignment is the budget's (an axis moves by the rotations about
  the other two: ``P_x^2 = s_y^2 + s_z^2``, ...)::

      s_x^2 = (P_y^2 + P_z^2 - P_x^2) / 2,  s_y^2 = (P_x^2 + P_z^2 - P_y^2) / 2,
      s_z^2 = (P_x^2 + P_y^2 - P_z^2) / 2                                              (R2)

  With the initial attitude taken as the vehicle's, this is an **initial attitude error** of the
  navigation (``ResidualErrors.mount``): a tilt ``eps`` puts ``g eps`` into the horizontal channels
  from ``t = 0`` (velocity ``g eps t``, position ``g eps t^2 / 2``), a heading error stays constant;
* ``"turns"``: the initial attitude is aligned in place by the IMU itself (levelled by its own
  accelerometers), which absorbs a rigid rotation; what is left is the gyro axes' misalignment
  relative to that frame (``SensorErrors.tilt``: axis ``i`` leans by ``theta_i = P_i`` rms in a
  random direction, ``dM_ij, dM_ik ~ N(0, theta_i^2 / 2)``). It acts only through the body's turns
  (and the Earth rate): a static mission costs nothing from it.

Where each figure comes from (:func:`residual_errors`):

* an ``allan`` result: ``N, B, K, R`` of the fit of each channel (quantization is left out: its
  angle error stays bounded); with several runs, the run-to-run repeatability is the turn-on bias;
* an ``alignment`` or ``calibrate`` result: ``sigma_M`` and ``sigma_bias``, the estimate's
  uncertainty, is the residual after it is applied. With ``raw = M x + b`` corrected by
  ``x^ = M^-1 (raw - b^)``, errors ``dM, db`` of the estimate leave ``x^ = (I - A dM) x - A db``
  (``A = M^-1``): the residual scale and misalignment is ``A dM`` (relative, whatever the unit of
  ``M``: dimensionless or counts per SI unit) and the residual bias ``A db`` in SI::

      sigma(A dM)_ij^2 = sum_k A_ik^2 sigma_M,kj^2,   sigma(A db)_i^2 = sum_k A_ik^2 sigma_b,k^2   (R3)

  (the estimate's correlations are not in the file: left out);
* a mounting budget: R2, as above;
* a datasheet preset: angle random walk (or noise density) and bias instability ``B`` (as the
  preset table and the planner read it: :attr:`align.parts.Part.bias_instability`);
* stated figures: a residual bias of each sensor.

Public names
------------
SensorErrors, ResidualErrors, residual_errors, mount_rotation, TERM_KEYS, MOUNT_ERRORS, label
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from align.errors import InputError
from align.units import to_unit
from align.values import Value, frozen_array

#: the error terms of one sensor, in the order of every table
TERM_KEYS = ("bias", "matrix", "tilt", "white", "flicker", "random_walk", "ramp")
_LABELS = {
    "gyroscope": {"bias": "gyro bias", "matrix": "gyro scale and misalignment", "tilt": "gyro mounting misalignment",
                  "white": "angle random walk", "flicker": "gyro bias instability", "random_walk": "rate random walk",
                  "ramp": "rate ramp"},
    "accelerometer": {"bias": "accel bias", "matrix": "accel scale and misalignment",
                      "tilt": "accel mounting misalignment", "white": "velocity random walk",
                      "flicker": "accel bias instability", "random_walk": "acceleration random walk",
                      "ramp": "acceleration ramp"},
    "imu": {"mount": "IMU mounting rotation (initial attitude error)"},
}
#: what a mounting budget's angles are taken as (module docstring)
MOUNT_ERRORS = ("attitude", "turns")
#: display units of each term in a file: (gyroscope, accelerometer)
UNITS = {"bias": ("deg/h", "ug"), "matrix": ("ppm", "ppm"), "tilt": ("deg", "deg"),
         "white": ("deg/sqrt(h)", "m/s/sqrt(h)"), "flicker": ("deg/h", "ug"),
         "random_walk": ("deg/h/sqrt(h)", "ug/sqrt(h)"), "ramp": ("deg/h^2", "ug/h"), "mount": ("deg", "deg")}


def label(sensor: str, term: str) -> str:
    """The name of a term as the report says it, e.g. ``angle random walk``."""
    return _LABELS[sensor][term]


def _unit(sensor: str, term: str) -> str:
    return UNITS[term][0 if sensor == "gyroscope" else 1]


@dataclass(frozen=True, eq=False)
class SensorErrors(Value):
    """Residual errors of one sensor triad (R1), SI, 1-sigma of zero-mean draws.

    Attributes
    ----------
    sensor : str
        ``"gyroscope"`` (rad/s) or ``"accelerometer"`` (m/s^2).
    bias : ndarray, shape (3,)
        Turn-on bias.
    matrix : ndarray, shape (3, 3)
        1-sigma of each element of ``dM`` (dimensionless).
    tilt : ndarray, shape (3,)
        rms misalignment angle of each axis, in a random direction (rad): ``dM_ij, dM_ik ~ N(0, tilt_i^2 / 2)``.
    white, flicker, random_walk, ramp : ndarray, shape (3,)
        ``N`` (rad/sqrt(s), m/s/sqrt(s)), ``B`` (rad/s, m/s^2), ``K`` (rad/s/sqrt(s), m/s^2/sqrt(s)),
        ``R`` (rad/s^2, m/s^3).
    sources : dict
        Term -> where its figures come from.
    """

    sensor: str
    bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    matrix: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    tilt: np.ndarray = field(default_factory=lambda: np.zeros(3))
    white: np.ndarray = field(default_factory=lambda: np.zeros(3))
    flicker: np.ndarray = field(default_factory=lambda: np.zeros(3))
    random_walk: np.ndarray = field(default_factory=lambda: np.zeros(3))
    ramp: np.ndarray = field(default_factory=lambda: np.zeros(3))
    sources: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in TERM_KEYS:
            shape = (3, 3) if name == "matrix" else (3,)
            value = np.broadcast_to(np.nan_to_num(np.asarray(getattr(self, name), float)), shape)
            if np.any(value < 0):
                raise InputError(f"a residual {label(self.sensor, name)} must be >= 0", label(self.sensor, name))
            object.__setattr__(self, name, frozen_array(value))
        object.__setattr__(self, "sources", dict(self.sources))
        super().__post_init__()

    def active(self) -> tuple[str, ...]:
        """The terms with a non-zero figure."""
        return tuple(k for k in TERM_KEYS if np.any(getattr(self, k) > 0))

    def only(self, term: str | None) -> SensorErrors:
        """These errors with every term but ``term`` set to zero (None: all zero)."""
        zero: dict[str, Any] = {k: np.zeros((3, 3) if k == "matrix" else 3) for k in TERM_KEYS if k != term}
        return replace(self, **zero)

    def to_dict(self) -> dict:
        """Engineering units (:data:`UNITS`), with the source of each term (null: not given, zero)."""
        out = {}
        for k in TERM_KEYS:
            unit = _unit(self.sensor, k)
            v = getattr(self, k) * (1e6 if unit == "ppm" else 1.0)
            out[k] = {"label": label(self.sensor, k), "unit": unit,
                      "value": (v if unit == "ppm" else to_unit(v, unit)).tolist(),
                      "source": self.sources.get(k)}
        return out

    @classmethod
    def from_dict(cls, sensor: str, d: dict) -> SensorErrors:
        """Read :meth:`to_dict`'s form."""
        from align.units import parse_unit

        values = {}
        for k in TERM_KEYS:
            unit = d[k]["unit"]
            factor = 1e-6 if unit == "ppm" else parse_unit(unit).factor
            values[k] = np.array(d[k]["value"], float) * factor
        return cls(sensor, **values, sources={k: d[k]["source"] for k in TERM_KEYS if d[k].get("source")})


@dataclass(frozen=True, eq=False)
class ResidualErrors(Value):
    """The residual errors of both sensors, and the rigid mounting rotation of the whole IMU.

    Attributes
    ----------
    gyro, accel : SensorErrors
    mount : ndarray, shape (3,)
        1-sigma of the IMU's rotation about body x, y, z relative to the vehicle (rad): the initial
        attitude error common to both sensors (module docstring, R2).
    mount_source : str
        Where ``mount`` comes from.
    """

    gyro: SensorErrors = field(default_factory=lambda: SensorErrors("gyroscope"))
    accel: SensorErrors = field(default_factory=lambda: SensorErrors("accelerometer"))
    mount: np.ndarray = field(default_factory=lambda: np.zeros(3))
    mount_source: str = ""

    def __post_init__(self) -> None:
        mount = np.broadcast_to(np.nan_to_num(np.asarray(self.mount, float)), (3,))
        if np.any(mount < 0):
            raise InputError(f"a residual {label('imu', 'mount')} must be >= 0", label("imu", "mount"))
        object.__setattr__(self, "mount", frozen_array(mount))
        super().__post_init__()

    def terms(self) -> list[tuple[str, str]]:
        """``(sensor, term)`` of every non-zero term (``("imu", "mount")`` for the mounting rotation)."""
        out = [(s.sensor, k) for s in (self.gyro, self.accel) for k in s.active()]
        return out + ([("imu", "mount")] if np.any(self.mount > 0) else [])

    def only(self, sensor: str, term: str) -> ResidualErrors:
        """Only one term of one sensor (the others zero): for a one-term Monte Carlo."""
        return ResidualErrors(self.gyro.only(term if sensor == "gyroscope" else None),
                              self.accel.only(term if sensor == "accelerometer" else None),
                              self.mount if sensor == "imu" else np.zeros(3), self.mount_source)

    def to_dict(self) -> dict:
        return {"gyroscope": self.gyro.to_dict(), "accelerometer": self.accel.to_dict(),
                "imu": {"mount": {"label": label("imu", "mount"), "unit": "deg", "value": to_unit(self.mount, "deg").tolist(),
                                  "source": self.mount_source or None}}}

    @classmethod
    def from_dict(cls, d: dict) -> ResidualErrors:
        mount = d.get("imu", {}).get("mount", {"value": [0.0] * 3, "unit": "deg"})  # absent in the first files
        from align.units import parse_unit

        return cls(SensorErrors.from_dict("gyroscope", d["gyroscope"]),
                   SensorErrors.from_dict("accelerometer", d["accelerometer"]),
                   np.array(mount["value"], float) * parse_unit(mount["unit"]).factor, mount.get("source") or "")


def mount_rotation(per_axis) -> tuple[np.ndarray, bool]:
    """The 1-sigma rotation about x, y, z (rad) whose rms axis misalignments are ``per_axis`` (rad) (R2).

    Returns
    -------
    s : ndarray, shape (3,)
    clipped : bool
        A square came out negative (one axis' figure exceeds the other two's RSS: no rigid rotation
        gives it) and was set to zero.
    """
    p2 = np.asarray(per_axis, float) ** 2
    s2 = (p2.sum() - 2 * p2) / 2
    return np.sqrt(np.clip(s2, 0.0, None)), bool(np.any(s2 < 0))


def _three(values, what: str, where: str) -> np.ndarray:
    v = np.asarray(values, float).reshape(-1)
    if v.size == 1:
        return np.repeat(v, 3)
    if v.size != 3:
        raise InputError(f"{what}: expected 3 axes (x, y, z), got {v.size} channels", where)
    return v


def _from_allan(job, where: str) -> tuple[str, dict, dict]:
    """Noise terms (and the repeatability as a turn-on bias) of an Allan result."""
    sensor = job.sensor
    params = np.array([f.params for f in job.fits], float)  # (C, 5): Q, N, B, K, R
    if params.shape[0] != 3:
        raise InputError(f"holds {params.shape[0]} channels; the navigation needs the three axes x, y, z of one sensor",
                         where)
    name = ", ".join(job.inputs) or "allan"
    values = {"white": params[:, 1], "flicker": params[:, 2], "random_walk": params[:, 3], "ramp": params[:, 4]}
    zero = [label(sensor, k) for k, v in values.items() if not np.any(v > 0)]
    note = f"fit of {where} ({name})" + (f"; fitted as zero: {', '.join(zero)}" if zero else "")
    sources = {k: note for k in values}
    if job.repeatability is not None and np.all(np.isfinite(job.repeatability)):
        values["bias"] = np.asarray(job.repeatability, float)
        sources["bias"] = f"run-to-run repeatability of {where} ({job.runs} runs)"
    return sensor, values, sources


def _from_correction(result, where: str) -> dict[str, tuple[dict, dict]]:
    """``sigma_M`` and ``sigma_bias`` of an alignment (gyro) or a calibration set (each sensor)."""
    found = {}
    cals = result.sensors.items() if hasattr(result, "sensors") else [(result.sensor, result)]
    for sensor, cal in cals:
        sm, sb = np.asarray(cal.sigma_M, float), np.asarray(cal.sigma_bias, float)
        if not (np.all(np.isfinite(sm)) and np.all(np.isfinite(sb))):
            raise InputError(f"its {sensor} result states no uncertainty (sigma of M and bias); "
                             "the residual errors come from it: regenerate it", where)
        m = np.asarray(cal.M, float)
        if not (np.all(np.isfinite(m)) and abs(np.linalg.det(m)) > 0):
            raise InputError(f"its {sensor} M is singular; regenerate it", where)
        a2 = np.linalg.inv(m) ** 2
        units = getattr(cal, "units", "")
        note = (f"1-sigma of the {sensor} estimate in {where}, through M^-1 (relative scale and misalignment, "
                f"bias in SI{'; M in counts' if units == 'counts' else ''})")
        found[sensor] = ({"matrix": np.sqrt(a2 @ sm**2), "bias": np.sqrt(a2 @ sb**2)}, {"matrix": note, "bias": note})
    return found


def residual_errors(allan=(), correction=None, budget=None, part=None, gyro_bias: float | None = None,
                    accel_bias: float | None = None, where: dict | None = None,
                    mount_error: str = "attitude") -> ResidualErrors:
    """The residual error set of a mission from the results and figures given (module docstring).

    Parameters
    ----------
    allan : sequence of AllanJob
        At most one per sensor (a gyroscope and/or an accelerometer Allan result).
    correction : AlignmentResult or CalibrationSet, optional
        Its uncertainties are the residual scale, misalignment and bias (R3).
    budget : mechanics Budget, optional
        Its per-axis angles (rms), uncompensated: as ``mount_error`` says (module docstring).
    part : align.parts.Part, optional
        Datasheet noise figures, used for the gyro when no gyro Allan result is given.
    gyro_bias, accel_bias : float, optional
        Residual turn-on bias 1-sigma (rad/s, m/s^2): replaces any other source of it.
    where : dict, optional
        Names of the inputs for messages and sources (keys ``allan``, ``correction``, ``budget``, ``part``).
    mount_error : {"attitude", "turns"}
        What the budget is taken as (:data:`MOUNT_ERRORS`).

    Returns
    -------
    ResidualErrors
        1-sigma per sensor (R1), SI: ``bias`` (3,), ``matrix`` (3, 3), ``tilt`` (3,), rad, and the noise terms (3,);
        ``mount`` (3,), rad (R2).

    Examples
    --------
    >>> from align.units import DEG_H
    >>> err = residual_errors(gyro_bias=10 * DEG_H)
    >>> err.terms(), round(float(err.gyro.bias[2] / DEG_H), 6)
    ([('gyroscope', 'bias')], 10.0)
    """
    where = where or {}
    values: dict[str, dict] = {"gyroscope": {}, "accelerometer": {}}
    sources: dict[str, dict] = {"gyroscope": {}, "accelerometer": {}}
    allan_names = where.get("allan", [])
    for k, job in enumerate(allan):
        name = allan_names[k] if k < len(allan_names) else f"Allan result {k + 1}"
        sensor, v, s = _from_allan(job, name)
        if values[sensor]:
            raise InputError(f"two {sensor} Allan results; give one per sensor", name)
        values[sensor].update(v)
        sources[sensor].update(s)
    if part is not None and not any(k in values["gyroscope"] for k in ("white", "flicker")):
        white = part.si("arw", "angle_random_walk")
        if white is None and part.noise_density is not None:
            white = part.si("noise_density", "angle_random_walk")
        flicker = part.si("bias_instability", "angular_rate")
        pname = f"preset {part.name}"
        if white is not None:
            values["gyroscope"]["white"] = _three(white, "arw", pname)
            sources["gyroscope"]["white"] = f"{pname} datasheet figure"
        if flicker is not None:
            values["gyroscope"]["flicker"] = _three(flicker, "bias instability", pname)
            sources["gyroscope"]["flicker"] = f"{pname} datasheet figure (B, the Allan floor is 0.664 B)"
    if correction is not None:
        cname = where.get("correction", "the alignment result")
        for sensor, (v, s) in _from_correction(correction, cname).items():
            if "bias" in values[sensor]:  # repeatability and the estimate's uncertainty add
                v["bias"] = np.hypot(v["bias"], values[sensor]["bias"])
                s["bias"] = f"{s['bias']} (root-sum-square with {sources[sensor]['bias']})"
            values[sensor].update(v)
            sources[sensor].update(s)
    mount, mount_source = np.zeros(3), ""
    if mount_error not in MOUNT_ERRORS:
        raise InputError(f"choose {' or '.join(MOUNT_ERRORS)} (got {mount_error!r})", "{mount_error}")
    if budget is not None:
        per_axis = np.asarray(budget.per_axis, float)
        shown = "/".join(f"{v:.4g}" for v in to_unit(per_axis, "deg"))
        bname = where.get("budget", "given")
        if mount_error == "turns":
            values["gyroscope"]["tilt"] = per_axis
            sources["gyroscope"]["tilt"] = (f"per-axis RSS of the budget {bname} ({shown} deg) as the rms misalignment "
                                            "of each gyro axis, random direction, relative to a frame aligned in place")
        else:
            mount, clipped = mount_rotation(per_axis)
            mount_source = (f"budget {bname}: per-axis RSS {shown} deg (x/y/z) taken as each axis' rms misalignment; "
                            "rigid rotation of the whole IMU, 1-sigma about x/y/z "
                            + "/".join(f"{v:.4g}" for v in to_unit(mount, "deg")) + " deg (R2)"
                            + ("; one axis' figure exceeds the RSS of the other two: no rigid rotation gives it, "
                               "its square was clipped at zero" if clipped else ""))
    for sensor, value, name in (("gyroscope", gyro_bias, "{gyro_bias}"), ("accelerometer", accel_bias, "{accel_bias}")):
        if value is not None:
            values[sensor]["bias"] = _three(value, "bias", name)
            sources[sensor]["bias"] = f"stated residual {sensor} bias"
    return ResidualErrors(SensorErrors("gyroscope", **values["gyroscope"], sources=sources["gyroscope"]),
                          SensorErrors("accelerometer", **values["accelerometer"], sources=sources["accelerometer"]),
                          mount, mount_source)
