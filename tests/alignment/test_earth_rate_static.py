"""Earth's rate in the static periods is a constant, not a bias drift (issue 23).

An independent rate-table simulation (numpy + scipy.spatial.transform; not :mod:`align.alignment.simulate`):
the fixture is re-mounted before each step so that the step's axis points along the table axis, at a random
heading; the table turns through a trapezoid (ramps, dwell); the static gap before a step is in that step's
orientation, the last one in the orientation the table stopped at. The gyros read
``g = M (w_table + C(t)^T Omega_L) + b + noise`` with a constant bias (no drift at all) and Earth's rate
``Omega_L = Omega (0, cos L, sin L)`` (ENU) at latitude ``L``.

* Vertical table axis, no latitude in the plan: the static periods see Earth's rate in several orientations.
  Before, the drift fit read that as a random walk (about 75 deg/h/sqrt(h)) and ``M`` came out 5.7x worse than
  the same dwells give with the true bias; now within 3x of that, with honest sigmas.
* Horizontal (east) table axis, latitude stated, unequal +/- rates: the bias is compared with what the dwell
  pairs alone give (each gyro from the pair about its own axis) and must be honest.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from align.alignment.job import AlignOptions, align
from align.alignment.plan import Plan, Step
from align.model import SensorModel
from align.units import DEG, DEG_H

FS = 100.0
#: the vertical case: 3 whole turns a step (ramps included), so that the horizontal Earth rate averages out
DWELL = 10.3
OMEGA = 7.2921150e-5
ENU_DIRECTIONS = {"up": (0.0, 0.0, 1.0), "east": (1.0, 0.0, 0.0)}


def _truth(rng: np.random.Generator) -> SensorModel:
    small = Rotation.from_rotvec(rng.normal(0, 0.6 * DEG, 3)).as_matrix().T
    return SensorModel(small * (1 + rng.normal(0, 3e-3, 3))[:, None], rng.normal(0, 0.5 * DEG, 3))


def _trapezoid(rate: float, dwell: float, accel: float = 200 * DEG) -> np.ndarray:
    ramp = np.arange(1, int(np.ceil(abs(rate) / accel * FS)) + 1) / (abs(rate) / accel * FS)
    ramp = np.minimum(ramp, 1.0)
    return rate * np.concatenate([ramp, np.ones(int(dwell * FS)), ramp[::-1]])


def _session(steps: list[tuple[int, float]], table: str, latitude: float, seed: int, noise: float,
             dwell: float, static: float):
    """Time, gyro readings and the true model of a drift-free session (see the module docstring)."""
    rng = np.random.default_rng(seed)
    model = _truth(rng)
    spin = np.array(ENU_DIRECTIONS[table])
    earth = OMEGA * np.array([0.0, np.cos(latitude), np.sin(latitude)])
    rates, att = [], []
    c = None
    for axis, rate in steps:
        u = np.eye(3)[axis]
        mount = Rotation.align_vectors([spin], [u])[0]  # the step's axis onto the table axis
        c = Rotation.from_rotvec(spin * rng.uniform(0, 2 * np.pi)) * mount  # system -> ENU, random heading
        profile = _trapezoid(rate, dwell)
        angle = np.cumsum(profile) / FS
        rates.append(np.zeros(int(static * FS)))
        att.append(Rotation.concatenate([c] * int(static * FS)))
        rates.append(profile)
        att.append(Rotation.from_rotvec(np.outer(angle, spin)) * c)
        c = att[-1][-1]
    rates.append(np.zeros(int(static * FS)))
    att.append(Rotation.concatenate([c] * int(static * FS)))
    rate, att = np.concatenate(rates), Rotation.concatenate(att)
    # body rate: the table's spin (along the step's axis in the system frame) plus Earth's, both via C^T
    w = att.inv().apply(np.outer(rate, spin) + earth)
    g = w @ model.M.T + model.bias + rng.normal(0, noise * np.sqrt(FS), w.shape)
    return np.arange(len(rate)) / FS, g, model


def _dwells(result):
    return [s for s in result.segments if s.kind == "rate"]


def _vertical_case(seed: int):
    plan = Plan.standard_rate(100 * DEG)
    t, g, model = _session([(s.axis, s.rate) for s in plan.steps], "up", 45 * DEG, seed, 0.0002 * DEG, DWELL, 30.0)
    r = align(t, g, plan, AlignOptions(method="lsq"))
    best = np.zeros((3, 3))  # the same dwells with the true bias: each column by least squares over its +/- pair
    for a in range(3):
        pairs = [(st.rate, g[s.start:s.end].mean(axis=0) - model.bias) for s, st in zip(_dwells(r), plan.steps)
                 if st.axis == a]
        w, y = np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])
        best[:, a] = w @ y / (w @ w)
    walk = float(next(n for n in r.notes if "random walk" in n).split("random walk ")[1].split()[0])
    return np.abs(r.M - model.M).max(), np.abs(best - model.M).max(), np.abs((r.M - model.M) / r.sigma_M).max(), walk


def _check_vertical(seeds) -> None:
    got = np.array([_vertical_case(s) for s in seeds])
    ratio = np.sqrt(np.mean(got[:, 0] ** 2) / np.mean(got[:, 1] ** 2))
    assert ratio < 3.0, ratio  # measured 1.00 over 12 seeds (5.7 before)
    assert np.mean(got[:, 2] < 3) >= 0.9 and got[:, 2].max() < 4.5, got[:, 2]  # honest sigmas
    assert np.median(got[:, 3]) < 5.0, got[:, 3]  # no false random walk (75 deg/h/sqrt(h) before)


def test_no_latitude_earth_rate_is_not_read_as_drift():
    _check_vertical(range(3))


@pytest.mark.slow
def test_no_latitude_earth_rate_is_not_read_as_drift_many_seeds():
    _check_vertical(range(3, 23))


def _east_case(seed: int):
    lat = 45 * DEG
    rates = [(0, 40 * DEG), (0, -100 * DEG), (1, -60 * DEG), (1, 150 * DEG), (2, 30 * DEG), (2, -90 * DEG)]
    plan = Plan(tuple(Step(a, 1, rate=w, table_axis="east") for a, w in rates), latitude=lat, table_axis="east")
    t, g, model = _session(rates, "east", lat, seed, 0.0002 * DEG, 20.0, 10.0)
    r = align(t, g, plan, AlignOptions(method="lsq"))
    along = OMEGA * np.array([0.0, np.cos(lat), np.sin(lat)]) @ np.array(ENU_DIRECTIONS["east"])
    pair = np.zeros(3)  # each gyro's bias from the +/- pair about its own axis (no Earth across it)
    for a in range(3):
        (s1, (_, w1)), (s2, (_, w2)) = [(s, st) for s, st in zip(_dwells(r), rates) if st[0] == a]
        y1, y2 = g[s1.start:s1.end].mean(axis=0), g[s2.start:s2.end].mean(axis=0)
        w1, w2 = w1 + along, w2 + along
        pair[a] = ((y1 * w2 - y2 * w1) / (w2 - w1))[a]
    return np.abs(r.bias - model.bias).max(), np.abs(pair - model.bias).max(), \
        np.abs((r.bias - model.bias) / r.sigma_bias).max()


def test_horizontal_axis_bias_uses_what_the_dwells_hold():
    got = np.array([_east_case(s) for s in range(4)])
    assert np.sqrt(np.mean(got[:, 0] ** 2)) < 1.5 * np.sqrt(np.mean(got[:, 1] ** 2)), got
    assert got[:, 0].max() < 0.5 * DEG_H  # against a 1 deg/h goal (1.07 deg/h before in the issue)
    assert got[:, 2].max() < 3.5, got[:, 2]
