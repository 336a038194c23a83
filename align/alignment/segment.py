"""Segmentation of a rate-table log into constant-rate dwells, turns and static periods.

A sample is *steady* when the moving mean of the gyros changes by less than a
noise-scaled threshold across the sample (the ramps between table rates fail
this test). Runs of steady samples are *plateaus*; a plateau whose mean is near
the quietest plateau is *static*. Rate steps are matched, in order, to the
non-static plateaus; angle steps to the motion between consecutive static
plateaus. Everything here works on SI arrays and never reads files.

Public names
------------
Segment, Motion, Segmentation, SegmentOptions, noise_sigma, find_plateaus, integrate, segment_log, moves_between,
untaken, segments_from_ranges, true_runs
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.alignment.match import Candidate, match_steps
from align.alignment.plan import Plan
from align.errors import InputError, literal
from align.io.keys import check_keys, require_keys
from align.units import DEG, DEG_S


@dataclass(frozen=True)
class Segment:
    """A stretch of the log, samples ``start`` to ``end`` (end exclusive).

    ``kind`` is ``"rate"``, ``"angle"`` or ``"static"``; ``step`` is the plan
    step index (0-based) or None for static periods.
    """

    name: str
    kind: str
    start: int
    end: int
    step: int | None = None

    @property
    def n(self) -> int:
        return self.end - self.start


@dataclass(frozen=True)
class Motion:
    """A motion in the log that no plan step claimed (a fixture re-orientation, a stop and restart, ...).

    Attributes
    ----------
    name : str
        ``"motion 1"``, ...
    kind : str
        ``"rate"`` (a constant-rate plateau) or ``"turn"`` (the motion between two static periods).
    start, end : int
        Samples (end exclusive).
    t_start, t_end : float
        s.
    value : float
        Size: rad/s for a plateau, rad for a turn.
    axis : tuple of 3 float
        Unit vector of the motion's axis in the system frame (through the estimated ``A``).
    label : str
        For people, e.g. ``"about +z at 20.0 deg/s"``.
    """

    name: str
    kind: str
    start: int
    end: int
    t_start: float
    t_end: float
    value: float
    axis: tuple[float, float, float]
    label: str

    def to_dict(self) -> dict:
        """The JSON form (SI values: rad/s or rad, s)."""
        return {"name": self.name, "kind": self.kind, "start": self.start, "end": self.end, "t_start": self.t_start,
                "t_end": self.t_end, "value": self.value, "axis": list(self.axis), "label": self.label}


@dataclass(frozen=True)
class SegmentOptions:
    """Settings of the automatic segmentation (SI units).

    Attributes
    ----------
    window_s : float
        Moving-mean window, s.
    margin_s : float
        Trimmed from each end of every plateau, s, beyond the ramps themselves.
    min_plateau_s : float
        Shortest steady run that counts as a dwell or static period, s.
    static_threshold : float
        A plateau within this rate (rad/s) of the quietest plateau is static.
    """

    window_s: float = 0.1
    margin_s: float = 0.1
    min_plateau_s: float = 0.5
    static_threshold: float = 1.0 * DEG_S


def noise_sigma(g: np.ndarray, most: int = 200_000) -> np.ndarray:
    """Robust per-sample white-noise sigma of each column from first differences.

    ``1.4826 MAD(diff) / sqrt(2)``, over at most ``most`` differences evenly spread through the log
    (a robust scale needs no more); falls back to the plain standard deviation of the differences for
    quantised signals whose MAD is zero.
    """
    if len(g) > 2 * most:  # adjacent differences, at evenly spread samples
        k = np.arange(0, len(g) - 1, (len(g) - 1) // most)
        d = g[k + 1] - g[k]
    else:
        d = np.diff(g, axis=0)
    med = np.median(d, axis=0)
    sigma = 1.4826 * np.median(np.abs(d - med), axis=0) / np.sqrt(2.0)
    if np.all(sigma > 0):
        return sigma
    return np.where(sigma > 0, sigma, np.std(np.diff(g, axis=0), axis=0) / np.sqrt(2.0))


def _moving_mean(g: np.ndarray, w: int) -> np.ndarray:
    """Trailing moving mean over ``w`` samples; row ``k`` averages ``g[k:k+w]``."""
    c = np.cumsum(g, axis=0, dtype=float)
    out = np.empty((len(g) - w + 1, g.shape[1]))
    out[0] = c[w - 1]
    out[1:] = c[w:] - c[:-w]
    return out / w


def true_runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Start/end (exclusive) of the runs of True in a boolean array."""
    edges = np.diff(np.concatenate(([0], mask.view(np.int8), [0])))
    starts = np.flatnonzero(edges == 1)
    ends = np.flatnonzero(edges == -1)
    return list(zip(starts.tolist(), ends.tolist()))


def find_plateaus(g: np.ndarray, fs: float, opts: SegmentOptions, sigma: np.ndarray | None = None) -> list[tuple[int, int]]:
    """Steady runs of ``g`` (shape (n, 3), rad/s) as (start, end) sample ranges.

    A sample ``k`` is steady when the means of the windows just before and just
    after it differ by less than ``6 sigma sqrt(2/w) + 1e-4 |mean rate|`` on every
    axis, where ``w`` is the window length in samples. Runs are trimmed by
    ``margin_s`` on both sides and kept when at least ``min_plateau_s`` long.
    """
    n = len(g)
    w = max(3, int(round(opts.window_s * fs)))
    if n < 4 * w:
        return []
    if sigma is None:
        sigma = noise_sigma(g)
    mm = _moving_mean(g, w)                      # mm[k] = mean g[k:k+w]
    before, after = mm[: n - 2 * w + 1], mm[w:]  # windows ending at k+w, starting at k+w
    thr = 6.0 * sigma * np.sqrt(2.0 / w) + 1e-4 * np.linalg.norm(after, axis=1, keepdims=True) + 1e-12
    steady_mid = np.all(np.abs(after - before) < thr, axis=1)
    # steady_mid[k]: the windows g[k:k+w] and g[k+w:k+2w] agree, centred on sample k+w.
    # A run of centres is the plateau; margin_s more is trimmed from each end.
    margin = int(round(opts.margin_s * fs))
    shortest = max(int(round(opts.min_plateau_s * fs)), 2)
    out = []
    for s, e in true_runs(steady_mid):
        a, b = s + w + margin, e + w - margin
        if b - a >= shortest:
            out.append((a, b))
    return out


def integrate(t: np.ndarray, g: np.ndarray, start: int, end: int) -> tuple[np.ndarray, float]:
    """Rectangle-rule integral ``sum g[k] (t[k+1] - t[k])`` over samples ``start..end-1``.

    Returns the integrated vector and the duration it covers (s), so that a bias
    ``b`` contributes exactly ``b * duration`` (Eq 31).
    """
    stop = min(end + 1, len(t))
    dt = np.diff(t[start:stop])
    if len(dt) < end - start:  # the last sample of the log: repeat the last step
        dt = np.append(dt, dt[-1] if len(dt) else 0.0)
    return dt @ g[start:end], float(dt.sum())


def _split_static(g: np.ndarray, runs: list[tuple[int, int]], plan: Plan,
                  opts: SegmentOptions) -> tuple[list[tuple[int, int]], list[tuple[int, int]]]:
    """The plateaus that are static and the ones that move.

    A plateau is static when its mean lies within ``static_threshold`` (and, for rate plans, a quarter of the
    slowest planned rate) of the quietest plateau; for a rate plan the quietest plateau itself must be slower than
    half the slowest planned rate (a log without rests is all dwells).
    """
    if not runs:
        return [], []
    means = np.array([np.mean(g[a:b], axis=0) for a, b in runs])
    ref = means[int(np.argmin(np.linalg.norm(means, axis=1)))]
    threshold = opts.static_threshold
    if plan.kind == "rate":
        slowest = min(abs(s.turn) for s in plan.steps)
        threshold = min(threshold, 0.25 * slowest)
        if np.linalg.norm(ref) >= 0.5 * slowest:
            return [], list(runs)
    static = np.linalg.norm(means - ref, axis=1) < threshold
    return [r for r, st in zip(runs, static) if st], [r for r, st in zip(runs, static) if not st]


def _static_bias(g: np.ndarray, statics: list[tuple[int, int]]) -> np.ndarray:
    """Mean reading over the static periods (zeros without any): the bias the candidates are judged with."""
    if not statics:
        return np.zeros(g.shape[1])
    return np.sum([g[a:b].sum(axis=0) for a, b in statics], axis=0) / sum(b - a for a, b in statics)


def _turns(t: np.ndarray, g: np.ndarray, statics: list[tuple[int, int]], sigma: np.ndarray,
           head: bool) -> list[Candidate]:
    """The motions between consecutive static periods (and, with ``head``, before the first), bias removed.

    A stretch is a turn when its integrated reading, less the neighbouring rests' bias, exceeds
    ``max(1 deg, 10 sigma sqrt(dt T))`` (a static period split in two is not a turn).
    """
    dt = float(np.median(np.diff(t)))
    pieces: list[tuple[tuple[int, int] | None, tuple[int, int]]] = (
        [(None, statics[0])] if head and statics and statics[0][0] > 0 else [])
    pieces += list(zip(statics[:-1], statics[1:]))
    out = []
    for before, after in pieces:
        e0, s1 = (0 if before is None else before[1]), after[0]
        if s1 <= e0:
            continue
        rests = [r for r in (before, after) if r is not None]
        bias = np.mean([np.mean(g[a:b], axis=0) for a, b in rests], axis=0)
        angle, duration = integrate(t, g, e0, s1)
        v = angle - bias * duration
        if np.linalg.norm(v) > max(DEG, 10 * float(np.linalg.norm(sigma)) * np.sqrt(dt * duration)):
            out.append(Candidate("turn", e0, s1, v))
    return out


def _describer(t: np.ndarray):
    def describe(c: Candidate) -> str:
        v = c.vector / (DEG_S if c.kind == "rate" else DEG)
        unit = "deg/s" if c.kind == "rate" else "deg"
        return f"t={t[c.start]:.2f}-{t[c.end - 1]:.2f} s: ({v[0]:+.2f}, {v[1]:+.2f}, {v[2]:+.2f}) {unit}"
    return describe


def _merge_similar(g: np.ndarray, runs: list[tuple[int, int]], tol: float, max_gap: int) -> list[tuple[int, int]]:
    """Join consecutive plateaus split by a short glitch: their means, and the samples between, agree within ``tol``."""
    out: list[tuple[int, int]] = []
    for s, e in runs:
        if out and s - out[-1][1] <= max_gap:
            ps, pe = out[-1]
            mean = np.mean(g[ps:pe], axis=0)
            if np.linalg.norm(mean - np.mean(g[s:e], axis=0)) < tol and np.linalg.norm(mean - np.mean(g[pe:s], axis=0)) < tol:
                out[-1] = (ps, e)
                continue
        out.append((s, e))
    return out


@dataclass(frozen=True)
class Segmentation:
    """What :func:`segment_log` found.

    Attributes
    ----------
    segments : tuple of Segment
        One per plan step, in plan order (``step`` its index), then the static periods.
    unclaimed : tuple of Candidate
        Motions no step took (plateaus and turns between rests), in time order; vectors in the gyro frame.
    mounting : ndarray, shape (3, 3)
        The nominal mounting ``N`` the steps were found with (:mod:`align.alignment.geometry`).
    source : str
        ``"declared"`` (the plan's ``[mounting]``) or ``"detected"``.
    """

    segments: tuple[Segment, ...]
    unclaimed: tuple[Candidate, ...]
    mounting: np.ndarray
    source: str


def segment_log(
    t: np.ndarray,
    g: np.ndarray,
    plan: Plan,
    opts: SegmentOptions = SegmentOptions(),
    where: str = "log",
    sigma: np.ndarray | None = None,
) -> Segmentation:
    """Find the plan's steps (in order, among whatever else the log holds) and the static periods.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Time, s, increasing.
    g : ndarray, shape (n, 3)
        Gyro readings, rad/s.
    plan : Plan
        Steps in the order they were run; all rate steps or all angle steps.
    opts : SegmentOptions
    where : str
        Name of the log, for messages.
    sigma : ndarray, shape (3,), optional
        Per-sample noise (rad/s) if already known, see :func:`noise_sigma`.

    Returns
    -------
    Segmentation
        Rate steps are constant-rate plateaus; angle steps the motion between two rests (a log that starts
        moving gives a turn from its first sample). Motions the plan does not list are kept as unclaimed.

    Raises
    ------
    TestError
        When a planned step cannot be found (named, with what the log shows instead), a unit mix-up, or an
        IMU mounted at an angle that the plan does not declare (:func:`align.alignment.match.match_steps`).
    HandednessError
        When the steps fit only a mirrored mounting.
    """
    if plan.kind == "mixed":
        raise InputError("the plan mixes rate and angle steps; automatic segmentation needs one kind (or give {segments})", where)
    fs = 1.0 / float(np.median(np.diff(t)))
    sigma = noise_sigma(g) if sigma is None else sigma
    runs = find_plateaus(g, fs, opts, sigma)
    statics, moving = _split_static(g, runs, plan, opts)
    bias = _static_bias(g, statics)
    turns = _turns(t, g, statics, sigma, head=plan.kind == "angle")
    if plan.kind == "rate":
        moving = _merge_similar(g, moving, 0.08 * min(abs(s.turn) for s in plan.steps), int(fs))
        cands = [Candidate("rate", a, b, np.mean(g[a:b], axis=0) - bias) for a, b in moving]
    else:
        cands = turns
    sizes = [float(np.linalg.norm(np.mean(g[a:b], axis=0) - bias)) for a, b in runs] if plan.kind == "rate" else None
    match = match_steps(plan, cands, _describer(t), where, sizes=sizes)
    segs = [Segment(f"step {k + 1} ({s.label})", s.kind, a, b, k) for k, (s, (a, b)) in enumerate(zip(plan.steps, match.ranges))]
    segs += [Segment(f"static {k + 1}", "static", a, b) for k, (a, b) in enumerate(statics)]
    unclaimed = list(match.unclaimed)
    if plan.kind == "rate":  # the moves between rests that hold no dwell at all (fixture re-orientations)
        taken = [(s.start, s.end) for s in segs if s.kind == "rate"] + [(c.start, c.end) for c in unclaimed]
        unclaimed += untaken(turns, taken)
    unclaimed.sort(key=lambda c: c.start)
    return Segmentation(tuple(segs), tuple(unclaimed), match.mounting, match.source)


def untaken(turns: list[Candidate], taken: list[tuple[int, int]]) -> list[Candidate]:
    """The turns between rests that overlap none of the ``taken`` sample ranges: motions no step holds."""
    return [c for c in turns if not any(a < c.end and c.start < b for a, b in taken)]


def moves_between(t: np.ndarray, g: np.ndarray, segments: list[Segment], sigma: np.ndarray) -> list[Candidate]:
    """Motions between the static periods of explicit ``segments`` that no step segment holds (fixture moves)."""
    statics = sorted((s.start, s.end) for s in segments if s.kind == "static")
    return untaken(_turns(t, g, statics, sigma, head=False), [(s.start, s.end) for s in segments if s.step is not None])


#: the keys of one range of an explicit segments file
RANGE_KEYS = ("start", "end")


def _sample_range(name: str, rng: object, n: int, where: str) -> tuple[int, int]:
    """``start``, ``end`` of one explicit range, checked: integers, ``0 <= start < end <= n``."""
    here = f"{where}: {name}"
    if not isinstance(rng, dict):
        raise InputError(f"must be an object {{\"start\": i, \"end\": j}} of sample indices, got {literal(repr(rng))}", here)
    check_keys(rng, RANGE_KEYS, here)
    require_keys(rng, {"start": '"start": 0', "end": '"end": 1000'}, here)
    a, b = rng["start"], rng["end"]
    if not all(isinstance(v, int) and not isinstance(v, bool) for v in (a, b)):
        raise InputError(f"start={literal(repr(a))}, end={literal(repr(b))}: sample indices must be whole numbers", here)
    if not 0 <= a < b <= n:
        raise InputError(f"start={a}, end={b} is not a sample range inside the log's {n} rows", here)
    return a, b


def segments_from_ranges(ranges: dict, plan: Plan, n: int, where: str = "segments") -> list[Segment]:
    """Segments from explicit sample ranges ``{name: {"start": i, "end": j}}`` (imucal's form).

    Names beginning with ``static`` are static periods; the others are matched to
    the plan's steps in file order. ``end`` is exclusive. Each range holds just
    ``start`` and ``end`` (integers, ``0 <= start < end <= n``); ranges must not
    overlap.
    """
    segs: list[Segment] = []
    k = 0
    for name, rng in ranges.items():
        a, b = _sample_range(str(name), rng, n, where)
        for other in segs:
            if a < other.end and other.start < b:
                raise InputError(f"samples {a}-{b} overlap '{literal(other.name)}' ({other.start}-{other.end}); "
                                 "a sample belongs to one segment", f"{where}: {name}")
        if str(name).lower().startswith("static"):
            segs.append(Segment(str(name), "static", a, b))
            continue
        if k >= len(plan.steps):
            raise InputError(f"more step segments than the plan's {len(plan.steps)} steps", f"{where}: {name}")
        segs.append(Segment(str(name), plan.steps[k].kind, a, b, k))
        k += 1
    if k != len(plan.steps):
        raise InputError(f"{k} step segments for a plan of {len(plan.steps)} steps; give one per step, in plan order", where)
    return segs
