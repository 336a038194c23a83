"""Covariance of overlapping Allan variance estimates of power-law noise, from a noise model.

The overlapping estimator at ``m`` (``tau = m tau0``, ``M = N - 2m`` terms, ``N`` phase points) is
``AVAR(m) = sum_i d_m(i)^2 / (2 tau^2 M)`` with ``d_m(i) = x[i+2m] - 2 x[i+m] + x[i]``
(NIST SP 1065 section 5.2.4). For Gaussian noise ``cov(d^2, e^2) = 2 cov(d, e)^2``, so

    cov(AVAR(m1), AVAR(m2)) = sum_l c(l) C(l)^2 / (2 tau1^2 tau2^2 M1 M2),
    C(l) = sum_{p,q=0..2} a_p a_q G((l + p m1 - q m2) tau0),   a = (1, -2, 1),

with ``c(l)`` the number of pairs ``(i, j)`` with ``i - j = l``. Second differences annihilate
straight lines, so the phase enters only through its generalised covariance (an intrinsic random
function of order 1), one per term of the IEEE Std 952 model (:mod:`align.noise.model`)::

    G(t) = Q^2 [t = 0] - N^2 |t| / 2 + B^2 t^2 ln|t| / (2 pi) + K^2 |t|^3 / 12

(white PM / quantization, white FM, flicker FM, random-walk FM; each reproduces its Allan variance
term ``3 Q^2/tau^2``, ``N^2/tau``, ``(2 ln 2/pi) B^2``, ``K^2 tau/3``).

A rate ramp ``R`` adds the same second difference ``mu_m = R tau^2`` to every ``d_m(i)``, so
``AVAR(m) = R^2 tau^2 / 2 + R ebar_m + sum_i e_m(i)^2 / (2 tau^2 M)`` with ``e`` the noise's second
differences and ``ebar_m`` their mean; the middle term is linear in the noise (uncorrelated with the
quadratic one for Gaussian noise) and adds

    cov(AVAR(m1), AVAR(m2)) += R^2 cov(ebar_1, ebar_2) = R^2 sum_l c(l) C(l) / (M1 M2):

under a rate random walk the record's own trend of the rate looks like a ramp, and this is what
keeps the ramp's uncertainty honest (about ``K / sqrt(T)`` for a record of ``T``). Only the rate random
walk's part is kept: ``ebar_m`` telescopes to the difference of the rate's means over the record's first and
last ``2 m`` samples, times ``m^2 tau0 / M``, whose variance is of order ``K^2 T`` for a random walk but
``N^2 / (m tau0)`` (white) and ``B^2`` (flicker) for stationary rates, smaller by ``(m / M)^2`` or more, and
sums of nearly cancelling lags that the trapezoid rule would not resolve.

``C(l)`` vanishes for ``l`` outside ``[-2 m1, 2 m2]`` but for flicker, whose tail
falls as ``1/l^2`` and is cut at eight times the larger ``m``. Lags are summed exactly when at most
:data:`LAGS` of them matter, otherwise by the trapezoid rule on :data:`LAGS` equally spaced lags
(the quantization term, a point mass at the nine knots, is always added exactly). As ``C`` is linear
in the squared coefficients, the covariance is a quadratic form in them, computed once per set of
taus (:func:`avar_covariance_basis`) and evaluated for any model at once. Its diagonal gives
the equivalent degrees of freedom ``2 AVAR^2 / var(AVAR)`` of each point.

Public names
------------
avar_covariance, avar_covariance_basis, combine_covariance, model_edf, LAGS
"""

from __future__ import annotations

import functools

import numpy as np

from align.noise.model import model_avar

__all__ = ["avar_covariance", "avar_covariance_basis", "combine_covariance", "model_edf", "LAGS"]

#: lags summed per pair of taus (exactly below this many, by the trapezoid rule above)
LAGS = 192

_A = np.array([1.0, -2.0, 1.0])
_COEF = np.outer(_A, _A).ravel()                # a_p a_q, (p, q) flattened
_P = np.repeat(np.arange(3), 3).astype(float)   # p of each of the nine knots
_Q = np.tile(np.arange(3), 3).astype(float)     # q


def _g_terms(t: np.ndarray) -> list[np.ndarray]:
    """Generalised covariance of the phase per unit squared coefficient of ``N, B, K``, ``t`` in s."""
    at = np.abs(t)
    tiny = at < 1e-300
    return [-at / 2, np.where(tiny, 0.0, at * at * np.log(np.where(tiny, 1.0, at))) / (2 * np.pi), at**3 / 12]


def avar_covariance_basis(m, n_phase: float, fs: float, lags: int = LAGS, ramp: bool = False) -> np.ndarray:
    """The covariance of the overlapping Allan variances as a quadratic form in the squared coefficients.

    ``cov = sum_{a,b} p_a p_b S[a, b]`` with ``p = (Q^2, N^2, B^2, K^2)``, or with ``ramp`` ``p = (Q^2, .., K^2, R^2)``
    and ``S[R, K] = S[K, R] = cov(ebar_1, ebar_2) / (2 K^2)`` (the ramp's cross term with the rate random walk,
    module docstring; zero elsewhere in the fifth row): computed once, the covariance of any model on the same
    taus costs one contraction (:func:`combine_covariance`).

    Parameters
    ----------
    m : array_like of int, shape (T,)
        Averaging factors, ``1 <= m <= (n_phase - 1) // 2``.
    n_phase : int or float
        Phase points of the record (samples + 1).
    fs : float
        Sample rate, Hz.
    lags : int
        Lags summed per pair beyond which the sum becomes a trapezoid rule.
    ramp : bool
        Also the ramp's cross terms (a fifth row and column).

    Returns
    -------
    ndarray, shape (4, 4, T, T), or (5, 5, T, T) with ``ramp``
        ``S[a, b]`` in s^-4 times the phase's generalised covariance units (SI), symmetric in ``(a, b)``; read-only
        (the basis of the same taus and record length is computed once: every channel of a record shares it).
    """
    m = np.ascontiguousarray(m, dtype=float)
    return _basis(m.tobytes(), float(n_phase), float(fs), int(lags), bool(ramp))


@functools.lru_cache(maxsize=32)
def _basis(m_bytes: bytes, n_phase: float, fs: float, lags: int, ramp: bool) -> np.ndarray:
    m = np.frombuffer(m_bytes, dtype=float)
    tau0 = 1.0 / fs
    t = len(m)
    ia, ib = np.triu_indices(t)
    m1, m2 = m[ia][:, None], m[ib][:, None]                 # (P, 1), m1 <= m2
    big1, big2 = n_phase - 2 * m1, n_phase - 2 * m2
    tail = 8 * np.maximum(m1, m2)                           # the flicker term's 1/l^2 tail
    lo = np.maximum(-(big2 - 1), -2 * m1 - tail)
    hi = np.minimum(big1 - 1, 2 * m2 + tail)
    span = hi - lo
    exact = span + 1 <= lags
    step = np.where(exact, 1.0, span / (lags - 1))
    grid = np.arange(lags, dtype=float)[None, :]
    lag = np.where(exact, np.minimum(lo + grid, hi), lo + grid * step)
    weight = np.clip(np.minimum(big1, big2 + lag) - np.maximum(0.0, lag), 0.0, None)
    weight = np.where(exact, np.where(lo + grid <= hi, weight, 0.0), weight * step)
    approx = ~exact[:, 0]
    weight[approx, 0] /= 2      # trapezoid end weights on the approximated pairs
    weight[approx, -1] /= 2
    # C_a(l): the nine knots (l + p m1 - q m2) tau0, summed with a_p a_q, per term a = N, B, K
    c = np.zeros((3,) + lag.shape)
    for k in range(9):
        c += _COEF[k] * np.array(_g_terms((lag + _P[k] * m1 - _Q[k] * m2) * tau0))
    nk = 5 if ramp else 4
    s = np.zeros((nk, nk, len(ia)))
    if ramp:  # cov(ebar_1, ebar_2) per unit K^2: sum_l c(l) C_K(l) / (M1 M2), halved (S[R,K] = S[K,R])
        s[4, 3] = s[3, 4] = np.sum(weight * c[2], axis=1) / (2 * big1[:, 0] * big2[:, 0])
    for a in range(3):
        for b in range(a, 3):
            s[a + 1, b + 1] = s[b + 1, a + 1] = np.sum(weight * c[a] * c[b], axis=1)
    # quantization: C_Q(l) = sum a_p a_q [l = q m2 - p m1], at the knots only
    knots = _Q[None, :] * m2 - _P[None, :] * m1                       # (P, 9)
    same = knots[:, :, None] == knots[:, None, :]
    cq = same @ _COEF
    per = np.clip(np.minimum(big1, big2 + knots) - np.maximum(0.0, knots), 0.0, None) / same.sum(axis=2)
    co = np.zeros((3,) + knots.shape)
    for k in range(9):
        co += _COEF[k] * np.array(_g_terms((knots + _P[k] * m1 - _Q[k] * m2) * tau0))
    s[0, 0] = np.sum(per * cq * cq, axis=1)
    for a in range(3):
        s[0, a + 1] = s[a + 1, 0] = np.sum(per * cq * co[a], axis=1)
    tau1, tau2 = m1[:, 0] * tau0, m2[:, 0] * tau0
    s[:4, :4] /= 2 * tau1**2 * tau2**2 * big1[:, 0] * big2[:, 0]
    out = np.zeros((nk, nk, t, t))
    out[:, :, ia, ib] = s
    out[:, :, ib, ia] = s
    out.flags.writeable = False
    return out


def combine_covariance(basis: np.ndarray, params) -> np.ndarray:
    """``cov = sum_{a,b} p_a p_b S[a, b]`` for ``params = (Q, N, B, K, R)`` (SI), shape (T, T).

    ``basis`` (4, 4, T, T) or (5, 5, T, T) (with the ramp's cross terms) from :func:`avar_covariance_basis`.
    """
    p = np.square(np.asarray(params, dtype=float)[: basis.shape[0]])
    return np.einsum("a,b,abij->ij", p, p, basis)


def avar_covariance(m, n_phase: float, fs: float, params, lags: int = LAGS) -> np.ndarray:
    """Covariance of the overlapping Allan variances at averaging factors ``m`` under a noise model.

    Parameters
    ----------
    m : array_like of int, shape (T,)
    n_phase : int or float
    fs : float
        As :func:`avar_covariance_basis`.
    params : array_like, shape (5,)
        ``Q, N, B, K, R`` (SI; see :mod:`align.noise.model`).
    lags : int

    Returns
    -------
    ndarray, shape (T, T)
        ``cov(AVAR_i, AVAR_j)`` in (unit^2)^2, symmetric; with a ramp its cross term with the noise included.
    """
    ramp = bool(np.asarray(params, dtype=float).reshape(-1)[4:5].sum() != 0)
    return combine_covariance(avar_covariance_basis(m, n_phase, fs, lags, ramp=ramp), params)


def model_edf(m, n_phase: int, fs: float, params, cov: np.ndarray | None = None) -> np.ndarray:
    """Equivalent degrees of freedom ``2 AVAR^2 / var(AVAR)`` of each point under the model, shape (T,)."""
    cov = avar_covariance(m, n_phase, fs, params) if cov is None else cov
    avar = model_avar(np.asarray(m, dtype=float) / fs, params)
    return 2 * avar**2 / np.maximum(np.diag(cov), 1e-300)
