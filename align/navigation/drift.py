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

from align.errors import InputError
from align.navigation.closed import QUANTITIES, dominance, dominance_text, static_sigma, term_sigmas
from align.navigation.mission import Mission
from align.navigation.montecarlo import monte_carlo, navigation_step, slow_grid, term_monte_carlo
from align.navigation.residuals import ResidualErrors, label
from align.navigation.result import DriftResult
from align.units import DEG

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


def drift(mission: Mission, errors: ResidualErrors, runs: int = 1000, seed: int = 0, nav_rate: float | None = None,
          points: int = 601, term_runs: int = TERM_RUNS, inputs: dict | None = None, progress=None) -> DriftResult:
    """Attitude, velocity and position error growth of ``mission`` with the residual ``errors``.

    Parameters
    ----------
    mission : Mission
    errors : ResidualErrors
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

    Returns
    -------
    DriftResult

    Raises
    ------
    InputError
        No residual error given.
    """
    if not errors.terms():
        raise InputError("no residual error to propagate: give an Allan result, an alignment or calibration result, "
                         "a budget, a part or a residual bias", "{allan}")
    mc = monte_carlo(mission, errors, runs, seed, nav_rate, points, progress)
    notes = ["quantization noise is left out (its angle and velocity errors stay bounded)",
             "the navigation frame is local level and Earth-fixed without transport rate (seed 002 Eq 2: low speed, "
             "small area): no Schuler feedback, so errors grow as the closed forms' powers of time"]
    closed = None
    if mission.kind == "static":
        steps = int(round(mc.t[-1] * mission.fs / navigation_step(mission.fs, nav_rate)))
        terms = term_sigmas(errors, mc.t, mission.gravity, mission.heading, mission.earth_body,
                            duration=float(mc.t[-1]), points=slow_grid(steps))
        closed = static_sigma(terms, mc.sigma.shape)
        method = "closed forms E1-E4 of each term (align.navigation.closed)"
        if mission.earth_rate:
            notes.append(f"the closed forms leave out the Earth-rate couplings (omega_ie t = "
                         f"{7.292115e-5 * mc.t[-1]:.3g} rad at the end)")
        note = _agreement_note(mc.sigma, closed, runs)
        if note:
            notes.append(note)
    else:
        n = min(runs, term_runs)
        terms = term_monte_carlo(mission, errors, n, seed, nav_rate, points)
        method = f"a Monte Carlo of {n} runs with each error term alone"
    rows = dominance(mc.t, terms)
    final = {label(*k): v[-1] for k, v in terms.items()}
    for key in ("gyroscope", "accelerometer"):
        s = errors.gyro if key == "gyroscope" else errors.accel
        if not s.active():
            notes.append(f"no {key} error given: its errors are taken as zero")
    info = dict(inputs or {})
    info.setdefault("initial_heading_deg", mission.heading / DEG)
    return DriftResult(mission.to_dict(), errors, mc.t, mc.mean, mc.sigma, closed, final, tuple(rows),
                       dominance_text(rows), method, runs, seed, mc.nav_rate, info, tuple(notes))
