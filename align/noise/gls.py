"""Generalised least squares of the Allan variance on the IEEE Std 952 model, with its covariance.

The model ``y = A p`` (``y`` the overlapping Allan variances at T taus, ``A`` the columns of
:func:`align.noise.model.avar_design`, ``p`` the squared coefficients ``Q^2 .. R^2``) is fitted by
minimising ``chi2(p) = (y - A p)' S(p)^-1 (y - A p)`` over ``p >= 0``, with ``S(p)`` the covariance of
the estimates under the model itself (:mod:`align.noise.covariance`, a quadratic form in ``p``),
iterated from a start. A term stays only when the data demand it (:meth:`GlsFit.solve`): a likelihood-ratio
test of each term against the model without it,

    D_k = chi2_0(p_0) - min_{p >= 0} chi2_0(p),

both with the covariance ``S(p_0)`` of the model refitted without the term (the null hypothesis's own
covariance: the fitted term cannot lower the weights it is tested with). A term on the boundary of its
domain (``p_k >= 0``) has the chi-bar-square null distribution ``D ~ 1/2 chi2_0 + 1/2 chi2_1`` (Self & Liang
1987), p-value ``P_k = erfc(sqrt(D_k / 2)) / 2``. The look-elsewhere effect of trying :data:`TRIED` terms is
held by Holm's step-down procedure (Holm 1979): sorted p-values ``P_(1) <= P_(2) <= ...`` are significant while
``P_(i) <= FALSE_ALARM / (TRIED - i + 1)``. A deterministic signal (the ramp, a periodic part) that is not
significant is dropped, the least significant first, the model refitted and the tests repeated; a noise term
that is not significant stays in the model, unclaimed (its variance belongs in the covariance every other term
is weighed with: a rate random walk's own trend looks like a ramp, and the ramp must prove itself against the
whole noise model, not the noise model against the ramp). The chance that a record without a term
still gets it is then at most :data:`FALSE_ALARM` over all the terms tried. A curve the model does not describe
(``chi2`` above its 99 % quantile; real sensors: a slope between the ideal ones, a bump) would make
GLS chase the differences between nearly equal, strongly correlated points; such a fit adds an
independent relative error ``e`` to every point, ``S + diag((e A p)^2)``, with ``e`` set so that
``chi2 / dof = 1`` (the model's inadequacy, estimated; ``excess``).

The covariance of the kept coefficients is ``(A' S^-1 A)^-1`` at the estimate, scaled by
``chi2 / dof`` when above 1. A deterministic signal's variance is the larger of that and the same with every noise
term Holm's test does not claim raised to at least :data:`UPPER_Z` (one-sided 95 %) times its standard deviation
from the Fisher information of all the columns (:meth:`GlsFit._signal_cov`): an unclaimed term may still be there,
and what the ramp's estimate is most uncertain about is a rate random walk (its own trend looks like a ramp, ``K /
sqrt(T)`` over a record of length ``T``); fitted at zero, flicker and the ramp taking its place, it left 3 of 31
claimed ramps 3-5 sigma off.

The model covariance is whitened with a ridge on the diagonal of its correlations (:func:`whitener`): 1e-10
(rounding) where it factorises so, else ten times the least of :data:`RIDGES` that does. Under a rate random walk
the correlation matrix of a dense grid has eigenvalues down to -1e-4 (the lag sums' errors); its Cholesky factor
failed, and the fit fell back to independent points in a third of the fits (the likelihood-ratio tests then counted
correlated points as independent evidence: a bias instability that is not there in 5 of 120 records, 22 of its 120
p-values below 0.01; now 3 and 8, tests/noise/test_term_selection.py).

Public names
------------
nnls_small, GlsFit, PRUNE_CHI2, FALSE_ALARM, TRIED, term_pvalue, holm
"""

from __future__ import annotations

import numpy as np

from align.noise.covariance import combine_covariance

__all__ = ["nnls_small", "GlsFit", "PRUNE_CHI2", "FALSE_ALARM", "TRIED", "term_pvalue", "holm"]

#: the stated false-alarm rate: the chance that a record lacking a term gets it claimed, over all terms tried
FALSE_ALARM = 0.01
#: the terms tried (the five IEEE terms and a periodic component): Holm's family
TRIED = 6
#: columns from this index on are deterministic signals (ramp, periodic), dropped before any noise term
DETERMINISTIC = 4
#: ridges tried on the diagonal of the correlations of the Allan variances before whitening (:func:`whitener`)
RIDGES = (1e-10, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2)
#: one-sided 95 % normal quantile: an unclaimed noise term's upper value in a deterministic signal's variance
UPPER_Z = 1.645
#: least drop of chi-square for which a single term alone would pass Holm's first step (chi-bar-square at
#: FALSE_ALARM / TRIED; kept for callers of the former fixed threshold)
PRUNE_CHI2 = 8.6154  # 2 erfcinv(2 FALSE_ALARM / TRIED)^2


def term_pvalue(delta: float) -> float:
    """p-value of a likelihood-ratio drop ``delta`` of one non-negative term: ``P(1/2 chi2_0 + 1/2 chi2_1 > delta)``."""
    from scipy.special import erfc

    return 1.0 if not delta > 0 else float(0.5 * erfc(np.sqrt(delta / 2)))


def holm(pvalues: np.ndarray, alpha: float = FALSE_ALARM, tried: int = TRIED) -> np.ndarray:
    """Holm's step-down test: which of ``pvalues`` (K,) are significant at family-wise rate ``alpha`` over ``tried``.

    Sorted ascending, ``P_(i)`` is significant while every ``P_(j) <= alpha / (tried - j + 1)``, ``j <= i``.
    """
    pvalues = np.asarray(pvalues, dtype=float)
    out = np.zeros(len(pvalues), dtype=bool)
    for i, k in enumerate(np.argsort(pvalues, kind="stable")):
        if not pvalues[k] <= alpha / (tried - i):
            break
        out[k] = True
    return out


def nnls_small(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Non-negative least squares for a handful of unknowns, exactly: Lawson and Hanson's active-set method.

    ``min |A x - b|`` subject to ``x >= 0`` (Lawson and Hanson 1974, "Solving Least Squares Problems", ch. 23):
    the column of largest gradient ``A'(b - A x)`` joins the passive set, the unconstrained solution on the
    passive set is taken while positive, else the step is cut back to the first coefficient that reaches zero,
    which leaves. It ends at the optimum (the Karush-Kuhn-Tucker conditions hold) in a few least-squares
    solves for k = 5 or 6 columns (enumerating the ``2^k`` supports takes 63), and without scipy.optimize on the
    command line's path.
    """
    m, k = a.shape
    x = np.zeros(k)
    passive = np.zeros(k, dtype=bool)
    tol = 10 * np.finfo(float).eps * max(m, k) * max(float(np.abs(a).sum(axis=0).max(initial=0.0)), 1.0)
    for _ in range(3 * k + 3):
        w = a.T @ (b - a @ x)
        free = ~passive
        if not free.any() or w[free].max() <= tol:
            break
        passive[np.flatnonzero(free)[np.argmax(w[free])]] = True
        for _ in range(3 * k + 3):
            z = np.zeros(k)
            z[passive] = np.linalg.lstsq(a[:, passive], b, rcond=None)[0]
            if np.all(z[passive] > tol):
                x = z
                break
            neg = passive & (z <= tol)
            alpha = float(np.min(x[neg] / (x[neg] - z[neg])))
            x = x + alpha * (z - x)
            passive &= x > tol
            x[~passive] = 0.0
            if not passive.any():
                break
    return x


def _nnls_enumerated(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The NNLS optimum by enumerating the ``2^k`` supports (the reference :func:`nnls_small` is tested against)."""
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
    """``L^-1`` with ``L L' = cov + r diag(cov)``; the diagonal ``fallback`` variances if unusable.

    ``r`` is 1e-10 (rounding) when the correlation matrix factorises with it. When it does not, an eigenvalue is
    negative: the lag sums' errors (:mod:`align.noise.covariance`) exceed it, and directions of that variance are not
    resolved; ``r`` is then ten times the least of :data:`RIDGES` that factorises (an independent error of
    ``sqrt(r)`` of each point's standard deviation), so that no direction is weighed by the inverse of a rounding
    error (module docstring).
    """
    d = np.diag(cov)
    if np.all(d > 0) and np.all(np.isfinite(cov)):
        s = np.sqrt(d)
        corr, eye = cov / np.outer(s, s), np.eye(len(d))
        for i, ridge in enumerate(RIDGES):
            try:
                chol = np.linalg.cholesky(corr + ridge * eye)
            except np.linalg.LinAlgError:
                continue
            if i > 0:
                chol = np.linalg.cholesky(corr + 10 * ridge * eye)
            return np.linalg.inv(chol) / s[None, :]
    return np.diag(1 / np.sqrt(fallback))


class GlsFit:
    """One channel's GLS problem on fixed taus: ``A`` (T, J), ``y`` (T,), covariance basis (4 or 5, 4 or 5, T, T).

    The first five columns of ``A`` are the IEEE terms (:func:`align.noise.model.avar_design`); further columns
    (a periodic component) add no covariance. ``fallback`` (T,) are variances used where the model covariance is
    singular (a zero model). ``scan`` (J,) is the number of shapes a column was chosen from (the periodic
    component's periods: its p-value is multiplied by it, Bonferroni); 1 for the terms.
    """

    def __init__(self, a: np.ndarray, y: np.ndarray, basis: np.ndarray, fallback: np.ndarray,
                 scan: np.ndarray | None = None, signal_points: np.ndarray | None = None) -> None:
        self.a, self.y, self.basis, self.fallback = a, y, basis, fallback
        self.excess = 0.0
        self.scan = np.ones(a.shape[1]) if scan is None else np.asarray(scan, dtype=float)
        #: the points a deterministic signal is tested on (T,) bool: None, all (see :meth:`test_terms`)
        self.signal_points = signal_points
        self._sub: GlsFit | None = None
        #: p-value of each column's likelihood-ratio test in the final model (1 where fitted as zero)
        self.pvalues = np.ones(a.shape[1])
        #: the columns Holm's test finds significant in the final model
        self.claimed = np.zeros(a.shape[1], dtype=bool)

    def cov(self, p: np.ndarray) -> np.ndarray:
        """Covariance (T, T) of the Allan variances under squared coefficients ``p`` (J,), with the excess error."""
        q = np.sqrt(np.maximum(p[: self.basis.shape[0]], 0.0))
        cov = combine_covariance(self.basis, np.pad(q, (0, max(0, 5 - len(q)))))
        if self.excess > 0:
            cov = cov + np.diag((self.excess * (self.a @ p)) ** 2)
        return cov

    def wh(self, p: np.ndarray) -> np.ndarray:
        """Whitening matrix of the covariance under squared coefficients ``p`` (J,), with the model's excess error."""
        return whitener(self.cov(p), self.fallback)

    def chi2(self, p: np.ndarray, wh: np.ndarray) -> float:
        r = wh @ (self.a @ p - self.y)
        return float(r @ r)

    def _nnls(self, wh: np.ndarray, allowed: np.ndarray) -> tuple[np.ndarray, float]:
        """NNLS on the ``allowed`` columns with whitening ``wh``: the squared coefficients (J,) and their chi2."""
        aw, yw = wh @ self.a, wh @ self.y
        out = np.zeros(self.a.shape[1])
        c = np.flatnonzero(allowed)
        if len(c):
            out[c] = scaled_nnls(aw[:, c], yw)
        r = aw @ out - yw
        return out, float(r @ r)

    def _iterate(self, p: np.ndarray, iterations: int, allowed: np.ndarray | None = None) -> np.ndarray:
        """Iterated GLS from ``p``: each pass weighs with the covariance of the previous fit."""
        allowed = np.ones(len(p), dtype=bool) if allowed is None else allowed
        for _ in range(iterations + 1):
            p, _ = self._nnls(self.wh(p), allowed)
        return p

    def test_terms(self, p: np.ndarray, inplay: np.ndarray, iterations: int = 2) -> np.ndarray:
        """p-value (J,) of each positive column of ``p`` against the model refitted without it (module docstring).

        The model without column ``k`` may use every other column ``inplay`` (J,) (a term fitted as zero beside
        ``k`` may take its place); 1 for columns fitted as zero.
        """
        out = np.ones(len(p))
        for k in np.flatnonzero(p > 0):
            fit = self._signal_fit() if k >= DETERMINISTIC else self
            without = inplay.copy()
            without[k] = False
            q = fit._iterate(np.where(without, p, 0.0), iterations, without)
            wh = fit.wh(q)
            _, best = fit._nnls(wh, inplay)
            delta = fit.chi2(q, wh) - best
            out[k] = min(1.0, term_pvalue(delta) * self.scan[k])
        return out

    def _signal_fit(self) -> GlsFit:
        """The problem on :attr:`signal_points` alone: a deterministic signal (a ramp, a bump) is tested where
        the Allan variances are near enough to Gaussian for the likelihood ratio's chi-bar-square (enough
        degrees of freedom); on points of 2-9 EDF, chi-square tails the Gaussian likelihood misstates made
        false ramps and bumps several times the stated rate when a rate random walk dominates."""
        keep = self.signal_points
        if keep is None or keep.all() or keep.sum() < self.a.shape[1] + 2:
            return self
        sub = self._sub
        if sub is None:
            sub = self._sub = GlsFit(self.a[keep], self.y[keep], self.basis[:, :, keep][:, :, :, keep],
                                     self.fallback[keep], self.scan)
        sub.excess = self.excess
        return sub

    def select(self, p: np.ndarray, iterations: int) -> np.ndarray:
        """Holm's backward selection (module docstring) from the fit ``p``; the squared coefficients kept (J,).

        A deterministic signal (column ``>= DETERMINISTIC``) that is not significant leaves the model; a noise term
        that is not stays in it (its variance belongs in the covariance every other term is judged and weighed
        with) but is not claimed. :attr:`claimed` (J,) marks the columns Holm's test finds significant.
        """
        inplay = np.ones(len(p), dtype=bool)
        while True:
            pv = self.test_terms(p, inplay)
            active = np.flatnonzero(p > 0)
            ok = holm(pv[active])
            self.pvalues = pv
            self.claimed = np.zeros(len(p), dtype=bool)
            self.claimed[active[ok]] = True
            weak = active[~ok]
            signal = weak[weak >= DETERMINISTIC]
            if not len(signal):
                return p
            inplay[signal[np.argmax(pv[signal])]] = False
            p = self._iterate(np.where(inplay, p, 0.0), iterations, inplay)

    def solve(self, p0: np.ndarray, iterations: int = 4) -> tuple[np.ndarray, np.ndarray, float]:
        """Iterated GLS from ``p0``, the terms the data demand (Holm's selection), then the covariance of what stays.

        Returns the squared coefficients (J,), their covariance (J, J) (NaN for terms fitted as zero;
        ``(A' S^-1 A)^-1`` on the others) and ``chi2 / dof`` (1 when no degree of freedom is left). The p-values of
        the final model's terms are in :attr:`pvalues`.
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
                q = self._iterate(p, 2)
                lo, hi = (lo, (lo + hi) / 2) if self.chi2(q, self.wh(q)) < dof else ((lo + hi) / 2, hi)
            self.excess = 10**hi
            p = self._iterate(p, iterations)
        p = self.select(p, iterations)
        wh = self.wh(p)
        active = np.flatnonzero(p > 0)
        cov = np.full((len(p), len(p)), np.nan)
        if len(active):
            aw = wh @ self.a[:, active]
            cov[np.ix_(active, active)] = np.linalg.pinv(aw.T @ aw)
        dof = len(self.y) - len(active)
        scale = max(1.0, self.chi2(p, wh) / dof) if dof > 0 else 1.0
        cov = self._signal_cov(p, cov, wh)
        return p, cov * scale, scale

    def _signal_cov(self, p: np.ndarray, cov: np.ndarray, wh: np.ndarray) -> np.ndarray:
        """``cov`` (J, J) with each deterministic signal's variance the larger of its own and the one with every noise
        term Holm's test does not claim raised to at least :data:`UPPER_Z` times its standard deviation in the Fisher
        information ``A' S^-1 A`` of all the columns (module docstring); the signal's covariances scaled alike."""
        signal = np.flatnonzero((p > 0) & (np.arange(len(p)) >= DETERMINISTIC))
        if not len(signal):
            return cov
        aw = wh @ self.a
        norm = np.linalg.norm(aw, axis=0)
        norm[norm == 0] = 1.0
        full = np.linalg.pinv((aw / norm).T @ (aw / norm)) / np.outer(norm, norm)
        up = p.copy()
        for k in range(DETERMINISTIC):
            if not self.claimed[k]:
                up[k] = max(p[k], UPPER_Z * np.sqrt(max(float(full[k, k]), 0.0)))
        cols = np.flatnonzero(up > 0)
        aw = self.wh(up) @ self.a[:, cols]
        norm = np.linalg.norm(aw, axis=0)
        norm[norm == 0] = 1.0
        wide = np.linalg.pinv((aw / norm).T @ (aw / norm)) / np.outer(norm, norm)
        out = cov.copy()
        for j in signal.tolist():
            at = int(np.searchsorted(cols, j))
            var = float(wide[at, at])
            if var > out[j, j] > 0:
                f = np.sqrt(var / out[j, j])
                out[j, :] *= f
                out[:, j] *= f
        return out
