"""Segments as linear observations ``y_k = [M | b] phi_k`` of all three gyros (SI units).

* constant-rate dwell (Eq 19-30): ``y`` = mean reading (rad/s), ``phi = [w_k; 1]``;
* turn of known angle (Eq 31, integrated Eq 11-13): ``y`` = integrated reading (rad),
  ``phi = [theta_k u_k; T_k]`` (``T_k`` the duration, so a bias adds ``b T_k``);
* static period: ``y`` = mean reading, ``phi = [w_earth; 1]`` (``[0; 1]`` without an Earth-rate correction).

Public names
------------
Observation, observe
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.alignment.plan import Plan
from align.alignment.segment import Segment, integrate
from align.earth import vertical_rate
from align.values import Value


@dataclass(frozen=True, eq=False)
class Observation(Value):
    """One segment as a linear observation ``y = [M | b] phi`` (SI units; see the module docstring).

    Attributes
    ----------
    segment : Segment
    y : ndarray, shape (3,)
        Mean reading of a dwell or static period (rad/s; m/s^2 for an accelerometer) or a turn's integrated reading (rad).
    phi : ndarray, shape (4,)
        ``[w u; 1]`` for a dwell (table rate ``w``, rad/s, times the step's unit axis), ``[w_earth; 1]``
        or ``[0; 1]`` for a static period, ``[theta u; T]`` for a turn (angle, rad; duration, s).
    var : ndarray, shape (3,)
        Variance of ``y`` from the noise inside the segment (batch means for dwells, white noise for turns).
    duration : float
        s.
    """

    segment: Segment
    y: np.ndarray
    phi: np.ndarray
    var: np.ndarray
    duration: float


#: smallest variance of an observation ((rad/s)^2 or rad^2): keeps noiseless data finite
_VAR_FLOOR = 1e-30


def _batch_mean_var(x: np.ndarray, batches: int = 10) -> np.ndarray:
    """Variance of the mean of ``x`` (n, 3) by batch means: robust to short-term correlation."""
    n = len(x)
    if n < 4 * batches:
        return np.var(x, axis=0, ddof=1) / n
    m = n // batches
    means = x[: m * batches].reshape(batches, m, 3).mean(axis=1)
    return np.var(means, axis=0, ddof=1) / batches


def observe(t: np.ndarray, g: np.ndarray, segments: list[Segment], plan: Plan, sigma: np.ndarray,
            earth: bool = False) -> list[Observation]:
    """Turn segments into linear observations (see module docstring).

    Parameters
    ----------
    t, g : ndarray
        Time (s) and gyro readings (rad/s), shapes (n,) and (n, 3).
    segments : list of Segment
    plan : Plan
    sigma : ndarray, shape (3,)
        Per-sample white-noise sigma, rad/s (for the variance of turns).
    earth : bool
        Add the vertical Earth rate along the table axis (needs ``plan.latitude``): modelled in ``w``, not left in ``b``.

    Returns
    -------
    list of Observation
        One per segment, in order.
    """
    dt = float(np.median(np.diff(t)))
    e_up = vertical_rate(plan.latitude) if earth and plan.latitude is not None else 0.0
    out = []
    for seg in segments:
        x = g[seg.start : seg.end]
        if seg.kind == "angle":
            step = plan.steps[seg.step]
            y, duration = integrate(t, g, seg.start, seg.end)
            phi = np.append((step.angle + e_up * duration) * step.unit_axis, duration)
            var = sigma**2 * dt * duration
        else:
            duration = seg.n * dt
            y = x.mean(axis=0)
            if seg.kind == "rate":
                step = plan.steps[seg.step]
                phi = np.append((step.rate + e_up) * step.unit_axis, 1.0)
            else:
                phi = np.array([0.0, 0.0, 0.0, 1.0])
            var = np.maximum(_batch_mean_var(x), sigma**2 / seg.n)
        out.append(Observation(seg, y, phi, np.maximum(var, _VAR_FLOOR), duration))
    return out
