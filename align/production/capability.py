"""Process capability for distributions that are not normal: the percentile Cpk (ISO 22514-2), a normality test
deciding which Cpk a lot shows, and why.

The percentile (quantile) method of ISO 22514-2 replaces ``mean -/+ 3 sigma`` by the distribution's
0.135 % and 99.865 % points and the mean by its median::

    Cpk_pct = min((USL - X50) / (X99.865 - X50), (X50 - LSL) / (X50 - X0.135))

(one-sided: the side with a limit). For a normal population it equals the normal Cpk.

The quantiles
-------------
A lot of 30 to a few thousand units has no order statistic near 0.135 % (one is expected beyond it only from about
740 units on), so each tail is extrapolated from a distribution fitted to that tail: a Johnson curve (``Z = gamma +
delta f((X - xi) / lambda)``, ``f`` = asinh (S_U), ln(y / (1 - y)) (S_B) or ln (S_L)) through four sample quantiles
at the normal scores ``z0 + s (-3, -1, 1, 3)`` by the closed-form percentile fit of Slifker and Shapiro (1980,
Technometrics 22(2) 239-246), the family chosen by their discriminant ``m n / p^2`` (> 1: S_U, < 1: S_B). The step
``s`` is 0.4 up to 200 units and 0.3 from 500 on (:func:`tail_step`); the centre ``z0`` puts the top quantile about
``k`` units from the end, ``k`` 5 up to 1,250 units, growing to 12 at 3,000 (:func:`tail_centre`), and is at
least 1 (200 units: sample quantiles at 42, 73, 92 and 98.6 %); the lower tail is the mirror image. Each tail's
0.135 % point is the fitted curve's at the normal score -/+3, and X50 is the sample median. Sample quantiles are
numpy's ``"linear"`` (Hyndman and Fan type 7). Fitting each tail by itself follows a skewed distribution's long tail
and a mixture's outer mode (a single four-quantile Johnson fit across a bimodal lot's valley is biased: +20 to +40 %
Cpk on the mixture of the tests); the smaller step of a large lot keeps its lowest quantile out of the valley. No
quantile beyond about the fifth unit from either end enters, so one wild unit does not move the estimate (those are
:func:`align.production.stats.robust_z`'s outliers).

The interval
------------
A percentile bootstrap (Efron): :data:`BOOTSTRAP` resamples of the lot with replacement, drawn from
``numpy.random.default_rng(seed)`` (seeded: the same lot gives the same interval), each refitted; the 2.5 % point
of their Cpk_pct is the 95 % interval's lower end, and its upper end is the larger of their 97.5 % point and that
of a far-tail reading's bootstrap (each tail's lowest quantile at the 69 % point or beyond, :func:`far_step`;
:func:`percentile_interval`). Only the order statistics the fit reads are drawn, exactly in
distribution (:func:`bootstrap_quantiles`), so a resample costs the same at 100 as at 3,000 units. Measured over 200
simulated lots per case (lognormal, gamma, a two-mode normal mixture at 100, 200, 300, 400, 1,000 and 3,000 units;
``tests/production/test_capability_coverage.py``; seeds 7, 8, 11, 12) it covers the analytic truth in 95.5 to 100 %
of lots, its lower end above the truth in at most 4.5 % (3,000 skewed units, seed 11). The far reading's top is there
for the bimodal lot of 175 to 400 units: the lot's own reading alone covered it in 79 to 95 % (300 units: 79 and
86 %), its tails' lowest quantiles in the mixture's valley, every miss below the truth (the estimate -15 %); the far
reading alone covers it but biases every lot's Cpk low by 15 to 35 %, so it only raises the top (by 0 to 17 %,
median), never the lower end a capability claim rests on. Reading each tail 5 units from the end at a fixed step
undercovered large lots (83 to 90 % at 3,000 skewed units, 88 to 92 % at 1,000 bimodal ones): the fit's bias then
outgrew the interval. A type 7 quantile ``k`` units from the end reads a tail of probability about ``(k + 1) / n``,
not ``k / n`` (+20 % at ``k = 5``: the 99.865 % point extrapolated low, Cpk +2 to +4 % on the lognormal lot), and a
bimodal lot's lowest tail quantile fell in its valley; reading 12 units from the end at a step of 0.3 cuts both. Its
width states honestly how little a lot says about a 0.135 % point (the lower end 35 to 50 % of Cpk below the
estimate at 200 units, 15 to 30 % at 1,000).

The decision
------------
The Anderson-Darling test of normality (mean and variance estimated; ``A*^2 = A^2 (1 + 0.75/n + 2.25/n^2)``
and its p-value by D'Agostino and Stephens 1986, Table 4.9) at :data:`ALPHA`: the normal Cpk is shown when
normality is not rejected, else the percentile Cpk, and the normal one is flagged "not applicable".

Public names
------------
Capability, capability, percentile_cpk, percentile_interval, tail_quantiles, bootstrap_quantiles, tail_centre,
tail_step, far_step, anderson_darling, ALPHA, BOOTSTRAP, MIN_N
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from align.production.normality import MIN_N_TEST, anderson_darling

#: significance level of the normality test: the normal Cpk is shown when normality is not rejected at it
ALPHA = 0.05
#: bootstrap resamples of the percentile Cpk's interval
BOOTSTRAP = 1000
#: the fewest units for the percentile Cpk (its top sample quantile, 98.6 %, is then about the second-largest unit)
MIN_N = 30
#: a tail's fit: quantiles at normal scores ``z0 + STEP (-3, -1, 1, 3)`` (mirrored for the lower tail), ``z0`` from
#: :func:`tail_centre` (``Z0`` up to 200 units)
Z0, STEP = 1.0, 0.4
#: the tails' step from about 1,000 units on (:func:`tail_step`)
STEP_LARGE = 0.3
#: the top quantile of a tail's fit is about ``clip(n / FROM_END_PER, *FROM_END)`` units from the end
#: (:func:`tail_centre`): 5 up to 1,250 units, 12 from 3,000 on
FROM_END, FROM_END_PER = (5.0, 12.0), 250.0
#: the normal score of the 99.865 % point
Z3 = 3.0
#: the far-tail reading's lowest quantile: normal score 0.5, the 69 % point (:func:`far_step`)
FAR_FLOOR = 0.5


def _johnson_at(q: np.ndarray, step: float, z: float) -> np.ndarray:
    """The value at centred normal score ``z`` of the Johnson curve through quantiles ``q`` (shape (4, B)) at
    centred normal scores ``step (-3, -1, 1, 3)`` (Slifker and Shapiro 1980; NaN where a fit does not exist)."""
    xm3, xm1, x1, x3 = q
    m, n, p = x3 - x1, xm1 - xm3, x1 - xm1
    with np.errstate(all="ignore"):
        d = m * n / (p * p)
        mp, np_ = m / p, n / p
        # S_U: X = xi + lambda sinh((Z - gamma) / delta)
        eta = 2 * step / np.arccosh(0.5 * (mp + np_))
        gam = eta * np.arcsinh((np_ - mp) / (2 * np.sqrt(d - 1)))
        lam = 2 * p * np.sqrt(d - 1) / ((mp + np_ - 2) * np.sqrt(mp + np_ + 2))
        xi = (x1 + xm1) / 2 + p * (np_ - mp) / (2 * (mp + np_ - 2))
        su = xi + lam * np.sinh((z - gam) / eta)
        # S_B: X = xi + lambda / (1 + exp(-(Z - gamma) / delta))
        pm, pn = p / m, p / n
        a = (1 + pm) * (1 + pn)
        eta = step / np.arccosh(0.5 * np.sqrt(a))
        gam = eta * np.arcsinh((pn - pm) * np.sqrt(a - 4) / (2 * (pm * pn - 1)))
        lam = p * np.sqrt((a - 2) ** 2 - 4) / (pm * pn - 1)
        xi = (x1 + xm1) / 2 - lam / 2 + p * (pn - pm) / (2 * (pm * pn - 1))
        sb = xi + lam / (1 + np.exp(-(z - gam) / eta))
        # S_L (the boundary m n = p^2): X = xi + exp((Z - gamma) / delta)
        eta = 2 * step / np.log(mp)
        gam = eta * np.log((mp - 1) / (p * np.sqrt(mp)))
        xi = (x1 + xm1) / 2 - p / 2 * (mp + 1) / (mp - 1)
        sl = xi + np.exp((z - gam) / eta)
        out = np.where(d > 1 + 1e-9, su, np.where(d < 1 - 1e-9, sb, sl))
    return np.where((m > 0) & (n > 0) & (p > 0), out, np.nan)


def tail_step(n: int) -> float:
    """The step (in normal score) between a tail's quantiles for a lot of ``n``: :data:`STEP` up to 200 units,
    :data:`STEP_LARGE` from 500 on, linear in ``log n`` between (a larger lot reads its tail closer together, so that
    its lowest quantile stays out of a bimodal lot's valley)."""
    f = np.clip(np.log(max(n, 1) / 200) / np.log(500 / 200), 0.0, 1.0)
    return float(STEP + f * (STEP_LARGE - STEP))


def tail_centre(n: int, step: float | None = None) -> float:
    """The centre ``z0`` of a tail's four quantiles for a lot of ``n``: ``Phi^-1(1 - k/n) - 3 step``, the top quantile
    ``k = clip(n / FROM_END_PER, *FROM_END)`` units from the end (5 up to 1,250 units, 12 from 3,000), within ``Z0``
    and ``3 - 3 step`` (no extrapolation from about 9,000 units on); ``step`` by default :func:`tail_step`."""
    from scipy.special import ndtri

    step = tail_step(n) if step is None else step
    k = float(np.clip(n / FROM_END_PER, *FROM_END))
    return float(np.clip(ndtri(1 - k / max(n, k + 1)) - 3 * step, Z0, Z3 - 3 * step))


def _positions(n: int, probs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """0-based index ``j`` of the lower order statistic and weight ``g`` of the upper one of the sample quantile
    (Hyndman and Fan type 7: ``h = (n - 1) p + 1``, ``Q = x_(j) + g (x_(j+1) - x_(j))``; numpy's ``"linear"``) at each
    of ``probs``."""
    h = np.clip((n - 1) * np.asarray(probs, float) + 1, 1.0, float(n))
    j = np.minimum(np.floor(h), max(n - 1, 1)).astype(int)
    return j - 1, h - j


def _levels(n: int, z0: float, step: float) -> np.ndarray:
    """The 9 probabilities a lot of ``n`` is read at: the upper tail's 4, the lower tail's 4 (mirrored), 0.5."""
    from scipy.special import ndtr

    up = ndtr(z0 + step * np.array([-3.0, -1.0, 1.0, 3.0]))
    return np.r_[up, 1 - up, 0.5]


def _from_order(at: np.ndarray, g: np.ndarray, step: float, z: float) -> np.ndarray:
    """``(X0.135, X50, X99.865)`` from the order statistics ``at`` (shape (..., 9, 2): the lower and upper one of each
    of :func:`_levels`' quantiles) and the interpolation weights ``g`` (shape (9,)); shape (3, ...)."""
    q = at[..., 0] + g * (at[..., 1] - at[..., 0])  # (..., 9)
    q = np.moveaxis(q, -1, 0)
    hi = _johnson_at(q[:4], step, z)
    lo = -_johnson_at(-q[4:8], step, z)
    return np.array([lo, q[8], hi])


def tail_quantiles(values: np.ndarray, *, z0: float | None = None, step: float | None = None) -> np.ndarray:
    """``(X0.135, X50, X99.865)`` of each row of ``values``: each tail's Johnson fit (module docstring), the median.

    Parameters
    ----------
    values : array_like, shape (n,) or (B, n)
        One lot, or B lots (rows) of n units.

    Returns
    -------
    ndarray, shape (3,) or (3, B)
        NaN where a tail's fit does not exist (ties: quantiles that coincide).

    Examples
    --------
    >>> from scipy import stats
    >>> x = stats.norm.ppf((np.arange(20000) + 0.5) / 20000)  # a normal population's quantiles
    >>> np.round(tail_quantiles(x), 1).tolist()
    [-3.0, 0.0, 3.0]
    """
    x = np.sort(np.asarray(values, float), axis=-1)
    n = x.shape[-1]
    step = tail_step(n) if step is None else step
    z0 = tail_centre(n, step) if z0 is None else z0
    j, g = _positions(n, _levels(n, z0, step))
    at = x[..., np.stack([j, j + 1], axis=-1)]  # (..., 9, 2)
    return _from_order(at, g, step, Z3 - z0)


def bootstrap_quantiles(sorted_values: np.ndarray, resamples: int, rng: np.random.Generator, *,
                        z0: float | None = None, step: float | None = None) -> np.ndarray:
    """:func:`tail_quantiles` of ``resamples`` bootstrap resamples (n draws with replacement) of each sorted lot.

    Only the resample's order statistics the estimate reads are drawn, exactly in distribution: a resample is
    ``F_n^-1(U_i)`` with ``U_i`` uniform, so its ``r``-th order statistic is ``x_(ceil(n U_(r)))``, and the uniform
    order statistics at ranks ``r_1 < ... < r_m`` are ``S_(r_k) / S_(n+1)``, ``S`` the partial sums of ``n + 1``
    unit exponentials (David and Nagaraja, Order Statistics, 2003, 2.5), drawn as ``m + 1`` gamma variates of
    shapes ``r_k - r_(k-1)`` and ``n + 1 - r_m``. ``O(resamples)`` work instead of ``O(resamples n)``.

    Parameters
    ----------
    sorted_values : ndarray, shape (n,) or (L, n)
        A lot (or L lots) sorted ascending.
    resamples : int
    rng : numpy.random.Generator

    Returns
    -------
    ndarray, shape (3, resamples) or (3, L, resamples)

    Examples
    --------
    >>> x = np.sort(np.random.default_rng(0).lognormal(0.0, 0.5, 300))
    >>> bootstrap_quantiles(x, 50, np.random.default_rng(1)).shape
    (3, 50)
    """
    x = np.asarray(sorted_values, float)
    n = x.shape[-1]
    step = tail_step(n) if step is None else step
    z0 = tail_centre(n, step) if z0 is None else z0
    j, g = _positions(n, _levels(n, z0, step))
    pairs = np.stack([j, j + 1], axis=-1) + 1  # 1-based ranks, (9, 2)
    ranks, where = np.unique(pairs, return_inverse=True)
    shapes = np.diff(np.r_[0, ranks, n + 1]).astype(float)
    gam = rng.standard_gamma(shapes, size=x.shape[:-1] + (resamples, len(shapes)))
    u = np.cumsum(gam, axis=-1)
    u = u[..., :-1] / u[..., -1:]  # (..., B, m) uniform order statistics
    idx = np.clip(np.ceil(n * u).astype(int) - 1, 0, n - 1)
    xs = np.take_along_axis(x[..., None, :], idx, axis=-1) if x.ndim > 1 else x[idx]
    at = xs[..., where.reshape(pairs.shape)]  # (..., B, 9, 2)
    return _from_order(at, g, step, Z3 - z0)


def far_step(n: int) -> float:
    """The step of the far-tail reading of a lot of ``n`` units (:func:`percentile_interval`): at most
    :func:`tail_step`'s, the lowest quantile of a tail at normal score :data:`FAR_FLOOR` (the 69 % point), its top ``k``
    units from the end (:func:`tail_centre`; below about 80 units its centre is held at 1: the lowest quantile lies
    further out); 0 (no far reading) for a lot too small for one.

    >>> round(far_step(100), 3), round(far_step(300), 3), far_step(3000)
    (0.191, 0.271, 0.3)
    """
    from scipy.special import ndtri

    k = float(np.clip(n / FROM_END_PER, *FROM_END))
    return max(0.0, min(tail_step(n), float(ndtri(1 - k / max(n, k + 1)) - FAR_FLOOR) / 6))


def percentile_interval(sorted_values: np.ndarray, low: float | None, high: float | None, resamples: int,
                        rng: np.random.Generator, level: float = 0.95) -> tuple[np.ndarray, float]:
    """The percentile Cpk's interval ``(lower, upper)`` at ``level`` and the fraction of the lot's bootstrap
    resamples whose tails could be fitted (module docstring, "The interval").

    The lower end is the ``(1 - level) / 2`` point of the bootstrap of the lot's own reading (:func:`tail_quantiles`);
    the upper end is the larger of that bootstrap's ``(1 + level) / 2`` point and that of a far-tail reading
    (:func:`far_step`), drawn next from ``rng``.

    Parameters
    ----------
    sorted_values : ndarray, shape (n,) or (L, n)
        A lot (or L lots) sorted ascending, in the figure's unit.
    low, high : float or None
        The spec limits, the figure's unit (None: that side open).
    resamples : int
        Bootstrap resamples of each reading.
    rng : numpy.random.Generator
        Draws the lot's own reading's resamples, then the far reading's.
    level : float
        The interval's confidence level.

    Returns
    -------
    ends : ndarray, shape (2,) or (2, L)
    valid : float
        The fraction of the lot's own reading's resamples with a finite Cpk (of all lots).
    """
    x = np.asarray(sorted_values, float)
    n, tail = x.shape[-1], 100 * (1 - level) / 2
    boot, step = percentile_cpk(bootstrap_quantiles(x, resamples, rng), low, high), far_step(x.shape[-1])
    with warnings.catch_warnings():  # a lot whose every resample failed: NaN ends, said by ``valid``
        warnings.simplefilter("ignore", RuntimeWarning)
        lo, hi = np.nanpercentile(boot, [tail, 100 - tail], axis=-1)
        if step > 0:  # the far reading raises the top only where 95 % of its resamples could be fitted
            far = percentile_cpk(bootstrap_quantiles(x, resamples, rng, z0=tail_centre(n, step), step=step), low, high)
            usable = np.mean(np.isfinite(far), axis=-1) >= 0.95
            hi = np.where(usable, np.fmax(hi, np.nanpercentile(far, 100 - tail, axis=-1)), hi)
    return np.array([lo, hi]), float(np.mean(np.isfinite(boot)))


def percentile_cpk(quantiles: np.ndarray, low: float | None, high: float | None) -> np.ndarray:
    """``min((USL - X50) / (X99.865 - X50), (X50 - LSL) / (X50 - X0.135))`` of quantiles ``(X0.135, X50, X99.865)``
    (shape (3,) or (3, B)); a side without a limit is left out (ISO 22514-2, the percentile method).

    Examples
    --------
    >>> float(percentile_cpk(np.array([-3.0, 0.0, 3.0]), -4.0, 6.0))
    1.3333333333333333
    """
    lo, med, hi = np.asarray(quantiles, float)
    up = (high - med) / (hi - med) if high is not None else np.full_like(med, np.inf)
    down = (med - low) / (med - lo) if low is not None else np.full_like(med, np.inf)
    return np.minimum(up, down)


@dataclass(frozen=True)
class Capability:
    """Both capabilities of a figure over a lot, and which one it shows.

    ``cpk_normal`` (± ``cpk_normal_sigma``, Bissell) assumes a normal population; ``cpk_percentile`` is ISO
    22514-2's from ``quantiles`` ``(X0.135, X50, X99.865)`` (SI), with its bootstrap interval
    ``interval`` at ``level``; ``ad_statistic``/``ad_p`` the Anderson-Darling test of normality at ``alpha``.
    ``used`` is ``"normal"`` or ``"percentile"``; ``why`` says why in one phrase.
    """

    n: int
    cpk_normal: float
    cpk_normal_sigma: float
    cpk_percentile: float
    interval: tuple[float, float]
    quantiles: tuple[float, float, float]
    ad_statistic: float
    ad_p: float
    alpha: float
    used: str
    why: str
    level: float = 0.95
    resamples: int = BOOTSTRAP

    @property
    def normal(self) -> bool:
        """True when the test does not reject normality (or could not be made: too few units)."""
        return not (self.ad_p < self.alpha)

    @property
    def cpk(self) -> float:
        """The Cpk shown: the normal one or the percentile one (:attr:`used`)."""
        return self.cpk_normal if self.used == "normal" else self.cpk_percentile

    @property
    def normal_note(self) -> str:
        """What to say beside the normal Cpk: ``""`` when it applies, else why not."""
        if self.normal:
            return ""
        return f"not applicable: the distribution is not normal (Anderson-Darling p {_p(self.ad_p)} < {self.alpha:g})"


def _p(p: float) -> str:
    return "< 0.0001" if p < 1e-4 else f"{p:.2g}"


def capability(values: np.ndarray, low: float | None, high: float | None, *, alpha: float = ALPHA,
               resamples: int = BOOTSTRAP, seed: int = 0, level: float = 0.95) -> Capability:
    """The lot's normal and percentile Cpk of one figure against ``low``/``high`` and the one to show.

    Parameters
    ----------
    values : array_like, shape (n,)
        The figure of each unit (SI, like the limits).
    low, high : float or None
        The spec limits (None: that side open).
    alpha : float
        Significance level of the Anderson-Darling test deciding which Cpk is shown.
    resamples, seed : int
        The bootstrap's resamples and its generator's seed (``numpy.random.default_rng(seed)``).
    level : float
        The interval's confidence level (a percentile bootstrap interval).

    Returns
    -------
    Capability
        The percentile Cpk and its interval are NaN below :data:`MIN_N` units or when a tail's fit does not
        exist; the normal Cpk is then shown and :attr:`Capability.why` says so.

    Examples
    --------
    >>> x = np.random.default_rng(1).lognormal(0.0, 0.5, 200)
    >>> c = capability(x, 0.0, 5.0, resamples=200)
    >>> c.used, c.normal_note.startswith("not applicable: the distribution is not normal")
    ('percentile', True)
    """
    from align.production.stats import cpk as normal_cpk

    x = np.asarray(values, float)
    n = len(x)
    c, cs = normal_cpk(x, low, high)
    a2, p = anderson_darling(x)
    nan2 = (math.nan, math.nan)
    q: tuple[float, float, float] = (math.nan, math.nan, math.nan)
    cp, ci = math.nan, nan2
    if n >= MIN_N and (low is not None or high is not None):
        lo_q, med_q, hi_q = (float(v) for v in tail_quantiles(x))
        q = (lo_q, med_q, hi_q)
        cp = float(percentile_cpk(np.array(q), low, high))
        if math.isfinite(cp):
            ends, valid = percentile_interval(np.sort(x), low, high, resamples, np.random.default_rng(seed), level)
            if valid >= 0.95:
                ci = (float(ends[0]), float(ends[1]))
    if not p < alpha:
        why = (f"normal: Anderson-Darling p {_p(p)} >= {alpha:g}, normality not rejected" if math.isfinite(p)
               else f"normal: too few units ({n}) to test normality" if n < MIN_N_TEST
               else "normal: the values do not spread; normality not tested")
        used = "normal"
    elif math.isfinite(cp):
        why = f"percentile (ISO 22514-2): the distribution is not normal (Anderson-Darling p {_p(p)} < {alpha:g})"
        used = "percentile"
    else:
        why = (f"normal, though the distribution is not normal (Anderson-Darling p {_p(p)} < {alpha:g}): "
               + (f"too few units ({n} < {MIN_N}) for the percentile Cpk" if n < MIN_N
                  else "the tails could not be fitted (tied values)"))
        used = "normal"
    return Capability(n, c, cs, cp, ci, q, a2, p, alpha, used, why, level, resamples)
