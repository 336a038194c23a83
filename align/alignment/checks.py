"""Checks that turn a bad rate-table test into a clear error.

Each check either passes (returning a :class:`Check` to show in the result) or
raises :class:`~align.errors.TestError` naming the segment or step and what to
do. Directions are judged relative to the nominal mounting (the misalignment
being measured is a few degrees from it).

Public names
------------
Check, check_span, check_saturation, check_durations,
check_directions, check_scale, check_residuals
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.alignment.plan import Plan, axis_name
from align.alignment.segment import Segment
from align.errors import HandednessError, TestError
from align.plausible import scale_outside
from align.units import format_quantity, unit_mixup_hint
from align.values import Value

#: the status of a check that could not run
NOT_CHECKED = "not checked"


@dataclass(frozen=True, eq=False)
class Check(Value):
    """One check's outcome, shown in the alignment result.

    Attributes
    ----------
    name : str
        ``"durations"``, ``"saturation"``, ``"directions"``, ``"scale"`` or ``"residuals"``.
    status : str
        ``"pass"``, ``"warn"`` or ``"not checked"`` (:data:`NOT_CHECKED`: what it
        needed was not given). A failed check raises instead of returning.
    detail : str
        One line of plain text for people (no placeholders, no flags).
    """

    name: str
    status: str
    detail: str

    def to_dict(self) -> dict:
        """The check as an entry of an alignment result's ``checks`` list.

        Returns
        -------
        dict
            ``{"name", "status", "detail"}``, all strings.
        """
        return {"name": self.name, "status": self.status, "detail": self.detail}


def check_span(plan: Plan, allow_two_axis: bool = False) -> int | None:
    """The plan must turn about three independent axes (Eq 19-27; two for the shortcut of Eq 35-36).

    Parameters
    ----------
    plan : Plan
        The test plan.
    allow_two_axis : bool
        Accept a plan that never turns about exactly one axis (the two-axis
        shortcut then infers that column).

    Returns
    -------
    int or None
        The axis never turned about (0, 1, 2), when ``allow_two_axis`` and exactly
        one is missing; None when all three are turned about.

    Raises
    ------
    TestError
        When the turns do not span 3-D (and the shortcut does not apply).
    """
    turned = plan.axes_turned()
    missing = [a for a in range(3) if a not in turned]
    if not missing:
        return None
    names = ", ".join(axis_name(a)[1] for a in sorted(turned))
    if allow_two_axis and len(missing) == 1:
        return missing[0]
    hint = ("add steps about it or set {method=two-axis} (assumes orthogonal gyros)" if len(missing) == 1
            else "add steps about them")
    raise TestError(
        f"the rotations do not span 3-D: the plan turns about {names} only, never about "
        f"{', '.join(axis_name(a)[1] for a in missing)}; {hint}",
        "plan",
    )


def check_saturation(g: np.ndarray, segments: list[Segment], gyro_range: float | None, units: str) -> Check:
    """No sample used in a segment may reach 99 % of the stated gyro range.

    A clipped reading breaks the linear model ``g = M w + b`` (Eq 14-15) the
    estimate rests on.

    Parameters
    ----------
    g : ndarray, shape (n, 3)
        Gyro readings, rad/s.
    segments : list of Segment
        The stretches of the log used in the fit (samples ``start`` to ``end``).
    gyro_range : float or None
        The gyros' full-scale range, rad/s; None skips the check.
    units : str
        Rate unit the message shows rates in, e.g. ``"deg/s"``.

    Returns
    -------
    Check
        ``"pass"``, or ``"not checked"`` without a range.

    Raises
    ------
    TestError
        Naming the first segment whose peak ``|g|`` reaches ``0.99 gyro_range``.
    """
    if gyro_range is None:
        return Check("saturation", NOT_CHECKED, "no gyro range given: saturation not checked")
    limit = 0.99 * gyro_range
    for seg in segments:
        peak = float(np.max(np.abs(g[seg.start : seg.end])))
        if peak >= limit:
            raise TestError(
                f"reaches {format_quantity(peak, units, 5)}, at the gyro range {format_quantity(gyro_range, units, 5)}: "
                "the gyro saturated; lower the table rate",
                seg.name,
            )
    return Check("saturation", "pass", f"all segments below 99 % of {format_quantity(gyro_range, units, 5)}")


def check_durations(segments: list[Segment], fs: float, min_duration: float, min_samples: int = 10) -> Check:
    """Every step segment must last at least ``min_duration`` seconds and ``min_samples`` samples.

    Short dwells average too little noise away (Example 3: the averaging time
    sets the alignment accuracy). Static periods are not checked.

    Parameters
    ----------
    segments : list of Segment
        The stretches of the log found for the plan's steps.
    fs : float
        Sample rate, Hz.
    min_duration : float
        Shortest allowed segment, s.
    min_samples : int
        Fewest allowed samples in a segment.

    Returns
    -------
    Check
        ``"pass"``.

    Raises
    ------
    TestError
        Naming the first segment that is too short (and the ``{min_dwell}`` input).
    """
    for seg in segments:
        if seg.kind == "static":
            continue
        if seg.n < min_samples or seg.n / fs < min_duration:
            raise TestError(
                f"lasts {seg.n / fs:.3g} s ({seg.n} samples), shorter than the {min_duration:g} s minimum; "
                "dwell longer at this step (or lower {min_dwell})",
                seg.name,
            )
    return Check("durations", "pass", f"every step at least {min_duration:g} s")


def check_directions(measured: list[tuple[Segment, float, float]], plan: Plan, tolerance: float, units: str,
                     where: str = "log") -> Check:
    """Compare each step's measured turn with the plan.

    Parameters
    ----------
    measured : list of (Segment, along, across)
        Per step: the measured rate (rad/s) or angle (rad) along the planned
        spin axis, and the size of the part across it (bias removed where known).
    plan : Plan
    tolerance : float
        Largest relative difference from the planned rate or angle.
    units : str
        Display unit of rates (angles are shown in deg).
    where : str
        Name of the log, for errors that concern every step.

    Returns
    -------
    Check
        ``"pass"`` when every step turned as planned (Eq 19-31 assume it).

    Raises
    ------
    TestError
        A unit mix-up (measured / planned near 57.3 or 1000), a step turned the
        wrong way or about another axis, or a rate or angle off by more than
        ``tolerance``.
    HandednessError
        When every step about one axis, in both directions, is reversed (``det(M) < 0``).
    """
    steps = [plan.steps[seg.step] for seg, _, _ in measured if seg.step is not None]
    assert len(steps) == len(measured), "every measured turn is a plan step"
    planned = np.array([s.turn for s in steps])
    ratios = np.array([along for _, along, _ in measured]) / planned
    signed = planned * np.array([s.sign for s in steps])  # turn about the positive system axis
    hint = unit_mixup_hint(float(np.median(np.abs(ratios))))
    if hint:
        raise TestError(hint, where)
    described = []
    for (seg, along, across), step, value in zip(measured, steps, planned):
        unit = units if step.rate is not None else "deg"
        said = (f"planned {format_quantity(value, unit, 5)} about {axis_name(step.axis, step.sign)}, "
                f"measured {format_quantity(along, unit, 5)}")
        if abs(across) > 0.5 * abs(along):  # first: a step about another axis also looks like a reversed gyro
            raise TestError(
                f"{said} and {format_quantity(across, unit, 5)} across that axis: the table turned about another axis; "
                "check the fixture orientation and the step's axis",
                seg.name,
            )
        described.append(said)
    for axis in range(3):
        on = np.array([s.axis == axis for s in steps])
        if len(set(np.sign(signed[on]))) == 2 and np.all(ratios[on] < 0):
            raise HandednessError(
                f"every step about {'xyz'[axis]}, in both directions, measured reversed: the {'xyz'[axis]} gyro reads "
                "backwards (det(M) < 0, a handedness error) or the plan's axis signs are wrong; fix the wiring or sign, "
                "the tool does not flip it",
                where,
            )
    for (seg, _, _), ratio, step, said in zip(measured, ratios, steps, described):
        if ratio < 0:
            raise TestError(f"{said}: the table turned the wrong way; re-run the step or correct its sign in the plan", seg.name)
        if abs(ratio - 1) > tolerance:
            what = "rate" if step.rate is not None else "angle"
            raise TestError(
                f"{said}: off by {100 * (ratio - 1):+.1f} % (tolerance {100 * tolerance:g} %); "
                f"wrong table {what} or wrong plan step",
                seg.name,
            )
    return Check("directions", "pass", f"every step within {100 * tolerance:g} % of the plan, in the planned direction")


def check_scale(m: np.ndarray, tolerance: float, where: str = "result", assumed: int | None = None,
                scale_spec: float | None = None) -> list[Check]:
    """Scale factors ``|M[i, :]|`` (reference section 1) must lie within ``1 +/- tolerance``.

    Parameters
    ----------
    m : ndarray, shape (3, 3)
        The estimated ``M`` (Eq 14-15), dimensionless.
    tolerance : float
        Largest allowed ``| |M[i, :]| - 1 |``, dimensionless (e.g. 0.2).
    where : str
        Names the result in the error message.
    assumed : int, optional
        A gyro whose scale was assumed, not measured (the two-axis shortcut, Eq 35-36): not checked.
    scale_spec : float, optional
        The stated scale spec the assumption rests on (relative), for the not-checked entry.

    Returns
    -------
    list of Check
        ``"pass"`` listing the measured scale factors, and ``"not checked"`` for an assumed one.

    Raises
    ------
    TestError
        For the first measured gyro whose scale factor is outside the band (or NaN).
    """
    scale = np.linalg.norm(m, axis=1)
    measured = [i for i in range(3) if i != assumed]
    bad = scale_outside(m[measured], tolerance)
    if bad is not None:
        i, s = measured[bad[0]], bad[1]
        raise TestError(
            f"gyro {'xyz'[i]} scale factor {s:.4f} is outside 1 +/- {tolerance:g}: wrong gyro units, "
            "wrong table rate, or a broken gyro (raise {scale_tolerance} if this is expected)",
            where,
        )
    shown = ", ".join(f"{'xyz'[i]} {scale[i]:.5f}" for i in measured)
    out = [Check("scale", "pass", f"scale factors {shown} within 1 +/- {tolerance:g}")]
    if assumed is not None:
        spec = "" if scale_spec is None else f" +/- {100 * scale_spec:g} % (the stated scale spec, in its uncertainty)"
        out.append(Check(f"scale {'xyz'[assumed]}", NOT_CHECKED,
                         f"gyro {'xyz'[assumed]} scale not observable (its axis never turned): assumed 1{spec}"))
    return out


def check_residuals(segments: list[Segment], rms: np.ndarray, expected: np.ndarray, units: str) -> Check:
    """Warn (not fail) about segments whose residual is over 5x what their noise explains.

    The residuals are those of the fit of ``[M | b]`` (:func:`~align.alignment.estimate.fit_lsq`,
    Eq 28-31): a segment far off its noise hints at bias drift or a table error.

    Parameters
    ----------
    segments : list of Segment, length k
        The segments of the fit, in the order of ``rms`` and ``expected``.
    rms : ndarray, shape (k,)
        Size of each segment's residual (the alignment job passes the largest
        ``|y - [M | b] phi|`` over the three gyros): rad/s for dwells and static
        periods, rad for turns.
    expected : ndarray, shape (k,)
        The residual the segment's noise explains (1-sigma of its observation),
        same units as ``rms``.
    units : str
        Rate display unit; not used by the message today.

    Returns
    -------
    Check
        ``"warn"`` naming the worst segment when its ratio exceeds 5, else ``"pass"``.
    """
    ratio = rms / np.maximum(expected, 1e-300)
    worst = int(np.argmax(ratio)) if len(ratio) else 0
    if len(ratio) and ratio[worst] > 5:
        return Check("residuals", "warn",
                     f"{segments[worst].name}: residual {ratio[worst]:.1f}x its noise; bias drift or a table error? "
                     "inspect the segment table")
    return Check("residuals", "pass", "every segment's residual within 5x its noise")

