"""The drift analysis: a mission, its residual errors, the Monte Carlo, the closed forms, and which error dominates.

:func:`drift` runs the Monte Carlo of :mod:`align.navigation.montecarlo` and, for a static
mission, the closed forms of :mod:`align.navigation.closed` on the same times (with the same
flicker lines); which error dominates when comes from the closed forms' terms (static), or from a
one-term Monte Carlo of each error term (any other mission). It returns the registered
:class:`~align.navigation.result.DriftResult`.

Public names
------------
drift, TERM_RUNS
"""

from __future__ import annotations

import numpy as np

from align.earth import EARTH_RATE
from align.errors import InputError
from align.navigation.closed import (
    QUANTITIES,
    SYNTHESIS_SPAN,
    dominance,
    dominance_text,
    static_sigma,
    term_sigmas,
)
from align.navigation.mission import Mission
from align.navigation.montecarlo import KEEP, NAV_RATE, monte_carlo, navigation_step, slow_grid, term_monte_carlo
from align.navigation.residuals import ResidualErrors, label
from align.navigation.result import DriftResult
from align.units import DEG

#: the largest flicker span (mission lengths) the synthesis takes
MAX_FLICKER_SPAN = 256

#: runs of each one-term Monte Carlo (at most the main one's)
TERM_RUNS = 200
#: a closed-form 1-sigma further than this from the Monte Carlo's at the end is stated in the notes
AGREEMENT = 0.1


def _agreement_note(sigma: np.ndarray, closed: np.ndarray, runs: int) -> str | None:
    """Where the first-order closed forms and the Monte Carlo part at the end (second-order effects)."""
    end_mc, end_cf = sigma[-1], closed[-1]
    live = end_cf > 0
    ratio = np.where(live, end_mc / np.where(live, end_cf, 1.0), 1.0)
    off = [f"{QUANTITIES[i]} {ratio[i]:.2f}" for i in range(9) if live[i] and abs(ratio[i] - 1) > AGREEMENT]
    if not off:
        return None
    return (f"Monte Carlo / closed-form 1-sigma at the end: {', '.join(off)} (sampling error of {runs} runs: "
            f"{1 / np.sqrt(2 * (runs - 1)):.1%}); the closed forms are first order: the difference is what they leave "
            "out (the vertical channel's g eps^2 / 2 of a large tilt error, the Earth-rate couplings)")


def _rate_note(fs: float, nav_rate: float | None, used: float) -> str | None:
    """Say where the navigation rate used is not the one asked for (capped at the sample rate, or rounded)."""
    asked = NAV_RATE if nav_rate is None else float(nav_rate)
    if asked > fs * (1 + 1e-9):
        return (f"navigation rate {asked:g} Hz is above the sample rate: navigating at every sample, {used:g} Hz "
                "(the navigation rate is at most the sample rate)")
    if abs(used - asked) > 1e-9 * asked:
        return (f"navigation at {used:g} Hz, not {asked:g} Hz: a step is a whole number of samples "
                f"({round(fs / used)} at {fs:g} Hz)")
    return None


def _error_notes(mission: Mission, errors: ResidualErrors, span: int) -> list[str]:
    """What the error model assumes, for the terms present: flicker cutoff, mounting rotation, misalignment."""
    notes = []
    if any(np.any(s.flicker > 0) for s in (errors.gyro, errors.accel)):
        notes.append(f"bias instability: flicker of PSD B^2 / (pi f) from {1 / (span * mission.duration):.3g} Hz "
                     f"(1 / ({span} T), flicker span {span} mission lengths) up: slower wander is left out (it is the turn-on "
                     "bias's); the flicker's angle variance grows as ln of that span")
    if np.any(errors.mount > 0):
        notes.append("IMU mounting rotation (mount error: attitude): the whole IMU, gyros and accelerometers, turned "
                     "relative to the vehicle whose attitude starts the navigation: an initial attitude error, drawn "
                     "per run as a zero-mean Gaussian rotation whose rms axis misalignments are the budget's per-axis "
                     "RSS (1-sigma per axis in the errors' source); the attitude errors are the IMU's (the vehicle's "
                     "attitude read from it "
                     "is off by the same rotation in the body frame); a tilt puts g eps into the horizontal channels "
                     "from t = 0")
    if np.any(errors.gyro.tilt > 0):
        still = mission.kind == "static" and not mission.earth_rate
        notes.append("gyro mounting misalignment (mount error: turns): the initial attitude aligned in place by the "
                     "IMU, the budget's per-axis RSS as the gyro axes' rms misalignment relative to that frame (a zero-mean "
                     "Gaussian lean in a random direction per run): it acts only "
                     "through the body's turns (and the Earth rate)"
                     + ("; this static mission without the Earth rate costs nothing from it: give a manoeuvre or a "
                        "recorded trajectory, or take the mount error as an initial attitude error" if still else ""))
    return notes


def drift(mission: Mission, errors: ResidualErrors, runs: int = 1000, seed: int = 0, nav_rate: float | None = None,
          points: int = 601, term_runs: int = TERM_RUNS, inputs: dict | None = None, progress=None,
          flicker_span: int = SYNTHESIS_SPAN) -> DriftResult:
    """Attitude, velocity and position error growth of ``mission`` with the residual ``errors``.

    Parameters
    ----------
    mission : Mission
        True rates (n, 3), rad/s, and specific force (n, 3), m/s^2, at ``mission.fs`` Hz.
    errors : ResidualErrors
        1-sigma residual errors, SI (:func:`~align.navigation.residuals.residual_errors`).
    runs : int
        Monte Carlo runs (>= 2).
    seed : int
    nav_rate : float, optional
        Navigation update rate, Hz (:func:`align.navigation.montecarlo.navigation_step`).
    points : int
        Times kept.
    term_runs : int
        Runs of each one-term Monte Carlo for a non-static mission.
    inputs : dict, optional
        The files and figures the analysis came from, kept in the result.
    progress : callable, optional
        Called with the number of main runs done.
    flicker_span : int
        Flicker is synthesised down to ``1 / (flicker_span T)`` (:func:`align.navigation.closed.flicker_lines`).

    Returns
    -------
    DriftResult
        ``t`` (P,), s; ``mean``, ``sigma`` and, for a static mission, ``closed`` (P, 9): attitude (rad),
        velocity (m/s) and position (m) errors in :data:`~align.navigation.closed.QUANTITIES` order.

    Raises
    ------
    InputError
        No residual error given; a flicker span out of range.

    Examples
    --------
    A level body at rest for 60 s with a 10 deg/h gyro turn-on bias: the heading error grows as
    ``b t``, 1/6 deg at the end (the closed form, column ``heading`` of :data:`~align.navigation.closed.QUANTITIES`).

    >>> from align.navigation.closed import QUANTITIES
    >>> from align.navigation.mission import static_mission
    >>> from align.navigation.residuals import residual_errors
    >>> from align.units import DEG, DEG_H
    >>> res = drift(static_mission(60.0, 10.0), residual_errors(gyro_bias=10 * DEG_H), runs=10, points=31)
    >>> res.t.shape, round(float(res.closed[-1, QUANTITIES.index("heading")] / DEG), 4)
    ((31,), 0.1667)
    """
    if not errors.terms():
        raise InputError("no residual error to propagate: give at least one of {allan}, {alignment}, {budget}, "
                         "{imu}, {gyro_bias}, {accel_bias}")
    if not (isinstance(flicker_span, (int, np.integer)) and 2 <= flicker_span <= MAX_FLICKER_SPAN):
        raise InputError(f"the flicker span must be a whole number of mission lengths from 2 to {MAX_FLICKER_SPAN}",
                         "{flicker_span}")
    mc = monte_carlo(mission, errors, runs, seed, nav_rate, points, progress, flicker_span)
    notes = ["quantization noise is left out (its angle and velocity errors stay bounded)",
             "the navigation frame is local level and Earth-fixed without transport rate (seed 002 Eq 2: low speed, "
             "small area): no Schuler feedback, so errors grow as the closed forms' powers of time",
             f"down velocity and position: their second-order part g eps^2 / 2 (eps the tilt error) is one-signed, so "
             f"mean -/+ 3 sigma is no 99.7 % bound there: the picture draws the percentiles of the first "
             f"{min(runs, KEEP):,} runs for them (the file's down 'percentiles')"]
    notes += _error_notes(mission, errors, flicker_span)
    rate = _rate_note(mission.fs, nav_rate, mc.nav_rate)
    if rate:
        notes.append(rate)
    closed = None
    if mission.kind == "static":
        steps = int(round(mc.t[-1] * mission.fs / navigation_step(mission.fs, nav_rate)))
        terms = term_sigmas(errors, mc.t, mission.gravity, mission.heading, mission.earth_body,
                            duration=float(mc.t[-1]), points=slow_grid(steps), span=flicker_span)
        closed = static_sigma(terms, mc.sigma.shape)
        method = "closed forms E1-E4 of each term (align.navigation.closed)"
        if mission.earth_rate:
            notes.append(f"the closed forms leave out the Earth-rate couplings (omega_ie t = "
                         f"{EARTH_RATE * mc.t[-1]:.3g} rad at the end)")
        note = _agreement_note(mc.sigma, closed, runs)
        if note:
            notes.append(note)
    else:
        n = min(runs, term_runs)
        terms = term_monte_carlo(mission, errors, n, seed, nav_rate, points, flicker_span)
        method = f"a Monte Carlo of {n} runs with each error term alone"
    rows = dominance(mc.t, terms)
    if not rows:
        notes.append("no error term grows on this mission: every component stays zero (see the notes above)")
    final = {label(*k): v[-1] for k, v in terms.items()}
    for key in ("gyroscope", "accelerometer"):
        s = errors.gyro if key == "gyroscope" else errors.accel
        if not s.active():
            notes.append(f"no {key} error given: its errors are taken as zero")
    info = dict(inputs or {})
    info.setdefault("initial_heading_deg", mission.heading / DEG)
    info.setdefault("flicker_span", flicker_span)
    return DriftResult(mission.to_dict(), errors, mc.t, mc.mean, mc.sigma, closed, final, tuple(rows),
                       dominance_text(rows), method, runs, seed, mc.nav_rate, info, tuple(notes), mc.down_percentiles)
