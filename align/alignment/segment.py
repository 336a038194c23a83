"""Segmentation of a rate-table log into constant-rate dwells, turns and static periods.

A sample is *steady* when the moving mean of the gyros changes by less than a
noise-scaled threshold across the sample (the ramps between table rates fail
this test). Runs of steady samples are *plateaus*; a plateau whose mean is near
the quietest plateau is *static*. Rate steps are matched, in order, to the
non-static plateaus; angle steps to the motion between consecutive static
plateaus. Everything here works on SI arrays and never reads files.

Public names
------------
Segment, Motion, SegmentOptions, noise_sigma, find_plateaus, integrate, segment_log, segments_from_ranges,
static_intervals
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.alignment.plan import Plan
from align.errors import InputError, TestError, literal
from align.io.keys import check_keys, require_keys
from align.units import DEG_S, unit_mixup_hint


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


def noise_sigma(g: np.ndarray) -> np.ndarray:
    """Robust per-sample white-noise sigma of each column from first differences.

    ``1.4826 MAD(diff) / sqrt(2)``; falls back to the plain standard deviation of
    the differences for quantised signals whose MAD is zero.
    """
    d = np.diff(g, axis=0)
    med = np.median(d, axis=0)
    sigma = 1.4826 * np.median(np.abs(d - med), axis=0) / np.sqrt(2.0)
    fallback = np.std(d, axis=0) / np.sqrt(2.0)
    return np.where(sigma > 0, sigma, fallback)


def _moving_mean(g: np.ndarray, w: int) -> np.ndarray:
    """Trailing moving mean over ``w`` samples; row ``k`` averages ``g[k:k+w]``."""
    c = np.cumsum(g, axis=0, dtype=float)
    out = np.empty((len(g) - w + 1, g.shape[1]))
    out[0] = c[w - 1]
    out[1:] = c[w:] - c[:-w]
    return out / w


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
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
    for s, e in _runs(steady_mid):
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


def _describe(g: np.ndarray, t: np.ndarray, runs: list[tuple[int, int]]) -> str:
    parts = []
    for s, e in runs[:12]:
        mean = np.mean(g[s:e], axis=0) / DEG_S
        parts.append(f"t={t[s]:.2f}-{t[e - 1]:.2f} s ({mean[0]:+.2f}, {mean[1]:+.2f}, {mean[2]:+.2f} deg/s)")
    more = f" and {len(runs) - 12} more" if len(runs) > 12 else ""
    return "; ".join(parts) + more


def _classify(g: np.ndarray, runs: list[tuple[int, int]], threshold: float) -> tuple[list[bool], np.ndarray]:
    means = np.array([np.mean(g[s:e], axis=0) for s, e in runs]).reshape(-1, 3)
    if not len(runs):
        return [], np.zeros(3)
    ref = means[int(np.argmin(np.linalg.norm(means, axis=1)))]
    is_static = [bool(np.linalg.norm(m - ref) < threshold) for m in means]
    return is_static, ref


def segment_log(
    t: np.ndarray,
    g: np.ndarray,
    plan: Plan,
    opts: SegmentOptions = SegmentOptions(),
    where: str = "log",
    sigma: np.ndarray | None = None,
) -> list[Segment]:
    """Find the plan's steps (and the static periods) in a log.

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
    list of Segment
        One per plan step (``kind`` = the step's kind, ``step`` its index), in
        order, plus the static periods (``kind="static"``).

    Raises
    ------
    TestError
        When the number of dwells or turns found differs from the plan; the
        message lists what was found and where.
    """
    if plan.kind == "mixed":
        raise InputError("the plan mixes rate and angle steps; automatic segmentation needs one kind (or give {segments})", where)
    fs = 1.0 / float(np.median(np.diff(t)))
    runs = find_plateaus(g, fs, opts, noise_sigma(g) if sigma is None else sigma)
    if plan.kind == "rate":
        threshold = 0.25 * min(abs(s.rate) for s in plan.steps)
        is_static, ref = _classify(g, runs, threshold)
        if np.linalg.norm(ref) >= threshold:
            is_static = [False] * len(runs)
        moving = [r for r, st in zip(runs, is_static) if not st]
        moving = _merge_similar(g, moving, 0.02 * threshold / 0.25, int(fs))
        if len(moving) != len(plan.steps):
            biggest = sorted(np.linalg.norm(np.mean(g[a:b], axis=0)) for a, b in runs)[-len(plan.steps):]
            hint = unit_mixup_hint(float(np.median(biggest)) / float(np.median([abs(s.rate) for s in plan.steps])))
            if runs and hint:
                raise TestError(hint, where)
            raise _count_error("constant-rate dwells", len(moving), plan, f"dwells found: {_describe(g, t, moving) or 'none'}",
                               "check the plan, {window}/{min_dwell}, or give {segments}", where)
        segs = [Segment(f"step {k + 1} ({s.label})", "rate", a, b, k) for k, (s, (a, b)) in enumerate(zip(plan.steps, moving))]
    else:
        is_static, _ = _classify(g, runs, opts.static_threshold)
        statics = [r for r, st in zip(runs, is_static) if st]
        min_angle = 0.2 * min(abs(s.angle) for s in plan.steps)
        turns = []
        for (s0, e0), (s1, e1) in zip(statics[:-1], statics[1:]):
            bias = 0.5 * (np.mean(g[s0:e0], axis=0) + np.mean(g[s1:e1], axis=0))
            angle, duration = integrate(t, g, e0, s1)
            if np.linalg.norm(angle - bias * duration) > min_angle:
                turns.append((e0, s1))
        if len(turns) != len(plan.steps):
            found = "; ".join(f"t={t[a]:.2f}-{t[b - 1]:.2f} s" for a, b in turns) or "none"
            raise _count_error("turns between static periods", len(turns), plan,
                               f"turns found: {found}; static periods: {len(statics)}",
                               "each turn must start and end at rest (check {static_threshold}, or give {segments})", where)
        segs = [Segment(f"step {k + 1} ({s.label})", "angle", a, b, k) for k, (s, (a, b)) in enumerate(zip(plan.steps, turns))]
        moving = turns
    statics = [r for r, st in zip(runs, is_static) if st]
    segs += [Segment(f"static {k + 1}", "static", a, b) for k, (a, b) in enumerate(statics)]
    return segs


def _count_error(what: str, found: int, plan: Plan, detail: str, advice: str, where: str) -> TestError:
    """The segmentation found another number of steps than the plan lists."""
    return TestError(f"found {found} {what} but the plan has {len(plan.steps)} steps; {detail}; {advice}", where)


def _merge_similar(g: np.ndarray, runs: list[tuple[int, int]], tol: float, max_gap: int) -> list[tuple[int, int]]:
    """Join consecutive plateaus split by a short glitch when their means agree within ``tol``."""
    out: list[tuple[int, int]] = []
    for s, e in runs:
        if out and s - out[-1][1] <= max_gap:
            ps, pe = out[-1]
            if np.linalg.norm(np.mean(g[ps:pe], axis=0) - np.mean(g[s:e], axis=0)) < tol:
                out[-1] = (ps, e)
                continue
        out.append((s, e))
    return out


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
    segs, k = [], 0
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


def static_intervals(x: np.ndarray, fs: float, window_s: float = 1.0, factor: float = 6.0,
                     init_static_s: float | None = None, min_duration_s: float = 1.0) -> list[tuple[int, int]]:
    """Static intervals by a moving-variance threshold (imu_tk's detector).

    The variance of each axis over a trailing window of ``window_s`` is summed;
    the threshold is ``factor`` times its median over the initial static period
    (``init_static_s``, as imu_tk does) or, without one, over the quietest tenth
    of the record. Runs below it lasting ``min_duration_s`` are kept, trimmed by
    half a window at each end.
    """
    w = max(3, int(round(window_s * fs)))
    if len(x) < 3 * w:
        raise InputError(f"only {len(x)} samples: too short for a {window_s:g} s variance window")
    c1 = np.cumsum(np.vstack([np.zeros((1, x.shape[1])), x]), axis=0)
    c2 = np.cumsum(np.vstack([np.zeros((1, x.shape[1])), x * x]), axis=0)
    mean = (c1[w:] - c1[:-w]) / w
    var = np.maximum((c2[w:] - c2[:-w]) / w - mean**2, 0.0).sum(axis=1)   # var[k]: samples k..k+w-1
    if init_static_s:
        ref = var[: max(1, int(init_static_s * fs) - w)]
    else:
        ref = np.sort(var)[: max(1, len(var) // 10)]
    thr = factor * float(np.median(ref))
    quiet = np.zeros(len(x), dtype=bool)
    quiet[w // 2 : w // 2 + len(var)] = var < thr
    out = []
    half = w // 2
    for a, b in _runs(quiet):
        a, b = a + half, b - half
        if b - a >= min_duration_s * fs:
            out.append((a, b))
    return out
