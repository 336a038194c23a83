"""The electronic-alignment job: log + plan -> ``M``, ``A``, bias, uncertainties, checks.

:func:`align` runs segmentation, the checks and one estimator and returns an
:class:`AlignmentResult`, a frozen value that writes itself to a versioned
dictionary (``to_dict``) and reads itself back (``from_dict``).

Public names
------------
AlignOptions, AlignmentResult, SegmentReport, align, FORMAT, FORMAT_VERSION
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from align import CONVENTION
from align.alignment.checks import (
    Check,
    check_directions,
    check_durations,
    check_residuals,
    check_saturation,
    check_scale,
    check_span,
)
from align.alignment.estimate import alignment_sigma, fit_angle_pairs, fit_lsq, fit_rate_pairs
from align.alignment.observe import observe
from align.alignment.plan import Plan
from align.alignment.segment import Motion, Segment, SegmentOptions, noise_sigma, segment_log
from align.alignment.twoaxis import two_axis, two_axis_error_bound
from align.earth import EARTH_RATE, vertical_rate
from align.errors import InputError
from align.io import c_header, check_log
from align.model import Angles, SensorModel, angles, check_handedness
from align.plausible import array_field, malformed
from align.results import Result, file_unit
from align.units import DEG, DEG_H, parse_unit, to_unit
from align.values import Value

FORMAT = "imu-align.alignment"
FORMAT_VERSION = 1
METHODS = ("auto", "rate", "angle", "lsq", "two-axis")


@dataclass(frozen=True)
class AlignOptions:
    """Settings of :func:`align` (SI units).

    Attributes
    ----------
    method : {"auto", "rate", "angle", "lsq", "two-axis"}
        ``auto`` is ``lsq`` when the plan turns about three axes and
        ``two-axis`` when it turns about two.
    two_axis_variant : {"procrustes", "cross"}
    axis_to_axis : float
        Stated axis-to-axis (non-orthogonality) spec, rad, for the two-axis error.
    segmentation : SegmentOptions
    min_dwell : float
        Shortest acceptable step segment, s.
    rate_tolerance : float
        Largest relative difference of a measured turn from the plan.
    scale_tolerance : float
        Scale factors must lie within ``1 +/- scale_tolerance``.
    gyro_range : float or None
        rad/s; segments reaching 99 % of it are rejected as saturated.
    earth_correction : bool
        Model the vertical Earth rate along the table axis when the plan states
        a latitude.
    """

    method: str = "auto"
    two_axis_variant: str = "procrustes"
    axis_to_axis: float = 0.05 * DEG
    segmentation: SegmentOptions = field(default_factory=SegmentOptions)
    min_dwell: float = 1.0
    rate_tolerance: float = 0.10
    scale_tolerance: float = 0.05
    gyro_range: float | None = None
    earth_correction: bool = True


@dataclass(frozen=True, eq=False)
class SegmentReport(Value):
    """A segment as used in the fit; ``residual`` in rad/s (dwells, static) or rad (turns)."""

    name: str
    kind: str
    start: int
    end: int
    t_start: float
    t_end: float
    residual: tuple[float, float, float]
    noise: tuple[float, float, float]


#: the keys of an alignment result file after the envelope
FILE_KEYS = ("sensor", "method", "M", "A", "bias", "uncertainty", "angles", "condition_number", "dof", "inferred_axis",
             "segments", "checks", "notes", "inputs")


class AlignmentResult(Result, format=FORMAT, version=FORMAT_VERSION, convention=CONVENTION):
    """Result of an electronic alignment (``g = M w + b``, ``w = A (g - b)``).

    ``bias`` and ``sigma_bias`` are rad/s; ``M``, ``A`` and their sigmas are
    dimensionless; ``units`` is the display/file unit of rates.
    """

    method: str
    M: np.ndarray
    A: np.ndarray
    bias: np.ndarray
    sigma_M: np.ndarray
    sigma_A: np.ndarray
    sigma_bias: np.ndarray
    condition_number: float
    dof: int
    segments: tuple[SegmentReport, ...]
    checks: tuple[Check, ...]
    notes: tuple[str, ...]
    units: str = "deg/s"
    inferred_axis: int | None = None
    inputs: dict = field(default_factory=dict)
    mounting: np.ndarray = field(default_factory=lambda: np.eye(3))
    mounting_source: str = "identity"
    motions: tuple[Motion, ...] = ()


    @property
    def angles(self) -> Angles:
        """Scale factors and misalignment angles read from ``M`` (reference section 1)."""
        return angles(self.M)

    @property
    def model(self) -> SensorModel:
        """The measurement model ``g = M w + b`` this result estimated."""
        return SensorModel(self.M, self.bias)

    @property
    def sensor(self) -> str:
        """The sensor this result corrects: always ``"gyroscope"``."""
        return "gyroscope"

    def correct(self, g: np.ndarray) -> np.ndarray:
        """Aligned rates ``w = A (g - b)`` (Eq 15) for readings of shape (3,) or (n, 3), rad/s."""
        return self.model.correct(g)

    def correction(self, sensor: str | None = None, where: str = "result") -> AlignmentResult:
        """This result, which corrects gyro logs (see :class:`align.results.Correction`).

        Refuses (naming ``where``) an ``M`` that is not finite, singular or has ``det <= 0``
        (:func:`align.plausible.check_usable_model`).
        """
        return self._only_sensor("gyroscope", sensor, where, "M")

    def as_c_header(self, comment: str, name: str = "IMU_ALIGN") -> str:
        """A C header with ``A`` and the bias (in :attr:`units`) for ``w = A (g - b)`` in firmware."""
        return c_header(name, self.A, to_unit(self.bias, self.units), self.units, f"{comment}\n{CONVENTION}")

    def to_dict(self) -> dict:
        """The versioned JSON form; rates in ``self.units``, angles in deg."""
        u = self.units
        ang = self.angles
        pairs = ("xy", "xz", "yz")
        phi = {f"phi_{'xyz'[i]}{'xyz'[j]}": float(ang.phi[i, j] / DEG) for i in range(3) for j in range(3) if i != j}
        return {
            **self.envelope({"M": "1", "A": "1", "bias": u, "angles": "deg",
                             "residual_rate": u, "residual_angle": "deg", "time": "s"}),
            "sensor": "gyroscope",
            "method": self.method,
            "M": self.M.tolist(),
            "A": self.A.tolist(),
            "bias": to_unit(self.bias, u).tolist(),
            "uncertainty": {
                "level": "1 sigma",
                "M": self.sigma_M.tolist(),
                "A": self.sigma_A.tolist(),
                "bias": to_unit(self.sigma_bias, u).tolist(),
            },
            "angles": {
                "scale": ang.scale.tolist(),
                "psi_deg": {f"psi_{a}": float(v / DEG) for a, v in zip("xyz", ang.psi)},
                "phi_deg": phi,
                "delta_deg": {f"delta_{p}": float(v / DEG) for p, v in zip(pairs, ang.delta)},
                "mounting_rotvec_deg": (ang.mounting_rotvec / DEG).tolist(),
            },
            "condition_number": self.condition_number,
            "dof": self.dof,
            "inferred_axis": None if self.inferred_axis is None else "xyz"[self.inferred_axis],
            "segments": [
                {"name": s.name, "kind": s.kind, "start": s.start, "end": s.end,
                 "t_start": s.t_start, "t_end": s.t_end,
                 "residual": (np.array(s.residual) / (DEG if s.kind == "angle" else parse_unit(u).factor)).tolist(),
                 "noise": (np.array(s.noise) / (DEG if s.kind == "angle" else parse_unit(u).factor)).tolist()}
                for s in self.segments
            ],
            "checks": [c.to_dict() for c in self.checks],
            "notes": list(self.notes),
            "inputs": self.inputs,
        }

    @classmethod
    def from_dict(cls, d: dict, where: str = "result") -> AlignmentResult:
        """Read the form written by :meth:`to_dict` (any version up to the current one)."""
        cls.check_envelope(d, where, keys=FILE_KEYS)  # a misspelled key is refused, not ignored
        try:
            u, f = file_unit(d, "bias", "angular_rate", where)
            m = array_field(d, "M", (3, 3), "alignment result", where)
            unc = d.get("uncertainty", {})
            segs = tuple(
                SegmentReport(s["name"], s["kind"], s["start"], s["end"], s["t_start"], s["t_end"],
                              tuple(np.array(s["residual"], float) * (DEG if s["kind"] == "angle" else f)),
                              tuple(np.array(s["noise"], float) * (DEG if s["kind"] == "angle" else f)))
                for s in d.get("segments", [])
            )
            inferred = d.get("inferred_axis")
            a = array_field(d, "A", (3, 3), "alignment result", where)
            bias = array_field(d, "bias", (3,), "alignment result", where, f)
            return cls(
                method=d["method"], M=m, A=a, bias=bias,
                sigma_M=np.array(unc.get("M", np.full((3, 3), np.nan)), float).reshape(3, 3),
                sigma_A=np.array(unc.get("A", np.full((3, 3), np.nan)), float).reshape(3, 3),
                sigma_bias=np.array(unc.get("bias", [np.nan] * 3), float).reshape(3) * f,
                condition_number=float(d.get("condition_number") or np.nan), dof=int(d.get("dof", 0)),
                segments=segs,
                checks=tuple(Check(c["name"], c["status"], c["detail"]) for c in d.get("checks", [])),
                notes=tuple(d.get("notes", [])), units=u,
                inferred_axis=None if inferred is None else "xyz".index(inferred),
                inputs=dict(d.get("inputs", {})),
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"malformed alignment result ({malformed(exc)}); regenerate it with imu-align matrix",
                             where) from None


def _measured_turns(obs, plan: Plan, bias: np.ndarray):
    out = []
    for o in obs:
        if o.segment.kind == "static":
            continue
        step = plan.steps[o.segment.step]
        v = o.y - bias * (o.duration if o.segment.kind == "angle" else 1.0)
        along = float(v @ step.unit_axis)
        across = float(np.linalg.norm(v - along * step.unit_axis))
        out.append((o.segment, along, across))
    return out


def _choose(method: str, plan: Plan, missing: int | None) -> str:
    if method not in METHODS:
        raise InputError(f"unknown method '{method}'; choose one of {', '.join(METHODS)}", "{method}")
    if method == "auto":
        return "two-axis" if missing is not None else "lsq"
    return method


def align(
    t: np.ndarray,
    g: np.ndarray,
    plan: Plan,
    options: AlignOptions = AlignOptions(),
    segments: list[Segment] | None = None,
    units: str = "deg/s",
    where: str = "log",
) -> AlignmentResult:
    """Estimate ``M``, ``A = M^-1`` and the bias from a rate-table log.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Time, s.
    g : ndarray, shape (n, 3)
        Gyro readings, rad/s.
    plan : Plan
    options : AlignOptions
    segments : list of Segment, optional
        Explicit segments; found automatically when None.
    units : str
        Rate unit for messages and the written result.
    where : str
        Name of the log for messages.

    Returns
    -------
    AlignmentResult

    Raises
    ------
    InputError, TestError
        With a one-line message naming the file, step or segment.
    """
    check_log(t, g, where)
    missing = check_span(plan, allow_two_axis=options.method in ("auto", "two-axis"))
    method = _choose(options.method, plan, missing)
    if method == "two-axis" and missing is None:
        raise InputError("the two-axis method needs a plan that turns about exactly two axes", "{method}")
    fs = 1.0 / float(np.median(np.diff(t)))
    sigma = noise_sigma(g)
    if segments is None:
        segments = segment_log(t, g, plan, options.segmentation, where, sigma)
    checks = [check_durations(segments, fs, options.min_dwell),
              check_saturation(g, segments, options.gyro_range, units)]
    earth = options.earth_correction and plan.latitude is not None
    obs = observe(t, g, segments, plan, sigma, earth)
    statics = [o for o in obs if o.segment.kind == "static"]
    rough_bias = (np.mean([o.y for o in statics], axis=0) if statics else np.zeros(3))
    checks.append(check_directions(_measured_turns(obs, plan, rough_bias), plan, options.rate_tolerance, units, where))
    used = obs if plan.kind != "rate" else [o for o in obs if o.segment.kind != "static"]
    if method == "rate":
        fit = fit_rate_pairs(used, plan)
    elif method == "angle":
        fit = fit_angle_pairs(used, plan)
    else:
        fit = fit_lsq(used, _table_accuracy(plan), method)
    notes = []
    m, sigma_m = fit.M, fit.sigma_M
    if method == "two-axis":
        m = two_axis(fit, missing, options.two_axis_variant)
        bound = two_axis_error_bound(options.axis_to_axis)
        sigma_m = sigma_m.copy()
        sigma_m[:, missing] = np.hypot(np.nanmax(fit.sigma_M), options.axis_to_axis)
        notes.append(
            f"two-axis shortcut ({options.two_axis_variant}): column {'xyz'[missing]} inferred assuming orthogonal gyros; "
            f"for an axis-to-axis spec of {options.axis_to_axis / DEG:g} deg each inferred element may be off by that much "
            f"and the column's direction by up to {bound / DEG:.4g} deg"
        )
        fit = replace(fit, M=m, sigma_M=sigma_m)
    check_handedness(m, f"{where}: result")
    checks.append(check_scale(m, options.scale_tolerance, f"{where}: result"))
    cov = fit.cov.copy()
    if method == "two-axis":
        for i in range(3):
            cov[i, missing, :] = 0.0
            cov[i, :, missing] = 0.0
            cov[i, missing, missing] = sigma_m[i, missing] ** 2
    sigma_a = alignment_sigma(m, cov)
    noise = np.sqrt(np.array([o.var for o in used]))
    checks.append(check_residuals([o.segment for o in used], np.abs(fit.residuals).max(axis=1), noise.max(axis=1), units))
    notes.append(_earth_note(plan, earth, m))
    reports = tuple(
        SegmentReport(o.segment.name, o.segment.kind, o.segment.start, o.segment.end, float(t[o.segment.start]),
                      float(t[o.segment.end - 1]), tuple(map(float, r)), tuple(map(float, nz)))
        for o, r, nz in zip(used, fit.residuals, noise)
    )
    return AlignmentResult(
        method=method, M=m, A=np.linalg.inv(m), bias=fit.bias, sigma_M=sigma_m, sigma_A=sigma_a,
        sigma_bias=fit.sigma_bias, condition_number=fit.condition_number, dof=fit.dof, segments=reports,
        checks=tuple(checks), notes=tuple(notes), units=units, inferred_axis=missing,
    )


def _table_accuracy(plan: Plan) -> float:
    """Relative accuracy of the table: its rate accuracy, or its angle accuracy over the smallest turn."""
    if plan.kind == "angle" and plan.angle_accuracy:
        return plan.angle_accuracy / min(abs(s.angle) for s in plan.steps)
    return plan.rate_accuracy


def _earth_note(plan: Plan, corrected: bool, m: np.ndarray) -> str:
    if corrected:
        v = vertical_rate(plan.latitude)
        return (f"Earth rate corrected: vertical component {v / DEG_H:.4f} deg/h along each table axis "
                f"(latitude {plan.latitude / DEG:.4f} deg) modelled in w; its horizontal part averages out over full turns")
    return (f"Earth rate not corrected (no latitude in the plan): +/- pairs cancel it in M; its vertical part "
            f"(up to {EARTH_RATE / DEG_H:.3f} deg/h) is in the bias and the residuals")
