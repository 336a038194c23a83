"""Warm-up time of a static record: when the bias, a moving mean, has settled within a stated band of its final value.

IEEE Std 528 (inertial sensor terminology) calls warm-up time the interval from the instant a sensor is energized
until it reaches its specified performance under specified conditions; IEEE Std 952 and 1431 ask for it in their
test series without fixing the criterion. Here the criterion is stated with every result:

* the bias at time ``t`` is the centred moving mean of the readings over ``window`` seconds (``t`` its centre,
  counted from the first sample of the record);
* the settled value is the mean of the last ``final`` seconds of the record;
* the warm-up time is the earliest ``t`` after which the moving mean stays within ``+/- band`` of the settled value
  (linearly interpolated between the samples where it last leaves the band); 0 when it never leaves the band
  (the first ``window / 2`` s cannot be resolved);
* the record has settled when that time falls before the final segment begins and the drift over the final
  segment (a straight line through its window means) is not both beyond half the band and beyond 3 sigma (a bias
  still moving by half the band within the segment that defines its settled value has no settled value yet: an
  exponential far longer than the record looks like such a drift): a record still drifting at its end is reported
  as not settled, with no time.

The noise of the moving mean is the Allan deviation of the final segment at ``tau = window`` (the overlapping
differences of consecutive window means; drift-free to first order, and equal to ``sigma / sqrt(window fs)`` for
white noise ``sigma``), or, when larger, that white-noise level from the sample-to-sample differences (a precise
floor: the Allan deviation of a few windows scatters by tens of percent); the settled value's 1-sigma scales it by
``sqrt(window / final)``. The warm-up time's 1-sigma is the first-order propagation of both through the crossing:
``sqrt(s_m^2 + s_f^2) / |dm/dt|``, the slope of the moving mean at the crossing from the window means either side of
it. Without ``band`` the band is five times that noise (the narrowest band the window resolves); a band within three
times it is refused (noise alone would cross it).

Public names
------------
WarmupResult, ChannelWarmup, warmup_time, moving_mean, channel_figures, window_noise, simulate_warmup, settling_time
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from align.errors import InputError
from align.merit import Figure
from align.results import Result
from align.wellformed import malformed

WARMUP_FORMAT = "imu-align.warmup"
CONVENTION = "static records from turn-on; readings SI (rad/s or m/s^2); times s from each record's first sample"

__all__ = ["WarmupResult", "channel_figures", "ChannelWarmup", "warmup_time", "moving_mean", "window_noise",
           "simulate_warmup", "settling_time"]

#: default band, in units of the 1-sigma noise of the moving mean against the settled value
BAND_SIGMAS = 5.0
#: a band narrower than this many sigmas of that noise is refused
MIN_BAND_SIGMAS = 3.0
#: the fewest window lengths the final segment holds (its Allan deviation at tau = window needs several)
MIN_FINAL_WINDOWS = 4


@dataclass(frozen=True)
class ChannelWarmup:
    """The warm-up of one channel (SI: s, and the reading's unit, rad/s or m/s^2).

    Attributes
    ----------
    time : float
        Warm-up time, s from the first sample; NaN when the record has not settled.
    sigma : float
        1-sigma of ``time`` (module docstring), s; NaN when not settled or when the crossing is lost in noise.
    settled : bool
        Whether the record settled by the criterion.
    left_band : bool
        Whether the moving mean was ever outside the band (False: warm-up 0, none seen).
    value : float
        The settled value (mean of the final segment).
    value_sigma : float
        Its 1-sigma.
    band : float
        The band used (half-width).
    noise : float
        1-sigma of the moving mean (Allan deviation of the final segment at ``tau = window``).
    drift : float
        Drift over the final segment (straight line through its window means), with ``drift_sigma``.
    drift_sigma : float
    note : str
        Why not settled, or how the time was found.
    """

    time: float
    sigma: float
    settled: bool
    left_band: bool
    value: float
    value_sigma: float
    band: float
    noise: float
    drift: float
    drift_sigma: float
    note: str = ""


def moving_mean(x: np.ndarray, fs: float, window: float) -> tuple[np.ndarray, np.ndarray]:
    """Centred moving mean of ``x`` over ``window`` seconds, at every sample where the window fits.

    Parameters
    ----------
    x : ndarray, shape (n,)
    fs : float
        Sample rate, Hz.
    window : float
        Window, s (``k = round(window fs)`` samples, at least 1).

    Returns
    -------
    t : ndarray, shape (n - k + 1,)
        Centre of each window, s from the first sample (``(i + (k - 1) / 2) / fs``).
    m : ndarray, shape (n - k + 1,)

    Examples
    --------
    >>> t, m = moving_mean(np.arange(5.0), 1.0, 3.0)
    >>> t.tolist(), m.tolist()
    ([1.0, 2.0, 3.0], [1.0, 2.0, 3.0])
    """
    k = max(1, int(round(window * fs)))
    c = np.concatenate([[0.0], np.cumsum(np.asarray(x, float))])
    m = (c[k:] - c[:-k]) / k
    return (np.arange(len(m)) + (k - 1) / 2) / fs, m


def window_noise(y: np.ndarray, fs: float, window: float) -> float:
    """1-sigma noise of a ``window``-second mean: the overlapping Allan deviation of ``y`` at ``tau = window``
    (IEEE Std 952 Annex C), ``sqrt(mean((m[i + k] - m[i])^2) / 2)`` over the window means ``m``.

    Examples
    --------
    >>> y = np.random.default_rng(0).normal(0, 1.0, 100_000)
    >>> round(window_noise(y, 100.0, 1.0), 2)  # white: 1 / sqrt(100)
    0.1
    """
    k = max(1, int(round(window * fs)))
    _, m = moving_mean(y, fs, window)
    d = m[k:] - m[:-k]
    return float(math.sqrt(0.5 * np.mean(d * d))) if len(d) else math.nan


def _drift(y: np.ndarray, fs: float, window: float, noise: float) -> tuple[float, float]:
    """Drift over ``y`` (a line through its consecutive window means) and its 1-sigma from ``noise``."""
    k = max(1, int(round(window * fs)))
    blocks = len(y) // k
    means = np.asarray(y[: blocks * k], float).reshape(blocks, k).mean(axis=1)
    centre = np.arange(blocks) - (blocks - 1) / 2
    sxx = float(centre @ centre)
    slope = float(centre @ (means - means.mean()) / sxx)  # per block
    return slope * blocks, noise / math.sqrt(sxx) * blocks


def _crossing_slope(m: np.ndarray, j: int, k: int, fs: float, noise: float) -> tuple[float, float]:
    """Slope of the moving mean at index ``j`` and its 1-sigma: a line through the non-overlapping window means
    ``m[j + i k]``, ``|i| <= s``, ``s`` = 1, 2, 4, 8 windows until the slope stands 3 sigma above the noise."""
    slope, sigma = 0.0, math.inf
    for s in (1, 2, 4, 8):
        idx = j + k * np.arange(-s, s + 1)
        idx = idx[(idx >= 0) & (idx < len(m))]
        if len(idx) < 2:
            break
        c = (idx - idx.mean()) / fs
        sxx = float(c @ c)
        slope, sigma = float(c @ (m[idx] - m[idx].mean()) / sxx), noise / math.sqrt(sxx)
        if abs(slope) > 3 * sigma:
            break
    return slope, sigma


def warmup_time(x: np.ndarray, fs: float, *, window: float, final: float | None = None,
                band: float | None = None) -> ChannelWarmup:
    """Warm-up time of one channel of a static record, by the criterion of the module docstring.

    Parameters
    ----------
    x : ndarray, shape (n,)
        Readings, SI, the first at the start of the record (turn-on).
    fs : float
        Sample rate, Hz.
    window : float
        Moving-mean window, s.
    final : float, optional
        Length of the final segment whose mean is the settled value, s (None: the last quarter of the record).
    band : float, optional
        Half-width of the band, in the unit of ``x`` (None: :data:`BAND_SIGMAS` times the noise of the moving mean
        against the settled value).

    Returns
    -------
    ChannelWarmup

    Raises
    ------
    InputError
        A record too short for the window (``{window}``) or the final segment (``{final}``); a band within three
        sigmas of the noise (``{band}``).

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> t = np.arange(0, 600, 0.1)
    >>> x = 1e-3 + 4e-3 * np.exp(-t / 30) + rng.normal(0, 1e-4, t.size)
    >>> w = warmup_time(x, 10.0, window=5.0, band=1e-4)  # truth: 30 ln(40) = 110.7 s
    >>> w.settled, bool(abs(w.time - 30 * np.log(40)) < 3 * w.sigma)
    (True, True)
    """
    x = np.asarray(x, float)
    n = len(x)
    k = int(round(window * fs))
    length = n / fs
    if k < 2 or 4 * k > n:
        raise InputError(f"a {window:g} s window holds {k} samples of a {length:g} s record at {fs:g} Hz; give a "
                         "window of at least 2 samples and at most a quarter of the record", "{window}")
    nf = int(round((final if final is not None else length / 4) * fs))
    if nf < MIN_FINAL_WINDOWS * k or nf > n:
        raise InputError(f"the final segment ({nf / fs:g} s) must hold at least {MIN_FINAL_WINDOWS} windows "
                         f"({MIN_FINAL_WINDOWS * k / fs:g} s) and fit in the {length:g} s record; give a shorter "
                         "{window}, a longer {final} or a longer record", "{final}" if final is not None else "{window}")
    tail = x[n - nf:]
    value = float(tail.mean())
    white = float(np.std(np.diff(tail)) / math.sqrt(2.0 * k))  # sigma / sqrt(k) of white noise, from n_f samples
    noise = max(window_noise(tail, fs, window), white)
    value_sigma = noise * math.sqrt(k / nf)
    total = math.hypot(noise, value_sigma)
    if band is None:
        band = BAND_SIGMAS * total
    elif not (band > MIN_BAND_SIGMAS * total):
        raise InputError(f"a band of {band:.4g} is within {MIN_BAND_SIGMAS:g} sigma of the moving mean's noise "
                         f"({total:.4g}, 1-sigma): noise alone would leave it; widen the band or lengthen the window",
                         "{band}")
    drift, drift_sigma = _drift(tail, fs, window, noise)
    t, m = moving_mean(x, fs, window)
    off = np.abs(m - value) - band
    out = np.flatnonzero(off > 0)
    common = dict(value=value, value_sigma=value_sigma, band=band, noise=noise, drift=drift, drift_sigma=drift_sigma)
    start_final = (n - nf) / fs
    if abs(drift) > band / 2 and abs(drift) > 3 * drift_sigma:
        return ChannelWarmup(math.nan, math.nan, False, bool(len(out)), **common,
                             note=f"not settled: still drifting by {drift:.4g} over the final {nf / fs:g} s "
                                  f"(beyond half the band {band:.4g}); record longer")
    if not len(out):
        return ChannelWarmup(0.0, 0.0, True, False, **common,
                             note=f"within the band from the first full window (its centre at {t[0]:g} s)")
    j = int(out[-1])
    if j + 1 >= len(m):
        return ChannelWarmup(math.nan, math.nan, False, True, **common,
                             note="not settled: the moving mean is outside the band at the end of the record")
    time = float(t[j] + off[j] / (off[j] - off[j + 1]) / fs)
    if time > start_final:
        return ChannelWarmup(math.nan, math.nan, False, True, **common,
                             note=f"not settled: the moving mean enters the band only at {time:g} s, inside the final "
                                  f"{nf / fs:g} s that define the settled value; record longer")
    slope, slope_sigma = _crossing_slope(m, j, k, fs, noise)
    if abs(slope) > 2 * slope_sigma:
        sigma = math.sqrt(total**2 / slope**2 + 1.0 / (12 * fs * fs))
        note = f"left the band for the last time at {time:g} s"
    else:
        sigma, note = math.nan, f"left the band for the last time at {time:g} s, crossing lost in noise (no sigma)"
    return ChannelWarmup(time, sigma, True, True, **common, note=note)


def settling_time(excursion: float, tau: float, band: float) -> float:
    """Settling time of ``b(t) = b_end + d exp(-t / tau)`` into ``|b - b_end| <= band``: ``tau ln(|d| / band)``
    (0 when ``|d| <= band``).

    Examples
    --------
    >>> round(settling_time(5e-3, 60.0, 2e-4), 2)
    193.13
    """
    return tau * math.log(abs(excursion) / band) if abs(excursion) > band else 0.0


def simulate_warmup(duration: float, fs: float, end_bias: np.ndarray, excursion: np.ndarray, tau: float,
                    noise: float, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A static record from turn-on: ``b(t) = b_end + d exp(-t / tau)`` plus white noise, per channel.

    Parameters
    ----------
    duration, fs : float
        Length (s) and sample rate (Hz).
    end_bias, excursion : array_like, shape (C,)
        ``b_end`` and ``d`` per channel, SI.
    tau : float
        Time constant, s.
    noise : float
        White noise 1-sigma per sample, SI.
    seed : int

    Returns
    -------
    t : ndarray, shape (n,)
        s, from 0.
    x : ndarray, shape (n, C)
    """
    rng = np.random.default_rng(seed)
    t = np.arange(int(round(duration * fs))) / fs
    b_end, d = np.atleast_1d(np.asarray(end_bias, float)), np.atleast_1d(np.asarray(excursion, float))
    x = b_end + d * np.exp(-t[:, None] / tau) + rng.normal(0.0, noise, (t.size, b_end.size))
    return t, x


def channel_figures(name: str, sensor: str, values: Sequence[tuple[float, float, str]], unit: str,
                      method: str, test: str) -> tuple[Figure, ...]:
    from align.keyfigures import AXES, title

    return tuple(Figure(f"{name}_{a}", sensor, v, s, unit, title(f"{name}_{a}"), method, test, detail=note)
                 for a, (v, s, note) in zip(AXES, values))



def _channel(c: dict[str, Any]) -> ChannelWarmup:
    got: dict[str, Any] = {k: (math.nan if c[k] is None else c[k]) for k in _CH_KEYS}
    return ChannelWarmup(**got)


_CH_KEYS = ("time", "sigma", "settled", "left_band", "value", "value_sigma", "band", "noise", "drift", "drift_sigma",
            "note")


class WarmupResult(Result, format=WARMUP_FORMAT, convention=CONVENTION):
    """The warm-up of each channel of a static record (SI).

    Attributes
    ----------
    sensor : str
        ``"gyroscope"`` or ``"accelerometer"``.
    names : tuple of str
        The channels.
    fs : float
        Sample rate, Hz.
    samples : int
    window : float
        Moving-mean window, s.
    final : float
        Final segment, s.
    criterion : str
        The criterion, as words.
    channels : tuple of ChannelWarmup
        One per channel.
    inputs, streams, notes : tuple
        The record, the stream read, the readers' remarks.
    """

    sensor: str
    names: tuple
    fs: float
    samples: int
    window: float
    final: float
    criterion: str
    channels: tuple
    inputs: tuple = ()
    streams: tuple = ()
    notes: tuple = ()

    @property
    def unit(self) -> str:
        """SI unit of the readings."""
        return "rad/s" if self.sensor == "gyroscope" else "m/s^2"

    def figures_of_merit(self) -> tuple[Figure, ...]:
        """``warmup_x..`` (s) of the first three channels; NaN (with the reason) when not settled."""
        vals = [(c.time, c.sigma, "" if c.settled else c.note) for c in self.channels[:3]]
        return channel_figures("warmup", self.sensor, vals, "s", self.criterion, "warmup")

    def to_dict(self) -> dict[str, Any]:
        """The versioned JSON form (SI)."""
        return {**self.envelope({"time": "s", "reading": self.unit}), "sensor": self.sensor, "fs_hz": self.fs,
                "samples": self.samples, "window_s": self.window, "final_s": self.final, "criterion": self.criterion,
                "channels": {n: {k: getattr(c, k) for k in _CH_KEYS} for n, c in zip(self.names, self.channels)},
                "inputs": list(self.inputs), "streams": [dict(s) for s in self.streams], "notes": list(self.notes)}

    @classmethod
    def from_dict(cls, d: dict[str, Any], where: str = "result") -> WarmupResult:
        """Read the form :meth:`to_dict` writes."""
        cls.check_envelope(d, where, keys=("sensor", "fs_hz", "samples", "window_s", "final_s", "criterion",
                                           "channels", "inputs", "streams", "notes"))
        try:
            chans = d["channels"]
            return cls(str(d["sensor"]), tuple(chans), float(d["fs_hz"]), int(d["samples"]), float(d["window_s"]),
                       float(d["final_s"]), str(d["criterion"]),
                       tuple(_channel(c) for c in chans.values()),
                       tuple(d.get("inputs", ())), tuple(dict(s) for s in d.get("streams", ())),
                       tuple(d.get("notes", ())))
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise InputError(f"malformed {WARMUP_FORMAT} result ({malformed(exc)}); regenerate it", where) from None
