"""Whole-model noise fit of an Allan variance curve by generalised least squares, and noise figures.

The five-term model of :mod:`align.noise.model` (IEEE Std 952 Annex C / Std 1554)::

    sigma^2(tau) = 3 Q^2 / tau^2 + N^2 / tau + (2 ln 2 / pi) B^2 + K^2 tau / 3 + R^2 tau^2 / 2  =  A(tau) p

is linear in the squared parameters ``p = (Q^2, N^2, B^2, K^2, R^2)``. Overlapping Allan variances
at neighbouring taus share most of their data and are strongly correlated (0.7-0.9 between
neighbours of a dense grid), so the fit is generalised least squares (:mod:`align.noise.gls`) with
their full covariance ``S(p)`` computed analytically from the fitted model itself
(:mod:`align.noise.covariance`, exact for Gaussian power-law noise; no bootstrap, no independence
assumption): non-negative ``p`` minimising ``(y - A p)' S(p)^-1 (y - A p)`` over at most
:data:`FIT_POINTS` log-spaced points of the curve, ``S`` recomputed from the fit :data:`ITERATIONS`
times, then only the terms the data demand (:mod:`align.noise.gls`: a likelihood-ratio test of each term
against the model refitted without it, chi-bar-square p-values, Holm's step-down procedure over the
:data:`~align.noise.gls.TRIED` terms tried at the family-wise rate :data:`~align.noise.gls.FALSE_ALARM`; a
ramp that fails leaves the model, a noise term that fails stays in it unclaimed). The ramp's cross terms with
every noise term (white, flicker, random walk, quantization) are in the covariance (:mod:`align.noise.covariance`).
The covariance of ``p`` is ``(A' S^-1 A)^-1`` on the kept terms, scaled by ``chi2 / dof`` when above 1 (a curve
the model does not describe; the ramp's variance at least that with the unclaimed noise terms at their upper values,
:mod:`align.noise.gls`), and a parameter's 1-sigma is ``sigma(p_k) / (2 sqrt(p_k))``.

A term is identifiable when Holm's test claims it, it is at least 30 % of the model at some fitted tau,
and it is known to 25 % (1-sigma). Otherwise the fit gives its one-sided 95 % upper bound (the largest value
whose curve alone stays under every point's one-sided 99 % chi-square
bound ``AVAR edf / chi2_0.01(edf)``, NIST SP 1065 Eq 5.34, about 95 % over the points: at the long-tau end for K and R) and the
record length (sample rate for ``Q`` and ``N``) at which a term of that size would be identifiable
by the same test, from the Fisher information ``A' S^-1 A`` of such a record. The IEEE point
readouts (:mod:`align.noise.readouts`) are kept beside the fit, labelled as such. SI throughout.

Public names
------------
NoiseFit, fit_noise, point_readouts, noise_figures, nnls_small, FIT_METHOD;
TERMS, model_adev (from :mod:`align.noise.model`)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from align.errors import TestError
from align.noise import periodic
from align.noise.allan import AllanResult, confidence_interval, edf_overlapping, tau_grid
from align.noise.covariance import avar_covariance, avar_covariance_basis
from align.noise.gls import FALSE_ALARM, GlsFit, nnls_small, scaled_nnls, whitener
from align.noise.model import NOISE_ALPHA, TERMS, NoiseModel, avar_design, model_adev
from align.noise.readouts import point_readouts
from align.values import Value

__all__ = ["NoiseFit", "fit_noise", "point_readouts", "noise_figures", "nnls_small", "FIT_METHOD", "TERMS",
           "model_adev"]

FIT_METHOD = ("generalised least squares on the overlapping Allan variance with its covariance from the fitted "
              "model (IEEE 952 five-term model, non-negative squared terms)")
#: most curve points the fit uses (log-spaced, the longest tau always among them)
FIT_POINTS = 32
#: least EDF of a point a deterministic signal (ramp, periodic disturbance) is tested on
SIGNAL_EDF = 10.0
#: refits with the covariance of the previous fit
ITERATIONS = 3
#: one-sided level of each point's bound behind them (the minimum over several points: about 95 % overall)
POINT_LEVEL = 0.99
#: the IEEE letter of each term
LETTERS = dict(zip(TERMS, "QNBKR"))


@dataclass(frozen=True, eq=False)
class NoiseFit(Value):
    """Fitted noise terms of one channel (SI: rad, rad/sqrt(s), rad/s, rad/s/sqrt(s), rad/s^2 for a gyro).

    Attributes
    ----------
    params, sigma : ndarray, shape (5,)
        ``Q, N, B, K, R`` and their 1-sigma, ``sqrt(cov_kk) / (2 p_k)`` from the generalised least-squares fit with
        the covariance of the overlapping Allan variances (module docstring); NaN sigma for a term fitted as zero.
    identifiable : tuple of bool
    notes : tuple of str
        Why a term is not identifiable, and what record would make it so (no values: those are ``upper`` and
        ``needed``).
    dominant : tuple of str
        The term dominant at each tau.
    edf : ndarray, shape (T,)
    ci_low, ci_high : ndarray, shape (T,)
        68.3 % interval of the deviation at each tau.
    readouts : dict
        IEEE point readouts (:data:`align.noise.readouts.READOUT_KEYS`): ``N_tau1``, ``B_floor``, ``K_tau3`` with
        ``_lo``/``_hi`` 68.3 % bounds and ``B_floor_tau`` (SI; NaN where no region of the right slope exists).
    cov : ndarray, shape (5, 5)
        Covariance of the squared parameters ``Q^2 .. R^2`` at the estimate, ``(A' S^-1 A)^-1`` (NaN rows for terms
        fitted as zero).
    upper : ndarray, shape (5,)
        One-sided 95 % upper bound of each term that is not identifiable (SI; NaN for identifiable terms).
    needed : ndarray, shape (5,)
        For each term that is not identifiable: the record length (s) at which a term as large as ``upper``
        would be identifiable, or for ``Q`` and ``N`` the sample rate (Hz); NaN where none within 65536x.
    method : str
    pvalues : ndarray, shape (5,)
        p-value of each term's likelihood-ratio test against the model without it (1 for a term fitted as zero).
    false_alarm : float
        The stated chance that a record lacking a term gets it claimed, over all terms tried
        (:data:`align.noise.gls.FALSE_ALARM`).
    periodic : ndarray, shape (2,)
        A periodic disturbance the test claims (:mod:`align.noise.periodic`): period (s) and amplitude (SI);
        NaN when none. Modelled apart from the five terms.
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
    cov: np.ndarray = field(default_factory=lambda: np.full((5, 5), np.nan))
    upper: np.ndarray = field(default_factory=lambda: np.full(5, np.nan))
    needed: np.ndarray = field(default_factory=lambda: np.full(5, np.nan))
    method: str = FIT_METHOD
    pvalues: np.ndarray = field(default_factory=lambda: np.ones(5))
    false_alarm: float = FALSE_ALARM
    periodic: np.ndarray = field(default_factory=lambda: np.full(2, np.nan))

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in ("identifiable", "notes", "dominant"):
            object.__setattr__(self, name, tuple(getattr(self, name)))
        object.__setattr__(self, "readouts", {k: float(v) for k, v in self.readouts.items()})

    @property
    def model(self) -> NoiseModel:
        """The fitted terms as a :class:`~align.noise.model.NoiseModel` (a curve ``sigma(tau)``)."""
        return NoiseModel.from_params(self.params)


def _point_edf(res: AllanResult, channel: int, p: np.ndarray) -> tuple[np.ndarray, tuple]:
    """EDF of each point: the result's own (per-tau identification) when it has them, else the fit's dominant term."""
    contrib = avar_design(res.tau) * p[None, :]
    dominant = tuple(TERMS[int(k)] for k in np.argmax(contrib, axis=1))
    own = getattr(res, "edf", None)
    if own is not None:
        return np.asarray(own, dtype=float)[channel], dominant
    return edf_overlapping(res.n_phase, res.m, np.array([NOISE_ALPHA[d] for d in dominant])), dominant


def fit_noise(res: AllanResult, channel: int, min_edf: float = 2.0, where: str | None = None) -> NoiseFit:
    """Fit the five-term model to one channel of an :class:`AllanResult` (module docstring: GLS, bounds).

    Parameters
    ----------
    res : AllanResult
        Overlapping Allan deviation, shape (C, T), in SI.
    channel : int
        Row of ``res.adev``.
    min_edf : float
        Points with fewer equivalent degrees of freedom are left out.
    where : str, optional
        The channel, for messages (by default its name).

    Returns
    -------
    NoiseFit
        ``params`` (5,): ``Q, N, B, K, R`` of ``sigma^2(tau) = 3Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3
        + R^2 tau^2/2`` (IEEE Std 952), SI, with their 1-sigma.

    Raises
    ------
    TestError
        The channel's Allan deviation is zero (a constant record: a stuck or disconnected sensor)
        or not reliable at any tau (``where``: the channel, by default its name).

    Examples
    --------
    A white-noise record (``N = 1e-3`` rad/s/sqrt(Hz)): ``N`` is identified within a few percent.

    >>> import numpy as np
    >>> from align.noise.allan import allan
    >>> from align.noise.sim import NoiseSpec, simulate_noise
    >>> r = allan(simulate_noise(20_000, 100.0, NoiseSpec(white=1e-3), seed=1), 100.0)
    >>> f = fit_noise(r, 0)
    >>> f.identifiable[1], bool(abs(f.params[1] / 1e-3 - 1) < 0.05)
    (True, True)
    """
    tau, adev = res.tau, res.adev[channel]
    avar = adev**2
    edf, _ = _point_edf(res, channel, np.array([0.0, 1.0, 0.0, 0.0, 0.0]))
    _check_fittable(res, channel, (edf >= min_edf) & (avar > 0), where)
    p = np.zeros(5)
    for _ in range(2):  # a start: weights from each point's EDF
        use = (edf >= min_edf) & (avar > 0)
        w = np.sqrt(edf[use] / 2.0) / avar[use]
        p = scaled_nnls(avar_design(tau[use]) * w[:, None], avar[use] * w)
        edf, dominant = _point_edf(res, channel, p)
    use = np.flatnonzero((edf >= min_edf) & (avar > 0))
    pick = use[np.unique(np.round(np.linspace(0, len(use) - 1, min(FIT_POINTS, len(use)))).astype(int))]
    a, y = avar_design(tau[pick]), avar[pick]
    basis = avar_covariance_basis(res.m[pick], res.n_phase, res.fs, ramp=True) / res.runs
    fallback = 2 * np.maximum(a @ p, y) ** 2 / np.maximum(edf[pick], 1.0)
    # where a deterministic signal is tested (GlsFit._signal_fit): the points' EDF, and not more than the start
    # model's dominant term gives them (the per-tau identification can read a long-tau point as white, EDF 100+)
    alpha = np.array([NOISE_ALPHA[d] for d in dominant])[pick]
    strong = np.minimum(edf[pick], edf_overlapping(res.n_phase, res.m[pick], alpha) * max(int(res.runs), 1)) >= SIGNAL_EDF
    gls = GlsFit(a, y, basis, fallback, signal_points=strong)
    period, periodic_note = float("nan"), []
    if len(pick) > 7:  # a sixth column: the period whose signature best fits what the terms leave (align.noise.periodic)
        q = gls._iterate(p, ITERATIONS)
        wh = gls.wh(q)
        period, _, count = periodic.scan(tau[pick], wh @ (y - a @ q), wh)
        if np.isfinite(period):
            a6 = np.column_stack([a, periodic.signature(tau[pick], period)])
            gls = GlsFit(a6, y, basis, fallback, scan=np.r_[np.ones(5), count], signal_points=strong)
            p = np.r_[q, 0.0]
    p, cov, _ = gls.solve(p, ITERATIONS)
    wave = np.array([period, np.sqrt(p[5])]) if len(p) > 5 and gls.claimed[5] else np.full(2, np.nan)
    if len(p) > 5:
        if np.isfinite(wave[1]):
            periodic_note.append(periodic.note(*wave))
        p, cov = p[:5], cov[:5, :5]
    params = np.sqrt(p)
    upper = np.full(5, np.nan)
    sigma = np.where(p > 0, np.sqrt(np.abs(np.diag(cov))) / (2 * np.where(params > 0, params, 1.0)), np.nan)
    contrib = a * p[None, :]
    share = (contrib / np.maximum(contrib.sum(axis=1), 1e-300)[:, None]).max(axis=0)
    rel = np.where(p > 0, sigma / np.where(params > 0, params, 1.0), np.inf)
    ident = (p > 0) & gls.claimed[:5] & (share >= 0.3) & (rel < 0.25)
    needed, notes = np.full(5, np.nan), []
    edf_all, dominant = _point_edf(res, channel, p)
    for k in np.flatnonzero(~ident).tolist():
        edf_k = edf_all[use] if res.runs <= 1 else np.minimum(edf_all[use], _term_edf(res, k, use))
        upper[k] = _upper(k, p, tau[use], avar[use], edf_k)
        needed[k], here = _needed(k, upper[k], p, res)
        notes.append(_note(k, p[k], share[k], rel[k], needed[k], res, here))
    lo, hi = confidence_interval(adev, edf)  # the channel's EDF: the result's own (per-tau identification)
    readouts = point_readouts(tau, adev, edf_all, lambda idx: avar_covariance(res.m[idx], res.n_phase, res.fs, params) / res.runs,
                              params)
    return NoiseFit(params, sigma, tuple(bool(i) for i in ident), tuple(periodic_note + notes), dominant, edf_all, lo,
                    hi, readouts, cov, upper, needed, pvalues=gls.pvalues[:5].copy(), periodic=wave)


def _term_edf(res: AllanResult, k: int, use: np.ndarray) -> np.ndarray:
    """EDF of the points ``use`` were term ``k`` the noise there (SP 1065 Table 5 with its alpha), times the runs
    pooled: the bound asks "could term ``k`` be this large?", and where it would dominate its points have its
    (fewer) degrees of freedom, not the sum of what each run's identification found there (that sum made the
    pooled bound of a rate random walk too tight: below the truth in 6 of 39 lots,
    tests/noise/test_pooled_bound_coverage.py). A single run keeps its own EDF, whose bounds cover
    (tests/noise/test_fit_coverage.py)."""
    m = np.asarray(res.m, dtype=float)[use]
    return edf_overlapping(res.n_phase, m, np.full(len(m), NOISE_ALPHA[TERMS[k]])) * max(int(res.runs), 1)


def _upper(k: int, p: np.ndarray, tau: np.ndarray, avar: np.ndarray, edf: np.ndarray) -> float:
    """One-sided 95 % upper bound of term ``k``: the largest value whose curve stays under every point's bound.

    Each point's bound is the one-sided chi-square one, ``AVAR edf / chi2_{1-POINT_LEVEL}(edf)`` (NIST SP 1065
    Eq 5.34); the term alone may not exceed it anywhere (the other terms only add to the curve), so the bound is
    set where the term rises fastest against the data: the long-tau end for K and R, the short-tau end for Q.
    The minimum runs over several correlated points, so each is taken at :data:`POINT_LEVEL` (99 %) to keep
    about 95 % overall (checked on simulated records, tests/noise/test_fit_coverage.py).
    """
    from scipy.special import gammaincinv

    top = avar * edf / (2 * gammaincinv(edf / 2, 1 - POINT_LEVEL))
    return float(np.sqrt(np.min(top / avar_design(tau)[:, k])))


def _identifiable_at(k: int, p: np.ndarray, n: float, fs: float, runs: int = 1) -> bool:
    """Whether term ``k`` of the squared parameters ``p`` is identifiable from ``runs`` records of ``n`` samples at
    ``fs``."""
    m = tau_grid(int(n), fs, "dense", per_decade=2).astype(float)
    a = avar_design(m / fs)
    cols = np.flatnonzero(p > 0)
    s = avar_covariance(m, n + 1, fs, np.sqrt(p), lags=32) / runs
    wh = whitener(s, np.diag(s) + 1e-300)
    aw = wh @ a[:, cols]
    at = cols.tolist().index(k)
    var = np.linalg.pinv(aw.T @ aw)[at, at]
    contrib = a * p[None, :]
    share = float(np.max(contrib[:, k] / np.maximum(contrib.sum(axis=1), 1e-300)))
    return bool(share >= 0.3 and np.sqrt(max(var, 0.0)) / (2 * p[k]) < 0.25)


def _needed(k: int, bound: float, p: np.ndarray, res: AllanResult) -> tuple[float, bool]:
    """Record length (s; sample rate, Hz, for Q and N) at which a term ``k`` of size ``bound`` would be identifiable,
    and whether a term that size would already be identified from this record (then the term is smaller than the
    bound, and no length can be named: NaN)."""
    if not bound > 0:
        return float("nan"), False
    q = p.copy()
    q[k] = bound**2
    rate = TERMS[k] in ("quantization", "white")
    scale = ((lambda j: (res.n * 2.0**j, res.fs * 2.0**j, res.runs)) if rate
             else (lambda j: (res.n * 2.0**j, res.fs, res.runs)))
    if _identifiable_at(k, q, *scale(0)):
        return float("nan"), True
    lo, hi = 0, 16
    if not _identifiable_at(k, q, *scale(hi)):
        return float("nan"), False
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if _identifiable_at(k, q, *scale(mid)) else (mid, hi)
    n, fs, _ = scale(hi)
    return (fs if rate else n / fs), False


def _note(k: int, pk: float, share: float, rel: float, needed: float, res: AllanResult, here: bool = False) -> str:
    """Why term ``k`` is not identifiable and what would make it so (values live in ``upper``/``needed``)."""
    term, hours = TERMS[k], res.n / res.fs / 3600
    record = f"this {hours:.3g} h record" if res.runs == 1 else f"these {res.runs} runs of {hours:.3g} h"
    per = "" if res.runs == 1 else " per run"
    if pk <= 0:
        why = "fitted as zero"
    elif share < 0.3:
        why = f"at most {100 * share:.0f} % of the curve at any tau"
    else:
        why = f"1-sigma {100 * rel:.0f} %"
    head = f"{term} ({LETTERS[term]}): not identifiable from {record} ({why}); 95 % upper bound given"
    if here:
        return head + (f"; a term as large as the bound would show in {'this record' if res.runs == 1 else 'these runs'}"
                       ", so it is smaller: how much longer or faster a record must be to identify it is not known")
    if not np.isfinite(needed):
        return head + "; no record up to 65536 times longer or faster would identify a term that size"
    if term in ("quantization", "white"):
        return head + f"; a sample rate of about {needed:.3g} Hz would identify a term that size"
    return head + f"; about {needed / 3600:.3g} h of record{per} would identify a term that size"


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


def noise_figures(y: np.ndarray, fs: float, periods=(1.0, 10.0)) -> dict:
    """The seed's figures of one run (reference section 6): bias and bias stability per period.

    ``bias = mean(y)`` (Eq 5); ``bias stability(P)`` = std (ddof 1) of the means
    of consecutive windows of ``P`` seconds (Eq 7). Units as ``y``.
    """
    y = np.asarray(y, dtype=float)
    stability: dict[float, float] = {}
    out = {"bias": float(np.mean(y)), "stability": stability}
    for p in periods:
        k = int(round(p * fs))
        windows = len(y) // k if k > 0 else 0
        if windows < 2:
            stability[p] = float("nan")
            continue
        means = y[: windows * k].reshape(windows, k).mean(axis=1)
        stability[p] = float(np.std(means, ddof=1))
    return out
