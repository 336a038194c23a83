"""A static IMU in a thermal chamber, with known truth: a profile of ramps (and soaks), a bias cubic per axis, a
thermal lag and a hysteresis, white and correlated noise, a temperature reading with its own noise and step.

The truth of each axis (readings in SI; ``u = (T - tref) / hs``, the temperature scaled over the profile)::

    reading = sum_k a_k u^k + lag dT/dt + state h / 2 + noise,    state = +1 heating, -1 cooling (held in a soak)

so the static curve is the cubic, the lag term moves the reading with the rate, and a cooling branch reads ``h``
below a heating one at equal temperature, on top of what the lag makes: at ramp rates ``r_up`` and ``r_down`` the
branches differ by ``h + lag (r_up + r_down)`` (:meth:`Truth.apparent_hysteresis`).

Public names
------------
Profile, Truth, Run, setpoint, chamber, random_truth, simulate, chamber_log
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from align.calibration.thermal.model import AxisModel, ThermalModel, shift_reference
from align.values import Value

__all__ = ["Profile", "Truth", "Run", "setpoint", "chamber", "random_truth", "simulate", "chamber_log"]


@dataclass(frozen=True)
class Profile:
    """A chamber profile: from ``low`` up to ``high`` and back, ``cycles`` times (1.5: up, down, up).

    Attributes
    ----------
    low, high : float
        C.
    rate_up, rate_down : float
        Ramp rates, C/s (> 0).
    soak_s : float
        Soak at each end, s.
    cycles : float
        Half-cycles / 2: 0.5 is one ramp up, 1 up and down.
    tau_s : float
        Time constant with which the chamber follows its set temperature, s (0: at once).
    """

    low: float = -10.0
    high: float = 60.0
    rate_up: float = 2.0 / 60
    rate_down: float = 3.0 / 60
    soak_s: float = 0.0
    cycles: float = 1.5
    tau_s: float = 30.0

    @property
    def legs(self) -> int:
        """Ramps in the profile."""
        return max(1, int(round(2 * self.cycles)))

    @property
    def duration(self) -> float:
        """Length of the profile, s."""
        span = self.high - self.low
        ups, downs = (self.legs + 1) // 2, self.legs // 2
        return ups * span / self.rate_up + downs * span / self.rate_down + (self.legs + 1) * self.soak_s


def setpoint(profile: Profile, t: np.ndarray) -> np.ndarray:
    """The chamber's set temperature at ``t`` (s): ramps between ``low`` and ``high`` with soaks at the ends, C."""
    span = profile.high - profile.low
    sp = np.full(len(t), float(profile.low))
    start = profile.soak_s
    for leg in range(profile.legs):
        up = leg % 2 == 0
        r = profile.rate_up if up else profile.rate_down
        end = start + span / r
        on = (t >= start) & (t < end)
        sp[on] = profile.low + r * (t[on] - start) if up else profile.high - r * (t[on] - start)
        sp[t >= end] = profile.high if up else profile.low
        start = end + profile.soak_s
    return sp


def chamber(profile: Profile, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Temperature (C) and its rate (C/s) at ``t`` (s, uniform), the set temperature followed with the
    chamber's time constant (first order: ``dT/dt = (set - T) / tau``), and the hysteresis state: +1 after
    heating, -1 after cooling (held while the temperature stands still).

    Examples
    --------
    >>> T, r, s = chamber(Profile(0.0, 10.0, 0.1, 0.1, 100.0, 1.0, tau_s=0.0), np.arange(500.0))
    >>> T[[150, 350]].round(6).tolist(), r[[150, 350]].round(6).tolist(), s[[150, 250, 350]].tolist()
    ([5.0, 5.0], [0.1, -0.1], [1.0, 1.0, -1.0])
    """
    sp = setpoint(profile, t)
    if profile.tau_s <= 0 or len(t) < 2:
        T = sp
        rate = np.gradient(sp, t) if len(t) > 1 else np.zeros(len(t))
    else:
        from scipy.signal import lfilter

        a = np.exp(-(t[1] - t[0]) / profile.tau_s)
        T = lfilter([1.0 - a], [1.0, -a], sp - sp[0]) + sp[0]
        rate = np.gradient(T, t)
    moving = np.abs(rate) > 1e-3 * max(profile.rate_up, profile.rate_down)
    state = np.where(moving, np.sign(rate), 0.0)
    idx = np.where(state != 0, np.arange(len(t)), 0)
    np.maximum.accumulate(idx, out=idx)
    state = state[idx]
    state[state == 0] = 1.0
    return T, rate, state


@dataclass(frozen=True, eq=False)
class Truth(Value):
    """The known thermal behaviour of one sensor (module docstring), SI.

    Attributes
    ----------
    a : ndarray, shape (3, 4)
        Cubic of each axis in ``u = (T - tref) / hs``: ``a[i, k] u^k``.
    tref, hs : float
        C.
    lag : ndarray, shape (3,)
        SI per (C/s).
    h : ndarray, shape (3,)
        Heating minus cooling at equal temperature, apart from the lag.
    """

    a: np.ndarray
    tref: float
    hs: float
    lag: np.ndarray
    h: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def static(self, temperature: np.ndarray) -> np.ndarray:
        """The static curves (n, 3), SI."""
        u = (np.asarray(temperature, float) - self.tref) / self.hs
        return np.column_stack([np.polynomial.polynomial.polyval(u, self.a[i]) for i in range(3)])

    def reading(self, temperature: np.ndarray, rate: np.ndarray, state: np.ndarray) -> np.ndarray:
        """Noise-free readings (n, 3), SI."""
        return self.static(temperature) + np.outer(rate, self.lag) + np.outer(state, self.h / 2)

    def apparent_hysteresis(self, profile: Profile) -> np.ndarray:
        """Heating minus cooling at equal temperature on the ramps (3,), SI: ``h + lag (r_up + r_down)``."""
        return self.h + self.lag * (profile.rate_up + profile.rate_down)

    def model(self, sensor: str, tmin: float, tmax: float) -> ThermalModel:
        """The static truth as a :class:`ThermalModel` about ``tref`` (zero covariance, no lag)."""
        axes = tuple(AxisModel(shift_reference(self.a[i], 0.0, self.hs), float(self.lag[i]), np.zeros((5, 5)))
                     for i in range(3))
        return ThermalModel(sensor, self.tref, tmin, tmax, axes)


@dataclass(frozen=True, eq=False)
class Run:
    """A simulated record.

    Attributes
    ----------
    t : ndarray, shape (n,)
        s.
    temperature : ndarray, shape (n,)
        The reading, C (noise and step applied).
    data : ndarray, shape (n, 3)
        SI.
    true_temperature, rate, state : ndarray, shape (n,)
    """

    t: np.ndarray
    temperature: np.ndarray
    data: np.ndarray
    true_temperature: np.ndarray
    rate: np.ndarray
    state: np.ndarray


def random_truth(rng: np.random.Generator, profile: Profile, size: float, lag_s: float = 10.0,
                 hysteresis: float = 0.3) -> Truth:
    """A random truth: cubic terms of about ``size`` (SI) each, a lag moving the reading by about ``size`` per
    ``1 / lag_s`` C/s (so ``size * lag_s * rate``), a hysteresis of about ``hysteresis * size``; random signs."""
    def draw(shape) -> np.ndarray:
        return rng.choice([-1.0, 1.0], size=shape) * rng.uniform(0.5, 1.5, shape)

    return Truth(draw((3, 4)) * size, 0.5 * (profile.low + profile.high), 0.5 * (profile.high - profile.low),
                 draw(3) * size * lag_s, draw(3) * size * hysteresis)


def simulate(profile: Profile, truth: Truth | Sequence[Truth], rate_hz: float, noise: float | Sequence[float],
             rng: np.random.Generator, *, correlated: float | Sequence[float] = 0.0, tau_s: float = 20.0,
             temperature_noise: float = 0.01, resolution: float = 0.0) -> Run:
    """A static record in the chamber: one sensor (``truth``) or several sharing the temperature (a sequence;
    their readings side by side, 3 columns each).

    Parameters
    ----------
    profile : Profile
    truth : Truth or sequence of Truth
    rate_hz : float
        Sample rate, Hz.
    noise : float or sequence of float
        White noise of each sensor, SI per sample (1-sigma).
    rng : numpy.random.Generator
    correlated : float or sequence of float
        1-sigma of a first-order Gauss-Markov noise (SI) of correlation time ``tau_s`` (s) added to it.
    temperature_noise : float
        1-sigma of the temperature reading's noise, C.
    resolution : float
        Step of the temperature reading, C (0: continuous).

    Returns
    -------
    Run
    """
    truths = [truth] if isinstance(truth, Truth) else list(truth)
    k = len(truths)
    white = np.broadcast_to(np.asarray(noise, float), (k,))
    gm = np.broadcast_to(np.asarray(correlated, float), (k,))
    n = int(profile.duration * rate_hz)
    t = np.arange(n) / rate_hz
    T, rate, state = chamber(profile, t)
    data = np.hstack([tr.reading(T, rate, state) for tr in truths]) + rng.normal(0.0, 1.0, (n, 3 * k)) * np.repeat(white, 3)
    if np.any(gm > 0):
        from scipy.signal import lfilter

        phi = np.exp(-1.0 / (rate_hz * tau_s))
        drive = rng.normal(0.0, np.sqrt(1 - phi * phi), (n, 3 * k))
        drive[0] = rng.normal(0.0, 1.0, 3 * k)
        data += lfilter([1.0], [1.0, -phi], drive, axis=0) * np.repeat(gm, 3)
    read = T + rng.normal(0.0, temperature_noise, n) if temperature_noise > 0 else T.copy()
    if resolution > 0:
        read = np.round(read / resolution) * resolution
    return Run(t, read, data, T, rate, state)


#: the simulated IMU: gyro and accelerometer term sizes and white noise per sample, SI
GYRO_SIZE, GYRO_NOISE = 2e-4, 1e-4
ACCEL_SIZE, ACCEL_NOISE = 0.01, 0.002
GRAVITY = 9.80665


def chamber_log(profile: Profile, rate_hz: float, seed: int, resolution: float = 0.0
                ) -> tuple[list[str], np.ndarray, dict[str, Any]]:
    """A chamber log of a static IMU (gyro and accelerometer, gravity on +z) and its truth, for
    ``imu-align simulate thermal``.

    Returns
    -------
    names : list of str
        ``time, gyro_x..z (deg/s), acc_x..z (m/s^2), temperature (C)``.
    table : ndarray, shape (n, 8)
    truth : dict
        The profile, and per sensor the cubic in ``u = (T - tref) / hs``, lag, hysteresis and the hysteresis a
        branch comparison sees on the ramps, SI.
    """
    rng = np.random.default_rng(seed)
    gyro, acc = random_truth(rng, profile, GYRO_SIZE), random_truth(rng, profile, ACCEL_SIZE)
    run = simulate(profile, (gyro, acc), rate_hz, (GYRO_NOISE, ACCEL_NOISE), rng, resolution=resolution)
    data = run.data.copy()
    data[:, :3] *= 180.0 / np.pi
    data[:, 5] += GRAVITY
    names = ["time", "gyro_x", "gyro_y", "gyro_z", "acc_x", "acc_y", "acc_z", "temperature"]
    truth: dict[str, Any] = {"seed": seed, "rate_hz": rate_hz, "profile": asdict(profile), "temperature_units": "degC"}
    for name, tr, unit in (("gyroscope", gyro, "rad/s"), ("accelerometer", acc, "m/s^2")):
        truth[name] = {"units": unit, "model": "sum_k a_k u^k + lag dT/dt + state h / 2, u = (T - tref) / hs",
                       "tref": tr.tref, "hs": tr.hs, "a": tr.a.tolist(), "lag": tr.lag.tolist(), "h": tr.h.tolist(),
                       "apparent_hysteresis": tr.apparent_hysteresis(profile).tolist()}
    truth["accelerometer"]["gravity_on_z"] = GRAVITY
    return names, np.column_stack([run.t, data, run.temperature]), truth
