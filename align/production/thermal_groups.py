"""Units of a lot grouped by thermal profile: how many groups, which units, one compensation curve per group.

A lot whose units have thermal calibrations (``imu-align calibrate thermal``: :class:`ThermalCalibration` files
named in the table's ``result`` column) often falls into a few families (a supplier's batch, a board revision)
whose bias-versus-temperature curves share a shape. Grouping them lets one curve per family compensate units that
were not all characterised in the chamber.

The method
----------
1. Each unit's static bias curve (:meth:`~align.calibration.thermal.model.ThermalModel.bias`, no lag term) on a common grid of
   :data:`POINTS` temperatures spanning the range every unit's model covers (no extrapolation).
2. Its shape: the curve less its mean over the grid, per axis. The turn-on bias (the curve's level) is each unit's
   own and is not what groups units; a unit compensated with its group's curve keeps its own level.
3. The shapes (3 axes x the grid, per unit) projected on their principal components (at most :data:`MAX_DIMS`, as
   many as explain 99 % of the spread).
4. k-means (k-means++ starts, :data:`RESTARTS` of them, seeded) for k = 1 .. ``max_groups``; the number of groups is
   the k of the least BIC (Schwarz 1978) of the fitted classification model: a Gaussian per group with a shared
   diagonal covariance, ``BIC = -2 log L + p ln n``, ``log L = sum_i log(n_k(i) / n) - n/2 sum_j (ln(2 pi s_j^2) + 1)``,
   ``s_j^2`` the within-group variance of component ``j``, ``p = k d + (k - 1) + d`` (the X-means criterion of
   Pelleg and Moore 2000, with a diagonal covariance). More groups are taken only when they lower the BIC by more
   than :data:`EVIDENCE` below the best fewer groups gave (10: "very strong" evidence, Kass and Raftery 1995, JASA
   90(430) 773-795): the classification likelihood of hard k-means groups favours splitting a small lot. A k with a
   group of fewer than :data:`MIN_MEMBERS` units is not taken.
5. Per group: its members, the mean of their curves on the grid (SI), the polynomial of the members' highest
   order (at most 3) fitted to it by least squares about the reference temperature (the coefficients of a
   compensation curve, ``bias(T) = sum_k c_k (T - tref)^k``), and the RMS of the members' shapes about the group's
   (how well one curve serves them).

Public names
------------
ThermalGroup, ThermalGrouping, group_thermal, thermal_models, lot_groups, POINTS, MAX_DIMS, RESTARTS, MIN_MEMBERS, EVIDENCE
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from align.errors import InputError

if TYPE_CHECKING:
    from align.calibration.thermal.model import ThermalModel

#: temperatures of the common grid
POINTS = 31
#: the most principal components the shapes are clustered in
MAX_DIMS = 5
#: k-means starts per number of groups
RESTARTS = 10
#: the fewest units a group may have
MIN_MEMBERS = 2
#: how much lower a BIC must be for more groups to be taken ("very strong" evidence, Kass and Raftery 1995)
EVIDENCE = 10.0
#: what decides the number of groups, as stated in results
CRITERION = ("least BIC (more groups only when 10 lower) of k-means groups of the curves' shapes (mean over the grid "
             "removed per axis) on their principal components, a Gaussian per group with a shared diagonal covariance")


@dataclass(frozen=True)
class ThermalGroup:
    """One group: ``members`` (serials), their mean bias ``curve`` on the grid (shape (T, 3), SI), the compensation
    polynomial ``coefficients`` (shape (3, K + 1), SI per C^k about ``tref`` C) fitted to it, and ``spread`` (shape
    (3,), SI): the RMS of the members' shapes about the group's, per axis."""

    members: tuple[str, ...]
    curve: np.ndarray
    coefficients: np.ndarray
    tref: float
    spread: np.ndarray

    def bias(self, temperature: np.ndarray) -> np.ndarray:
        """The group's compensation curve (n, 3), SI, at ``temperature`` (C)."""
        d = np.asarray(temperature, float) - self.tref
        return np.column_stack([np.polynomial.polynomial.polyval(d, c) for c in self.coefficients])


@dataclass(frozen=True)
class ThermalGrouping:
    """The lot's thermal groups: ``sensor``, the ``grid`` (C), the ``groups`` (largest first), ``bic`` (k -> BIC,
    NaN where a group would be too small), ``dims`` (principal components used) and the ``criterion``."""

    sensor: str
    grid: np.ndarray
    groups: tuple[ThermalGroup, ...]
    bic: dict
    dims: int
    criterion: str = CRITERION

    @property
    def count(self) -> int:
        return len(self.groups)

    def group_of(self, serial: str) -> int:
        """The index of the group ``serial`` is in."""
        return next(k for k, g in enumerate(self.groups) if serial in g.members)


def _kmeans(x: np.ndarray, k: int, rng: np.random.Generator, iterations: int = 100) -> tuple[np.ndarray, float]:
    """Labels and within-group sum of squares of the best of :data:`RESTARTS` k-means++ runs on ``x`` (n, d)."""
    n = len(x)
    best: tuple[np.ndarray, float] = (np.zeros(n, int), math.inf)
    for _ in range(RESTARTS if k > 1 else 1):
        centres = [x[rng.integers(n)]]
        for _ in range(1, k):
            d2 = np.min(((x[:, None, :] - np.array(centres)[None]) ** 2).sum(-1), axis=1)
            centres.append(x[rng.choice(n, p=d2 / d2.sum())] if d2.sum() > 0 else x[rng.integers(n)])
        c = np.array(centres)
        labels = np.full(n, -1)
        for _ in range(iterations):
            new = np.argmin(((x[:, None, :] - c[None]) ** 2).sum(-1), axis=1)
            if np.array_equal(new, labels):
                break
            labels = new
            c = np.array([x[labels == j].mean(0) if np.any(labels == j) else c[j] for j in range(k)])
        sse = float(((x - c[labels]) ** 2).sum())
        if sse < best[1]:
            best = (labels, sse)
    return best


def _bic(x: np.ndarray, labels: np.ndarray, k: int) -> float:
    """The BIC of the classification model (module docstring, step 4)."""
    n, d = x.shape
    counts = np.bincount(labels, minlength=k)
    if np.any(counts < MIN_MEMBERS):
        return math.nan
    centres = np.array([x[labels == j].mean(0) for j in range(k)])
    var = np.maximum(((x - centres[labels]) ** 2).sum(0) / n, 1e-300)
    log_l = float(np.sum(counts * np.log(counts / n)) - n / 2 * np.sum(np.log(2 * math.pi * var) + 1))
    return -2 * log_l + (k * d + (k - 1) + d) * math.log(n)


def group_thermal(models: Mapping[str, ThermalModel], *, max_groups: int = 6, seed: int = 0) -> ThermalGrouping:
    """Group units by the shape of their thermal bias curves (module docstring).

    Parameters
    ----------
    models : mapping of str -> align.calibration.thermal.model.ThermalModel
        Each unit's (serial's) model of one sensor (:meth:`ThermalCalibration.model`).
    max_groups : int
        The most groups tried (fewer when the lot is small: at most ``n // MIN_MEMBERS``).
    seed : int
        Seed of the k-means starts (``numpy.random.default_rng``): the same lot gives the same groups.

    Returns
    -------
    ThermalGrouping

    Raises
    ------
    InputError
        Fewer than 2 units, models of different sensors, or ranges that do not overlap.

    Examples
    --------
    >>> from align.calibration.thermal.model import AxisModel, ThermalModel
    >>> rng = np.random.default_rng(0)
    >>> def unit(c1, c2):  # a profile (slope, curvature per axis) and each unit's scatter about it
    ...     axes = [AxisModel(np.array([0.0, c1, c2]) + rng.normal(0, [1e-3, 2e-6, 5e-8]), None, np.zeros((3, 3)))
    ...             for _ in range(3)]
    ...     return ThermalModel("gyroscope", 25.0, -10.0, 60.0, tuple(axes))
    >>> lot = {f"A{k}": unit(1e-4, 0.0) for k in range(8)} | {f"B{k}": unit(-1e-4, 2e-6) for k in range(6)}
    >>> g = group_thermal(lot)
    >>> g.count, g.groups[0].members, g.groups[1].members
    (2, ('A0', 'A1', 'A2', 'A3', 'A4', 'A5', 'A6', 'A7'), ('B0', 'B1', 'B2', 'B3', 'B4', 'B5'))
    """
    serials = list(models)
    if len(serials) < 2:
        raise InputError(f"{len(serials)} unit(s) with a thermal model: grouping needs at least 2", "{thermal}")
    ms = [models[s] for s in serials]
    sensors = {m.sensor for m in ms}
    if len(sensors) > 1:
        raise InputError(f"thermal models of several sensors ({', '.join(sorted(sensors))}); group one sensor at a "
                         "time", "{sensor}")
    lo, hi = max(m.tmin for m in ms), min(m.tmax for m in ms)
    if not lo < hi:
        raise InputError(f"the units' thermal ranges have no temperature in common (the highest low end {lo:g} C is "
                         f"above the lowest high end {hi:g} C); group units characterised over one range", "{thermal}")
    grid = np.linspace(lo, hi, POINTS)
    curves = np.array([m.bias(grid)[0] for m in ms])  # (n, T, 3)
    shapes = curves - curves.mean(axis=1, keepdims=True)
    flat = shapes.reshape(len(ms), -1)
    centred = flat - flat.mean(0)
    _, sv, vt = np.linalg.svd(centred, full_matrices=False)
    share = np.cumsum(sv ** 2) / max(float(np.sum(sv ** 2)), 1e-300)
    dims = min(MAX_DIMS, len(ms) - 1, int(np.searchsorted(share, 0.99)) + 1)
    x = centred @ vt[:dims].T
    rng = np.random.default_rng(seed)
    bic, labelled = {}, {}
    for k in range(1, max(1, min(max_groups, len(ms) // MIN_MEMBERS)) + 1):
        labels, _ = _kmeans(x, k, rng)
        bic[k], labelled[k] = _bic(x, labels, k), labels
    k = 1
    for kk in sorted(bic):  # one group more only on very strong evidence (Kass and Raftery 1995: BIC lower by 10)
        if math.isfinite(bic[kk]) and bic[kk] < bic[k] - EVIDENCE:
            k = kk
    labels = labelled[k]
    trefs = {m.tref for m in ms}
    tref = trefs.pop() if len(trefs) == 1 else float((lo + hi) / 2)
    groups = []
    for j in range(k):
        idx = np.flatnonzero(labels == j)
        order = min(3, max(ax.order for i in idx for ax in ms[i].axes))
        mean = curves[idx].mean(0)
        design = np.vander(grid - tref, order + 1, increasing=True)
        coef = np.linalg.lstsq(design, mean, rcond=None)[0].T  # (3, K + 1)
        spread = np.sqrt(np.mean((shapes[idx] - shapes[idx].mean(0)) ** 2, axis=(0, 1)))
        groups.append(ThermalGroup(tuple(serials[i] for i in idx), mean, coef, float(tref), spread))
    groups.sort(key=lambda g: (-len(g.members), g.members))
    return ThermalGrouping(sensors.pop(), grid, tuple(groups), bic, dims)


def thermal_models(rows: Iterable[dict], folder: str | Path, sensor: str) -> dict[str, ThermalModel]:
    """Each unit's thermal model of ``sensor`` from the results its rows name (the table's ``result`` column,
    relative to ``folder``, the table's folder, when not absolute); rows whose result is no thermal calibration
    or holds no such sensor are left out.

    Returns
    -------
    dict of str -> align.calibration.thermal.model.ThermalModel
        By serial (the latest row's result when a serial has several).
    """
    from align.calibration.thermal.result import ThermalCalibration
    from align.results import load_result

    out = {}
    for r in rows:
        name = r.get("result")
        if r.get("status") != "ok" or not name:
            continue
        path = Path(name) if Path(name).is_absolute() else Path(folder) / name
        if not path.is_file() or path.suffix.lower() != ".json":
            continue
        try:
            res = load_result(path)
        except InputError:
            continue
        if isinstance(res, ThermalCalibration) and sensor in res.sensors:
            out[r["serial"]] = res.model(sensor)
    return out


def lot_groups(rows: Iterable[dict], folder: str | Path) -> tuple[ThermalGrouping, ...]:
    """The lot's units grouped by thermal profile, per sensor, when the lot has thermal results (jobs ``calibrate
    thermal``) of at least ``2 MIN_MEMBERS`` units (:func:`group_thermal`); empty otherwise.

    Parameters
    ----------
    rows : iterable of dict
        The lot's latest rows (:func:`align.production.table.latest_rows`).
    folder : str or Path
        The folder the rows' ``result`` paths are relative to (the batch's output folder).
    """
    mine = [r for r in rows if "thermal" in (r.get("job") or "")]
    out = []
    for sensor in ("gyroscope", "accelerometer") if mine else ():
        models = thermal_models(mine, folder, sensor)
        if len(models) >= 2 * MIN_MEMBERS:
            out.append(group_thermal(models))
    return tuple(out)
