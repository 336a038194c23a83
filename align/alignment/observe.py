"""Segments as linear observations ``y_k = [M | b] phi_k`` of all three gyros (SI units).

* constant-rate dwell (Eq 19-30): ``y`` = mean reading (rad/s), ``phi = [w_k; 1]``;
* turn of known angle (Eq 31, integrated Eq 11-13): ``y`` = integrated reading (rad),
  ``phi = [theta_k u_k; T_k]`` (``T_k`` the duration, so a bias adds ``b T_k``);
* static period: ``y`` = mean reading, ``phi = [w_earth; 1]`` (``[0; 1]`` without an Earth-rate correction).

Earth rate (reference section 4, last item), with a latitude: ``Omega_L = Omega (0, cos L, sin L)`` in the
local level frame (:func:`align.earth.earth_rate_enu`). What the plan's geometry
(:mod:`align.alignment.geometry`) allows is modelled in ``phi``, and what it does not goes into ``var``:

* a dwell or turn about the table axis ``a``: the component ``Omega_L . a`` along the spin axis is modelled;
  the part across it (size ``P = |Omega_L x a|``) turns with the table, and its mean over the segment has the
  size ``P |sum_k exp(i theta_k) dt_k| / T`` (``theta`` the table angle, from the readings; only its direction,
  set by the unknown heading, is unknown), which enters the variance as ``size^2 / 2`` on each of the two
  directions across the axis;
* a static period just before a step with a stated ``rest``: the whole vector ``C^T Omega_L``;
* a static period with the step's axis along the table axis but no rest: the component along it; the part
  across (``P``, direction unknown) enters the variance;
* a static period after a motion the plan does not list: nothing modelled; ``Omega^2 / 3`` per axis enters
  the variance.

Without a latitude (or with the correction switched off) nothing is modelled (``phi`` as above with
``w_earth = 0``), but the Earth rate is still there: a constant vector ``Omega_L`` of size ``Omega`` and unknown
direction (latitude and heading unknown), taken as isotropic, ``cov(Omega_L) = Omega^2 / 3 I`` (Eq O1). What the
geometry says about it is kept, so that nothing downstream mistakes it for a bias drift
(:mod:`align.alignment.biasdrift`) or for noise that averages out:

* the component along a table axis ``a``, ``Omega_L . a``, is the same in every dwell, turn and static period
  with that axis: ``y_k`` holds ``E_k Omega_L`` with ``E_k = N u_k a^T`` (times ``T_k`` for a turn; ``u_k`` the
  step's axis in the system frame); a static period with a stated rest holds ``E_k = N C^T`` (Eq O2). These
  shared terms are the observation's ``earth`` (3, 3), scaled by ``Omega / sqrt(3)`` so that their covariance
  is ``cov(y_k, y_l)_i = earth_k[i] . earth_l[i]`` per gyro ``i`` (Eq O3);
* the part across the axis (size ``P``, ``E[P^2] = 2 Omega^2 / 3``) enters the variance as above (a static
  period: ``Omega^2 / 3`` on each direction across the axis; a dwell or turn: the same times its turning
  mean's fraction squared), and after a motion the plan does not list ``Omega^2 / 3`` per axis.

Public names
------------
Observation, EarthModel, observe
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from align.alignment.plan import Plan, Step
from align.alignment.segment import Segment, integrate
from align.earth import EARTH_RATE, earth_rate_enu
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
    earth : ndarray, shape (3, 3), or None
        Without a latitude: the unmodelled Earth rate ``y`` shares with other segments, ``E_k Omega / sqrt(3)``
        (Eq O2; rad/s per unit of the isotropic Earth-rate direction, rad for a turn); per gyro ``i``
        ``cov(y_k, y_l) = earth_k[i] . earth_l[i]`` (Eq O3). None when nothing is shared (keyword only).
    """

    segment: Segment
    y: np.ndarray
    phi: np.ndarray
    var: np.ndarray
    duration: float
    earth: np.ndarray | None = field(default=None, kw_only=True)


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


@dataclass(frozen=True)
class EarthModel:
    """What of the Earth rate the observations model (see the module docstring).

    Attributes
    ----------
    latitude : float or None
        rad; None: not modelled at all.
    steps : int
        Dwells and turns with the component along the spin axis modelled.
    whole : int
        Static periods with the whole vector modelled (rest orientation stated).
    along : int
        Static periods with the component along the table axis modelled.
    unknown : int
        Static periods after a motion the plan does not list (nothing modelled).
    across : float
        Largest unmodelled part put into an observation's variance, rad/s (turns: per second of turn).
    along_rate : tuple of float
        The distinct along-axis components modelled, rad/s.
    """

    latitude: float | None
    steps: int = 0
    whole: int = 0
    along: int = 0
    unknown: int = 0
    across: float = 0.0
    along_rate: tuple[float, ...] = ()


def _across_var(size: float, u: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Per-gyro variance of a vector of ``size`` with an unknown direction across the system axis ``u``."""
    return size**2 / 2 * np.maximum(1.0 - (n @ u) ** 2, 0.0)


def _turning_mean(t: np.ndarray, g: np.ndarray, seg: Segment, direction: np.ndarray) -> float:
    """``|sum_k exp(i theta_k) dt_k|`` over the segment, ``theta`` integrated from the readings along ``direction``."""
    stop = min(seg.end + 1, len(t))
    dt = np.diff(t[seg.start : stop])
    dt = np.append(dt, dt[-1:]) if len(dt) < seg.n else dt
    theta = np.cumsum(g[seg.start : seg.end] @ direction * dt)
    return float(abs(np.sum(np.exp(1j * theta) * dt)))


def _static_geometry(seg: Segment, steps: list[Segment], moves: list[tuple[int, int]], plan: Plan
                     ) -> tuple[str, Step | None]:
    """How a static period sits: ``("whole" | "along" | "unknown", the step whose axis is along the table)``."""
    after = [s for s in steps if s.start >= seg.end]
    before = [s for s in steps if s.end <= seg.start]

    def clear(a: int, b: int) -> bool:
        return not any(a < e and s < b for s, e in moves)

    if after and clear(seg.end, after[0].start):
        k = after[0].step
        assert k is not None  # ``steps`` holds the step segments only
        step = plan.steps[k]
        return ("whole" if step.rest is not None else "along"), step
    if before and clear(before[-1].end, seg.start):
        k = before[-1].step
        assert k is not None
        return "along", plan.steps[k]
    return "unknown", None


def observe(t: np.ndarray, g: np.ndarray, segments: list[Segment], plan: Plan, sigma: np.ndarray,
            earth: bool = False, mounting: np.ndarray | None = None,
            moves: Sequence[tuple[int, int]] = ()) -> tuple[list[Observation], EarthModel]:
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
        Model the Earth rate (needs ``plan.latitude``) as far as the plan's geometry allows.
    mounting : ndarray, shape (3, 3), optional
        The nominal mounting ``N`` (identity when None): which gyros an unmodelled part reaches.
    moves : sequence of (int, int)
        Sample ranges of the motions the plan does not list (after one, a rest orientation is unknown).

    Returns
    -------
    observations : list of Observation
        One per segment, in order.
    earth : EarthModel
        What was modelled.
    """
    n_nom = np.eye(3) if mounting is None else np.asarray(mounting, float)
    dt = float(np.median(np.diff(t)))
    lat = plan.latitude if earth else None
    omega = earth_rate_enu(lat) if lat is not None else np.zeros(3)
    steps = [s for s in segments if s.step is not None]
    out = []
    model: dict[str, Any] = {"steps": 0, "whole": 0, "along": 0, "unknown": 0, "across": 0.0}
    along_rates: set[float] = set()
    for seg in segments:
        x = g[seg.start : seg.end]
        extra, shared = np.zeros(3), None
        if seg.kind == "angle":
            assert seg.step is not None  # a turn is a plan step
            step = plan.steps[seg.step]
            y, duration = integrate(t, g, seg.start, seg.end)
            along = float(omega @ step.table_vector)
            phi = np.append((step.turn + along * duration) * step.unit_axis, duration)
            var = sigma**2 * dt * duration
        else:
            duration = seg.n * dt
            y = x.mean(axis=0)
            var = np.maximum(_batch_mean_var(x), sigma**2 / seg.n)
            if seg.kind == "rate":
                assert seg.step is not None  # a dwell is a plan step
                step = plan.steps[seg.step]
                along = float(omega @ step.table_vector)
                phi = np.append((step.turn + along) * step.unit_axis, 1.0)
            elif lat is not None:
                phi, extra = _static_phi(seg, steps, list(moves), plan, omega, n_nom, model, along_rates)
            else:
                phi = np.array([0.0, 0.0, 0.0, 1.0])
        if seg.kind != "static" and lat is not None:
            across = float(np.linalg.norm(np.cross(omega, step.table_vector)))
            size = across * _turning_mean(t, g, seg, n_nom @ step.unit_axis) / (1.0 if seg.kind == "angle" else duration)
            extra = _across_var(size, step.unit_axis, n_nom)
            model["steps"] += 1
            model["across"] = max(model["across"], size / (duration if seg.kind == "angle" else 1.0))
            along_rates.add(round(along, 15))
        if lat is None:
            shared, extra = _unmodelled(t, g, seg, duration, steps, list(moves), plan, n_nom)
        out.append(Observation(seg, y, phi, np.maximum(var + extra, _VAR_FLOOR), duration, earth=shared))
    return out, EarthModel(lat, along_rate=tuple(sorted(along_rates)), **model)


#: 1-sigma of each component of the isotropic Earth rate of unknown direction (Eq O1), rad/s
_EARTH_SD = EARTH_RATE / np.sqrt(3.0)


def _unmodelled(t: np.ndarray, g: np.ndarray, seg: Segment, duration: float, steps: list[Segment],
                moves: list[tuple[int, int]], plan: Plan, n_nom: np.ndarray) -> tuple[np.ndarray | None, np.ndarray]:
    """Without a latitude: the segment's shared Earth term ``earth`` (3, 3) (Eq O2-O3) and the variance (3,) of the
    part it holds alone (across the table axis, or all of it after an unlisted motion)."""
    if seg.kind == "static":
        how, step = _static_geometry(seg, steps, moves, plan)
        if how == "unknown":
            return None, np.full(3, _EARTH_SD**2)
        assert step is not None  # known geometry: the step along the table
        if how == "whole":
            rest = step.rest_matrix
            assert rest is not None  # "whole": the step states its rest orientation
            return n_nom @ rest.T * _EARTH_SD, np.zeros(3)
        fraction = 1.0
    else:
        assert seg.step is not None  # not static: a plan step
        step = plan.steps[seg.step]
        fraction = _turning_mean(t, g, seg, n_nom @ step.unit_axis) / (1.0 if seg.kind == "angle" else duration)
    scale = _EARTH_SD * (duration if seg.kind == "angle" else 1.0)
    shared = np.outer(n_nom @ step.unit_axis, step.table_vector) * scale
    # across: E[P^2] / 2 = Omega^2 / 3 per direction across the axis, times the turning mean's fraction squared
    return shared, _across_var(np.sqrt(2.0) * _EARTH_SD * fraction, step.unit_axis, n_nom)


def _static_phi(seg: Segment, steps: list[Segment], moves: list[tuple[int, int]], plan: Plan, omega: np.ndarray,
                n_nom: np.ndarray, model: dict, along_rates: set) -> tuple[np.ndarray, np.ndarray]:
    """``phi`` of a static period and the variance of the Earth rate it leaves unmodelled (zeros without Earth)."""
    if not omega.any():
        return np.array([0.0, 0.0, 0.0, 1.0]), np.zeros(3)
    how, step = _static_geometry(seg, steps, moves, plan)
    model[how] += 1
    if how == "unknown":
        model["across"] = max(model["across"], EARTH_RATE)
        return np.array([0.0, 0.0, 0.0, 1.0]), np.full(3, EARTH_RATE**2 / 3)
    assert step is not None  # known geometry: the step along the table
    if how == "whole":
        rest = step.rest_matrix
        assert rest is not None  # "whole": the step states its rest orientation
        return np.append(rest.T @ omega, 1.0), np.zeros(3)
    along = float(omega @ step.table_vector)
    across = float(np.linalg.norm(np.cross(omega, step.table_vector)))
    model["across"] = max(model["across"], across)
    along_rates.add(round(along, 15))
    return np.append(along * step.unit_axis, 1.0), _across_var(across, step.unit_axis, n_nom)
