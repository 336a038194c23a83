"""Whole-model noise fit of an Allan variance curve, IEEE point readouts, noise figures.

The five-term model of :mod:`align.noise.model` (IEEE Std 952 / 1554, reference
section 6)::

    sigma^2(tau) = 3 Q^2 / tau^2 + N^2 / tau + (2 ln 2 / pi) B^2 + K^2 tau / 3 + R^2 tau^2 / 2

quantization ``Q``, angle (velocity) random walk ``N``, bias instability ``B``
(curve floor ``0.664 B``), rate random walk ``K``, rate ramp ``R``. The squared
parameters are found by weighted non-negative least squares on the Allan
variance (weights from each point's equivalent degrees of freedom), refitted
once with the noise type the first fit makes dominant at each tau. The IEEE
point readouts (the tau = 1 s line, floor / 0.664, the tau = 3 s line) are kept
beside it, labelled as such.

Public names
------------
NoiseFit, fit_noise, point_readouts, noise_figures, nnls_small;
TERMS, model_adev (from :mod:`align.noise.model`)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.errors import TestError
from align.noise.allan import AllanResult, confidence_interval, edf_overlapping
from align.noise.model import FLICKER_FACTOR, NOISE_ALPHA, TERMS, NoiseModel, avar_design, model_adev
from align.values import Value

__all__ = ["NoiseFit", "fit_noise", "point_readouts", "noise_figures", "nnls_small", "TERMS", "model_adev"]


@dataclass(frozen=True, eq=False)
class NoiseFit(Value):
    """Fitted noise terms of one channel (SI: rad, rad/sqrt(s), rad/s, rad/s/sqrt(s), rad/s^2 for a gyro).

    Attributes
    ----------
    params, sigma : ndarray, shape (5,)
        ``Q, N, B, K, R`` and their 1-sigma (first-order from the NNLS covariance,
        scaled by the fit's chi-square per degree of freedom when above 1;
        neighbouring overlapping points are correlated, so take them as indicative).
    identifiable : tuple of bool
    notes : tuple of str
        Why a term is not identifiable, and what record would make it so.
    dominant : tuple of str
        The term dominant at each tau (used for the confidence intervals).
    edf : ndarray
    ci_low, ci_high : ndarray
        68.3 % interval of the deviation at each tau.
    readouts : dict
        IEEE point readouts ``N_tau1``, ``B_floor``, ``K_tau3`` (SI; NaN where no
        segment of the right slope exists).
    """

    params: np.ndarray
    sigma: np.ndarray
    identifiable: tuple
    notes: tuple
    dominant: tuple
    edf: np.ndarray
    ci_low: np.ndarray
    ci_high: np.ndarray
    readouts: dict

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in ("identifiable", "notes", "dominant"):
            object.__setattr__(self, name, tuple(getattr(self, name)))
        object.__setattr__(self, "readouts", {k: float(v) for k, v in self.readouts.items()})

    @property
    def model(self) -> NoiseModel:
        """The fitted terms as a :class:`~align.noise.model.NoiseModel` (a curve ``sigma(tau)``)."""
        return NoiseModel.from_params(self.params)


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


def _nnls_fit(tau, avar, edf):
    a = avar_design(tau)
    w = np.sqrt(edf / 2.0) / avar          # 1 / (relative sigma of AVAR) / AVAR
    aw, bw = a * w[:, None], avar * w
    scale = np.linalg.norm(aw, axis=0)
    scale[scale == 0] = 1.0
    p = nnls_small(aw / scale, bw) / scale
    return p, aw, bw


def fit_noise(res: AllanResult, channel: int, min_edf: float = 2.0, where: str | None = None) -> NoiseFit:
    """Fit the five-term model to one channel of an :class:`AllanResult`.

    Raises
    ------
    TestError
        The channel's Allan deviation is zero (a constant record: a stuck or disconnected sensor)
        or not reliable at any tau (``where``: the channel, by default its name).
    """
    tau, adev = res.tau, res.adev[channel]
    avar = adev**2
    edf = edf_overlapping(res.n_phase, res.m, np.zeros(len(tau)))
    _check_fittable(res, channel, (edf >= min_edf) & (avar > 0), where)
    for _ in range(2):
        use = (edf >= min_edf) & (avar > 0)
        p, aw, bw = _nnls_fit(tau[use], avar[use], edf[use])
        contrib = avar_design(tau) * p[None, :]
        dominant = tuple(TERMS[int(k)] for k in np.argmax(contrib, axis=1))
        edf = edf_overlapping(res.n_phase, res.m, np.array([NOISE_ALPHA[d] for d in dominant]))
    use = (edf >= min_edf) & (avar > 0)
    p, aw, bw = _nnls_fit(tau[use], avar[use], edf[use])
    params = np.sqrt(p)
    active = p > 0
    cov = np.full((5, 5), np.nan)
    dof = int(use.sum()) - int(active.sum())
    if active.any():
        sub = aw[:, active]
        c = np.linalg.pinv(sub.T @ sub)
        chi2 = float(np.sum((aw @ p - bw) ** 2))
        c *= max(1.0, chi2 / dof) if dof > 0 else 1.0
        cov[np.ix_(active, active)] = c
    var_p = np.diag(cov)
    sigma = np.where(active, np.sqrt(np.abs(var_p)) / (2 * np.where(params > 0, params, 1.0)), np.nan)
    contrib = avar_design(tau) * p[None, :]
    model = contrib.sum(axis=1)
    share = np.where(use[:, None], contrib / np.maximum(model, 1e-300)[:, None], 0.0).max(axis=0)
    ident, notes = [], []
    lo, hi = confidence_interval(adev, edf)
    for k, term in enumerate(TERMS):
        rel = sigma[k] / params[k] if params[k] > 0 else np.inf
        ok = bool(params[k] > 0 and share[k] >= 0.3 and rel < 0.25)
        ident.append(ok)
        if not ok:
            notes.append(_why(term, params, share[k], rel, tau, use, hi, model, res))
    return NoiseFit(params, sigma, tuple(ident), tuple(n for n in notes if n), dominant, edf, lo, hi,
                    point_readouts(tau, adev))


def _check_fittable(res: AllanResult, channel: int, use: np.ndarray, where: str | None) -> None:
    """Refuse a channel with no usable point of its Allan deviation (constant, or nearly so)."""
    if use.any():
        return
    where = where or str(res.names[channel])
    adev = res.adev[channel]
    if not np.any(adev > 0):
        raise TestError("the record is constant (Allan deviation 0 at every tau): a stuck or disconnected sensor, or "
                        "a column of zeros? record the sensor while it runs", where)
    raise TestError(f"the Allan deviation is 0 or unreliable at every tau of this {res.n:,}-sample record (nearly constant: "
                    "coarse quantisation?); record longer or at a finer resolution", where)


def _why(term, params, share, rel, tau, use, hi, model, res) -> str:
    """A sentence on why a term is not identifiable and, for slow terms, the record needed."""
    T = res.n / res.fs
    if params[TERMS.index(term)] > 0 and share >= 0.3:
        return f"{term}: estimated but uncertain ({100 * rel:.0f} % 1-sigma)"
    if term not in ("random_walk", "ramp"):
        return f"{term}: never more than {100 * share:.0f} % of the curve; not identifiable from this record"
    # the largest value the longest reliable tau (edf >= 5) allows, and where a term that size would show
    reliable = np.flatnonzero(use & (res.n_phase - 2 * res.m >= 5))
    last = reliable[-1] if len(reliable) else np.flatnonzero(use)[-1]
    if not hi[last] ** 2 > model[last]:  # the fit already fills the interval: no room for a bound
        return f"{term}: not identifiable from this {T / 3600:.3g} h record (largest share of the curve {100 * share:.0f} %)"
    room = hi[last] ** 2 - model[last]
    floor = max(FLICKER_FACTOR * params[2] ** 2 + params[1] ** 2 / tau[last], 1e-300)
    if term == "random_walk":
        bound = np.sqrt(3 * room / tau[last])
        cross = 3 * floor / bound**2
        symbol = "K"
    else:
        bound = np.sqrt(2 * room / tau[last] ** 2)
        cross = np.sqrt(2 * floor) / bound
        symbol = "R"
    need = max(20 * cross, 2 * T)
    return (f"{term}: not identifiable from this {T / 3600:.3g} h record (largest share of the curve {100 * share:.0f} %); "
            f"{symbol} < {bound:.3g} (SI) here, and a term that size would dominate only beyond tau ~ {cross:.3g} s: "
            f"about {need / 3600:.3g} h of record needed")


def point_readouts(tau: np.ndarray, adev: np.ndarray) -> dict:
    """IEEE Std 952 point readouts from the curve itself (labelled as such, not a fit).

    ``N_tau1``: the slope -1/2 line through the points of local slope -1/2 +/- 0.1,
    read at tau = 1 s; ``B_floor``: the curve minimum / 0.664; ``K_tau3``: the slope
    +1/2 line through points of local slope +1/2 +/- 0.1, read at tau = 3 s.
    """
    out = {}
    keep = np.asarray(adev) > 0  # a zero deviation has no logarithm
    tau, adev = np.asarray(tau)[keep], np.asarray(adev)[keep]
    if len(tau) == 0:
        return {"N_tau1": float("nan"), "B_floor": 0.0, "K_tau3": float("nan")}
    lt, la = np.log(tau), np.log(adev)
    slope = np.gradient(la, lt) if len(tau) > 2 else np.zeros_like(tau)
    white = np.abs(slope + 0.5) < 0.1
    out["N_tau1"] = float(np.exp(np.median(la[white] + 0.5 * lt[white]))) if white.any() else float("nan")
    out["B_floor"] = float(np.min(adev) / 0.664)
    rw = np.abs(slope - 0.5) < 0.1
    out["K_tau3"] = float(np.exp(np.median(la[rw] - 0.5 * lt[rw])) * np.sqrt(3.0)) if rw.any() else float("nan")
    return out


def noise_figures(y: np.ndarray, fs: float, periods=(1.0, 10.0)) -> dict:
    """The seed's figures of one run (reference section 6): bias and bias stability per period.

    ``bias = mean(y)`` (Eq 5); ``bias stability(P)`` = std (ddof 1) of the means
    of consecutive windows of ``P`` seconds (Eq 7). Units as ``y``.
    """
    y = np.asarray(y, dtype=float)
    out = {"bias": float(np.mean(y)), "stability": {}}
    for p in periods:
        k = int(round(p * fs))
        windows = len(y) // k if k > 0 else 0
        if windows < 2:
            out["stability"][p] = float("nan")
            continue
        means = y[: windows * k].reshape(windows, k).mean(axis=1)
        out["stability"][p] = float(np.std(means, ddof=1))
    return out
