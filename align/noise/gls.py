"""Generalised least squares of the Allan variance on the IEEE Std 952 model, with its covariance.

The model ``y = A p`` (``y`` the overlapping Allan variances at T taus, ``A`` the columns of
:func:`align.noise.model.avar_design`, ``p`` the squared coefficients ``Q^2 .. R^2``) is fitted by
minimising ``chi2(p) = (y - A p)' S(p)^-1 (y - A p)`` over ``p >= 0``, with ``S(p)`` the covariance of
the estimates under the model itself (:mod:`align.noise.covariance`, a quadratic form in ``p``),
iterated from a start. A term stays only when dropping it raises ``chi2`` by at least
:data:`PRUNE_CHI2` (a likelihood-ratio test at about 2 sigma). A curve the model does not describe
(``chi2`` above its 99 % quantile; real sensors: a slope between the ideal ones, a bump) would make
GLS chase the differences between nearly equal, strongly correlated points; such a fit adds an
independent relative error ``e`` to every point, ``S + diag((e A p)^2)``, with ``e`` set so that
``chi2 / dof = 1`` (the model's inadequacy, estimated; ``excess``).

The covariance of the kept coefficients is ``(A' S^-1 A)^-1`` at the estimate, scaled by
``chi2 / dof`` when above 1.

Public names
------------
nnls_small, GlsFit, PRUNE_CHI2
"""

from __future__ import annotations

import numpy as np

from align.noise.covariance import combine_covariance

__all__ = ["nnls_small", "GlsFit", "PRUNE_CHI2"]

#: least drop of chi-square for which a term stays in the fit (2 sigma)
PRUNE_CHI2 = 4.0


def nnls_small(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Non-negative least squares for a handful of unknowns, exactly, by enumerating supports.

    The NNLS optimum is the unconstrained least-squares solution on its own
    support with all coefficients positive; every such candidate is feasible,
    so the best of them over all ``2^k`` supports is the optimum (k = 5 here:
    32 tiny solves, and no scipy.optimize import on the command line's path).
    """
    k = a.shape[1]
    best, best_r = np.zeros(k), float(b @ b)
    for mask in range(1, 2**k):
        cols = [j for j in range(k) if mask >> j & 1]
        sol, *_ = np.linalg.lstsq(a[:, cols], b, rcond=None)
        if np.all(sol > 0):
            r = float(np.sum((a[:, cols] @ sol - b) ** 2))
            if r < best_r:
                best, best_r = np.zeros(k), r
                best[cols] = sol
    return best


def scaled_nnls(aw: np.ndarray, bw: np.ndarray) -> np.ndarray:
    """:func:`nnls_small` with the columns scaled to unit norm (the terms span many decades)."""
    scale = np.linalg.norm(aw, axis=0)
    scale[scale == 0] = 1.0
    return nnls_small(aw / scale, bw) / scale


def whitener(cov: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    """``L^-1`` with ``L L' = cov`` (a tiny ridge for rounding); the diagonal ``fallback`` variances if singular."""
    d = np.diag(cov)
    if np.all(d > 0) and np.all(np.isfinite(cov)):
        try:
            s = np.sqrt(d)
            chol = np.linalg.cholesky(cov / np.outer(s, s) + 1e-10 * np.eye(len(d)))
            return np.linalg.inv(chol) / s[None, :]
        except np.linalg.LinAlgError:
            pass
    return np.diag(1 / np.sqrt(fallback))


class GlsFit:
    """One channel's GLS problem on fixed taus: ``A`` (T, 5), ``y`` (T,), covariance basis (4, 4, T, T).

    ``fallback`` (T,) are variances used where the model covariance is singular (a zero model).
    """

    def __init__(self, a: np.ndarray, y: np.ndarray, basis: np.ndarray, fallback: np.ndarray) -> None:
        self.a, self.y, self.basis, self.fallback = a, y, basis, fallback
        self.excess = 0.0

    def wh(self, p: np.ndarray) -> np.ndarray:
        """Whitening matrix of the covariance under squared coefficients ``p`` (5,), with the model's excess error."""
        cov = combine_covariance(self.basis, np.sqrt(np.maximum(p, 0.0)))
        if self.excess > 0:
            cov = cov + np.diag((self.excess * (self.a @ p)) ** 2)
        return whitener(cov, self.fallback)

    def chi2(self, p: np.ndarray, wh: np.ndarray) -> float:
        r = wh @ (self.a @ p - self.y)
        return float(r @ r)

    def _nnls(self, wh: np.ndarray, allowed: np.ndarray, test: bool) -> np.ndarray:
        aw, yw = wh @ self.a, wh @ self.y

        def fit(c: np.ndarray) -> tuple[np.ndarray, float]:
            out = np.zeros(5)
            if len(c):
                out[c] = scaled_nnls(aw[:, c], yw)
            r = aw @ out - yw
            return out, float(r @ r)

        p, chi2 = fit(np.flatnonzero(allowed))
        while test:
            active = np.flatnonzero(p > 0)
            if len(active) < 2:
                break
            trials = [fit(np.setdiff1d(active, [k])) for k in active]
            best = int(np.argmin([t[1] for t in trials]))
            if trials[best][1] - chi2 >= PRUNE_CHI2:
                break
            p, chi2 = trials[best]
        return p

    def _iterate(self, p: np.ndarray, iterations: int, test: bool = True) -> np.ndarray:
        allowed = np.ones(5, dtype=bool)
        for it in range(iterations + 1):
            p = self._nnls(self.wh(p), allowed, test=test and it == iterations - 1)
            allowed = p > 0
        return p

    def solve(self, p0: np.ndarray, iterations: int = 4) -> tuple[np.ndarray, np.ndarray, float]:
        """Iterated GLS from ``p0``; the test of terms after ``iterations`` passes, then a refit of what stays.

        Returns the squared coefficients (5,), their covariance (5, 5) (NaN for terms fitted as zero;
        ``(A' S^-1 A)^-1`` on the others) and ``chi2 / dof`` (1 when no degree of freedom is left).
        """
        from scipy.special import gammaincinv

        p = self._iterate(np.asarray(p0, dtype=float), iterations)
        dof = len(self.y) - int(np.sum(p > 0))
        if dof > 0 and self.chi2(p, self.wh(p)) > 2 * gammaincinv(dof / 2, 0.99):
            # the curve departs from the model beyond its scatter: a relative excess error per point, set so
            # that chi2 / dof = 1 (the model's inadequacy, estimated; zero for a curve the model describes)
            lo, hi = -6.0, 0.0
            for _ in range(14):
                self.excess = 10 ** ((lo + hi) / 2)
                q = self._iterate(p, 2, test=False)
                lo, hi = (lo, (lo + hi) / 2) if self.chi2(q, self.wh(q)) < dof else ((lo + hi) / 2, hi)
            self.excess = 10**hi
            p = self._iterate(p, iterations)
        wh = self.wh(p)
        active = np.flatnonzero(p > 0)
        cov = np.full((5, 5), np.nan)
        if len(active):
            aw = wh @ self.a[:, active]
            cov[np.ix_(active, active)] = np.linalg.pinv(aw.T @ aw)
        dof = len(self.y) - len(active)
        scale = max(1.0, self.chi2(p, wh) / dof) if dof > 0 else 1.0
        return p, cov * scale, scale
