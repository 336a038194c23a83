"""The Anderson-Darling test of normality, which decides whether a lot shows the normal or the percentile Cpk
(:mod:`align.production.capability`).

Public names
------------
anderson_darling, MIN_N_TEST
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["anderson_darling", "MIN_N_TEST"]

#: the fewest units for the normality test
MIN_N_TEST = 8


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
