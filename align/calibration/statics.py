"""Static intervals of a multi-position session by a moving-variance threshold (imu_tk's detector).

Public names
------------
static_intervals, initial_static_period, common_intervals
"""

from __future__ import annotations

import numpy as np

from align.alignment.segment import true_runs
from align.errors import InputError


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
    for a, b in true_runs(quiet):
        a, b = a + half, b - half
        if b - a >= min_duration_s * fs:
            out.append((a, b))
    return out


def initial_static_period(x: np.ndarray, fs: float, window_s: float = 1.0, factor: float = 6.0,
                          min_duration_s: float = 1.0, where: str = "log") -> float:
    """Length (s) of the static period a record starts with, for a detector without a given one.

    The record's quiet windows (``factor`` times the median variance of its quietest tenth, as
    :func:`static_intervals` without ``init_static_s``) are found; the first run must start within a
    window of the first sample. Its length, half a window added back at each end, is the initial period
    that :func:`static_intervals` then takes its threshold from (imu_tk's ``T_init``).

    Raises
    ------
    TestError
        The record does not start at rest.
    """
    from align.errors import TestError

    runs = static_intervals(x, fs, window_s, factor, None, min_duration_s)
    w = max(3, int(round(window_s * fs)))
    if not runs or runs[0][0] > w:
        moving = runs[0][0] / fs if runs else len(x) / fs
        raise TestError(f"the record does not start at rest (the first {moving:.1f} s move): the initial static period "
                        "gives the gyro bias and the static threshold; record one first, or give its length with "
                        "{init_static_s}", where)
    return (runs[0][1] + w // 2) / fs


def common_intervals(first: list, second: list, min_samples: int) -> list[tuple[int, int]]:
    """The sample ranges inside an interval of both lists (``(start, end)``, end exclusive), at least
    ``min_samples`` long: static for two sensors at once."""
    if not first or not second:
        return []
    n = max(first[-1][1], second[-1][1])
    both = np.zeros(n, dtype=bool)
    for a, b in first:
        both[a:b] = True
    other = np.zeros(n, dtype=bool)
    for a, b in second:
        other[a:b] = True
    return [(a, b) for a, b in true_runs(both & other) if b - a >= min_samples]
