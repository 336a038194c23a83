"""Bias repeatability (turn-on to turn-on) and in-run bias stability from several static records of one unit.

IEEE Std 952 and 1431 name two bias figures a test series reports (wording here ours):

* **bias repeatability** (turn-on to turn-on): the 1-sigma spread of the bias from one turn-on to the next under
  the same conditions (the unit switched off and cooled between records);
* **in-run bias stability**: the 1-sigma spread of the bias within one run, as ``period``-second averages
  (seed 002 Eq 7: std, ddof 1, of consecutive ``period``-second means).

Per record the bias is the mean after its warm-up (``skip`` seconds, or the warm-up time :mod:`align.noise.warmup`
finds, the longest of the channels); its 1-sigma is that of a mean of correlated noise by batch means: the record
after warm-up cut into ``K`` equal blocks, ``sigma_b = sigma_A(T / K) / sqrt(K)`` with ``sigma_A(T / K)`` the Allan
deviation of the block means (``sqrt(mean(diff^2) / 2)``, insensitive to a slow drift), equal to
``sigma / sqrt(n)`` for white noise. The repeatability is the sample standard deviation (ddof 1) of the ``N``
per-record biases; ``(N - 1) s^2 / sigma^2`` is chi-square with ``N - 1`` degrees of freedom for normal biases,
so the two-sided interval at level ``1 - alpha`` is ``[s sqrt((N - 1) / chi2_{1 - alpha/2}), s sqrt((N - 1) /
chi2_{alpha/2})]`` (NIST/SEMATECH e-Handbook 7.2.3.1). The spread includes each bias's own estimation noise: the
result states its rms (``within``), and says so when it is not small against the spread.

Public names
------------
RepeatabilityResult, RunBias, record_bias, repeatability, chi2_interval, simulate_turn_ons, BLOCKS
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from align.errors import InputError
from align.merit import Figure
from align.noise.warmup import CONVENTION, channel_figures
from align.results import Result
from align.wellformed import malformed

REPEATABILITY_FORMAT = "imu-align.repeatability"

__all__ = ["RepeatabilityResult", "RunBias", "record_bias", "repeatability", "chi2_interval", "simulate_turn_ons", "BLOCKS"]

#: blocks of the batch-means sigma of a record's bias
BLOCKS = 20


@dataclass(frozen=True)
class RunBias:
    """One record's bias after warm-up (SI).

    Attributes
    ----------
    bias, sigma : ndarray, shape (C,)
        Mean after warm-up and its 1-sigma (batch means, module docstring).
    stability : ndarray, shape (C,)
        In-run bias stability: std (ddof 1) of consecutive ``period``-second means after warm-up; NaN when fewer
        than two periods fit.
    skip : float
        Seconds left out at the start (the warm-up).
    samples : int
        Samples averaged.
    """

    bias: np.ndarray
    sigma: np.ndarray
    stability: np.ndarray
    skip: float
    samples: int


def record_bias(x: np.ndarray, fs: float, skip: float = 0.0, period: float = 10.0, where: str = "record") -> RunBias:
    """A record's bias after ``skip`` seconds, its batch-means 1-sigma and its in-run stability.

    Parameters
    ----------
    x : ndarray, shape (n, C)
        Readings, SI.
    fs : float
        Sample rate, Hz.
    skip : float
        Warm-up left out, s.
    period : float
        Averaging period of the in-run stability, s.
    where : str
        The record, for messages.

    Returns
    -------
    RunBias

    Raises
    ------
    InputError
        Fewer than ``2 BLOCKS`` samples left after the warm-up.

    Examples
    --------
    >>> x = np.random.default_rng(2).normal(0.01, 0.1, (100_000, 1))
    >>> r = record_bias(x, 100.0)
    >>> bool(0.7 < r.sigma[0] / (0.1 / np.sqrt(1e5)) < 1.3)  # white noise: sigma / sqrt(n), within its 16 % scatter
    True
    """
    x = np.asarray(x, float)
    if x.ndim == 1:
        x = x[:, None]
    start = int(math.ceil(skip * fs))
    y = x[start:]
    n = len(y)
    if n < 2 * BLOCKS:
        raise InputError(f"holds {n} samples after the {skip:g} s warm-up; the bias needs at least {2 * BLOCKS}: "
                         "record longer or skip less", where)
    k = n // BLOCKS
    means = y[: BLOCKS * k].reshape(BLOCKS, k, -1).mean(axis=1)
    adev = np.sqrt(0.5 * np.mean(np.diff(means, axis=0) ** 2, axis=0))
    p = int(round(period * fs))
    windows = n // p if p > 0 else 0
    if windows >= 2:
        stability = np.std(y[: windows * p].reshape(windows, p, -1).mean(axis=1), axis=0, ddof=1)
    else:
        stability = np.full(x.shape[1], np.nan)
    return RunBias(y.mean(axis=0), adev / math.sqrt(BLOCKS), stability, start / fs, n)


def chi2_interval(s: np.ndarray | float, dof: int, level: float = 0.95) -> tuple[np.ndarray, np.ndarray]:
    """Two-sided confidence interval of a standard deviation from its sample value ``s`` with ``dof`` degrees of
    freedom: ``[s sqrt(dof / chi2_{1 - a/2}), s sqrt(dof / chi2_{a/2})]``, ``a = 1 - level``.

    Examples
    --------
    >>> lo, hi = chi2_interval(1.0, 9, 0.95)
    >>> round(float(lo), 3), round(float(hi), 3)
    (0.688, 1.826)
    """
    from scipy.stats import chi2

    a = 1.0 - level
    s = np.asarray(s, float)
    return s * np.sqrt(dof / chi2.ppf(1 - a / 2, dof)), s * np.sqrt(dof / chi2.ppf(a / 2, dof))


@dataclass(frozen=True)
class Repeatability:
    """The turn-on to turn-on repeatability of ``N`` records (SI).

    Attributes
    ----------
    value : ndarray, shape (C,)
        Std (ddof 1) of the per-record biases.
    sigma : ndarray, shape (C,)
        Its 1-sigma, ``value / sqrt(2 (N - 1))`` (normal biases).
    low, high : ndarray, shape (C,)
        Chi-square interval at ``level``.
    level : float
    within : ndarray, shape (C,)
        Rms of the per-record biases' own 1-sigma (their estimation noise, inside ``value``).
    mean : ndarray, shape (C,)
        Mean of the per-record biases.
    """

    value: np.ndarray
    sigma: np.ndarray
    low: np.ndarray
    high: np.ndarray
    level: float
    within: np.ndarray
    mean: np.ndarray


def repeatability(runs: Sequence[RunBias], level: float = 0.95) -> Repeatability:
    """Bias repeatability of several records of one unit (module docstring).

    Parameters
    ----------
    runs : sequence of RunBias
        At least two records.
    level : float
        Confidence level of the interval, in (0, 1).

    Returns
    -------
    Repeatability

    Raises
    ------
    InputError
        Fewer than two records (``{logs}``).

    Examples
    --------
    >>> runs = [RunBias(np.array([b]), np.array([0.0]), np.array([np.nan]), 0.0, 100) for b in (1.0, 2.0, 3.0)]
    >>> float(repeatability(runs).value[0])
    1.0
    """
    if len(runs) < 2:
        raise InputError(f"{len(runs)} record given; the turn-on to turn-on repeatability needs at least two (five or "
                         "more for a useful interval)", "{logs}")
    b = np.stack([np.asarray(r.bias, float) for r in runs])
    s = np.std(b, axis=0, ddof=1)
    dof = len(runs) - 1
    low, high = chi2_interval(s, dof, level)
    within = np.sqrt(np.mean(np.stack([np.asarray(r.sigma, float) for r in runs]) ** 2, axis=0))
    return Repeatability(s, s / math.sqrt(2 * dof), low, high, level, within, b.mean(axis=0))


def simulate_turn_ons(count: int, duration: float, fs: float, bias: np.ndarray, spread: float, noise: float,
                      seed: int = 0) -> tuple[np.ndarray, list[np.ndarray]]:
    """Static records of ``count`` turn-ons: each a bias drawn from ``N(bias, spread^2)`` per channel plus white noise.

    Parameters
    ----------
    count : int
    duration, fs : float
        Length of each record (s) and sample rate (Hz).
    bias : array_like, shape (C,)
        Mean bias, SI.
    spread : float
        Turn-on to turn-on 1-sigma (the repeatability), SI.
    noise : float
        White noise 1-sigma per sample, SI.
    seed : int

    Returns
    -------
    biases : ndarray, shape (count, C)
        The turn-on biases drawn.
    records : list of ndarray, shape (n, C)
    """
    rng = np.random.default_rng(seed)
    mean = np.atleast_1d(np.asarray(bias, float))
    n = int(round(duration * fs))
    biases = mean + rng.normal(0.0, spread, (count, mean.size))
    return biases, [b + rng.normal(0.0, noise, (n, mean.size)) for b in biases]


class RepeatabilityResult(Result, format=REPEATABILITY_FORMAT, convention=CONVENTION):
    """Bias repeatability of several turn-ons of one unit, and each record's bias and in-run stability (SI).

    Attributes
    ----------
    sensor : str
    names : tuple of str
    fs : float
    runs : tuple of dict
        Per record: ``input``, ``skip_s`` (warm-up left out), ``samples``, ``bias``, ``sigma``, ``stability`` (lists
        of C, SI).
    value, sigma, low, high : ndarray, shape (C,)
        Repeatability (std, ddof 1, of the biases), its 1-sigma, and its chi-square interval at ``level``.
    level : float
    within : ndarray, shape (C,)
        Rms of the biases' own 1-sigma (estimation noise inside ``value``).
    mean : ndarray, shape (C,)
        Mean bias over the turn-ons.
    period : float
        Averaging period of the in-run stability, s.
    skip_rule : str
        How the warm-up left out of each record was chosen.
    inputs, streams, notes : tuple
    """

    sensor: str
    names: tuple
    fs: float
    runs: tuple
    value: np.ndarray
    sigma: np.ndarray
    low: np.ndarray
    high: np.ndarray
    level: float
    within: np.ndarray
    mean: np.ndarray
    period: float
    skip_rule: str
    inputs: tuple = ()
    streams: tuple = ()
    notes: tuple = ()

    @property
    def unit(self) -> str:
        """SI unit of the readings."""
        return "rad/s" if self.sensor == "gyroscope" else "m/s^2"

    @property
    def method(self) -> str:
        """How the repeatability was found, as words."""
        return (f"std (ddof 1) of the biases of {len(self.runs)} turn-ons (IEEE Std 952/1431 turn-on to turn-on), "
                f"{100 * self.level:g} % chi-square interval; bias = mean after warm-up ({self.skip_rule})")

    def figures_of_merit(self) -> tuple[Figure, ...]:
        """``bias_repeatability_x..`` of the first three channels, with the interval and the estimation noise said."""
        vals = []
        for j in range(min(3, len(self.names))):
            note = f"{100 * self.level:g} % interval [{self.low[j]:.4g}, {self.high[j]:.4g}] {self.unit}"
            if self.within[j] > 0.3 * self.value[j]:
                note += f"; the biases' own noise ({self.within[j]:.3g}) is not small against the spread"
            vals.append((float(self.value[j]), float(self.sigma[j]), note))
        return channel_figures("bias_repeatability", self.sensor, vals, self.unit, self.method, "repeatability")

    def to_dict(self) -> dict[str, Any]:
        """The versioned JSON form (SI)."""
        per = {k: dict(zip(self.names, np.asarray(getattr(self, k), float).tolist()))
               for k in ("value", "sigma", "low", "high", "within", "mean")}
        return {**self.envelope({"reading": self.unit, "time": "s"}), "sensor": self.sensor, "fs_hz": self.fs,
                "level": self.level, "period_s": self.period, "skip_rule": self.skip_rule, "method": self.method,
                "repeatability": per, "runs": [dict(r) for r in self.runs], "channels": list(self.names),
                "inputs": list(self.inputs), "streams": [dict(s) for s in self.streams], "notes": list(self.notes)}

    @classmethod
    def from_dict(cls, d: dict[str, Any], where: str = "result") -> RepeatabilityResult:
        """Read the form :meth:`to_dict` writes."""
        cls.check_envelope(d, where, keys=("sensor", "fs_hz", "level", "period_s", "skip_rule", "method",
                                           "repeatability", "runs", "channels", "inputs", "streams", "notes"))
        try:
            names = tuple(d["channels"])
            rep = d["repeatability"]
            arr = {k: np.array([math.nan if rep[k][n] is None else rep[k][n] for n in names], float)
                   for k in ("value", "sigma", "low", "high", "within", "mean")}
            return cls(str(d["sensor"]), names, float(d["fs_hz"]), tuple(dict(r) for r in d["runs"]), arr["value"],
                       arr["sigma"], arr["low"], arr["high"], float(d["level"]), arr["within"], arr["mean"],
                       float(d["period_s"]), str(d["skip_rule"]), tuple(d.get("inputs", ())),
                       tuple(dict(s) for s in d.get("streams", ())), tuple(d.get("notes", ())))
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise InputError(f"malformed {REPEATABILITY_FORMAT} result ({malformed(exc)}); regenerate it",
                             where) from None
