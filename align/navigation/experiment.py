"""Seed 002's experiment: static records simulated by methods A, B and statistics restoring, navigated against a real one.

The seed (section 3.1) measures an IMU's figures on static data, simulates static records from
them by three error models, navigates every record from the same initial state, and compares the
simulated drifts with the real one::

    d     = d_real - d_sim                                  (its Eq 19), over time
    e_abs = max |d_real - d_sim|                            (Eq 20)
    e_rel = e_abs / |d_real(end)| x 100 %                   (Eq 21)

for the east and north position and the heading, each the mean over 5 repetitions (its Table 2;
it finds statistics restoring smallest in all six). The figures (:func:`seed_figures`), from one
run cut into ``M`` segments standing for the seed's ``M`` calibrations: bias ``B`` (Eq 5-6), bias
stability ``B_s`` over ``P`` = 1 s (Eq 7-8), repeatability ``B_r`` (Eq 9), and from the Allan fit
of the whole run the angle (velocity) random walk ``N`` and the bias instability. The three
models are :func:`align.noise.sim.seed_method_a` (Eq 12), :func:`~align.noise.sim.seed_method_b`
(Eq 13) and :func:`~align.noise.sim.seed_restoring` (Eq 14-18), on each of the six channels with
a zero true signal (the bias is the mean reading: gravity included for the accelerometers).

Public names
------------
SeedFigures, seed_figures, seed_experiment, Experiment, METHODS, table_rows
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np

from align.errors import InputError
from align.navigation.strapdown import IDENTITY, navigate
from align.noise.fit import noise_figures
from align.noise.sim import seed_method_a, seed_method_b, seed_restoring
from align.units import DEG, STANDARD_GRAVITY
from align.values import Value

#: the three error models, in the seed's order
METHODS = ("method A", "method B", "statistics restoring")
#: the compared outputs (Eq 19-21)
OUTPUTS = ("east position", "north position", "heading")


@dataclass(frozen=True, eq=False)
class SeedFigures(Value):
    """Seed 002's figures of six channels (gyro x, y, z in rad/s; accelerometer x, y, z in m/s^2), each (6,).

    Attributes
    ----------
    bias, stability, repeatability : ndarray
        Eq 5-6, Eq 7-8 (over ``period``), Eq 9, from ``segments`` segments of ``segment_s``.
    white : ndarray
        Angle / velocity random walk ``N`` (rad/sqrt(s), m/s/sqrt(s)), Allan fit of the whole run.
    instability : ndarray
        Bias instability ``B`` (rad/s, m/s^2), Allan fit of the whole run.
    period, segment_s : float
        s.
    segments : int
    """

    bias: np.ndarray
    stability: np.ndarray
    repeatability: np.ndarray
    white: np.ndarray
    instability: np.ndarray
    period: float
    segment_s: float
    segments: int


def seed_figures(gyro: np.ndarray, accel: np.ndarray, fs: float, segment_s: float, period: float = 1.0) -> SeedFigures:
    """The figures of one static run (rad/s, m/s^2, shape (n, 3) each) (module docstring).

    Raises
    ------
    InputError
        Fewer than two segments of ``segment_s`` in the run.
    """
    from align.noise.job import run_allan

    data = np.hstack([np.asarray(gyro, float), np.asarray(accel, float)])
    k = int(round(segment_s * fs))
    m = len(data) // k if k > 0 else 0
    if m < 2:
        raise InputError(f"the run holds {len(data) / fs:.4g} s: fewer than two segments of {segment_s:g} s", "{segment}")
    figs = [[noise_figures(seg[:, c], fs, (period,)) for c in range(6)] for seg in data[: m * k].reshape(m, k, 6)]
    b_m = np.array([[f["bias"] for f in row] for row in figs])  # (M, 6)
    s_m = np.array([[f["stability"][period] for f in row] for row in figs])
    fits = [run_allan([data[:, :3]], fs, ["x", "y", "z"], "rad/s").fits,
            run_allan([data[:, 3:]], fs, ["x", "y", "z"], "m/s^2").fits]
    params = np.array([f.params for sensor in fits for f in sensor])  # (6, 5): Q, N, B, K, R
    return SeedFigures(b_m.mean(axis=0), s_m.mean(axis=0), b_m.std(axis=0, ddof=1), params[:, 1], params[:, 2],
                       float(period), float(segment_s), int(m))


def _simulate(method: str, fig: SeedFigures, n: int, fs: float, rng: np.random.Generator) -> np.ndarray:
    """One simulated static record (n, 6) of ``method`` (a zero true signal: the bias is the mean reading)."""
    zero = np.zeros(n)
    out = np.empty((n, 6))
    for c in range(6):
        if method == METHODS[0]:
            out[:, c] = seed_method_a(zero, fs, fig.bias[c], fig.stability[c], fig.period, fig.white[c], rng)
        elif method == METHODS[1]:
            out[:, c] = seed_method_b(zero, fs, fig.bias[c], fig.instability[c], fig.white[c], rng)
        else:
            out[:, c] = seed_restoring(zero, fs, fig.bias[c], fig.repeatability[c], fig.stability[c], fig.period,
                                       fig.white[c], rng)
    return out


def _drift(record: np.ndarray, fs: float, gravity: float) -> np.ndarray:
    """East, north position (m) and heading (rad) over time (n, 3) of a static record navigated from rest, level."""
    tr = navigate(record[:, :3], record[:, 3:], 1.0 / fs, IDENTITY, gravity=gravity)
    return np.column_stack([tr.p[:, 1], tr.p[:, 0], np.unwrap(tr.euler[:, 2])])


def _entry(table: Callable[[str], np.ndarray], k: int, method: str) -> float:
    """Element ``k`` of ``table(method)``: a sort key of :meth:`Experiment.ranking`."""
    return table(method)[k]


@dataclass(frozen=True, eq=False)
class Experiment(Value):
    """The experiment's numbers and drifts.

    Attributes
    ----------
    t : ndarray, shape (n,)
        s.
    real : ndarray, shape (n, 3)
        East, north (m) and heading (rad) of the real record.
    sims : dict
        Method -> ndarray (repetitions, n, 3): the simulated drifts.
    e_abs, e_rel : dict
        Method -> ndarray (repetitions, 3): Eq 20 (m, m, rad) and Eq 21 (%) for east, north, heading.
    figures : SeedFigures
    """

    t: np.ndarray
    real: np.ndarray
    sims: dict
    e_abs: dict
    e_rel: dict
    figures: SeedFigures

    def mean_abs(self, method: str) -> np.ndarray:
        """Eq 20 averaged over the repetitions (3,): m, m, rad."""
        return self.e_abs[method].mean(axis=0)

    def mean_rel(self, method: str) -> np.ndarray:
        """Eq 21 averaged over the repetitions (3,), %."""
        return self.e_rel[method].mean(axis=0)

    def ranking(self) -> list[list[str]]:
        """For each of the six rows of Table 2 (abs/rel of east, north, heading), the methods from best to worst."""
        rows = []
        for k in range(3):
            for table in (self.mean_abs, self.mean_rel):
                rows.append(sorted(METHODS, key=partial(_entry, table, k)))
        return rows


def seed_experiment(gyro: np.ndarray, accel: np.ndarray, fs: float, figures: SeedFigures, repetitions: int = 5,
                    seed: int = 0, gravity: float = STANDARD_GRAVITY) -> Experiment:
    """Navigate the real static record (rad/s, m/s^2, (n, 3)) and ``repetitions`` records of each method (Eq 19-21).

    Every record starts at rest, level, heading north, at the origin (the seed's initial state),
    with gravity ``gravity`` down; the Earth rate is left out (the seed neglects it indoors).
    """
    real_rec = np.hstack([np.asarray(gyro, float), np.asarray(accel, float)])
    n = len(real_rec)
    real = _drift(real_rec, fs, gravity)
    rng = np.random.default_rng(seed)
    sims, e_abs, e_rel = {}, {}, {}
    end = np.abs(real[-1])
    for method in METHODS:
        runs = np.stack([_drift(_simulate(method, figures, n, fs, rng), fs, gravity) for _ in range(repetitions)])
        d = real[None] - runs  # Eq 19
        sims[method] = runs
        e_abs[method] = np.abs(d).max(axis=1)  # Eq 20
        e_rel[method] = e_abs[method] / np.where(end > 0, end, np.nan) * 100.0  # Eq 21
    return Experiment(np.arange(n) / fs, real, sims, e_abs, e_rel, figures)


def table_rows(exp: Experiment) -> list[list[str]]:
    """Table 2 of the seed: the six rows, each method's mean over the repetitions (and their spread, 1 sigma)."""
    rows = []
    units = ("m", "m", "deg")
    scale = (1.0, 1.0, 1.0 / DEG)
    for k, (name, unit) in enumerate(zip(OUTPUTS, units)):
        for kind, values, u, f in (("absolute", exp.e_abs, unit, scale[k]), ("relative", exp.e_rel, "%", 1.0)):
            cells = [f"largest {kind} {name} error ({u})"]
            for method in METHODS:
                v = values[method][:, k] * f
                cells.append(f"{v.mean():.4g} +/- {v.std(ddof=1):.2g}" if len(v) > 1 else f"{v.mean():.4g}")
            rows.append(cells)
    return rows
