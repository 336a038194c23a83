"""IEEE Std 952 point readouts of an Allan deviation curve, each with its 68.3 % interval.

IEEE Std 952-1997 Annex C reads three numbers off the curve, each where it is defined:

* ``N_tau1``: the straight line of slope -1/2 through the region where the curve has that slope
  (white FM: ``sigma^2 = N^2 / tau``), read at ``tau = 1 s``;
* ``B_floor``: the flat bottom of the curve divided by ``sqrt(2 ln 2 / pi) = 0.664``;
* ``K_tau3``: the straight line of slope +1/2 through the region of that slope
  (``sigma^2 = K^2 tau / 3``), read at ``tau = 3 s``.

The regions of slope +/-1/2 are where the local slope ``d ln sigma / d ln tau`` of the fitted
model is within 0.1 of it (the fitted slopes; from the curve itself without a model). Each line's
coefficient is the generalised least-squares fit of one column to the Allan variances of its
region, ``c = (a' S^-1 y) / (a' S^-1 a)``, ``var c = 1 / (a' S^-1 a)`` with ``S`` the covariance of
the overlapping Allan variances (:mod:`align.noise.covariance`); the floor is the mean Allan
variance of the contiguous points within 10 % of the lowest deviation among those with at least
:data:`FLOOR_EDF` degrees of freedom (never a last point of a few degrees of freedom), its
variance ``1' S 1 / n^2``. A coefficient of variance ``v`` has ``edf = 2 c^2 / v`` and the
chi-square interval of NIST SP 1065 section 5.3 (Eq 5.34).

Public names
------------
point_readouts, FLOOR_EDF, READOUT_KEYS
"""

from __future__ import annotations

import numpy as np

from align.noise.model import avar_design

__all__ = ["point_readouts", "FLOOR_EDF", "READOUT_KEYS"]

#: fewest equivalent degrees of freedom of a point the floor may be read at (deviation known to about 7 %, 68 %)
FLOOR_EDF = 30.0

#: most points a slope line is fitted to (log-spaced within its region)
LINE_POINTS = 16

#: the keys of a readout dict: value, 68.3 % interval, and the tau the floor was read at (SI)
READOUT_KEYS = ("N_tau1", "N_tau1_lo", "N_tau1_hi", "B_floor", "B_floor_lo", "B_floor_hi", "B_floor_tau",
                "K_tau3", "K_tau3_lo", "K_tau3_hi")

_SLOPES = np.array([-1.0, -0.5, 0.0, 0.5, 1.0])  # d ln sigma / d ln tau of each term


def _interval(c: float, var: float, level: float = 0.682689492137086) -> tuple[float, float]:
    """68.3 % chi-square interval of ``sqrt(c)`` for a variance estimate ``c`` of variance ``var``."""
    from scipy.special import gammaincinv

    if not (c > 0 and np.isfinite(var) and var > 0):
        return float("nan"), float("nan")
    edf = max(2 * c * c / var, 0.5)
    lo = np.sqrt(c * edf / (2 * gammaincinv(edf / 2, 0.5 + level / 2)))
    hi = np.sqrt(c * edf / (2 * gammaincinv(edf / 2, 0.5 - level / 2)))
    return float(lo), float(hi)


def _line(col: np.ndarray, avar: np.ndarray, region: np.ndarray, sub, edf: np.ndarray | None) -> tuple[float, float]:
    """GLS coefficient of one model column over ``region`` and its variance (NaN, NaN when empty)."""
    if not region.any():
        return float("nan"), float("nan")
    at = np.flatnonzero(region)
    if len(at) > LINE_POINTS:  # neighbours are nearly one measurement: a log-spaced subset carries the same
        region = np.zeros_like(region)
        region[at[np.unique(np.round(np.linspace(0, len(at) - 1, LINE_POINTS)).astype(int))]] = True
    a, y = col[region], avar[region]
    s = sub(region)
    if s is not None:
        s = s + 1e-9 * np.trace(s) / len(s) * np.eye(len(s))
        sa = np.linalg.solve(s, a)
        info = float(a @ sa)
        return float(sa @ y / info), 1.0 / info
    if edf is not None:  # independent points of variance 2 avar^2 / edf: a lower bound of the variance
        w = edf[region] / (2 * y * y)
        info = float(np.sum(w * a * a))
        return float(np.sum(w * a * y) / info), 1.0 / info
    return float(np.median(y / a)), float("nan")


def point_readouts(tau: np.ndarray, adev: np.ndarray, edf: np.ndarray | None = None, cov=None,
                   params: np.ndarray | None = None) -> dict:
    """IEEE Std 952 point readouts (see module docstring), SI, with 68.3 % intervals.

    Parameters
    ----------
    tau : ndarray, shape (T,)
        s.
    adev : ndarray, shape (T,)
        Allan deviation (unit, e.g. rad/s).
    edf : ndarray, shape (T,), optional
        Equivalent degrees of freedom of each point; without it every point may carry the floor.
    cov : ndarray, shape (T, T), or callable, optional
        Covariance of the Allan variances (unit^4), or a function of an index array (into ``tau``) giving the
        covariance of those points; without it the intervals treat points as independent (the floor's neighbours
        as fully correlated).
    params : ndarray, shape (5,), optional
        Fitted ``Q, N, B, K, R`` whose local slope picks the regions of slope -1/2 and +1/2; without it
        the curve's own slope does.

    Returns
    -------
    dict
        :data:`READOUT_KEYS`: ``N_tau1`` (unit sqrt(s)), ``B_floor`` (unit), ``K_tau3`` (unit/sqrt(s)), each with
        ``_lo``/``_hi`` (68.3 %; NaN where unknown), and ``B_floor_tau`` (s). NaN where no region of the right slope
        exists.
    """
    out = dict.fromkeys(READOUT_KEYS, float("nan"))
    tau, adev = np.asarray(tau, dtype=float), np.asarray(adev, dtype=float)
    keep = adev > 0  # a zero deviation has no logarithm
    if not keep.any():
        out["B_floor"] = 0.0
        return out
    idx = np.flatnonzero(keep)
    tau, adev = tau[keep], adev[keep]
    edf = None if edf is None else np.asarray(edf, dtype=float)[keep]

    def sub(mask: np.ndarray) -> np.ndarray | None:
        if cov is None:
            return None
        at = idx[mask]
        return np.asarray(cov(at) if callable(cov) else np.asarray(cov, dtype=float)[np.ix_(at, at)], dtype=float)

    avar = adev**2
    if params is not None:
        contrib = avar_design(tau) * np.square(np.asarray(params, dtype=float))[None, :]
        slope = contrib @ _SLOPES / np.maximum(contrib.sum(axis=1), 1e-300)
    elif len(tau) > 2:
        slope = np.gradient(np.log(adev), np.log(tau))
    else:
        slope = np.zeros_like(tau)
    design = avar_design(tau)
    for key, k, target in (("N_tau1", 1, -0.5), ("K_tau3", 3, 0.5)):
        c, v = _line(design[:, k], avar, np.abs(slope - target) < 0.1, sub, edf)
        if np.isfinite(c) and c > 0:  # the line sqrt(c / tau) at 1 s, sqrt(c tau / 3) at 3 s: sqrt(c) both
            out[key] = float(np.sqrt(c))
            out[key + "_lo"], out[key + "_hi"] = _interval(c, v)
    ok = edf >= FLOOR_EDF if edf is not None else np.ones(len(tau), dtype=bool)
    if not ok.any():
        assert edf is not None  # without an EDF every point is kept
        ok = edf >= np.max(edf)
    i0 = int(np.flatnonzero(ok)[np.argmin(adev[ok])])
    lo_i = hi_i = i0
    while lo_i > 0 and ok[lo_i - 1] and adev[lo_i - 1] <= 1.1 * adev[i0]:
        lo_i -= 1
    while hi_i < len(tau) - 1 and ok[hi_i + 1] and adev[hi_i + 1] <= 1.1 * adev[i0]:
        hi_i += 1
    region = np.zeros(len(tau), dtype=bool)
    region[lo_i : hi_i + 1] = True
    c = float(np.mean(avar[region]))
    s = sub(region)
    if s is not None:
        v = float(np.sum(s)) / (hi_i - lo_i + 1) ** 2
    elif edf is not None:  # fully correlated neighbours: the mean of their standard deviations
        v = float(np.mean(avar[region] * np.sqrt(2 / edf[region]))) ** 2
    else:
        v = float("nan")
    f = 1 / 0.664  # IEEE Std 952's rounding of sqrt(2 ln 2 / pi)
    out["B_floor"] = float(np.sqrt(c)) * f
    lo, hi = _interval(c, v)
    out["B_floor_lo"], out["B_floor_hi"] = lo * f, hi * f
    out["B_floor_tau"] = float(np.exp(np.mean(np.log(tau[region]))))
    return out
