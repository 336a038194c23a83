"""Heating and cooling branches of a thermal record, and the hysteresis between them.

The temperature rate is the slope of a straight line fitted over a centred window (a smooth derivative that a
1 C-stepped or noisy reading does not upset, if the window spans several steps).
A sample is heating where the rate exceeds ``min_rate``, cooling where it is below ``-min_rate``, neither in
between (a soak); runs of one sign shorter than ``min_branch_s`` (a brief re-warming, a wiggle) count as neither.

Hysteresis is the largest difference between the heating and the cooling fit at equal temperature over the
range both branches cover: each branch is fitted on its own samples with the order chosen for the axis (no lag
term: within one branch the rate hardly changes sign or size, so a lag would be confounded with the constant;
the branch difference therefore includes what a lag term explains). Its 1-sigma is that of the difference at
the temperature where it is largest, from the two branches' covariances (independent samples; each inflated for
its residuals' autocorrelation as the axis fit's is).

Public names
------------
temperature_rate, branch_labels, Hysteresis, hysteresis, crosscheck, branch_counts
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.calibration.thermal.fit import fit_axis
from align.calibration.thermal.model import design
from align.calibration.thermal.sums import Sums, solve, sse

__all__ = ["temperature_rate", "branch_labels", "Hysteresis", "hysteresis", "crosscheck", "branch_counts"]

HEATING, COOLING = 1, -1
#: a branch moves at least this fraction of the typical rate (the turns between branches, where the rate passes
#: through zero, belong to neither)
STEADY = 0.5


def temperature_rate(t: np.ndarray, temperature: np.ndarray, window_s: float) -> np.ndarray:
    """dT/dt, C/s: the slope of a straight line fitted to the temperature over a centred window (a
    Savitzky-Golay first derivative); within half a window of either end, the slope of the first or last full
    window. A long record is averaged over short blocks first (a sixteenth of the half-window: the temperature
    is a straight line over them), the slope found on the block means and interpolated back to every sample.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Time, s (uniform sampling assumed: the median step is used).
    temperature : ndarray, shape (n,)
        C.
    window_s : float
        Width of the window, s.

    Returns
    -------
    ndarray, shape (n,)

    Examples
    --------
    >>> t = np.arange(600.0)
    >>> float(temperature_rate(t, 20 + 0.05 * t, 60.0)[0].round(6))
    0.05
    """
    n = len(t)
    if n < 3:
        return np.zeros(n)
    dt = float(np.median(np.diff(t[:100_001])))
    h = max(1, round(window_s / dt / 2))
    m = max(1, min(h // 16, n // 3))
    nb = n // m
    tb = t[:nb * m].reshape(nb, m).mean(axis=1) if m > 1 else np.asarray(t, float)
    x = np.asarray(temperature, float)
    xb = x[:nb * m].reshape(nb, m).mean(axis=1) if m > 1 else x
    hb = int(min(max(1, round(h / m)), (nb - 1) // 2))
    k = np.arange(-hb, hb + 1, dtype=float)
    inner = np.convolve(xb - xb[hb], k[::-1] / (dt * m * float(k @ k)), mode="valid")
    rate = np.concatenate([np.full(hb, inner[0]), inner, np.full(hb, inner[-1])])
    return rate if m == 1 else np.interp(t, tb, rate)


def branch_labels(t: np.ndarray, rate: np.ndarray, min_rate: float, min_branch_s: float,
                  steady: float = STEADY) -> np.ndarray:
    """+1 heating, -1 cooling, 0 neither, per sample (module docstring).

    Examples
    --------
    >>> t = np.arange(10.0)
    >>> branch_labels(t, np.array([1, 1, 1, 1, 0, -1, -1, 1, 1, 1.0]), 0.5, 2.5).tolist()
    [1, 1, 1, 1, 0, 0, 0, 0, 0, 0]
    """
    size = np.abs(rate[::max(1, len(rate) // 1_000_000)])  # the typical rate: a million samples tell it
    moving = size[size > min_rate]
    floor = max(min_rate, steady * float(np.median(moving))) if moving.size else min_rate
    label = (rate > floor).astype(np.int8)
    label -= rate < -floor
    if len(label) == 0:
        return label
    cuts = np.flatnonzero(label[1:] != label[:-1]) + 1
    starts, ends = np.r_[0, cuts], np.r_[cuts, len(label)]
    for a, b in zip(starts, ends):
        if label[a] != 0 and t[b - 1] - t[a] < min_branch_s:
            label[a:b] = 0
    return label


def branch_counts(s: Sums) -> dict[str, int]:
    """Samples on each branch: ``{"heating": n, "cooling": n}``."""
    return {"heating": s.count(s.label == HEATING), "cooling": s.count(s.label == COOLING)}


@dataclass(frozen=True)
class Hysteresis:
    """The largest heating-minus-cooling difference at equal temperature.

    Attributes
    ----------
    value : float
        Heating minus cooling where it is largest in size, SI (signed).
    sigma : float
        Its 1-sigma, SI.
    at : float
        The temperature where it is largest, C.
    lo, hi : float
        The temperature range both branches cover, C.
    """

    value: float
    sigma: float
    at: float
    lo: float
    hi: float


def hysteresis(s: Sums, axis: int, order: int, points: int = 201) -> Hysteresis | None:
    """The hysteresis of one axis (module docstring); None when the branches do not overlap in temperature."""
    heat, cool = s.label == HEATING, s.label == COOLING
    if not heat.any() or not cool.any():
        return None
    lo = max(float(s.tlo[heat].min()), float(s.tlo[cool].min()))
    hi = min(float(s.thi[heat].max()), float(s.thi[cool].max()))
    if not hi > lo:
        return None
    fh, fc = fit_axis(s, axis, order, False, heat), fit_axis(s, axis, order, False, cool)
    grid = np.linspace(lo, hi, points)
    X = design(s.scaled(grid), order)
    diff = X @ (fh.c - fc.c)
    var = np.einsum("ni,ij,nj->n", X, fh.cov + fc.cov, X)
    i = int(np.argmax(np.abs(diff)))
    return Hysteresis(float(diff[i]), float(np.sqrt(max(var[i], 0.0))), float(grid[i]), lo, hi)


def crosscheck(s: Sums, axis: int, order: int, lag: bool) -> tuple[float, float] | None:
    """The model fitted on one branch and judged on the other: rms residual (heating -> cooling, cooling ->
    heating), SI; None without both branches."""
    heat, cool = s.label == HEATING, s.label == COOLING
    if not heat.any() or not cool.any():
        return None
    y, cols = s.axis_column(axis), s.columns(order, lag)
    out = []
    for train, test in ((heat, cool), (cool, heat)):
        held = s.total(test)
        c = solve(s.total(train), cols, y)
        out.append(float(np.sqrt(max(sse(held, cols, y, c), 0.0) / held[0, 0])))
    return out[0], out[1]
