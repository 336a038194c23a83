"""The thermal calibration of one sensor from a static log with a temperature column: checks, the one pass of
sums, the order of each axis by blocked cross-validation, the fit and its band, branches and hysteresis, the
residual before and after, the held-out branch check.

Public names
------------
Settings, AxisReport, SensorThermal, fit_sensor, recorded_rate
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from align.calibration.thermal import checks
from align.calibration.thermal.branches import (
    Hysteresis,
    branch_counts,
    branch_labels,
    crosscheck,
    hysteresis,
    temperature_rate,
)
from align.calibration.thermal.fit import FOLDS, candidates, choose, cross_validate, fit_axis, physical
from align.calibration.thermal.model import ThermalModel
from align.calibration.thermal.sums import Sums, accumulate, extremes, solve, sse
from align.errors import InputError
from align.values import Value

__all__ = ["Settings", "AxisReport", "SensorThermal", "fit_sensor", "recorded_rate"]

#: fewest samples a thermal log may hold
MIN_SAMPLES = 200


@dataclass(frozen=True)
class Settings:
    """How the fit is made (the job's options, SI and C).

    Attributes
    ----------
    order : int or None
        A fixed polynomial order; None: chosen by cross-validation up to ``max_order``.
    max_order : int
    lag : bool or None
        The thermal-lag term on, off, or chosen by cross-validation (None).
    window_s : float
        Smoothing window of the temperature rate, s.
    min_rate : float
        Smallest ``|dT/dt|`` that is a branch, C/s.
    min_branch_s : float
        Shortest run of one sign that is a branch, s.
    hysteresis : bool
        Detect heating and cooling branches and report the hysteresis (both branches then required).
    reference : float or None
        Reference temperature, C; None: the middle of the range (PX4's choice).
    blocks : int
        Contiguous blocks the sums are kept for (the units of the cross-validation blocks, the autocorrelation
        time and the branch fits).
    motion_factor : float
        A window varying this many times the noise is motion.
    """

    order: int | None = None
    max_order: int = 5
    lag: bool | None = None
    window_s: float = 20.0
    min_rate: float = 0.002
    min_branch_s: float = 120.0
    hysteresis: bool = True
    reference: float | None = None
    blocks: int = 200
    motion_factor: float = checks.MOTION_FACTOR


@dataclass(frozen=True, eq=False)
class AxisReport(Value):
    """What the fit of one axis found (readings in SI).

    Attributes
    ----------
    order : int
        The polynomial order chosen (or given).
    lag : bool
        Whether the lag term is in the model.
    cv : tuple of (int, bool, float)
        Each candidate's held-out rms residual: (order, lag, rms).
    rms_before, max_before : float
        Residual with only a constant bias removed: rms and largest.
    rms_after, max_after : float
        Residual after compensation (with the lag term): rms and largest.
    rms_cubic : float
        One cubic over all samples (the autopilots' offline method), rms.
    band_max : float
        Largest 1-sigma of the static curve over the range.
    inflation : float
        Mean ratio of the band to the white-noise band (the autocorrelation's effect).
    hysteresis : Hysteresis or None
    crosscheck : tuple of float or None
        rms residual of the model fitted on the heating branch judged on the cooling one, and the reverse.
    """

    order: int
    lag: bool
    cv: tuple
    rms_before: float
    max_before: float
    rms_after: float
    max_after: float
    rms_cubic: float
    band_max: float
    inflation: float
    hysteresis: Hysteresis | None = None
    crosscheck: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "cv", tuple((int(k), bool(g), float(r)) for k, g, r in self.cv))


@dataclass(frozen=True, eq=False)
class SensorThermal(Value):
    """One sensor's thermal calibration: the model and what its fit found.

    Attributes
    ----------
    model : ThermalModel
    units : str
        Unit the file shows readings in (``"deg/s"``, ``"m/s^2"``).
    axes : tuple of AxisReport
    branches : dict
        Samples on each branch (``heating``, ``cooling``); empty without branches.
    resolution : float
        Step of the temperature reading, C.
    samples : int
    notes : tuple of str
    """

    model: ThermalModel
    units: str
    axes: tuple
    branches: dict = field(default_factory=dict)
    resolution: float = 0.0
    samples: int = 0
    notes: tuple = ()

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "axes", tuple(self.axes))
        object.__setattr__(self, "branches", dict(self.branches))
        object.__setattr__(self, "notes", tuple(self.notes))


def _rate(t: np.ndarray, temperature: np.ndarray, step: float, settings: Settings, notes: list[str]) -> np.ndarray:
    """dT/dt over the window asked for, widened to span four steps of a stepped reading at the typical rate."""
    rate = temperature_rate(t, temperature, settings.window_s)
    size = np.abs(rate[::max(1, len(rate) // 100_000)])
    moving = size[size > settings.min_rate]
    need = 4 * step / float(np.median(moving)) if moving.size else 0.0
    if need > settings.window_s:
        window = min(need, 0.25 * float(t[-1] - t[0]))
        notes.append(f"temperature rate over {window:.3g} s, not {settings.window_s:.3g} s: the reading steps by "
                     f"{step:.3g} C")
        rate = temperature_rate(t, temperature, window)
    return rate


def recorded_rate(t: np.ndarray, temperature: np.ndarray, settings: Settings) -> np.ndarray:
    """dT/dt (n,), C/s, as :func:`fit_sensor` takes it for ``settings`` (the window widened for a stepped reading):
    what a report needs to find the branches and the lag term again.

    Examples
    --------
    >>> t = np.arange(2000.0)
    >>> float(recorded_rate(t, 20 + 0.01 * t, Settings())[1000].round(6))
    0.01
    """
    t, temperature = np.asarray(t, float), np.asarray(temperature, float)
    return _rate(t, temperature, checks.resolution(temperature), settings, [])


def _axis(s: Sums, axis: int, cands: list[tuple[int, bool]], do_branches: bool, folds: int):
    mse = cross_validate(s, axis, cands, folds)
    k, g = cands[choose(mse, cands)]
    fit = fit_axis(s, axis, k, g)
    cv = tuple((kk, gg, float(np.sqrt(np.nanmean(m)))) for (kk, gg), m in zip(cands, mse))
    y, n = s.axis_column(axis), s.count()
    total = s.total()
    cubic = float(np.sqrt(max(sse(total, s.columns(3, False), y, solve(total, s.columns(3, False), y)), 0.0) / n))
    hyst = hysteresis(s, axis, k) if do_branches else None
    cross = crosscheck(s, axis, k, g) if do_branches else None
    return fit, cv, cubic, hyst, cross


def fit_sensor(t: np.ndarray, temperature: np.ndarray, data: np.ndarray, sensor: str, units: str, rate_hz: float,
               settings: Settings, where: str) -> SensorThermal:
    """Thermal calibration of one sensor (module docstring).

    Parameters
    ----------
    t : ndarray, shape (n,)
        Time, s.
    temperature : ndarray, shape (n,)
        C.
    data : ndarray, shape (n, 3)
        Readings, SI.
    sensor : str
        ``"gyroscope"`` or ``"accelerometer"``.
    units : str
        Unit to show the readings in.
    rate_hz : float
        Sample rate, Hz.
    settings : Settings
    where : str
        The log, for messages.

    Returns
    -------
    SensorThermal

    Raises
    ------
    InputError
        The refusals of :mod:`align.calibration.thermal.checks`, or too few samples.
    """
    n = len(t)
    if n < MIN_SAMPLES:
        raise InputError(f"holds {n} samples; a thermal calibration needs at least {MIN_SAMPLES} over a temperature "
                         "ramp or several soaks", where)
    checks.check_unit(temperature, where)
    noise = checks.noise_and_motion(data, rate_hz, sensor, where, settings.motion_factor)
    tmin, tmax = float(np.min(temperature)), float(np.max(temperature))
    top = checks.orders_allowed(tmax - tmin, settings.order, settings.max_order, where)
    notes = []
    if settings.order is None and top < settings.max_order:
        notes.append(f"orders above {top} not tried: the span {tmax - tmin:.3g} C allows "
                     f"{checks.SPAN_PER_ORDER:g} C per order")
    step = checks.resolution(temperature)
    rate = _rate(t, temperature, step, settings, notes)
    label = (branch_labels(t, rate, settings.min_rate, settings.min_branch_s) if settings.hysteresis
             else np.zeros(n, np.int8))
    blocks = int(max(2 * FOLDS, min(settings.blocks, n // 20)))
    s = accumulate(temperature, rate, data, label, blocks, max(top, 3))
    counts = branch_counts(s) if settings.hysteresis else {}
    if settings.hysteresis:
        checks.check_branches(counts, max(50, 10 * (top + 2)), where)
    orders = range(top + 1) if settings.order is None else [settings.order]
    cands = [(k, g) for k, g in candidates(top, settings.lag) if k in orders]
    tref = 0.5 * (tmin + tmax) if settings.reference is None else float(settings.reference)
    results = [_axis(s, i, cands, settings.hysteresis, FOLDS) for i in range(3)]
    model = ThermalModel(sensor, tref, tmin, tmax, tuple(physical(s, r[0], i, tref) for i, r in enumerate(results)))
    white = ThermalModel(sensor, tref, tmin, tmax, tuple(physical(s, r[0], i, tref, white=True)
                                                         for i, r in enumerate(results)))
    grid = np.linspace(tmin, tmax, 201)
    band, band_white = model.sigma(grid), white.sigma(grid)
    slope = np.abs(np.gradient(model.bias(grid)[0], grid, axis=0)).max(axis=0)
    checks.check_resolution(step, slope, noise, sensor, where)
    W = np.zeros((s.P + 2, 3))
    for i, r in enumerate(results):
        W[s.columns(r[0].order, r[0].lag), i] = r[0].c
    big_before, big_after = extremes(temperature, rate, data, s, W)
    total = s.total()
    std = np.sqrt(np.maximum([total[s.axis_column(i), s.axis_column(i)] for i in range(3)], 0.0) / n)
    reports = []
    for i, (fit, cv, cubic, hyst, cross) in enumerate(results):
        ratio = band[:, i] / np.maximum(band_white[:, i], 1e-300)
        reports.append(AxisReport(fit.order, fit.lag, cv, float(std[i]), float(big_before[i]),
                                  float(np.sqrt(fit.sse / fit.n)), float(big_after[i]), cubic,
                                  float(band[:, i].max()), float(np.mean(ratio)), hyst, cross))
    return SensorThermal(model, units, tuple(reports), counts, step, n, tuple(notes))
