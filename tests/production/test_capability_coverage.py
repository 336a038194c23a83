"""Issue 27: the percentile Cpk's 95 % interval covers the truth for skewed (lognormal, gamma) and bimodal lots of
100, 1,000 and 3,000 units. The truth is the percentile Cpk of the generating distribution, from its exact
0.135 / 50 / 99.865 % points (scipy.stats ``ppf``; the mixture's by root-finding on its CDF), not from the code."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import optimize
from scipy import stats as sst

from align.production.capability import (
    bootstrap_quantiles,
    capability,
    far_step,
    percentile_cpk,
    percentile_interval,
    tail_centre,
    tail_quantiles,
)

P = sst.norm.cdf([-3.0, 0.0, 3.0])
W, MU, SD = (0.6, 0.4), (0.0, 3.0), (0.7, 0.7)


def _mixture_ppf(p: float) -> float:
    return optimize.brentq(lambda x: sum(w * sst.norm.cdf(x, m, s) for w, m, s in zip(W, MU, SD)) - p, -20, 20,
                           xtol=1e-12)


def _mixture(rng, size):
    return np.where(rng.random(size) < W[0], rng.normal(MU[0], SD[0], size), rng.normal(MU[1], SD[1], size))


#: name -> (draw(rng, shape), true (X0.135, X50, X99.865), LSL, USL)
CASES = {
    "lognormal": (lambda rng, s: rng.lognormal(0.0, 0.5, s), sst.lognorm(0.5).ppf(P), 0.0, 5.0),
    "gamma": (lambda rng, s: rng.gamma(3.0, 1.0, s), sst.gamma(3.0).ppf(P), 0.0, 12.0),
    "bimodal": (_mixture, np.array([_mixture_ppf(p) for p in P]), -3.0, 6.0),
}


def _true_cpk(q, low, high) -> float:
    lo, med, hi = q
    return min((high - med) / (hi - med), (med - low) / (med - lo))  # ISO 22514-2, written out here


def _coverage(name: str, n: int, lots: int = 200, resamples: int = 1000, seed: int = 7):
    """(truth, coverage, median estimate, fraction of lots whose interval lies above the truth) over ``lots`` lots,
    all at once: :func:`capability`'s interval (:func:`percentile_interval`), vectorised over the lots."""
    draw, q, low, high = CASES[name]
    rng = np.random.default_rng(10_000 * seed + n)
    x = np.sort(draw(rng, (lots, n)), axis=1)
    est = percentile_cpk(tail_quantiles(x), low, high)
    (a, b), _ = percentile_interval(x, low, high, resamples, rng)
    true = _true_cpk(q, low, high)
    return true, float(np.mean((a <= true) & (true <= b))), float(np.median(est)), float(np.mean(a > true))


def test_the_exact_order_statistic_bootstrap_is_the_resampling_bootstrap():
    """The drawn order statistics give the same bootstrap distribution as resampling whole lots (the textbook way)."""
    x = np.random.default_rng(0).gamma(3.0, 1.0, 400)
    rng = np.random.default_rng(1)
    naive = tail_quantiles(x[rng.integers(0, len(x), (3000, len(x)))])
    fast = bootstrap_quantiles(np.sort(x), 3000, np.random.default_rng(2))
    for a, b in zip(naive, fast):
        pa, pb = np.nanpercentile(a, [5, 25, 50, 75, 95]), np.nanpercentile(b, [5, 25, 50, 75, 95])
        assert np.allclose(pa, pb, rtol=0.04, atol=0.02 * np.ptp(pa)), (pa, pb)
    cap = capability(x, 0.0, 12.0, seed=4)  # the library's interval is this bootstrap's, its top raised by the far one's
    rng = np.random.default_rng(4)
    boot = percentile_cpk(bootstrap_quantiles(np.sort(x), 1000, rng), 0.0, 12.0)
    s = far_step(len(x))
    far = percentile_cpk(bootstrap_quantiles(np.sort(x), 1000, rng, z0=tail_centre(len(x), s), step=s), 0.0, 12.0)
    lo, hi = np.nanpercentile(boot, [2.5, 97.5])
    assert cap.interval == pytest.approx((lo, max(hi, np.nanpercentile(far, 97.5))))


def test_a_skewed_lot_of_3000_is_covered():
    """The case that undercovered (0.83-0.87 with the tails read 5 units from the end at a fixed step)."""
    true, cover, median, _ = _coverage("lognormal", 3000)
    assert cover >= 0.93, (true, cover)
    assert abs(median / true - 1) < 0.05


@pytest.mark.slow
def test_percentile_cpk_coverage_skewed_and_bimodal_from_100_to_3000():
    """200 lots per case; measured 0.955-1.0 (capability.py's module docstring; 200 and 400 units too, measured, left
    out for CI's time). 300 units: with the lot's own reading alone, the bimodal lot was covered in 0.79-0.86, every
    miss below the truth."""
    got = {(name, n): _coverage(name, n) for name in CASES for n in (100, 300, 1000, 3000)}
    bad = {k: v for k, v in got.items() if v[1] < 0.93 or v[3] > 0.05}  # 200 lots: a standard error of about 1.5 %
    assert not bad, bad


def test_a_bimodal_lot_of_300_is_covered():
    """The case the lot's own reading missed in 14-21 % of lots (its interval below the truth)."""
    true, cover, median, above = _coverage("bimodal", 300, lots=100)
    assert cover >= 0.93 and above <= 0.03, (true, cover, above)
