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


@njit(cache=True, fastmath=True)
def _gather(row, m, im, sm, mu0, j0, n, w):  # pragma: no cover - compiled
    """``w[i]``: the block mean ``j0 + i`` of factor ``m``, less the trend and the mean, for ``i < n``."""
    xs = row[j0 * m : (j0 + n) * m + 1 : m]
    a = sm * j0 + mu0
    for i in range(n):
        w[i] = (xs[i + 1] - xs[i]) * im - (a + sm * i)


@njit(cache=True, fastmath=True)
def _lag1_part(w, mu1, acc):  # pragma: no cover - compiled
    """Adds the d = 0, 1 terms of ``lag1_sums`` for ``j = 3 .. len(w) - 1`` (``w`` centred, contiguous) to ``acc``."""
    s0 = p0 = s1 = p1 = 0.0
    for j in range(3, len(w)):
        c1 = w[j] - w[j - 1] - mu1
        c1p = w[j - 1] - w[j - 2] - mu1
        s0 += w[j] * w[j]
        p0 += w[j] * w[j - 1]
        s1 += c1 * c1
        p1 += c1 * c1p
    acc[0] += s0
    acc[1] += p0
    acc[2] += s1
    acc[3] += p1


@njit(cache=True, fastmath=True)
def _lag1_part2(w, mu2, acc):  # pragma: no cover - compiled
    """Adds the d = 2 terms of ``lag1_sums`` for ``j = 3 .. len(w) - 1`` to ``acc``."""
    s2 = p2 = 0.0
    for j in range(3, len(w)):
        c2 = w[j] - 2.0 * w[j - 1] + w[j - 2] - mu2
        c2p = w[j - 1] - 2.0 * w[j - 2] + w[j - 3] - mu2
        s2 += c2 * c2
        p2 += c2 * c2p
    acc[4] += s2
    acc[5] += p2


@njit(cache=True)
def _bmean(row, m, im, sm, mu0, j):  # pragma: no cover - compiled
    return (row[(j + 1) * m] - row[j * m]) * im - sm * j - mu0


@njit(cache=True, parallel=True, nogil=True)
def lag1_sums(x, ms, slope, depth):  # pragma: no cover - compiled
    """Sums behind the lag-1 autocorrelation and the B1 ratio of block means, shape (C, K, 7).

    For channel c and factor m, ``z0[j] = (x[c, (j+1) m] - x[c, j m]) / m - slope[c] m j`` (the
    non-overlapping block means, in phase units per sample, with the record's linear trend removed),
    ``z1 = diff(z0)``, ``z2 = diff(z1)``; each ``zd`` is centred on its mean (known before the pass
    from its end points). Returns ``[S0, P0, S1, P1, S2, P2, Q1]``: ``Sd = sum (zd - mean)^2``,
    ``Pd = sum (zd[j] - mean)(zd[j+1] - mean)``, ``Q1 = sum z1^2``; ``S2``, ``P2`` only with
    ``depth`` 2 (else 0). Tiled as ``avar_sums``: each work item is one stretch of 65536 phase
    points of one channel, for every factor (the blocks that start in it), so the phase is read
    from memory about once; block means are gathered into a small buffer and the sums vectorised;
    the tiles' partial sums are added in a fixed order. Fewer than 4 blocks give zeros.
    """
    c_n, n_x = x.shape
    k_n = len(ms)
    width = 65536
    n_t = (n_x - 1 + width - 1) // width
    mu = np.zeros((c_n, k_n, 3))
    for c in range(c_n):
        row = x[c]
        for k in range(k_n):
            m = ms[k]
            nb = (n_x - 1) // m
            if nb >= 4:
                im, sm = 1.0 / m, slope[c] * m
                mu0 = (row[nb * m] - row[0]) * im / nb - sm * (nb - 1) / 2.0
                b0, b1 = _bmean(row, m, im, sm, mu0, 0), _bmean(row, m, im, sm, mu0, 1)
                bl, bp = _bmean(row, m, im, sm, mu0, nb - 1), _bmean(row, m, im, sm, mu0, nb - 2)
                mu[c, k, 0] = mu0
                mu[c, k, 1] = (bl - b0) / (nb - 1)
                mu[c, k, 2] = ((bl - bp) - (b1 - b0)) / (nb - 2)
    part = np.zeros((c_n, n_t, k_n, 6))
    for item in prange(c_n * n_t):
        c = item // n_t
        tile = item % n_t
        row = x[c]
        p0 = tile * width
        sub = 4096
        w = np.empty(sub + 3)
        for k in range(k_n):
            m = ms[k]
            nb = (n_x - 1) // m
            ja = (p0 + m - 1) // m  # the blocks that start in this tile
            jb = min((p0 + width + m - 1) // m, nb)
            if nb < 4 or ja >= jb:
                continue
            im, sm = 1.0 / m, slope[c] * m
            mu0, mu1, mu2 = mu[c, k, 0], mu[c, k, 1], mu[c, k, 2]
            acc = part[c, tile, k]
            for j in range(ja, min(jb, 3)):  # the first terms, where a difference or a product is not yet defined
                v = _bmean(row, m, im, sm, mu0, j)
                acc[0] += v * v
                if j >= 1:
                    vp = _bmean(row, m, im, sm, mu0, j - 1)
                    acc[1] += v * vp
                    acc[2] += (v - vp - mu1) ** 2
                if j >= 2:
                    vpp = _bmean(row, m, im, sm, mu0, j - 2)
                    acc[3] += (v - vp - mu1) * (vp - vpp - mu1)
                    acc[4] += (v - 2.0 * vp + vpp - mu2) ** 2
            for s0 in range(max(ja, 3), jb, sub):
                s1 = min(s0 + sub, jb)
                _gather(row, m, im, sm, mu0, s0 - 3, s1 - s0 + 3, w)
                _lag1_part(w[: s1 - s0 + 3], mu1, acc)
                if depth >= 2:
                    _lag1_part2(w[: s1 - s0 + 3], mu2, acc)
    out = np.zeros((c_n, k_n, 7))
    for c in range(c_n):
        for k in range(k_n):
            for t in range(n_t):
                for q in range(6):
                    out[c, k, q] += part[c, t, k, q]
            nb = (n_x - 1) // ms[k]
            if nb >= 4:
                out[c, k, 6] = out[c, k, 2] + (nb - 1) * mu[c, k, 1] ** 2
            if depth < 2:
                out[c, k, 4] = 0.0
    return out
