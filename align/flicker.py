"""Flicker (1/f) noise, shared by the noise simulator and the rate-table simulator.

Public names
------------
flicker_fft, flicker_gm
"""

from __future__ import annotations

import numpy as np


def flicker_fft(n: int, fs: float, b: float, rng: np.random.Generator, channels: int) -> np.ndarray:
    """1/f rate noise of one-sided PSD ``S(f) = b^2 / (pi f)`` by spectral synthesis (IEEE 952 flicker term).

    Parameters
    ----------
    n : int
        Samples.
    fs : float
        Sample rate, Hz.
    b : float
        Flicker coefficient ``B`` (the Allan deviation's floor is ``0.664 B``), rad/s for a gyro.
    rng : numpy.random.Generator
    channels : int

    Returns
    -------
    ndarray, shape (n, channels)
        Zero-mean samples, the unit of ``b``.
    """
    k = np.arange(1, n // 2 + 1)
    f = k * fs / n
    amp = np.sqrt(b**2 / (np.pi * f) * n * fs / 4.0)
    out = np.empty((n, channels))
    for c in range(channels):
        spec = np.zeros(n // 2 + 1, dtype=complex)
        spec[1:] = amp * (rng.standard_normal(len(k)) + 1j * rng.standard_normal(len(k)))
        if n % 2 == 0:
            spec[-1] = spec[-1].real * np.sqrt(2.0)  # the Nyquist bin is real
        out[:, c] = np.fft.irfft(spec, n)
    return out


def flicker_gm(n: int, fs: float, b: float, rng: np.random.Generator, channels: int, bank: int) -> np.ndarray:
    """1/f noise (as :func:`flicker_fft`) approximated by ``bank`` Gauss-Markov processes, equal variance per log-step
    of correlation time (5 samples to half the record); streams sample by sample, shape (n, channels)."""
    from scipy.signal import lfilter

    dt = 1.0 / fs
    t_lo, t_hi = 5 * dt, n * dt / 2
    times = np.geomspace(t_lo, t_hi, bank)
    step = np.log(times[1] / times[0]) if bank > 1 else 1.0
    sigma = np.sqrt(b**2 / np.pi * step)  # sum_j 4 sigma^2 T_j / (1 + (2 pi f T_j)^2) ~ sigma^2 / (step f)
    out = np.zeros((n, channels))
    for t in times:
        phi = np.exp(-dt / t)
        w = rng.standard_normal((n, channels)) * sigma * np.sqrt(1 - phi**2)
        w[0] = rng.standard_normal(channels) * sigma  # start in the stationary state
        out += lfilter([1.0], [1.0, -phi], w, axis=0)
    return out
