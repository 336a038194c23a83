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

for every term of the noise. ``ebar_m`` telescopes: ``sum_i e_m(i) = sum_j v_m(j) x_j`` with ``v_m`` four boxes of
``m`` phase points (``+1, -1`` at the record's start, ``-1, +1`` at its end), i.e. the rate weighted by
``w_m = L(t - T + 2 tau) - L(t)``, ``L`` the triangle of height ``tau`` on ``[0, 2 tau]`` (``T`` the record's length,
``fs`` the sample rate): the difference of the rate's means over the record's last and first ``2 tau``, times
``m^2 tau0``. So, per term (continuous time; :func:`_ebar_covariance`)::

    Q (white phase):       Q^2 fs   int v_1 v_2 dt
    N (white rate):        N^2 fs^2 int w_1 w_2 dt                 (~ 4 m^3 tau0 / 3 on the diagonal)
    B (flicker):           -(B^2 / pi) fs^2 int int w_1(t) w_2(u) ln|t - u| dt du
    K (rate random walk):  K^2 fs^2 int W_1 W_2 dt,   W_m(r) = int_r^T w_m = A(r) + A(T - r) - tau^2

each over ``M1 M2`` (``A(x) = int_0^x L``; the rate's generalised covariances ``-G''``: ``N^2 delta(t)``,
``-(B^2 / pi) ln|t|`` up to a constant, ``-K^2 |t| / 2``, the last as white increments weighted by ``W``). Under a
rate random walk the record's own trend of the rate looks like a ramp (``W`` has a plateau ``tau^2`` over the
record: a variance ``~ K^2 T m^4 tau0^2 / M^2``, the ramp's uncertainty about ``K / sqrt(T)``); under white noise
the term is ``(R^2 tau^2 / 2) / (N^2 / tau) * (m / M)`` times the noise's own variance of the estimate, thousands
of times it at the longest taus of a strong ramp. The integrands are piecewise polynomials (Gauss-Legendre, exact)
but for flicker's logarithm (closed form near the diagonal, Gauss-Legendre elsewhere); they match the exact
discrete double sums to about 1e-3 but at ``m`` of 1-3 (a negligible term there), and a Monte Carlo of the
estimator on simulated ramp-plus-noise records (tests/noise/test_ramp_covariance.py).

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
    and ``S[R, a] = S[a, R] = cov(ebar_1, ebar_2) / (2 p_a)`` for each noise term ``a`` (the ramp's cross terms,
    module docstring; ``S[R, R] = 0``): computed once, the covariance of any model on the same taus costs one
    contraction (:func:`combine_covariance`).

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
        Also the ramp's cross terms with the noise (a fifth row and column).

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
    if ramp:  # cov(ebar_1, ebar_2) per unit Q^2, N^2, B^2, K^2, halved (S[R,a] = S[a,R]; module docstring)
        s[4, :4] = s[:4, 4] = _ebar_covariance(m1[:, 0], m2[:, 0], n_phase, tau0) / 2
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


def _ebar_covariance(m1: np.ndarray, m2: np.ndarray, n_phase: float, tau0: float) -> np.ndarray:
    """``cov(ebar_1, ebar_2)`` per unit ``Q^2, N^2, B^2, K^2`` (4, P) at pairs of averaging factors (module docstring).

    ``sum_i e_m(i) = fs int w_m y dt`` with ``w_m = L(t - T + 2 tau) - L(t)``, ``L`` the triangle of height ``tau`` on
    ``[0, 2 tau]`` (``T`` the record's length); white rate: ``N^2 fs^2 int w_1 w_2``; a rate random walk ``K W(t)``:
    ``K^2 fs^2 int W_1 W_2`` with ``W_m(r) = int_r^T w_m = A(r) + A(T - r) - tau^2``, ``A(x) = int_0^x L`` (a plateau
    ``tau^2`` between the record's ends); white phase: ``Q^2 fs int v_1 v_2`` with ``v_m`` the four boxes of
    ``sum_i e_m(i) = sum_j v_m(j) x_j``. Piecewise polynomials of degree <= 4 between the knots ``0, tau, 2 tau,
    T - 2 tau, T - tau, T``: three-point Gauss-Legendre per piece is exact. Flicker by the log kernel
    (:func:`_flicker_ebar`). Each divided by ``M1 M2``.
    """
    fs, big1, big2 = 1.0 / tau0, n_phase - 2 * m1, n_phase - 2 * m2
    t1, t2 = m1 * tau0, m2 * tau0
    rec = (n_phase - 1) * tau0
    x, wq = np.polynomial.legendre.leggauss(3)
    out = np.zeros((4, len(m1)))
    for k, end in ((0, n_phase * tau0), (1, rec), (3, rec)):
        knots = np.sort(np.concatenate([np.stack([np.zeros_like(t), t, 2 * t, end - 2 * t, end - t], axis=1)
                                        for t in (t1, t2)] + [np.full((len(t1), 1), end)], axis=1), axis=1)
        knots = np.clip(knots, 0.0, end)
        a, b = knots[:, :-1, None], knots[:, 1:, None]
        t = (a + b) / 2 + (b - a) / 2 * x                                   # (P, 10, 3)
        f1, f2 = (_ebar_weight(k, t, tau[:, None, None], end) for tau in (t1, t2))
        out[k] = np.sum(f1 * f2 * wq * (b - a) / 2, axis=(1, 2))
    out[[1, 3]] *= fs * fs
    out[0] *= fs
    out[2] = _flicker_ebar(m1, m2, n_phase - 1, tau0)
    return out / (big1 * big2)


def _ebar_weight(k: int, t: np.ndarray, tau: np.ndarray, end: float) -> np.ndarray:
    """The weight of ``sum_i e_m(i)`` on the phase (``k`` 0: boxes ``v``), the rate (1: ``w``) or the rate's white
    increments (3: ``W``), at times ``t`` (s) of a record of length ``end``."""
    if k == 0:
        box = np.where(t < tau, 1.0, np.where(t < 2 * tau, -1.0, 0.0))
        u = end - t
        return box + np.where(u <= tau, 1.0, np.where(u <= 2 * tau, -1.0, 0.0))
    if k == 1:
        return _tri(t - end + 2 * tau, tau) - _tri(t, tau)
    return _tri_area(t, tau) + _tri_area(end - t, tau) - tau * tau


def _tri(t: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """The triangle of height ``tau`` on ``[0, 2 tau]``."""
    return np.clip(np.minimum(t, 2 * tau - t), 0.0, None)


def _tri_area(t: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """``int_0^t`` of :func:`_tri`: 0, ``t^2 / 2``, ``tau^2 - (2 tau - t)^2 / 2``, ``tau^2``."""
    c = np.clip(t, 0.0, 2 * tau)
    return np.where(c <= tau, c * c / 2, tau * tau - (2 * tau - c) ** 2 / 2)


def _flicker_ebar(m1: np.ndarray, m2: np.ndarray, n: float, tau0: float) -> np.ndarray:
    """Flicker's ``cov(sum e_1, sum e_2)`` per unit ``B^2`` (P,), from the rate's generalised covariance
    ``-G''(t) = -(2 ln|t| + 3) / (2 pi)`` (only ``-ln|t| / pi`` survives: ``int w = 0``): ``-(fs^2 / pi) int int w_1(t)
    w_2(u) ln|t - u|``. As ``w_m(n - t) = -w_m(t)`` this is ``-(2 tau0^2 / pi) (J(F, F) - J(F, L))`` in samples, with
    ``J(F, X) = int int L_1(t) X_2(u) ln|t - u|`` over the first triangle ``F`` and the last ``L`` (``n`` samples):
    the inner integral in closed form on each linear piece near ``t`` (``int (a + s d) ln|d| dd``), by Gauss-Legendre
    on pieces four lengths or more away; the outer by eight-point Gauss-Legendre between the knots.
    """
    x8, w8 = np.polynomial.legendre.leggauss(8)
    x3, w3 = np.polynomial.legendre.leggauss(3)
    a, b = m1[:, None], m2[:, None]
    cuts = np.sort(np.clip(np.concatenate([np.zeros_like(a), a, 2 * a, b, 2 * b, n - 2 * b, n - b], axis=1),
                           0.0, 2 * a), axis=1)
    lo, hi = cuts[:, :-1, None], cuts[:, 1:, None]
    t = (lo + hi) / 2 + (hi - lo) / 2 * x8                            # (P, 6, 8): outer nodes on [0, 2 m1]
    weight = _tri(t, a[:, :, None]) * w8 * (hi - lo) / 2
    j = np.zeros(len(m1))
    # the pieces of F (sign +1 in J(F, F)) and L (-1): start u0, length, value at u0, slope
    for sign, u0, v0, slope in ((1, 0 * b, 0 * b, 1), (1, b, b, -1), (-1, n - 2 * b, 0 * b, 1), (-1, n - b, b, -1)):
        u0, v0, ln = u0[:, :, None], v0[:, :, None], b[:, :, None]
        d0, d1 = u0 - t, u0 + ln - t                                  # d = u - t over the piece
        alpha = v0 - slope * d0                                       # value a + s d at d
        near = np.abs((d0 + d1) / 2) < 4 * ln
        inner = _log_moment(alpha, slope, d1) - _log_moment(alpha, slope, d0)
        dd = (d0 + d1)[..., None] / 2 + (d1 - d0)[..., None] / 2 * x3
        far = np.sum((alpha[..., None] + slope * dd) * np.log(np.abs(np.where(dd == 0, 1.0, dd))) * w3, axis=-1)
        far *= (d1 - d0) / 2
        j += sign * np.sum(weight * np.where(near, inner, far), axis=(1, 2))
    return -2 * tau0 * tau0 / np.pi * j


def _log_moment(alpha: np.ndarray, slope: float, d: np.ndarray) -> np.ndarray:
    """``int (alpha + slope d) ln|d| dd = alpha (d ln|d| - d) + slope (d^2 ln|d| / 2 - d^2 / 4)`` (0 at ``d = 0``)."""
    ld = np.log(np.where(d == 0, 1.0, np.abs(d)))
    return alpha * (d * ld - d) + slope * (d * d * ld / 2 - d * d / 4)


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
