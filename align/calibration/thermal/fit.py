"""The fit of one axis: its polynomial order (and lag term) chosen by blocked cross-validation, the coefficients
from all samples, and their covariance inflated for autocorrelated residuals.

Order by cross-validation
    The record is cut into :data:`CV_BLOCKS` contiguous blocks (each much longer than the residuals'
    correlation time); block ``b`` belongs to fold ``b mod K``, so that every fold spans the whole temperature
    range while neighbouring samples, which are correlated, stay in the same fold (blocked cross-validation,
    Roberts et al. 2017, Ecography 40:913). Each candidate (order 0..max, with and without the lag term) is
    fitted on K-1 folds and scored by its mean squared error on each held-out block. The simplest candidate
    whose paired excess error over the best, across the held-out blocks, is within one standard error of that
    excess (the one-standard-error rule, Hastie, Tibshirani and Friedman, ESL 7.10) is chosen: a term is added
    only when it helps by more than the blocks disagree.

Uncertainty band
    Residuals of a thermal record are autocorrelated (noise, flicker, the lag left over), so the textbook
    ``s^2 (X^T X)^-1`` is too small. It is multiplied by the residuals' integrated autocorrelation time ``tau``
    (in samples), estimated by the blocking method from the residual sums over the blocks (free from the sums
    of :mod:`~align.calibration.thermal.sums`): with the temperature nearly constant over a correlation time,
    ``tau s^2 (X^T X)^-1`` is the long-run (Newey-West) covariance. ``sqrt(tau)`` is reported as the band's
    inflation.

Public names
------------
AxisFit, candidates, cross_validate, choose, fit_axis, physical, autocorrelation_time, FOLDS
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.calibration.thermal.model import AxisModel, _shift_matrix
from align.calibration.thermal.sums import Sums, solve, sse

__all__ = ["AxisFit", "candidates", "cross_validate", "choose", "fit_axis", "physical", "autocorrelation_time", "FOLDS"]

#: folds of the blocked cross-validation
FOLDS = 5
#: contiguous blocks of the cross-validation (each held out with its fold)
CV_BLOCKS = 40
#: fewest batches the blocking method of the autocorrelation time uses
MIN_BATCHES = 8


@dataclass(frozen=True)
class AxisFit:
    """A fit in the scaled variables of :class:`~align.calibration.thermal.sums.Sums`.

    Attributes
    ----------
    order : int
    lag : bool
    c : ndarray, shape (p,)
        Coefficients of ``(1, x, ..., x^order[, r])``, readings less their mean.
    cov : ndarray, shape (p, p)
        The covariance: ``cov_white`` times ``tau``.
    cov_white : ndarray, shape (p, p)
        ``s^2 (X^T X)^-1``, the band if the residuals were white.
    sse : float
        Sum of squared residuals, SI^2.
    n : int
        Samples.
    tau : float
        Integrated autocorrelation time of the residuals, samples (the variance inflation).
    """

    order: int
    lag: bool
    c: np.ndarray
    cov: np.ndarray
    cov_white: np.ndarray
    sse: float
    n: int
    tau: float = 1.0


def candidates(max_order: int, lag: bool | None) -> list[tuple[int, bool]]:
    """The (order, lag) pairs tried, simplest first: order 0..max_order, the lag term off, on, or both (None).

    Examples
    --------
    >>> candidates(1, None)
    [(0, False), (0, True), (1, False), (1, True)]
    """
    lags = [False, True] if lag is None else [lag]
    return [(k, g) for k in range(max_order + 1) for g in lags]


def cross_validate(s: Sums, axis: int, cands: list[tuple[int, bool]], folds: int = FOLDS,
                   groups: int = CV_BLOCKS) -> np.ndarray:
    """Held-out mean squared error of each candidate on each cross-validation block (C, G), SI^2.

    The B blocks of ``s`` are merged into ``groups`` contiguous cross-validation blocks (long against the
    residuals' correlation); block ``g`` is held out with its fold ``g mod folds`` (module docstring).
    """
    y = s.axis_column(axis)
    per = s.per_block()
    g = min(groups, s.blocks)
    group = (np.arange(s.blocks) * g) // s.blocks
    cv = np.zeros((g,) + per.shape[1:])
    np.add.at(cv, group, per)
    fold = np.arange(g) % folds
    total = cv.sum(axis=0)
    out = np.full((len(cands), g), np.nan)
    for f in range(folds):
        idx = np.flatnonzero((fold == f) & (cv[:, 0, 0] > 0))
        held = cv[idx]
        train = total - held.sum(axis=0)
        for i, (k, lag) in enumerate(cands):
            cols = s.columns(k, lag)
            c = solve(train, cols, y)
            A = held[:, cols][:, :, cols]
            sse_j = held[:, y, y] - 2.0 * held[:, cols, y] @ c + np.einsum("hij,i,j->h", A, c, c)
            out[i, idx] = sse_j / held[:, 0, 0]
    return out


def choose(mse: np.ndarray, cands: list[tuple[int, bool]]) -> int:
    """The candidate the one-standard-error rule picks (module docstring): the simplest (fewest terms, then
    the lower error) whose mean excess error over the best is within the standard error of that excess, over
    the held-out blocks."""
    ok = np.all(np.isfinite(mse), axis=0)
    m = mse[:, ok]
    mean = m.mean(axis=1)
    best = int(np.argmin(mean))
    order = sorted(range(len(cands)), key=lambda i: (cands[i][0] + cands[i][1], mean[i]))
    for i in order:
        diff = m[i] - m[best]
        se = diff.std(ddof=1) / np.sqrt(diff.size) if diff.size > 1 else 0.0
        if diff.mean() <= se:
            return i
    return best


def autocorrelation_time(sums: np.ndarray, counts: np.ndarray, variance: float, p: int = 0,
                         min_batches: int = MIN_BATCHES) -> float:
    """Integrated autocorrelation time of residuals, in samples (>= 1), from their sums over consecutive blocks.

    The blocking method (Flyvbjerg and Petersen 1989, J. Chem. Phys. 91:461): for residuals with autocorrelation
    ``rho``, a batch of ``m`` samples much longer than the correlation has ``var(sum) = m sigma^2 tau``,
    ``tau = 1 + 2 sum_k rho_k``. Blocks are merged in pairs while at least ``min_batches`` remain; ``tau`` is
    estimated at every size (times ``B / (B - p)``: the fit's ``p`` terms absorb that much of the batch-level
    spread) and the largest is kept, so a correlation longer than the smallest block is not missed.

    Parameters
    ----------
    sums : ndarray, shape (B,)
        Residual sum of each block, in time order (empty blocks skipped).
    counts : ndarray, shape (B,)
        Samples in each block.
    variance : float
        Residual variance per sample.
    p : int
        Terms fitted.

    Returns
    -------
    float

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> e = rng.normal(size=64000)
    >>> s = e.reshape(200, 320).sum(axis=1)
    >>> 0.7 < autocorrelation_time(s, np.full(200, 320), 1.0) < 1.6
    True
    """
    keep = counts > 0
    s, c = np.asarray(sums, float)[keep], np.asarray(counts, float)[keep]
    if variance <= 0 or len(s) < 2:
        return 1.0
    best = 1.0
    while len(s) >= min_batches:
        b = len(s)
        best = max(best, float(np.sum(s * s) / (variance * c.sum())) * b / max(b - p, 1))
        half = b // 2
        s = s[:2 * half].reshape(half, 2).sum(axis=1)
        c = c[:2 * half].reshape(half, 2).sum(axis=1)
    return best


def fit_axis(s: Sums, axis: int, order: int, lag: bool, mask: np.ndarray | None = None) -> AxisFit:
    """Coefficients from every selected sample and their covariance: ``tau s^2 (X^T X)^-1``, the white-noise
    covariance inflated by the residuals' integrated autocorrelation time (:func:`autocorrelation_time`; a
    slowly varying temperature makes the design nearly constant over a correlation time, where this is the
    long-run variance of Newey and West).

    Parameters
    ----------
    s : Sums
    axis : int
        0, 1, 2.
    order : int
    lag : bool
    mask : ndarray of bool, shape (S,), optional
        Segments used (a branch); all when None.

    Returns
    -------
    AxisFit
    """
    y = s.axis_column(axis)
    cols = s.columns(order, lag)
    per_block = s.per_block(mask)
    total = per_block.sum(axis=0)
    c = solve(total, cols, y)
    n = int(round(total[0, 0]))
    p = len(cols)
    resid = max(sse(total, cols, y, c), 0.0)
    try:
        white = resid / max(n - p, 1) * np.linalg.inv(total[np.ix_(cols, cols)])
    except np.linalg.LinAlgError:
        white = np.full((p, p), np.nan)
    sums = per_block[:, 0, y] - per_block[:, 0, cols] @ c
    tau = autocorrelation_time(sums, per_block[:, 0, 0], resid / max(n, 1), p)
    return AxisFit(order, lag, c, tau * white, white, resid, n, tau)


def physical(s: Sums, fit: AxisFit, axis: int, tref: float, white: bool = False) -> AxisModel:
    """The fit as an :class:`AxisModel` about ``tref``: powers of ``d = T - tref`` in SI per C^k, the lag in SI
    per (C/s), the mean of the readings put back into ``c_0``, the covariance carried by the same linear map."""
    L = _shift_matrix(fit.order, tref - s.tc, s.hs)
    J = L if not fit.lag else np.block([[L, np.zeros((len(L), 1))], [np.zeros((1, len(L))), np.eye(1) / s.rs]])
    full = J @ fit.c
    coef = full[:fit.order + 1].copy()
    coef[0] += s.ymean[axis]
    cov = J @ (fit.cov_white if white else fit.cov) @ J.T
    return AxisModel(coef, float(full[-1]) if fit.lag else None, cov)
