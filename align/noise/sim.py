"""Sensor-error simulator: turn-on bias, white noise, bias instability, rate random walk,
quantization, rate ramp, scale and misalignment; and the seed's three error models.

Every draw comes from the ``numpy.random.Generator`` passed in (or seeded from an
int); inputs are never modified. Terms (IEEE Std 952 names, SI units, gyro
wording; an accelerometer works the same in m/s^2):

* ``white`` ``N`` (rad/s/sqrt(Hz) = rad/sqrt(s)): per-sample sigma ``N sqrt(fs)``;
* ``flicker`` ``B`` (rad/s): one-sided PSD ``B^2 / (pi f)`` (Allan floor ``0.664 B``),
  synthesised by FFT, or as a bank of first-order Gauss-Markov processes with
  log-spaced correlation times (``flicker_model="gauss-markov"``);
* ``random_walk`` ``K`` (rad/s/sqrt(s)): ``b[k] = b[k-1] + K sqrt(dt) w`` (Allan ``K^2 tau / 3``),
  independent of the other terms;
* ``quantization`` ``Q`` (rad): white angle noise of sigma ``Q`` differenced (``3 Q^2 / tau^2``);
* ``ramp`` ``R`` (rad/s^2);
* ``turn_on`` sigma of the run-to-run bias, drawn once per run, plus a fixed ``bias``.

Public names
------------
NoiseSpec, FLICKER_MODELS, simulate_noise, simulate_imu, seed_method_a, seed_method_b, seed_restoring
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.errors import InputError
from align.flicker import flicker_fft, flicker_gm
from align.noise.fit import noise_figures
from align.noise.model import NoiseModel
from align.values import Value

#: the ways of synthesising flicker noise
FLICKER_MODELS = ("fft", "gauss-markov")


@dataclass(frozen=True, eq=False)
class NoiseSpec(Value):
    """Noise terms of one sensor axis (SI units; see module docstring).

    ``quantization``, ``white``, ``flicker``, ``random_walk`` and ``ramp`` are
    the five terms of :class:`~align.noise.model.NoiseModel` (:attr:`model`),
    so a simulated record's Allan deviation follows ``spec.model(tau)``.
    """

    bias: float = 0.0
    turn_on: float = 0.0
    white: float = 0.0
    flicker: float = 0.0
    random_walk: float = 0.0
    quantization: float = 0.0
    ramp: float = 0.0
    flicker_model: str = "fft"
    flicker_bank: int = 12

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.flicker_model not in FLICKER_MODELS:
            raise InputError(f"unknown flicker model {self.flicker_model!r}; use {' or '.join(FLICKER_MODELS)}",
                             "{flicker_model}")

    @property
    def model(self) -> NoiseModel:
        """The five IEEE terms of this spec as a curve ``sigma(tau)``."""
        return NoiseModel(self.quantization, self.white, self.flicker, self.random_walk, self.ramp)


def _rng(seed) -> np.random.Generator:
    return seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)


def simulate_noise(n: int, fs: float, spec: NoiseSpec, channels: int = 1, seed=0) -> np.ndarray:
    """Sensor error samples, shape (n, channels), for a static or moving run (see module docstring).

    Parameters
    ----------
    n : int
        Samples per channel.
    fs : float
        Sample rate, Hz.
    spec : NoiseSpec
        The terms, SI (e.g. ``white`` in rad/s/sqrt(Hz) for a gyro: the samples' sigma is ``white sqrt(fs)``).
    channels : int
        Independent channels.
    seed : int or numpy.random.Generator

    Returns
    -------
    ndarray, shape (n, channels)
        Errors in the unit of ``spec`` (rad/s for a gyro); their Allan deviation follows ``spec.model(tau)``.

    Examples
    --------
    >>> import numpy as np
    >>> e = simulate_noise(20_000, 100.0, NoiseSpec(bias=0.01, white=1e-3), channels=2, seed=1)
    >>> e.shape, round(float(e.mean()), 3), round(float(e.std() / np.sqrt(100.0)), 4)
    ((20000, 2), 0.01, 0.001)
    """
    rng = _rng(seed)
    dt = 1.0 / fs
    e = np.full((n, channels), spec.bias) + rng.normal(0.0, 1.0, channels) * spec.turn_on
    if spec.white:
        e = e + rng.standard_normal((n, channels)) * spec.white * np.sqrt(fs)
    if spec.flicker:
        if spec.flicker_model == "fft":
            e = e + flicker_fft(n, fs, spec.flicker, rng, channels)
        else:
            e = e + flicker_gm(n, fs, spec.flicker, rng, channels, spec.flicker_bank)
    if spec.random_walk:
        e = e + np.cumsum(rng.standard_normal((n, channels)), axis=0) * spec.random_walk * np.sqrt(dt)
    if spec.quantization:
        angle = rng.standard_normal((n + 1, channels)) * spec.quantization
        e = e + np.diff(angle, axis=0) / dt
    if spec.ramp:
        e = e + (np.arange(n) * dt * spec.ramp)[:, None]
    return e


def simulate_imu(w: np.ndarray, fs: float, spec: NoiseSpec, m: np.ndarray | None = None, seed=0) -> np.ndarray:
    """Sensor readings ``M w + errors`` for true inputs ``w`` (n, 3); ``M`` carries scale and misalignment."""
    w = np.asarray(w, dtype=float)
    clean = w @ (np.eye(3) if m is None else np.asarray(m)).T
    return clean + simulate_noise(len(w), fs, spec, w.shape[1], seed)


def seed_method_a(truth: np.ndarray, fs: float, bias: float, stability: float, period: float, white: float,
                  seed=0) -> np.ndarray:
    """Seed 002's method A (its Eq 12): bias, white noise and a random walk driven by the bias stability.

    ``F = F_true + B + W / sqrt(dt) w + s``, ``s[k] = s[k-1] + B_s sqrt(dt / P) w``.
    """
    rng = _rng(seed)
    dt = 1.0 / fs
    n = len(truth)
    walk = np.cumsum(rng.standard_normal(n)) * stability * np.sqrt(dt / period)
    return np.asarray(truth, float) + bias + rng.standard_normal(n) * white / np.sqrt(dt) + walk


def seed_method_b(truth: np.ndarray, fs: float, bias: float, instability: float, white: float, seed=0) -> np.ndarray:
    """Seed 002's method B (its Eq 13): the random walk driven by the bias instability.

    ``s[k] = s[k-1] + B_i sqrt(dt) w``.
    """
    rng = _rng(seed)
    dt = 1.0 / fs
    n = len(truth)
    walk = np.cumsum(rng.standard_normal(n)) * instability * np.sqrt(dt)
    return np.asarray(truth, float) + bias + rng.standard_normal(n) * white / np.sqrt(dt) + walk


def seed_restoring(truth: np.ndarray, fs: float, bias: float, repeatability: float, stability: float,
                   period: float, white: float, seed=0) -> np.ndarray:
    """Seed 002's statistics-restoring method (its Eq 14-18).

    Turn-on bias ``B' ~ N(B, B_r^2)``; ``Q = F_true + B' + W / sqrt(dt) w``; then the
    sequence is rescaled about its mean so that its bias stability over ``period``
    equals the stated one: ``Q' = Q B_s / B_s(real) + mean(Q) (1 - B_s / B_s(real))``.
    """
    rng = _rng(seed)
    dt = 1.0 / fs
    n = len(truth)
    b_run = rng.normal(bias, repeatability)
    q = np.asarray(truth, float) + b_run + rng.standard_normal(n) * white / np.sqrt(dt)
    real = noise_figures(q, fs, (period,))["stability"][period]
    ratio = stability / real
    return q * ratio + q.mean() * (1 - ratio)
