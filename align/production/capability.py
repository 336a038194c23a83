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
Technometrics 22(2) 239-246), the family chosen by their discriminant ``m n / p^2`` (> 1: S_U, < 1: S_B). The upper
tail uses ``s = 0.4`` and ``z0 = +1`` up to 200 units (sample quantiles at 42, 73, 92 and 98.6 %), moving out with
the lot so that the top quantile stays about 5 units from the end (:func:`tail_centre`; 1,000 units: 64 to 99.5 %),
the lower tail the mirror image; each tail's 0.135 % point is the fitted curve's at the normal score -/+3, and X50
is the sample median. Sample quantiles are numpy's ``"linear"`` (Hyndman and Fan type 7). Fitting each tail by
itself follows a skewed distribution's long tail and a mixture's outer mode (a single four-quantile Johnson fit
across a bimodal lot's valley is biased: +20 to +40 % Cpk on the mixture of the tests). No quantile beyond about the
fifth unit from either end enters, so one wild unit does not move the estimate (those are
:func:`align.production.stats.robust_z`'s outliers).

The interval
------------
A percentile bootstrap (Efron): :data:`BOOTSTRAP` resamples of the lot with replacement, drawn from
``numpy.random.default_rng(seed)`` (seeded: the same lot gives the same interval), each refitted; the
2.5 and 97.5 % points of their Cpk_pct are the 95 % interval. Measured over simulated lots of 100, 200 and
1,000 units (lognormal, gamma, a two-mode normal mixture, normal; ``tests/production/test_capability.py``), it
covers the analytic truth in 91 to 100 % of lots up to 1,000 units (conservative at small lots); at 3,000
units only 83 to 87 % on the skewed lots (the tail fit's +3 % bias then outgrows the interval). Its width states honestly how
little a lot says about a 0.135 % point (about +/-40 % of Cpk at 200 units, +/-25 % at 1,000).

The decision
------------
The Anderson-Darling test of normality (mean and variance estimated; ``A*^2 = A^2 (1 + 0.75/n + 2.25/n^2)``
and its p-value by D'Agostino and Stephens 1986, Table 4.9) at :data:`ALPHA`: the normal Cpk is shown when
normality is not rejected, else the percentile Cpk, and the normal one is flagged "not applicable".

Public names
------------
Capability, capability, percentile_cpk, tail_quantiles, tail_centre, anderson_darling, ALPHA, BOOTSTRAP, MIN_N
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: significance level of the normality test: the normal Cpk is shown when normality is not rejected at it
ALPHA = 0.05
#: bootstrap resamples of the percentile Cpk's interval
BOOTSTRAP = 1000
#: the fewest units for the percentile Cpk (its top sample quantile, 98.6 %, is then about the second-largest unit)
MIN_N = 30
#: the fewest units for the normality test
MIN_N_TEST = 8
#: a tail's fit: quantiles at normal scores ``z0 + STEP (-3, -1, 1, 3)`` (mirrored for the lower tail), ``z0`` from
#: :func:`tail_centre` (``Z0`` up to 200 units)
Z0, STEP = 1.0, 0.4
#: the normal score of the 99.865 % point
Z3 = 3.0


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


def tail_centre(n: int) -> float:
    """The centre ``z0`` of a tail's four quantiles for a lot of ``n``: ``Phi^-1(1 - 5/n) - 3 STEP`` (the top quantile
    about 5 units from the end), within ``Z0`` and ``3 - 3 STEP`` (no extrapolation from about 3,700 units on)."""
    from scipy.special import ndtri

    return float(np.clip(ndtri(1 - 5 / max(n, 6)) - 3 * STEP, Z0, Z3 - 3 * STEP))


def tail_quantiles(values: np.ndarray, *, z0: float | None = None, step: float = STEP) -> np.ndarray:
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
    from scipy.special import ndtr

    x = np.asarray(values, float)
    z0 = tail_centre(x.shape[-1]) if z0 is None else z0
    scores = ndtr(z0 + step * np.array([-3.0, -1.0, 1.0, 3.0]))
    hi = _johnson_at(np.quantile(x, scores, axis=-1), step, Z3 - z0)
    lo = -_johnson_at(np.quantile(-x, scores, axis=-1), step, Z3 - z0)
    return np.array([lo, np.median(x, axis=-1), hi])


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


def anderson_darling(values: np.ndarray) -> tuple[float, float]:
    """``(A^2, p)``: the Anderson-Darling statistic of normality (mean and ``ddof = 1`` deviation estimated) and
    its p-value from ``A*^2 = A^2 (1 + 0.75/n + 2.25/n^2)`` (D'Agostino and Stephens 1986, Table 4.9); NaN for
    fewer than :data:`MIN_N_TEST` values or none spread.

    Examples
    --------
    >>> a2, p = anderson_darling(np.array([-1.5, -0.9, -0.4, -0.1, 0.2, 0.5, 1.0, 1.6]))
    >>> round(a2, 3), p > 0.5
    (0.096, True)
    """
    from scipy.special import log_ndtr

    x = np.sort(np.asarray(values, float))
    n = len(x)
    s = float(np.std(x, ddof=1)) if n > 1 else 0.0
    if n < MIN_N_TEST or not s > 0:
        return math.nan, math.nan
    z = (x - x.mean()) / s
    i = np.arange(1, n + 1)
    a2 = float(-n - np.sum((2 * i - 1) * (log_ndtr(z) + log_ndtr(-z[::-1]))) / n)
    a = a2 * (1 + 0.75 / n + 2.25 / n ** 2)
    if a >= 0.6:
        p = math.exp(1.2937 - 5.709 * a + 0.0186 * a * a)
    elif a >= 0.34:
        p = math.exp(0.9177 - 4.279 * a - 1.38 * a * a)
    elif a >= 0.2:
        p = 1 - math.exp(-8.318 + 42.796 * a - 59.938 * a * a)
    else:
        p = 1 - math.exp(-13.436 + 101.14 * a - 223.73 * a * a)
    return a2, min(1.0, max(0.0, p))


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
            rng = np.random.default_rng(seed)
            boot = percentile_cpk(tail_quantiles(x[rng.integers(0, n, (resamples, n))]), low, high)
            good = boot[~np.isnan(boot)]
            if len(good) >= 0.95 * resamples:
                tail = 100 * (1 - level) / 2
                ci = (float(np.percentile(good, tail)), float(np.percentile(good, 100 - tail)))
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
