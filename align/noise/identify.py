"""Power-law noise type at each tau, and the equivalent degrees of freedom that follow from it.

Noise identification (as Stable32; NIST SP 1065 section 5.6). The frequency PSD is
``S_y(f) ~ f^alpha``: alpha 2 white PM (quantization), 1 flicker PM, 0 white FM (angle
random walk), -1 flicker FM (bias instability), -2 random-walk FM (rate random walk).
At averaging factor ``m`` the ``N = floor(n / m)`` non-overlapping block means of the
rate, with the record's linear trend removed ("frequency drift", Riley & Greenhall 2004
section 3), are

* ``N >= 30``: lag-1 autocorrelation (Riley & Greenhall, "Power law noise identification
  using the lag 1 autocorrelation", EFTF 2004, eqs. 2-4; SP 1065 section 5.6.2). For
  ``d = 0, 1, 2`` (times differenced): ``r1 = sum (z_t - zbar)(z_{t+1} - zbar) / sum (z_t - zbar)^2``,
  ``delta = r1 / (1 + r1)``; stop at the first ``d`` with ``delta < 0.25`` (stationary) or
  ``d = 2``; then ``p = -2 (delta + d)`` estimates the exponent of the PSD of the data
  differenced. For FREQUENCY data ``alpha = p`` (for phase data it would be ``p + 2``,
  ``S_x ~ f^(alpha - 2)``), rounded to the nearest integer and kept in [-2, 2];
* ``8 <= N < 30``: Barnes' B1 ratio ``B1 = s^2 / AVAR`` (N-sample variance of the block means
  over their two-sample variance; SP 1065 section 5.6.1, Howe et al. 2000 table 3) against
  ``B1(N, mu) = N (1 - N^mu) / (2 (N - 1)(1 - 2^mu))`` (``N ln N / (2 (N - 1) ln 2)`` at
  ``mu = 0``) for ``mu = -alpha - 1`` in {-2, -1, 0, 1}, split at the geometric means of
  neighbours; ``mu = -2`` (PM) is split into white and flicker PM with ``R(n) = MVAR / AVAR``
  (SP 1065 section 5.6.1) taking the nearer in ratio of ``1 / m`` (white PM) and
  ``3 ln(256/27) / (2 (1.038 + 3 ln(pi m)))`` (flicker PM, ``f_h = fs / 2``; IEEE Std 1139);
* fewer blocks, or a degenerate series (constant): the type of the nearest identified tau.
  (The threshold 8 is empirical: with it the identified type equals Stable32's at every
  tau of five published data sets shipped with allantools, three of them in tests/data/stable32.)

Equivalent degrees of freedom: Greenhall & Riley, "Uncertainty of stability variances based
on finite differences", 35th PTTI (2003), eqs. 7-10, cases 1-4 and tables 1-3 (the EDF
Stable32 prints), for the overlapping (``S = m``) Allan variance (``F = m``) and the modified
Allan variance (``F = 1``), ``d = 2``.

Public names
------------
NOISE_NAMES, IMU_TERMS, noise_type_name, LAG1_MIN_BLOCKS, B1_MIN_BLOCKS, alpha_from_lag1, b1_theory,
alpha_from_b1, identify_noise, edf_greenhall, edf_of
"""

from __future__ import annotations

from functools import lru_cache
from math import comb

import numpy as np

__all__ = ["NOISE_NAMES", "IMU_TERMS", "noise_type_name", "LAG1_MIN_BLOCKS", "B1_MIN_BLOCKS", "alpha_from_lag1",
           "b1_theory", "alpha_from_b1", "identify_noise", "edf_greenhall", "edf_of"]

#: time-and-frequency name of each power-law exponent alpha of the frequency PSD
NOISE_NAMES = {2: "white PM", 1: "flicker PM", 0: "white FM", -1: "flicker FM", -2: "random walk FM"}
#: the inertial-sensor term (IEEE Std 952) each alpha corresponds to
IMU_TERMS = {2: "quantization", 1: "flicker PM", 0: "angle random walk", -1: "bias instability",
             -2: "rate random walk"}
#: fewest block means for the lag-1 autocorrelation (SP 1065 section 5.6.2)
LAG1_MIN_BLOCKS = 30
#: fewest block means for the B1 ratio; fewer take the nearest identified tau
B1_MIN_BLOCKS = 8


def noise_type_name(alpha: int, imu: bool = False) -> str:
    """``"white PM"``, ``"flicker PM"``, ``"white FM"``, ``"flicker FM"`` or ``"random walk FM"``
    (with ``imu``: ``"quantization"``, ..., ``"rate random walk"``) for alpha 2 ... -2."""
    names = IMU_TERMS if imu else NOISE_NAMES
    if int(alpha) not in names:
        raise ValueError(f"alpha {alpha!r} is not a power-law exponent 2, 1, 0, -1 or -2")
    return names[int(alpha)]


def alpha_from_lag1(r1: np.ndarray) -> np.ndarray:
    """Riley & Greenhall's estimate from the lag-1 autocorrelations of frequency data.

    Parameters
    ----------
    r1 : ndarray, shape (..., 3)
        ``r1`` of the data differenced 0, 1 and 2 times.

    Returns
    -------
    ndarray, shape (...)
        ``p = -2 (delta + d)`` at the first ``d`` with ``delta = r1 / (1 + r1) < 0.25`` (else ``d = 2``);
        for frequency data this is alpha (not rounded). NaN where ``r1`` is NaN.
    """
    r1 = np.asarray(r1, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        delta = r1 / (1 + r1)
    p = np.full(r1.shape[:-1], np.nan)
    done = np.zeros(p.shape, dtype=bool)
    for d in range(3):
        take = ~done & ((delta[..., d] < 0.25) | (d == 2))
        p[take] = -2 * (delta[..., d][take] + d)
        done |= take | np.isnan(delta[..., d])
    return p


def b1_theory(n: float, mu: int) -> float:
    """Expected B1 ratio of ``n`` block means when ``AVAR ~ tau^mu`` (Barnes; Howe et al. 2000 table 3)."""
    if mu == 0:
        return n * np.log(n) / (2 * (n - 1) * np.log(2))
    return n * (1 - n**mu) / (2 * (n - 1) * (1 - 2.0**mu))


def alpha_from_b1(b1: float, n: int, rn: float | None, m: int) -> int:
    """Alpha from the B1 ratio of ``n`` block means; ``rn = MVAR / AVAR`` splits white and flicker PM.

    Returns 2 for PM when ``rn`` is None.
    """
    mus = (-2, -1, 0, 1)
    theory = [b1_theory(n, mu) for mu in mus]
    mu = 1
    for k in range(3):
        if b1 < np.sqrt(theory[k] * theory[k + 1]):
            mu = mus[k]
            break
    if mu > -2 or rn is None:
        return -mu - 1 if mu > -2 else 2
    white, flicker = 1.0 / m, 3 * np.log(256 / 27) / (2 * (1.038 + 3 * np.log(np.pi * m)))
    return 2 if abs(np.log(rn / white)) <= abs(np.log(rn / flicker)) else 1  # the nearer in ratio


def _nearest_fill(alpha: np.ndarray, known: np.ndarray) -> np.ndarray:
    """Each unknown entry of a row takes the nearest known one (ties: the shorter tau); none known: 0."""
    out = alpha.copy()
    for c in range(alpha.shape[0]):
        idx = np.flatnonzero(known[c])
        if len(idx) == 0:
            out[c] = 0
            continue
        for k in np.flatnonzero(~known[c]):
            out[c, k] = alpha[c, idx[np.argmin(np.abs(idx - k) * 2 + (idx > k))]]
    return out


def identify_noise(x: np.ndarray, m: np.ndarray, avar: np.ndarray, mvar_of=None) -> tuple[np.ndarray, np.ndarray]:
    """Noise type of every channel at every averaging factor (module docstring).

    Parameters
    ----------
    x : ndarray, shape (C, n + 1)
        Phase ``[0, cumsum(y - c) / fs]`` of each channel (any constant ``c``, any scale).
    m : ndarray of int, shape (T,)
        Averaging factors.
    avar : ndarray, shape (C, T)
        Overlapping Allan variance (for ``R(n)``).
    mvar_of : callable, optional
        ``mvar_of(k)`` -> modified Allan variance of every channel at ``m[k]``, shape (C,); asked only
        where the B1 ratio finds phase noise. Without it PM found by B1 is taken as white PM.

    Returns
    -------
    alpha : ndarray of int, shape (C, T)
        In {2, 1, 0, -1, -2}.
    method : ndarray of str, shape (C, T)
        ``"acf"`` (lag-1 autocorrelation), ``"b1"`` or ``"nearest"``.
    """
    from align.noise._kernels import lag1_sums

    c_n, n_x = x.shape
    n = n_x - 1
    m = np.asarray(m, dtype=np.int64)
    blocks = n // m
    # the record's least-squares line u_i = a + b i of u = diff(x): sum (i - ibar) u_i = n x_n - sum_j x_j - ibar x_n
    ibar = (n - 1) / 2
    slope = np.array([(n * x[c, n] - np.sum(x[c, 1:]) - ibar * x[c, n]) / (n * (n * n - 1) / 12.0)
                      for c in range(c_n)]) if n > 1 else np.zeros(c_n)
    use = blocks >= B1_MIN_BLOCKS
    sums = np.zeros((c_n, len(m), 7))
    if np.any(use):
        sums[:, use] = lag1_sums(x, np.ascontiguousarray(m[use]), slope, 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        r1 = sums[..., [1, 3, 5]] / sums[..., [0, 2, 4]]
        b1 = 2 * sums[..., 0] / sums[..., 6]
        deeper = np.any(r1[..., 1] / (1 + r1[..., 1]) >= 0.25, axis=0) & use  # d = 2 wanted (rare): a second pass
    if np.any(deeper):
        sums[:, deeper] = lag1_sums(x, np.ascontiguousarray(m[deeper]), slope, 2)
        with np.errstate(divide="ignore", invalid="ignore"):
            r1 = sums[..., [1, 3, 5]] / sums[..., [0, 2, 4]]
    p = alpha_from_lag1(r1)
    alpha = np.zeros((c_n, len(m)), dtype=np.int64)
    method = np.full((c_n, len(m)), "nearest", dtype=object)
    for k in range(len(m)):
        for c in range(c_n):
            if blocks[k] >= LAG1_MIN_BLOCKS and np.isfinite(p[c, k]):
                alpha[c, k], method[c, k] = int(np.clip(np.round(p[c, k]), -2, 2)), "acf"
            elif use[k] and np.isfinite(b1[c, k]) and b1[c, k] > 0:
                a = alpha_from_b1(b1[c, k], int(blocks[k]), None, int(m[k]))
                if a == 2 and mvar_of is not None:
                    a = alpha_from_b1(b1[c, k], int(blocks[k]), float(mvar_of(k)[c] / avar[c, k]), int(m[k]))
                alpha[c, k], method[c, k] = a, "b1"
    alpha = _nearest_fill(alpha, method != "nearest")
    return alpha, method.astype(str)


# --- Greenhall & Riley (2003) EDF -------------------------------------------------------------------

_JMAX = 100
_TABLE1 = {2: (7 / 9, 1 / 2), 1: (0.997, 0.616), 0: (1.033, 0.607), -1: (1.048, 0.534), -2: (1.302, 0.535)}  # d = 2
_TABLE2 = {2: (35 / 18, 1.0), 1: (790.0, 410.0), 0: (2 / 3, 1 / 3), -1: (0.852, 0.375), -2: (1.079, 0.368)}  # d = 2
_TABLE3 = (15.23, 12.0)  # alpha = 1, d = 2: sz(0, m) ~ b0 + b1 ln m


def _sw(t: np.ndarray, alpha: int) -> np.ndarray:
    """Greenhall eq. 7 (up to a sign per alpha, which cancels in every EDF ratio)."""
    t = np.abs(np.asarray(t, dtype=float))
    if alpha in (1, -1, -3):
        with np.errstate(divide="ignore", invalid="ignore"):
            v = t ** (3 - alpha) * np.log(t)
        return np.where(t == 0, 0.0, v)
    return t ** (3 - alpha) * (-1 if alpha == 2 else 1)


def _sx(t: np.ndarray, f: float, alpha: int) -> np.ndarray:
    """Greenhall eq. 8: the filter of factor ``F`` (``inf``: the limit ``sw(t, alpha + 2)``)."""
    if np.isinf(f):
        return _sw(t, alpha + 2)
    return f * f * (2 * _sw(t, alpha) - _sw(t - 1 / f, alpha) - _sw(t + 1 / f, alpha))


def _sz(t, f: float, alpha: int, d: int = 2) -> np.ndarray:
    """Greenhall eq. 9: ``sum_k (-1)^k C(2d, d + k) sx(t + k)``."""
    t = np.asarray(t, dtype=float)
    return sum((-1) ** abs(k) * comb(2 * d, d + k) * _sx(t + k, f, alpha) for k in range(-d, d + 1))


def _basic_sum(j_n: float, m_n: float, s: float, f: float, alpha: int, d: int = 2) -> float:
    """Greenhall eq. 10."""
    j = np.arange(1, int(j_n))
    return float(_sz(0.0, f, alpha, d) ** 2 + (1 - j_n / m_n) * _sz(j_n / s, f, alpha, d) ** 2
                 + 2 * np.sum((1 - j / m_n) * _sz(j / s, f, alpha, d) ** 2))


@lru_cache(maxsize=4096)
def edf_greenhall(alpha: int, m: int, n_phase: int, modified: bool = False) -> float:
    """EDF of the overlapping Allan (``modified`` False) or modified Allan variance (Greenhall & Riley 2003).

    Parameters
    ----------
    alpha : int
        Noise exponent, 2 ... -2.
    m : int
        Averaging factor.
    n_phase : int
        Phase points ``N`` (rate samples + 1).
    modified : bool

    Returns
    -------
    float
        Equivalent degrees of freedom (NaN when no difference of span ``L`` fits the record).
    """
    d, alpha, m = 2, int(alpha), int(m)
    f = 1.0 if modified else float(m)
    s = float(m)  # stride factor of the overlapping estimators
    big_m = 1 + np.floor(s * (n_phase - (m / f + m * d)) / m)
    if big_m < 1:
        return float("nan")
    j_n = min(big_m, (d + 1) * s)
    r = big_m / s
    if modified:  # case 1
        if j_n <= _JMAX:
            inv = _basic_sum(j_n, big_m, s, 1.0, alpha) / (_sz(0.0, 1.0, alpha) ** 2 * big_m)
        elif r >= d + 1:
            a0, a1 = _TABLE1[alpha]
            inv = (a0 - a1 / r) / r
        else:
            inv = _basic_sum(_JMAX, _JMAX, _JMAX / r, 1.0, alpha) / (_sz(0.0, 1.0, alpha) ** 2 * _JMAX)
    elif alpha <= 0:  # case 2
        if j_n <= _JMAX:
            fp = float(m) if m * (d + 1) <= _JMAX else np.inf
            inv = _basic_sum(j_n, big_m, s, fp, alpha) / (_sz(0.0, fp, alpha) ** 2 * big_m)
        elif r >= d + 1:
            a0, a1 = _TABLE2[alpha]
            inv = (a0 - a1 / r) / r
        else:
            inv = _basic_sum(_JMAX, _JMAX, _JMAX / r, np.inf, alpha) / (_sz(0.0, np.inf, alpha) ** 2 * _JMAX)
    elif alpha == 1:  # case 3
        b0, b1 = _TABLE3
        if j_n <= _JMAX:
            inv = _basic_sum(j_n, big_m, s, float(m), 1) / (_sz(0.0, float(m), 1) ** 2 * big_m)
        elif r >= d + 1:
            a0, a1 = _TABLE2[1]
            inv = (a0 - a1 / r) / ((b0 + b1 * np.log(m)) ** 2 * r)
        else:
            mp = _JMAX / r
            inv = _basic_sum(_JMAX, _JMAX, mp, mp, 1) / ((b0 + b1 * np.log(m)) ** 2 * _JMAX)
    else:  # case 4, white PM: sz(k) = 2m (-1)^k C(2d, d + k) at integer k, zero elsewhere
        c0 = comb(2 * d, d) ** 2
        inv = (1 + sum(2 * max(0.0, 1 - k / r) * comb(2 * d, d + k) ** 2 / c0 for k in range(1, d + 1))) / big_m
    return float(1 / inv)


def edf_of(alpha: np.ndarray, m: np.ndarray, n_phase: int, modified: bool = False) -> np.ndarray:
    """:func:`edf_greenhall` of every point, shape of ``alpha`` (C, T) for ``m`` shape (T,)."""
    alpha = np.asarray(alpha)
    m = np.broadcast_to(np.asarray(m), alpha.shape)
    return np.array([edf_greenhall(int(a), int(k), int(n_phase), modified) for a, k in zip(alpha.ravel(), m.ravel())],
                    dtype=float).reshape(alpha.shape)
