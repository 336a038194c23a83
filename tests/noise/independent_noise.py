"""An independent simulator of gyro rate records for the noise-fit tests (truth from outside align.noise).

Written from the definitions of IEEE Std 952 Annex C, not from align.noise.sim or align.flicker:

* white rate noise (angle random walk ``N``, rad/sqrt(s)): per-sample sigma ``N sqrt(fs)``;
* flicker rate noise (bias instability ``B``, rad/s): one-sided PSD ``B^2 / (pi f)``, synthesised as a sum of
  first-order Gauss-Markov processes, two per octave from ``fs / 4`` down to a tenth of the record's lowest
  frequency (each ``x_k = phi x_{k-1} + sqrt(1 - phi^2) s w``, a Lorentzian of variance ``s^2``; ``s^2`` set so
  that the sum is ``B^2 / (pi f)`` between the corners);
* rate random walk (``K``, rad/s/sqrt(s)): ``b_k = b_{k-1} + K / sqrt(fs) w``;
* rate ramp (``R``, rad/s^2): ``R t``;
* a sinusoid of amplitude ``A`` (rad/s) and period ``P`` (s) with a random phase.

Allan variance of each term (IEEE Std 952 Annex C): ``N^2 / tau``, ``(2 ln 2 / pi) B^2``, ``K^2 tau / 3``,
``R^2 tau^2 / 2``, and of the sinusoid ``A^2 (sin^2(pi tau / P) / (pi tau / P))^2``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

DEG_H = np.pi / 180 / 3600                     # 1 deg/h in rad/s
ARW = np.pi / 180 / 60                         # 1 deg/sqrt(h) in rad/sqrt(s)
RRW = np.pi / 180 / 3600 / 60                  # 1 deg/h/sqrt(h) in rad/s/sqrt(s)
RAMP = np.pi / 180 / 3600 / 3600               # 1 deg/h^2 in rad/s^2


@njit(cache=False)
def _markov_add(out: np.ndarray, w: np.ndarray, phi: float, s: float) -> None:
    """``out += x`` with ``x_0 = s w_0`` (stationary), ``x_k = phi x_(k-1) + s sqrt(1 - phi^2) w_k``, per column."""
    n, c = w.shape
    gain = s * np.sqrt(1.0 - phi * phi)
    x = s * w[0].copy()
    for j in range(c):
        out[0, j] += x[j]
    for k in range(1, n):
        for j in range(c):
            x[j] = phi * x[j] + gain * w[k, j]
            out[k, j] += x[j]


def flicker_markov(n: int, fs: float, b: float, rng: np.random.Generator, channels: int) -> np.ndarray:
    """Flicker of PSD ``B^2 / (pi f)`` as a bank of Gauss-Markov processes, shape (n, channels).

    A process of correlation time ``T_j`` and variance ``s^2`` has the one-sided PSD
    ``4 s^2 T_j / (1 + (2 pi f T_j)^2)``; with ``T_j`` spaced by a factor ``r`` in log, the sum approaches
    ``s^2 / (ln(r) f)`` (``integral 4 T / (1 + (2 pi f T)^2) dlnT = 1 / f``), so ``s^2 = B^2 ln(r) / pi``.
    Each process is the exact AR(1) of its step (``phi = exp(-dt / T_j)``), summed in one compiled pass.
    """
    dt = 1.0 / fs
    t_lo, t_hi = 2.0 / (np.pi * fs), 10.0 * n * dt       # corners from fs/4 down to a tenth of 1/T
    r = np.sqrt(2.0)
    times = t_lo * r ** np.arange(int(np.ceil(np.log(t_hi / t_lo) / np.log(r))) + 1)
    s = np.sqrt(b**2 * np.log(r) / np.pi)
    out = np.zeros((n, channels))
    for t in times:
        _markov_add(out, rng.standard_normal((n, channels)), float(np.exp(-dt / t)), float(s))
    return out


def record(n: int, fs: float, *, white: float = 0.0, flicker: float = 0.0, random_walk: float = 0.0,
           ramp: float = 0.0, sine: float = 0.0, period: float = 0.0, channels: int = 1, seed: int = 0) -> np.ndarray:
    """Rate records of the terms given (SI), shape (n, channels); each channel independent."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    y = np.zeros((n, channels))
    if white:
        y += rng.standard_normal((n, channels)) * white * np.sqrt(fs)
    if flicker:
        y += flicker_markov(n, fs, flicker, rng, channels)
    if random_walk:
        y += np.cumsum(rng.standard_normal((n, channels)), axis=0) * random_walk / np.sqrt(fs)
    if ramp:
        y += ramp * t[:, None]
    if sine:
        y += sine * np.sin(2 * np.pi * t[:, None] / period + rng.uniform(0, 2 * np.pi, channels))
    return y
