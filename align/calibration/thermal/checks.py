"""The refusals of a thermal calibration: one line each, naming what to do.

* a temperature no chip in a chamber has (the column in another unit): outside :data:`PLAUSIBLE_C`;
* a span too narrow for the order: at least :data:`SPAN_PER_ORDER` C per polynomial order (ArduPilot's learner
  asks 10 C for its cubic; a cubic is barely determined over less);
* a temperature resolution coarser than the fit needs: the compensation would step by more than the noise at
  each step of the reading (a 1 C sensor on a steep axis);
* a recording that moves: somewhere the readings vary far more than their noise (a rotation, a knock, a change
  of orientation): the thermal fit needs one static orientation;
* a branch with too few samples to be fitted.

Public names
------------
PLAUSIBLE_C, SPAN_PER_ORDER, MOTION_FACTOR, check_unit, orders_allowed, resolution, check_resolution, noise_and_motion,
check_branches
"""

from __future__ import annotations

import numpy as np

from align.errors import InputError

__all__ = ["PLAUSIBLE_C", "SPAN_PER_ORDER", "MOTION_FACTOR", "check_unit", "orders_allowed", "resolution",
           "check_resolution", "noise_and_motion", "check_branches"]

#: temperatures a MEMS chip in a chamber reads, C (AEC-Q100 grade 0 reaches -40..150 C)
PLAUSIBLE_C = (-60.0, 150.0)
#: temperature span needed per polynomial order, C
SPAN_PER_ORDER = 5.0
#: a window whose spread (or whose step in mean from the last) exceeds this many times the typical spread moves
MOTION_FACTOR = 100.0


def check_unit(temperature: np.ndarray, where: str) -> None:
    """Refuse temperatures no chip in a chamber reads (the column in K, in tenths of a degree, ...).

    Examples
    --------
    >>> check_unit(np.array([290.0, 330.0]), "log.csv")
    Traceback (most recent call last):
    ...
    align.errors.InputError: log.csv: temperature from 290 to 330 C is no chip's in a chamber (-60 to 150 C); if \
the column is in kelvin give temperature_units='K', else check temperature_column and temperature_units
    """
    lo, hi = float(np.min(temperature)), float(np.max(temperature))
    if lo >= PLAUSIBLE_C[0] and hi <= PLAUSIBLE_C[1]:
        return
    hint = "if the column is in kelvin give {temperature_units=K}, else check " if 200 <= lo and hi <= 430 else ""
    raise InputError(f"temperature from {lo:.6g} to {hi:.6g} C is no chip's in a chamber ({PLAUSIBLE_C[0]:g} to "
                     f"{PLAUSIBLE_C[1]:g} C); {hint or 'check '}{{temperature_column}} and {{temperature_units}}", where)


def orders_allowed(span: float, order: int | None, max_order: int, where: str) -> int:
    """The highest order the span allows (``order`` itself when fixed), or a refusal.

    Parameters
    ----------
    span : float
        Temperature span of the record, C.
    order : int or None
        A fixed order, or None (chosen up to ``max_order``).
    max_order : int
    where : str

    Returns
    -------
    int
        The largest order to try.
    """
    room = int(np.floor(span / SPAN_PER_ORDER + 1e-9))
    if order is not None and order > room:
        raise InputError(f"the temperature spans {span:.3g} C, too narrow for order {order} (at least "
                         f"{SPAN_PER_ORDER * order:g} C, {SPAN_PER_ORDER:g} C per order); record a wider span or give "
                         f"a lower {{order}}", where)
    if room < 1:
        raise InputError(f"the temperature spans only {span:.3g} C: no temperature dependence can be fitted over it "
                         f"(at least {SPAN_PER_ORDER:g} C); record a wider span, e.g. 20 C or more", where)
    return order if order is not None else min(max_order, room)


def resolution(temperature: np.ndarray, span: int = 200_000) -> float:
    """The temperature reading's step, C: the smallest change between consecutive samples that is not zero
    (the 1st percentile of the changes, so that a rare rounding artefact does not decide it), over the start,
    middle and end of the record (``span`` samples each); 0 for a constant reading.

    Examples
    --------
    >>> float(resolution(np.round(np.linspace(20.0, 30.0, 1000))))
    1.0
    """
    x = np.asarray(temperature, float)
    mid = len(x) // 2
    parts = [x[:span], x[max(mid - span // 2, 0):mid + span // 2], x[-span:]] if len(x) > 3 * span else [x]
    step = np.abs(np.concatenate([np.diff(p) for p in parts]))
    step = step[step > 0]
    return float(np.percentile(step, 1)) if step.size else 0.0


def check_resolution(step: float, slope: np.ndarray, noise: np.ndarray, sensor: str, where: str) -> None:
    """Refuse a temperature reading whose steps move the compensation by more than the readings' noise.

    Parameters
    ----------
    step : float
        The reading's resolution, C (:func:`resolution`).
    slope : ndarray, shape (3,)
        Largest ``|d bias / dT|`` of each axis over the range, SI per C.
    noise : ndarray, shape (3,)
        Noise of each axis (the typical spread over a short window), SI.
    """
    jump = 0.5 * step * np.asarray(slope)
    worst = int(np.argmax(jump / np.maximum(noise, 1e-300)))
    if jump[worst] > noise[worst]:
        raise InputError(f"the temperature reads in steps of {step:.3g} C, coarser than the fit needs: the {sensor}'s "
                         f"{'xyz'[worst]} bias moves {jump[worst] / noise[worst]:.3g} times its noise over half a step; "
                         "log the temperature at a finer resolution (the sensor's raw temperature register)", where)


def noise_and_motion(data: np.ndarray, rate_hz: float, sensor: str, where: str,
                     factor: float = MOTION_FACTOR) -> np.ndarray:
    """The noise of each axis (median spread over windows of 1 s, at least 16 samples), SI; refuses a recording
    that moves (module docstring).

    Parameters
    ----------
    data : ndarray, shape (n, 3)
        Readings, SI.
    rate_hz : float
    sensor : str
    where : str
    factor : float

    Returns
    -------
    ndarray, shape (3,)
    """
    n = len(data)
    w = int(max(16, round(rate_hz)))
    m = n // w
    if m < 3:
        return np.asarray(data, float).std(axis=0)
    mean, spread = np.empty((m, 3)), np.empty((m, 3))
    step = max(1, (1 << 18) // w)
    for a in range(0, m, step):
        b = min(a + step, m)
        block = np.asarray(data[a * w:b * w], float).T.reshape(3, b - a, w)
        mu = block.mean(axis=2)
        mean[a:b] = mu.T
        spread[a:b] = np.sqrt(np.maximum(np.einsum("ijk,ijk->ij", block, block) / w - mu * mu, 0.0)).T
    noise = np.median(spread, axis=0)
    floor = np.maximum(noise, 1e-12 * np.maximum(np.abs(mean).max(axis=0), 1e-300))
    jumps = np.abs(np.diff(mean, axis=0))
    for what, size in (("varies", spread), ("steps", jumps)):
        ratio = size / floor
        k, axis = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
        if ratio[k, axis] > factor:
            t0 = k * w / rate_hz
            raise InputError(f"the {sensor} {what} {ratio[k, axis]:.3g} times its noise near {t0:.1f} s ({'xyz'[axis]} "
                             "axis): the recording moves; a thermal calibration needs the sensor static in one "
                             "orientation (cut the log to the static part)", where)
    return noise


def check_branches(counts: dict[str, int], needed: int, where: str) -> None:
    """Refuse a heating or cooling branch with fewer than ``needed`` samples (both are needed for hysteresis)."""
    for name, k in counts.items():
        if k < needed:
            raise InputError(f"the {name} branch has {k} samples, too few to fit (at least {needed}); record a "
                             f"longer {name} ramp, or give {{hysteresis=false}} to fit without branches", where)
