"""The electronic-alignment pipeline: readings + plan -> ``M``, ``A``, bias, uncertainties, checks.

(Formerly ``align.alignment.job``; the command's job, which reads and checks the files and stamps
the provenance, is :mod:`align.alignment.jobs`.) :func:`align` runs segmentation, the checks and one estimator and returns an
:class:`AlignmentResult`, a frozen value that writes itself to a versioned
dictionary (``to_dict``) and reads itself back (``from_dict``).

Public names
------------
AlignOptions, align, METHODS (the result type, :class:`~align.alignment.result.AlignmentResult`, is in its own module)
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from align.alignment.biasdrift import estimate_drift, with_drift
from align.alignment.checks import (
    check_directions,
    check_durations,
    check_residuals,
    check_saturation,
    check_scale,
    check_span,
)
from align.alignment.estimate import alignment_sigma, fit_angle_pairs, fit_lsq, fit_rate_pairs
from align.alignment.geometry import mounting_label
from align.alignment.linearity import measure_linearity
from align.alignment.match import Candidate, match_steps
from align.alignment.observe import EarthModel, Observation, observe
from align.alignment.plan import Plan
from align.alignment.result import AlignmentResult, SegmentReport
from align.alignment.segment import (
    Motion,
    Segment,
    Segmentation,
    SegmentOptions,
    integrate,
    moves_between,
    noise_sigma,
    segment_log,
)
from align.alignment.twoaxis import two_axis, two_axis_error_bound
from align.earth import EARTH_RATE
from align.errors import InputError, literal
from align.io import check_log
from align.model import check_handedness
from align.units import DEG, DEG_H, DEG_S

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
    scale_spec : float
        Stated scale-factor error (1 sigma, relative) of the gyro the two-axis shortcut cannot measure.
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
    scale_spec: float = 0.01
    segmentation: SegmentOptions = field(default_factory=SegmentOptions)
    min_dwell: float = 1.0
    rate_tolerance: float = 0.10
    scale_tolerance: float = 0.05
    gyro_range: float | None = None
    earth_correction: bool = True


def _measured_turns(obs, plan: Plan, bias: np.ndarray, mounting: np.ndarray):
    """Per step: the measured turn along the gyro direction the nominal mounting expects, and the part across."""
    out = []
    for o in obs:
        if o.segment.kind == "static":
            continue
        step = plan.steps[o.segment.step]
        v = o.y - bias * (o.duration if o.segment.kind == "angle" else 1.0)
        e = mounting @ step.unit_axis
        along = float(v @ e)
        across = float(np.linalg.norm(v - along * e))
        out.append((o.segment, along, across))
    return out


def _choose(method: str, plan: Plan, missing: int | None) -> str:
    if method not in METHODS:
        raise InputError(f"unknown method '{method}'; choose one of {', '.join(METHODS)}", "{method}")
    if method == "auto":
        return "two-axis" if missing is not None else "lsq"
    return method


def _explicit(t: np.ndarray, g: np.ndarray, plan: Plan, segments: list[Segment], sigma: np.ndarray,
              where: str) -> Segmentation:
    """The mounting for explicit segments (the plan's, or the one their steps' readings fit, as for found ones) and
    the motions between their static periods that no step holds (after one, a rest orientation is unknown)."""
    statics = [s for s in segments if s.kind == "static"]
    bias = (np.sum([g[s.start:s.end].sum(axis=0) for s in statics], axis=0) / sum(s.n for s in statics)
            if statics else np.zeros(3))
    cands = []
    for s in sorted((s for s in segments if s.step is not None), key=lambda s: -1 if s.step is None else s.step):
        if s.kind == "angle":
            y, duration = integrate(t, g, s.start, s.end)
            cands.append(Candidate("turn", s.start, s.end, y - bias * duration))
        else:
            cands.append(Candidate("rate", s.start, s.end, g[s.start:s.end].mean(axis=0) - bias))
    names = {(s.start, s.end): s.name for s in segments}
    match = match_steps(plan, cands, lambda c: f"segment '{literal(names[c.start, c.end])}', samples {c.start}-{c.end}",
                        where)
    return Segmentation(tuple(segments), tuple(moves_between(t, g, segments, sigma)), match.mounting, match.source)


def _motions(t: np.ndarray, unclaimed, a: np.ndarray) -> tuple[Motion, ...]:
    """The motions no step took, with their axis in the system frame (through ``A``) and a label."""
    out = []
    for k, c in enumerate(unclaimed, start=1):
        w = a @ c.vector
        size = float(np.linalg.norm(w))
        axis = w / size if size > 0 else np.zeros(3)
        j = int(np.argmax(np.abs(axis)))
        name = (("+" if axis[j] > 0 else "-") + "xyz"[j]) if abs(axis[j]) > np.cos(10 * DEG) else \
            "(" + ", ".join(f"{v:+.2f}" for v in axis) + ")"
        how = f"at {size / DEG_S:.4g} deg/s" if c.kind == "rate" else f"through {size / DEG:.4g} deg"
        out.append(Motion(f"motion {k}", c.kind, c.start, c.end, float(t[c.start]), float(t[c.end - 1]), size,
                          (float(axis[0]), float(axis[1]), float(axis[2])), f"about {name} {how}"))
    return tuple(out)


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

    Implements ``g = M w + b`` (Eq 14-15): each +/- pair of rotations about global axis ``j`` gives
    column ``j``, ``M_ij = (g_i(+) - g_i(-)) / (2 w_TR)``, and the bias ``b_i = (g_i(+) + g_i(-)) / 2``
    (Eq 28-30); more rotations are solved by least squares; ``A = M^-1``.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Time, s.
    g : ndarray, shape (n, 3)
        Gyro readings, rad/s.
    plan : Plan
        The table steps: axes, rates (rad/s) and durations (s).
    options : AlignOptions
        Method, segmentation and tolerances (SI).
    segments : list of Segment, optional
        Explicit segments; found automatically when None.
    units : str
        Rate unit for messages and the written result.
    where : str
        Name of the log for messages.

    Returns
    -------
    AlignmentResult
        ``M`` and ``A`` (3, 3), dimensionless, whole (``A`` maps raw gyro readings to system rates); ``bias``
        (3,), rad/s; angles (rad) relative to the nominal mounting, which is in the result with where it came from.

    Raises
    ------
    InputError, TestError
        With a one-line message naming the file, step or segment.

    Examples
    --------
    A simulated noise-free session of the standard plan (+/- 100 deg/s about each axis): ``M`` and the
    bias come back, and ``A M = I``.

    >>> import numpy as np
    >>> from align.alignment.plan import Plan
    >>> from align.alignment.simulate import SessionSpec, simulate_session
    >>> from align.model import SensorModel
    >>> from align.units import DEG
    >>> plan = Plan.standard_rate(100 * DEG)
    >>> M = np.array([[1.002, 0.003, -0.002], [-0.004, 0.998, 0.001], [0.002, -0.001, 1.001]])
    >>> b = np.array([0.01, -0.02, 0.005]) * DEG
    >>> t, g, _ = simulate_session(plan, SensorModel(M, b), SessionSpec(noise_density=0.0), seed=1)
    >>> r = align(t, g, plan)
    >>> bool(np.allclose(r.M, M, atol=1e-6)), bool(np.allclose(r.bias, b, atol=1e-8))
    (True, True)
    >>> bool(np.allclose(r.A @ M, np.eye(3), atol=1e-6))
    True
    """
    check_log(t, g, where)
    missing = check_span(plan, allow_two_axis=options.method in ("auto", "two-axis"))
    method = _choose(options.method, plan, missing)
    if method == "two-axis" and missing is None:
        raise InputError("the two-axis method needs a plan that turns about exactly two axes", "{method}")
    fs = 1.0 / float(np.median(np.diff(t)))
    sigma = noise_sigma(g)
    found = (segment_log(t, g, plan, options.segmentation, where, sigma) if segments is None
             else _explicit(t, g, plan, list(segments), sigma, where))
    segments, nominal = list(found.segments), found.mounting
    checks = [check_durations(segments, fs, options.min_dwell),
              check_saturation(g, segments, options.gyro_range, units)]
    earth = options.earth_correction and plan.latitude is not None
    obs: list[Observation]
    obs, earth_model = observe(t, g, segments, plan, sigma, earth, nominal, [(c.start, c.end) for c in found.unclaimed])
    drift = estimate_drift(obs, t, sigma, nominal)  # the bias change between segments, from the static periods
    obs = list(with_drift(obs, drift, t, sigma))
    linearity = measure_linearity(obs, plan, nominal, g, options.gyro_range)  # None: one rate per direction
    statics = [o for o in obs if o.segment.kind == "static"]
    rough_bias = (np.mean([o.y for o in statics], axis=0) if statics else np.zeros(3))
    checks.append(check_directions(_measured_turns(obs, plan, rough_bias, nominal), plan, options.rate_tolerance, units,
                                   where))
    if method == "rate":
        fit = fit_rate_pairs(obs, plan)
    elif method == "angle":
        fit = fit_angle_pairs(obs, plan)
    else:
        fit = fit_lsq(obs, _table_accuracy(plan), method)
    notes = [_mounting_note(nominal, found.source), drift.note]
    assumed = None
    if method == "two-axis":
        assert missing is not None  # "two-axis" is chosen (or accepted) only with an axis never turned
        fit, assumed, note = _complete_two_axis(fit, missing, nominal, options)
        notes.append(note)
    m, sigma_m = fit.M, fit.sigma_M
    check_handedness(m, f"{where}: result")
    checks += check_scale(m, options.scale_tolerance, f"{where}: result", assumed,
                          options.scale_spec if assumed is not None else None)
    sigma_a = alignment_sigma(m, fit.cov)
    noise = np.sqrt(np.array([o.var for o in obs]))
    checks.append(check_residuals([o.segment for o in obs], np.abs(fit.residuals).max(axis=1), noise.max(axis=1), units))
    notes.append(_earth_note(plan, earth, earth_model))
    if linearity is not None and any(a is not None and a.significant for a in linearity.axes):
        notes.append("the scale factor is not linear across the range (see linearity): M is the least-squares line's, "
                     "and the rate steps' residuals hold the nonlinearity")
    a = np.linalg.inv(m)
    motions = _motions(t, found.unclaimed, a)
    if motions:
        notes.append(f"{len(motions)} motion{'s' if len(motions) > 1 else ''} in the log not in the plan (left out): "
                     + "; ".join(f"t={mo.t_start:.2f}-{mo.t_end:.2f} s {mo.label}" for mo in motions))
    reports = tuple(
        SegmentReport(o.segment.name, o.segment.kind, o.segment.start, o.segment.end, float(t[o.segment.start]),
                      float(t[o.segment.end - 1]), (float(r[0]), float(r[1]), float(r[2])),
                      (float(nz[0]), float(nz[1]), float(nz[2])))
        for o, r, nz in zip(obs, fit.residuals, noise)
    )
    return AlignmentResult(
        method=method, M=m, A=a, bias=fit.bias, sigma_M=sigma_m, sigma_A=sigma_a,
        sigma_bias=fit.sigma_bias, condition_number=fit.condition_number, dof=fit.dof, segments=reports,
        checks=tuple(checks), notes=tuple(notes), units=units, inferred_axis=missing,
        mounting=nominal, mounting_source=found.source, motions=motions, linearity=linearity,
    )


def _complete_two_axis(fit, missing: int, nominal: np.ndarray, options: AlignOptions):
    """Fill the never-turned column (Eq 35-36) and give it the uncertainty of the assumptions it rests on.

    The column ``c`` is assumed of unit length (the scale of the gyro along it, ``i = argmax |N[:, missing]|``,
    is not observable) and perpendicular to the measured ones; its covariance is
    ``scale_spec^2 c c^T + axis_to_axis^2 (I - c c^T)`` plus the measured columns' largest variance.
    Returns the completed fit, the assumed gyro and the note.
    """
    m = two_axis(fit, missing, options.two_axis_variant)
    c = m[:, missing] / np.linalg.norm(m[:, missing])
    measured = float(np.nanmax(fit.sigma_M)) ** 2
    var = options.scale_spec**2 * c**2 + options.axis_to_axis**2 * (1 - c**2) + measured
    sigma_m = fit.sigma_M.copy()
    sigma_m[:, missing] = np.sqrt(var)
    cov = fit.cov.copy()
    for i in range(3):
        cov[i, missing, :] = 0.0
        cov[i, :, missing] = 0.0
        cov[i, missing, missing] = var[i]
    gyro = int(np.argmax(np.abs(nominal[:, missing])))
    bound = two_axis_error_bound(options.axis_to_axis)
    note = (f"two-axis shortcut ({options.two_axis_variant}): column {'xyz'[missing]} not measured (never turned about "
            f"{'xyz'[missing]}); inferred assuming orthogonal gyros (axis-to-axis spec {options.axis_to_axis / DEG:g} deg: "
            f"its direction may be off by up to {bound / DEG:.4g} deg) and the scale of gyro {'xyz'[gyro]} assumed 1 "
            f"(scale spec {100 * options.scale_spec:g} %); both assumptions are in its uncertainty")
    return replace(fit, M=m, sigma_M=sigma_m, cov=cov), gyro, note


def _mounting_note(nominal: np.ndarray, source: str) -> str:
    if source == "declared":
        return f"nominal mounting (declared in the plan): {mounting_label(nominal)}; angles are relative to it"
    if np.allclose(nominal, np.eye(3)):
        return "nominal mounting: gyros along the system axes (the steps' readings agree)"
    return f"nominal mounting detected: {mounting_label(nominal)}; angles are relative to it"


def _table_accuracy(plan: Plan) -> float:
    """Relative accuracy of the table: its rate accuracy, or its angle accuracy over the smallest turn."""
    if plan.kind == "angle" and plan.angle_accuracy:
        return plan.angle_accuracy / min(abs(s.turn) for s in plan.steps)
    return plan.rate_accuracy


def _earth_note(plan: Plan, corrected: bool, model: EarthModel) -> str:
    """What of the Earth rate was modelled, and where the rest went."""
    if not corrected:
        why = "no latitude in the plan" if plan.latitude is None else "switched off"
        return (f"Earth rate not modelled ({why}): +/- pairs cancel it in M; up to {EARTH_RATE / DEG_H:.3f} deg/h of it "
                "is in the bias and the residuals")
    assert plan.latitude is not None  # corrected only with a latitude
    parts = [f"Earth rate at latitude {plan.latitude / DEG:.4f} deg ({EARTH_RATE / DEG_H:.3f} deg/h): modelled"]
    along = ", ".join(f"{v / DEG_H:.4f}" for v in model.along_rate)
    parts.append(f" the component along the spin axis ({along} deg/h) in {model.steps} dwells/turns")
    if model.whole:
        parts.append(f", the whole vector in {model.whole} static periods (rest orientation given)")
    if model.along:
        parts.append(f", the component along the table axis in {model.along} static periods")
    parts.append(f"; not modelled, in the uncertainty: the part across the spin axis (at most "
                 f"{model.across / DEG_H:.3f} deg/h, mostly averaged out by the turns)")
    if model.unknown:
        parts.append(f" and the whole rate in {model.unknown} static periods after motions the plan does not list")
    return "".join(parts)
