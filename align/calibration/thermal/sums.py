"""Sufficient statistics of the thermal fits: per contiguous segment, the sums ``Z^T Z`` of
``z = (1, x, ..., x^P, r, y_x, y_y, y_z)``; every fit, cross-validation fold, batch of the autocorrelation
time and branch fit is then a small solve on sums of these (one pass over the samples, in chunks: bounded memory).

``x = (T - tc) / hs`` (the temperature scaled to [-1, 1] over the record: well-conditioned powers), ``r = dT/dt /
rs`` (the rate scaled to about 1) and ``y`` the readings less their mean, so that the sums stay accurate for
10^7 samples.

Segments are cut at block edges (contiguous blocks of equal length: merged into the blocks of the cross-validation
and into the batches of the autocorrelation time) and wherever the branch label changes (heating, cooling,
neither).

Public names
------------
Sums, accumulate, extremes, solve, sse, CHUNK
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Sums", "accumulate", "extremes", "solve", "sse", "CHUNK"]

#: rows per chunk of the one pass (the design of a chunk is CHUNK x (P + 5) floats)
CHUNK = 1 << 16
#: rows per chunk of the pass of :func:`extremes`: its product (3 x (P + 2) by (P + 2) x SMALL_CHUNK) stays below
#: the size at which OpenBLAS spreads a product over threads (m n k < 262144), which on a loaded machine made it
#: ten times slower; the chunk (80 kB a row) also stays in the cache
SMALL_CHUNK = 1 << 13


@dataclass(frozen=True, eq=False)
class Sums:
    """Per-segment sums of ``z z^T`` (module docstring).

    Attributes
    ----------
    G : ndarray, shape (S, q, q)
        ``q = P + 5``: columns ``0..P`` the powers of x, ``P + 1`` the scaled rate, ``P + 2..P + 4`` the axes.
    block : ndarray, shape (S,)
        Block of each segment, 0..B-1.
    label : ndarray, shape (S,)
        +1 heating, -1 cooling, 0 neither.
    tlo, thi : ndarray, shape (S,)
        Temperature range of each segment, C.
    P : int
        Highest power held.
    tc, hs, rs : float
        Centre and half span of the temperature (C), scale of the rate (C/s).
    ymean : ndarray, shape (3,)
        Mean of the readings, SI.
    blocks : int
        B.
    """

    G: np.ndarray
    block: np.ndarray
    label: np.ndarray
    tlo: np.ndarray
    thi: np.ndarray
    P: int
    tc: float
    hs: float
    rs: float
    ymean: np.ndarray
    blocks: int

    def rate_column(self) -> int:
        """Index of the rate column."""
        return self.P + 1

    def axis_column(self, axis: int) -> int:
        """Index of axis ``axis``'s readings."""
        return self.P + 2 + axis

    def count(self, mask: np.ndarray | None = None) -> int:
        """Samples in the segments selected by ``mask`` (all when None)."""
        g = self.G if mask is None else self.G[mask]
        return int(round(float(g[:, 0, 0].sum())))

    def total(self, mask: np.ndarray | None = None) -> np.ndarray:
        """``sum z z^T`` over the segments selected by ``mask`` (q, q)."""
        return (self.G if mask is None else self.G[mask]).sum(axis=0)

    def per_block(self, mask: np.ndarray | None = None) -> np.ndarray:
        """``sum z z^T`` per block (B, q, q) over the segments selected by ``mask``."""
        out = np.zeros((self.blocks,) + self.G.shape[1:])
        keep = np.ones(len(self.block), bool) if mask is None else mask
        np.add.at(out, self.block[keep], self.G[keep])
        return out

    def columns(self, order: int, lag: bool) -> list[int]:
        """The design columns of a model of ``order`` with or without the lag term."""
        return list(range(order + 1)) + ([self.rate_column()] if lag else [])

    def scaled(self, temperature: np.ndarray) -> np.ndarray:
        """``x = (T - tc) / hs``."""
        return (np.asarray(temperature, float) - self.tc) / self.hs


def _design(temperature: np.ndarray, rate: np.ndarray, readings: np.ndarray, a: int, b: int, P: int, tc: float,
            hs: float, rs: float, ymean: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Rows ``a:b`` as ``z`` (q, b - a), one row per column of the sums (module docstring), in ``z``'s buffer."""
    zz = z[:, :b - a]
    zz[0] = 1.0
    np.subtract(temperature[a:b], tc, out=zz[1])
    zz[1] /= hs
    for k in range(2, P + 1):
        np.multiply(zz[k - 1], zz[1], out=zz[k])
    np.divide(rate[a:b], rs, out=zz[P + 1])
    np.subtract(readings[a:b].T, ymean[:, None], out=zz[P + 2:])
    return zz


def accumulate(temperature: np.ndarray, rate: np.ndarray, readings: np.ndarray, label: np.ndarray, blocks: int,
               P: int) -> Sums:
    """The per-segment sums of one record, in one pass.

    Parameters
    ----------
    temperature : ndarray, shape (n,)
        C.
    rate : ndarray, shape (n,)
        dT/dt, C/s (smoothed).
    readings : ndarray, shape (n, 3)
        SI.
    label : ndarray, shape (n,)
        Branch label: +1 heating, -1 cooling, 0 neither.
    blocks : int
        Number of contiguous blocks B (>= 2).
    P : int
        Highest power of the temperature the fits will use.

    Returns
    -------
    Sums
    """
    n = len(temperature)
    lo, hi = float(np.min(temperature)), float(np.max(temperature))
    tc, hs = 0.5 * (lo + hi), max(0.5 * (hi - lo), 1e-9)
    rs = float(np.sqrt(np.dot(rate, rate) / n)) or 1.0
    ymean = np.ones(n) @ readings / n
    edges = np.linspace(0, n, blocks + 1).round().astype(np.int64)
    changes = np.flatnonzero(label[1:] != label[:-1]) + 1
    cuts = np.union1d(edges, changes)
    starts, ends = cuts[:-1], cuts[1:]
    q = P + 5
    G = np.zeros((len(starts), q, q))
    tlo, thi = np.empty(len(starts)), np.empty(len(starts))
    z = np.empty((q, min(CHUNK, n)))
    for s, (a, b) in enumerate(zip(starts, ends)):
        tlo[s], thi[s] = np.min(temperature[a:b]), np.max(temperature[a:b])
        for c0 in range(a, b, CHUNK):
            zz = _design(temperature, rate, readings, c0, min(c0 + CHUNK, b), P, tc, hs, rs, ymean, z)
            G[s] += zz @ zz.T
    block = np.searchsorted(edges, starts, side="right") - 1
    return Sums(G, block, label[starts].astype(np.int8), tlo, thi, P, tc, hs, rs, ymean, blocks)


def extremes(temperature: np.ndarray, rate: np.ndarray, readings: np.ndarray, s: Sums, W: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray]:
    """Largest ``|reading - mean|`` and ``|reading - model|`` of each axis (3,), SI, in one pass.

    ``W`` (P + 2, 3): each axis' coefficients of the design columns ``1, x, ..., x^P, r`` (zero where unused),
    for the readings less their mean.
    """
    n, P = len(temperature), s.P
    z = np.empty((P + 5, min(SMALL_CHUNK, n)))
    model = np.empty((3, min(SMALL_CHUNK, n)))
    extreme = np.zeros((4, 3))  # largest and smallest y, largest and smallest y - model
    Wt = W.T
    for a in range(0, n, SMALL_CHUNK):
        zz = _design(temperature, rate, readings, a, min(a + SMALL_CHUNK, n), P, s.tc, s.hs, s.rs, s.ymean, z)
        y, m = zz[P + 2:], model[:, :zz.shape[1]]
        np.matmul(Wt, zz[:P + 2], out=m)
        np.subtract(y, m, out=m)
        np.maximum(extreme[0], y.max(axis=1), out=extreme[0])
        np.minimum(extreme[1], y.min(axis=1), out=extreme[1])
        np.maximum(extreme[2], m.max(axis=1), out=extreme[2])
        np.minimum(extreme[3], m.min(axis=1), out=extreme[3])
    return np.maximum(extreme[0], -extreme[1]), np.maximum(extreme[2], -extreme[3])


def solve(G: np.ndarray, cols: list[int], y: int) -> np.ndarray:
    """Least-squares coefficients from sums: ``G[cols, cols] c = G[cols, y]`` (pseudo-inverse when singular)."""
    A, b = G[np.ix_(cols, cols)], G[cols, y]
    try:
        c = np.linalg.solve(A, b)
        if np.all(np.isfinite(c)):
            return c
    except np.linalg.LinAlgError:
        pass
    return np.linalg.lstsq(A, b, rcond=None)[0]


def sse(G: np.ndarray, cols: list[int], y: int, c: np.ndarray) -> float:
    """Sum of squared residuals of coefficients ``c`` over the samples whose sums are ``G``:
    ``y^T y - 2 c^T X^T y + c^T X^T X c``."""
    return float(G[y, y] - 2.0 * c @ G[cols, y] + c @ G[np.ix_(cols, cols)] @ c)
