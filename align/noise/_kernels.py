"""Compiled kernels of :mod:`align.noise.allan` (numba), imported on first use.

Module-level functions so that numba's on-disk cache (``cache=True``) holds
them between runs.
"""

import numpy as np
from numba import njit, prange


@njit(cache=True, fastmath=True, inline="always")
def block_sum(far, mid, near):  # pragma: no cover - compiled
    s = 0.0
    for j in range(len(near)):
        v = far[j] - 2.0 * mid[j] + near[j]
        s += v * v
    return s

# Tiled: each work item is one block of 32768 phase points of one channel, for every tau,
# so the small-m streams come from cache; fastmath lets LLVM vectorise the block sums
# (reassociation only: the partial sums stay near machine precision), and the block
# partial sums are added in a fixed order, so the result does not depend on the threads.
@njit(cache=True, parallel=True, nogil=True, fastmath=True)
def avar_sums(x, ms):  # pragma: no cover - compiled
    """sum_i (x[c, i+2m] - 2 x[c, i+m] + x[c, i])^2 for every channel c and factor m, shape (C, K)."""
    c_n, n_x = x.shape
    k_n = len(ms)
    width = 32768
    n_b = (n_x + width - 1) // width
    part = np.zeros((c_n, n_b, k_n))
    for item in prange(c_n * n_b):
        c = item // n_b
        b = item % n_b
        row = x[c]  # a C-contiguous row: the slices below are contiguous and vectorise
        j0 = b * width
        for k in range(k_n):
            m = ms[k]
            j1 = min(j0 + width, n_x - 2 * m)
            if j1 > j0:
                part[c, b, k] = block_sum(row[j0 + 2 * m : j1 + 2 * m], row[j0 + m : j1 + m], row[j0:j1])
    out = np.zeros((c_n, k_n))
    for c in range(c_n):
        for k in range(k_n):
            t = 0.0
            for b in range(n_b):
                t += part[c, b, k]
            out[c, k] = t
    return out

@njit(cache=True, parallel=True, nogil=True)
def mvar_sums(x, ms):  # pragma: no cover - compiled
    """sum_j (sum_{i=j}^{j+m-1} x[c, i+2m] - 2 x[c, i+m] + x[c, i])^2, shape (C, K)."""
    c_n, n_x = x.shape
    k_n = len(ms)
    out = np.empty((c_n, k_n))
    for item in prange(c_n * k_n):
        c = item // k_n
        m = ms[item % k_n]
        row = x[c]
        n = n_x - 3 * m + 1
        run = 0.0
        for j in range(m):
            run += row[j + 2 * m] - 2.0 * row[j + m] + row[j]
        total = 0.0
        block = run * run
        count = 1
        for j in range(1, n):
            run += row[j + 3 * m - 1] - 3.0 * row[j + 2 * m - 1] + 3.0 * row[j + m - 1] - row[j - 1]
            block += run * run
            count += 1
            if count == 4096:
                total += block
                block = 0.0
                count = 0
        out[c, item % k_n] = total + block
    return out
