"""The plan's steps found, in order, among the motions of a log; the nominal mounting with them.

Every motion the segmentation finds (a constant-rate plateau, or a turn between two rests) is a
*candidate* with a measured vector ``v`` in the gyro frame (mean rate, or integrated angle, bias
removed). Under a nominal mounting ``N`` (:mod:`align.alignment.geometry`) a step about the signed
system axis ``u`` with signed rate or angle ``s`` should read ``e = s N u`` (Eq 14 with ``M ~ N``).
The steps are matched greedily in plan order: each takes the first candidate after the previous
match with ``|v - e| <= tolerance |e|``; the candidates skipped are motions the plan does not list
(fixture re-orientations, stops and restarts). An angle step may also take the sum of up to three
consecutive turns (a turn interrupted by a stop).

Without a declared mounting every proper signed permutation (90/180 deg turns) is tried, identity
first, and the one that finds every step is kept; a mirrored set (``det = -1``) that finds them is a
handedness error, and directions that fit no signed permutation are an IMU mounted at an angle,
which must be declared.

Public names
------------
Candidate, Match, match_steps, MATCH_TOLERANCE
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.alignment.geometry import SIGNED_PERMUTATIONS, mounting_label
from align.alignment.plan import Plan, Step, axis_name
from align.errors import HandednessError, TestError
from align.model import nearest_rotation
from align.units import format_quantity, unit_mixup_hint

#: largest relative distance |v - e| / |e| of a motion from a step's expected reading (90 deg apart is 1.41)
MATCH_TOLERANCE = 0.35

@dataclass(frozen=True)
class Candidate:
    """A motion found in the log.

    Attributes
    ----------
    kind : str
        ``"rate"`` (a constant-rate plateau) or ``"turn"`` (the motion between two rests).
    start, end : int
        Samples (end exclusive).
    vector : ndarray, shape (3,)
        Gyro frame, bias removed: mean rate (rad/s) or integrated angle (rad).
    """

    kind: str
    start: int
    end: int
    vector: np.ndarray


@dataclass(frozen=True)
class Match:
    """The outcome of :func:`match_steps`.

    Attributes
    ----------
    ranges : tuple of (int, int)
        Per plan step, the samples it was found in.
    unclaimed : tuple of Candidate
        The motions no step took, in time order.
    mounting : ndarray, shape (3, 3)
        The nominal mounting ``N`` the steps were found with.
    source : str
        ``"declared"`` or ``"detected"``.
    """

    ranges: tuple[tuple[int, int], ...]
    unclaimed: tuple[Candidate, ...]
    mounting: np.ndarray
    source: str


def _expected(step: Step, n: np.ndarray) -> np.ndarray:
    value = step.rate if step.rate is not None else step.angle
    return value * (n @ step.unit_axis)


def _find(step: Step, cands: list[Candidate], pos: int, e: np.ndarray, tol: float):
    """The first candidate from ``pos`` that reads ``e`` (``(index, width, distance)``), else the first run of two or
    three consecutive turns along ``e`` whose sum does (an angle step interrupted by a stop); None when neither."""
    size = np.linalg.norm(e)
    for j in range(pos, len(cands)):
        d = float(np.linalg.norm(cands[j].vector - e) / size)
        if d <= tol:
            return j, 1, d
    if step.angle is None:
        return None
    unit = e / size
    for j in range(pos, len(cands)):
        total = np.zeros(3)
        for width, c in enumerate(cands[j : j + 3], start=1):
            along = float(c.vector @ unit)
            if c.kind != "turn" or along <= 0 or np.linalg.norm(c.vector - along * unit) > tol * along:
                break
            total = total + c.vector
            d = float(np.linalg.norm(total - e) / size)
            if width > 1 and d <= tol:
                return j, width, d
    return None


def _greedy(plan: Plan, cands: list[Candidate], n: np.ndarray, tol: float):
    """Match the steps in order under mounting ``n``: (ranges, used candidate indices, cost, first unmatched step,
    position reached, first departure ``(step, position)`` where a motion was skipped, or None)."""
    ranges: list[tuple[int, int]] = []
    used: set[int] = set()
    pos, cost, departed = 0, 0.0, None
    for k, step in enumerate(plan.steps):
        found = _find(step, cands, pos, _expected(step, n), tol)
        if found is None:
            return ranges, used, cost, k, pos, departed
        j, width, d = found
        if j > pos and departed is None:
            departed = (k, pos)
        ranges.append((cands[j].start, cands[j + width - 1].end))
        used.update(range(j, j + width))
        cost += d
        pos = j + width
    return ranges, used, cost, None, pos, departed


def match_steps(plan: Plan, cands: list[Candidate], describe, where: str = "log",
                tolerance: float = MATCH_TOLERANCE, sizes: list[float] | None = None) -> Match:
    """Find each plan step among the candidates, in order, with the declared or a detected mounting.

    Parameters
    ----------
    plan : Plan
        Its ``nominal`` mounting, when declared, is the only one tried.
    cands : list of Candidate
        The motions of the log, in time order.
    describe : callable
        ``describe(candidate) -> str`` for messages (times and measured values).
    where : str
        Name of the log.
    tolerance : float
        Largest ``|v - e| / |e|`` of a match.
    sizes : list of float, optional
        The sizes of every motion seen (rad/s or rad), for the unit mix-up test when steps are not found;
        the candidates' sizes when None.

    Returns
    -------
    Match

    Raises
    ------
    HandednessError
        When the nominal mounting with one gyro reversed finds every step (``det(M) < 0``).
    TestError
        A unit mix-up (every motion about 57.3 or 1000 times the plan's), or naming the first planned step
        that cannot be found, and why (turned the wrong way, about another axis, an IMU mounted at an angle
        that is not declared).
    """
    declared = plan.nominal
    hypotheses = [declared] if declared is not None else list(SIGNED_PERMUTATIONS)
    best = None
    for n in hypotheses:
        ranges, used, cost, missing, pos, departed = _greedy(plan, cands, n, tolerance)
        # a full match wins; among partial ones (for the message) the one that got furthest skipping least, with
        # a prior for the identity (a non-identity mounting must explain three more steps to be preferred)
        prior = 0 if declared is not None or np.allclose(n, np.eye(3)) else 3
        key = (missing is None, len(ranges) - 2 * (pos - len(used)) - prior, -cost)
        if best is None or key > best[0]:
            best = (key, n, ranges, used, missing, pos, departed)
    assert best is not None  # at least one mounting hypothesis is always tried
    _, n, ranges, used, missing, pos, departed = best
    if missing is None:
        source = "declared" if declared is not None else "detected"
        return Match(tuple(ranges), tuple(c for j, c in enumerate(cands) if j not in used), n, source)
    _refuse_mixup(plan, [float(np.linalg.norm(c.vector)) for c in cands] if sizes is None else sizes, where)
    _refuse_mirrored(plan, cands, np.eye(3) if declared is None else declared, tolerance, where)
    if declared is None:
        _refuse_unaligned(plan, cands, where)
    raise _not_found(plan, missing, departed, cands, pos, n, describe, declared is not None, where)


def _refuse_mixup(plan: Plan, sizes: list[float], where: str) -> None:
    """The motions are all about 57.3 or 1000 times the plan's: a unit mixed up (:func:`align.units.unit_mixup_hint`)."""
    if not sizes:
        return
    biggest = sorted(sizes)[-len(plan.steps):]
    planned = [abs(s.turn) for s in plan.steps]
    hint = unit_mixup_hint(float(np.median(biggest)) / float(np.median(planned)))
    if hint:
        raise TestError(hint, where)


def _refuse_mirrored(plan: Plan, cands: list[Candidate], proper: np.ndarray, tol: float, where: str) -> None:
    """The nominal mounting (``proper``: the declared one or the identity) with one gyro reversed finds every step:
    that gyro reads backwards. Only said when the axis it measures was turned both ways (with one direction only, a
    turn the wrong way looks the same)."""
    both = {a for a in range(3) if len({np.sign(s.turn * s.sign)
                                         for s in plan.steps if s.axis == a}) == 2}
    for i in range(3):
        flip = proper.copy()
        flip[i] *= -1
        if int(np.argmax(np.abs(flip[i]))) in both and _greedy(plan, cands, flip, tol)[3] is None:
            raise HandednessError(
                f"the steps are found only if gyro {'xyz'[i]} reads backwards: the {'xyz'[i]} gyro reads backwards "
                "(det(M) < 0, a handedness error) or the plan's axis signs are wrong; fix the wiring or sign, "
                "the tool does not flip it", where)


def _refuse_unaligned(plan: Plan, cands: list[Candidate], where: str) -> None:
    """Steps found by size in order but along no single gyro: an IMU mounted at an angle, to be declared."""
    sizes: dict[int, list[np.ndarray]] = {}
    pos = 0
    for step in plan.steps:
        want = abs(step.turn)
        for j in range(pos, len(cands)):
            if abs(np.linalg.norm(cands[j].vector) / want - 1) <= 0.1:
                sizes.setdefault(step.axis, []).append(cands[j].vector / (want * np.sign(
                    step.turn * step.sign)))
                pos = j + 1
                break
        else:
            return
    if len(sizes) < 2 or all(np.abs(v).max() / np.linalg.norm(v) > np.cos(15 * np.pi / 180)
                             for vs in sizes.values() for v in vs):
        return  # each along one gyro (within 15 deg): a step is wrong, not the mounting (said by _not_found)
    cols = np.zeros((3, 3))
    for axis, vs in sizes.items():
        cols[:, axis] = np.mean(vs, axis=0)
    if len(sizes) == 2:
        a, b = sorted(sizes)
        c = 3 - a - b
        cols[:, c] = np.cross(cols[:, (c + 1) % 3], cols[:, (c + 2) % 3])
    n = nearest_rotation(cols)
    angle, about, nominal = _round_rotation(n)
    rows = ", ".join("[" + ", ".join(f"{v:.4f}" for v in row) + "]" for row in nominal)
    raise TestError(f"the turns are found but each moves several gyros: the IMU is mounted at an angle to the system "
                    f"axes (measured: {mounting_label(n)}); declare its nominal mounting in the plan (the nearest round "
                    f"rotation is {angle:g} deg about {about}: check it against the drawing), e.g. [mounting] matrix = "
                    f"[{rows}]", where)


def _round_rotation(n: np.ndarray) -> tuple[float, str, np.ndarray]:
    """The measured mounting ``n`` rounded to a nominal one: its rotation (``N = R^T``) to whole degrees about the
    nearest system axis (within 3 deg) or an axis rounded to 0.1; returns (angle deg, axis text, ``N``)."""
    from scipy.spatial.transform import Rotation

    rotvec = Rotation.from_matrix(n.T).as_rotvec()
    angle = float(np.linalg.norm(rotvec))
    axis = rotvec / angle if angle > 0 else np.array([0.0, 0.0, 1.0])
    j = int(np.argmax(np.abs(axis)))
    if abs(axis[j]) > np.cos(3 * np.pi / 180):
        axis, text = np.sign(axis[j]) * np.eye(3)[j], ("+" if axis[j] > 0 else "-") + "xyz"[j]
    else:
        axis = np.round(axis, 1) / np.linalg.norm(np.round(axis, 1))
        text = "(" + ", ".join(f"{v:.2g}" for v in axis) + ")"
    degrees = float(np.round(angle * 180 / np.pi))
    return degrees, text, Rotation.from_rotvec(axis * degrees * np.pi / 180).as_matrix().T


def _label(plan: Plan, k: int) -> str:
    return f"step {k + 1} ({plan.steps[k].label})"


def _why(plan: Plan, k: int, cands: list[Candidate], pos: int, n: np.ndarray, describe, declared: bool) -> str | None:
    """Why step ``k`` is not the motion at ``pos`` (turned about another axis, the wrong way, off in size); None when
    no motion is left."""
    if pos >= len(cands):
        return None
    step = plan.steps[k]
    e = _expected(step, n)
    v = cands[pos].vector
    along = float(v @ e / np.linalg.norm(e))
    across = float(np.linalg.norm(v - along * e / np.linalg.norm(e)))
    seen = describe(cands[pos])
    unit = "deg/s" if step.rate is not None else "deg"
    said = f"planned {format_quantity(step.turn, unit, 5)} about " \
           f"{axis_name(step.axis, step.sign)}"
    if across > 0.5 * abs(along):
        mount = "the declared mounting" if declared else f"the mounting {mounting_label(n)}"
        return (f"{said}, the next motion ({seen}) turned about another axis than {mount} expects; check the fixture "
                "orientation, the step's axis or the plan's [mounting]")
    if along < 0:
        also = " (or a sign of the plan's [mounting])" if declared else ""
        return (f"{said}, the next motion ({seen}) turned the wrong way; re-run the step or correct its sign in the "
                f"plan{also}")
    return (f"{said}, the next motion ({seen}) is off by {100 * (along / np.linalg.norm(e) - 1):+.1f} %: wrong table "
            "rate or angle, or a wrong plan step")


def _not_found(plan: Plan, missing: int, departed: tuple[int, int] | None, cands: list[Candidate], pos: int,
               n: np.ndarray, describe, declared: bool, where: str) -> TestError:
    """The error for the step that could not be found; when motions were skipped before it, where the log first left
    the plan (the step named there, and why, judged on the motion that came instead)."""
    if departed is not None:
        k, at = departed
        return TestError(f"the log departs from the plan at {_label(plan, k)}: "
                         f"{_why(plan, k, cands, at, n, describe, declared)}; {_label(plan, missing)} is not found at all",
                         where)
    after = f"after step {missing}" if missing else "in the log"
    why = _why(plan, missing, cands, pos, n, describe, declared)
    if why is None:
        listed = "; ".join(describe(c) for c in cands) or "none"
        why = f"no motion left in the log (motions found: {listed}); check the plan against the log, or give {{segments}}"
    return TestError(f"{_label(plan, missing)} not found {after}: {why}", where)
