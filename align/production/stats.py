"""Statistics of a lot against its spec: spread, capability, yield, outliers, trend, control limits.

For each figure (and sensor) over the units that gave it:

* count, mean, standard deviation (``ddof = 1``), min, max, median;
* process capability ``Cpk = min(USL - mean, mean - LSL) / (3 s)`` (one-sided: the side with a limit),
  with its standard error ``sqrt(1/(9n) + Cpk^2/(2(n-1)))`` (Bissell 1990);
* the figure's yield: the fraction of units within its limit, with its binomial standard error;
* outliers by the robust z-score ``z = 0.6745 (x - median) / MAD`` (Iglewicz and Hoaglin), ``|z| > 3.5``;
* the trend: least-squares slope of the figure over the lot's order (per unit) or time (per day),
  with its standard error ``s_res / sqrt(sum (x - mean x)^2)``;
* an individuals control chart: centre the mean, limits ``mean -/+ 3 MR/1.128`` (``MR`` the mean moving
  range in lot order), and the units outside them.

A unit passes when it ran (status ok) and every figure it gave lies within every limit that applies
to it (a figure its job does not give, or an Allan term its record could not identify, is not judged);
the lot's yield is the units passing over all units, those that failed or errored included.

Public names
------------
FigureStats, UnitVerdict, LotStats, lot_statistics, figures_needed, judge_rows, rejudge_rows, cpk, robust_z, trend,
OUTLIER_Z, KEY_FIGURES
"""

from __future__ import annotations

import fnmatch
import math
from dataclasses import dataclass

import numpy as np

from align.production.figures import FIGURES, shown_unit
from align.production.spec import Limit, Spec
from align.units import to_unit

#: the robust z-score beyond which a unit is an outlier (Iglewicz and Hoaglin)
OUTLIER_Z = 3.5
#: figures described when no spec names any
KEY_FIGURES = ("scale_*", "phi_*", "delta_*", "bias_?", "arw_*", "bi_*", "rrw_*", "field", "coverage", "heading_error")


def cpk(values: np.ndarray, low: float | None, high: float | None) -> tuple[float, float]:
    """``(Cpk, its standard error)`` of ``values`` against ``low``/``high`` (None: open); NaN for fewer than 2."""
    x = np.asarray(values, float)
    n = len(x)
    if n < 2 or (low is None and high is None):
        return math.nan, math.nan
    m, s = float(np.mean(x)), float(np.std(x, ddof=1))
    sides = [(high - m) if high is not None else math.inf, (m - low) if low is not None else math.inf]
    if s == 0:
        return (math.inf if min(sides) > 0 else -math.inf), math.nan
    c = min(sides) / (3 * s)
    return c, math.sqrt(1 / (9 * n) + c * c / (2 * (n - 1)))


def robust_z(values: np.ndarray) -> np.ndarray:
    """``0.6745 (x - median) / MAD`` (``MAD = 0``: the mean absolute deviation times 1.2533 instead; both 0: zeros)."""
    x = np.asarray(values, float)
    if not len(x):
        return x
    med = np.median(x)
    mad = np.median(np.abs(x - med))
    if mad > 0:
        return 0.6745 * (x - med) / mad
    mean_ad = np.mean(np.abs(x - med))
    return (x - med) / (1.2533 * mean_ad) if mean_ad > 0 else np.zeros_like(x)


def trend(x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """``(slope, its standard error)`` of the least-squares line ``y = a + b x``; NaN for fewer than 3 points."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) < 3 or np.ptp(x) == 0:
        return math.nan, math.nan
    xc = x - x.mean()
    sxx = float(xc @ xc)
    b = float(xc @ (y - y.mean())) / sxx
    res = y - y.mean() - b * xc
    return b, math.sqrt(float(res @ res) / (len(x) - 2) / sxx)


@dataclass(frozen=True)
class FigureStats:
    """One figure of one sensor over the lot (SI; ``unit`` is the one it is shown in).

    ``serials``, ``x`` (lot order or days) and ``values`` are the units that gave it, in lot order;
    ``outliers`` and ``out_of_control`` name serials.
    """

    figure: str
    sensor: str
    limit: Limit | None
    unit: str
    serials: tuple
    x: np.ndarray
    values: np.ndarray
    mean: float
    std: float
    minimum: float
    maximum: float
    median: float
    cpk: float
    cpk_sigma: float
    passed: int
    outliers: tuple
    slope: float
    slope_sigma: float
    centre: float
    lcl: float
    ucl: float
    out_of_control: tuple

    @property
    def n(self) -> int:
        return len(self.values)

    @property
    def yield_(self) -> float:
        """Fraction of the units that gave the figure within its limit (NaN without one)."""
        return self.passed / self.n if self.limit is not None and self.n else math.nan

    def shown(self, value: float) -> float:
        """An SI value of this figure in :attr:`unit`."""
        return float(to_unit(value, self.unit)) if self.unit != "1" else float(value)


@dataclass(frozen=True)
class UnitVerdict:
    """A unit of the lot: ``verdict`` ``"pass"``, ``"fail"`` (outside a limit), ``"failed"`` (its job refused
    it) or ``"error"``; ``reasons`` the limits it broke (``phi_xy = 0.31 deg: |phi_xy| <= 0.1 deg``) or its message."""

    serial: str
    job: str
    order: int
    verdict: str
    reasons: tuple


@dataclass(frozen=True)
class LotStats:
    """The lot: its figures' statistics, its units (failing first, then in lot order) and its yield."""

    figures: tuple
    units: tuple
    trend_by: str
    spec: Spec | None

    @property
    def count(self) -> int:
        return len(self.units)

    @property
    def passed(self) -> int:
        return sum(u.verdict == "pass" for u in self.units)

    @property
    def yield_(self) -> float:
        return self.passed / self.count if self.count else math.nan

    @property
    def yield_sigma(self) -> float:
        p, n = self.yield_, self.count
        return math.sqrt(p * (1 - p) / n) if n else math.nan


def _violations(row: dict, spec: Spec | None) -> list[str]:
    out = []
    if spec is None:
        return out
    for lim in spec.limits:
        v = row.get(lim.figure)
        if lim.applies(row.get("sensor")) and isinstance(v, float) and math.isfinite(v) and not lim.ok(v):
            u = "" if lim.unit == "1" else f" {lim.unit}"
            out.append(f"{lim.figure} = {_beside(lim.shown(v), lim)}{u}, outside {lim.describe()}")
    return out


def _beside(value: float, lim: Limit) -> str:
    """``value`` to 4 significant digits, or as many more as tell it from the limit it broke (0.996998, not 0.997)."""
    bounds = [f"{lim.shown(b):g}" for b in (lim.low, lim.high) if b is not None]
    for digits in range(4, 12):
        text = f"{value:.{digits}g}"
        if text not in bounds:
            return text
    return repr(value)


def judge_rows(rows: list[dict], spec: Spec | None) -> list[dict]:
    """A unit's rows with ``verdict`` ``"fail"`` and the broken limits as ``message`` when a figure is outside ``spec``."""
    if spec is None:
        return rows
    out = []
    for r in rows:
        broken = _violations(r, spec) if r.get("status") == "ok" else []
        out.append({**r, "verdict": "fail", "message": "outside the spec: " + "; ".join(broken)} if broken else r)
    return out


def rejudge_rows(rows: list[dict], spec: Spec | None) -> list[dict]:
    """Rows judged before (a previous run's, against its spec) judged again against ``spec``."""
    fresh = []
    for r in rows:
        if r.get("verdict") == "fail":
            r = {**r, "verdict": "warn" if ": warn" in (r.get("checks") or "") else "pass",
                 "message": "" if (r.get("message") or "").startswith("outside the spec") else r.get("message")}
        fresh.append(r)
    return judge_rows(fresh, spec)


def _figure_names(rows: list[dict], spec: Spec | None) -> list[tuple[str, str]]:
    """(figure, sensor) pairs to describe: those the spec limits, else the key figures the rows give."""
    sensors = sorted({r["sensor"] for r in rows if r.get("sensor")})
    if spec is not None:
        pairs = []
        for lim in spec.limits:
            for s in sensors if lim.sensor == "" else [lim.sensor]:
                if (lim.figure, s) not in pairs:
                    pairs.append((lim.figure, s))
        return pairs
    names = [f for f in FIGURES if any(fnmatch.fnmatchcase(f, p) for p in KEY_FIGURES)]
    return [(f, s) for s in sensors for f in names]


def _figure(rows: list[dict], figure: str, sensor: str, spec: Spec | None, xs: dict) -> FigureStats | None:
    got = [(r["serial"], xs[id(r)], r[figure]) for r in rows
           if r.get("status") == "ok" and r.get("sensor") == sensor and isinstance(r.get(figure), float)
           and math.isfinite(r[figure])]
    if not got:
        return None
    serials = tuple(g[0] for g in got)
    x, v = np.array([g[1] for g in got], float), np.array([g[2] for g in got], float)
    limits = spec.limits_for(figure, sensor) if spec is not None else []
    lim = limits[0] if limits else None
    c, cs = cpk(v, lim.low, lim.high) if lim else (math.nan, math.nan)
    z = robust_z(v)
    slope, slope_s = trend(x, v)
    order = np.argsort(x, kind="stable")
    mr = np.abs(np.diff(v[order]))
    sigma = float(np.mean(mr)) / 1.128 if len(mr) else math.nan
    mean = float(np.mean(v))
    lcl, ucl = mean - 3 * sigma, mean + 3 * sigma
    return FigureStats(figure, sensor, lim, lim.unit if lim else shown_unit(figure, sensor), serials, x, v, mean,
                       float(np.std(v, ddof=1)) if len(v) > 1 else math.nan, float(v.min()), float(v.max()),
                       float(np.median(v)), c, cs, int(sum(lim.ok(a) for a in v)) if lim else 0,
                       tuple(s for s, zz in zip(serials, z) if abs(zz) > OUTLIER_Z), slope, slope_s, mean, lcl, ucl,
                       tuple(s for s, a in zip(serials, v) if not lcl <= a <= ucl) if math.isfinite(sigma) else ())


def figures_needed(spec: Spec | None) -> list[str]:
    """The figures :func:`lot_statistics` looks at: those ``spec`` limits, else the key figures."""
    if spec is not None:
        return sorted({lim.figure for lim in spec.limits})
    return [f for f in FIGURES if any(fnmatch.fnmatchcase(f, p) for p in KEY_FIGURES)]


def lot_statistics(rows: list[dict], spec: Spec | None = None, trend_by: str = "order") -> LotStats:
    """The lot's statistics from its table's rows (:func:`align.production.table.latest_rows`).

    Parameters
    ----------
    rows : list of dict
        One per unit and sensor (figures SI, NaN where absent), with serial, job, order, time, status, message.
    spec : Spec, optional
    trend_by : str
        ``"order"`` (the manifest's order; slope per unit) or ``"time"`` (when each unit ran; slope per day).

    Returns
    -------
    LotStats
    """
    if trend_by == "time":
        times = [r["time"] for r in rows if r.get("time") is not None]
        t0 = min(times) if times else None
        xs = {id(r): (r["time"] - t0).total_seconds() / 86400.0 if r.get("time") is not None else math.nan
              for r in rows}
    else:
        xs = {id(r): float(r["order"]) if r.get("order") is not None else math.nan for r in rows}
    figures = tuple(f for f in (_figure(rows, fig, s, spec, xs) for fig, s in _figure_names(rows, spec)) if f)
    units: dict[tuple, UnitVerdict] = {}
    for r in rows:
        key = (r["serial"], r["job"])
        prev = units.get(key)
        if r.get("status") != "ok":
            verdict, reasons = r.get("status") or "error", (r.get("message") or "",)
        else:
            broken = tuple(_violations(r, spec))
            verdict, reasons = ("fail", broken) if broken else ("pass", ())
        if prev is not None:  # another sensor of the unit: the worse verdict, every reason
            rank = ("pass", "fail", "failed", "error")
            worse = max(prev.verdict, verdict, key=lambda v: rank.index(v) if v in rank else len(rank))
            verdict, reasons = worse, prev.reasons + reasons
        units[key] = UnitVerdict(r["serial"], r["job"], r.get("order") or 0, verdict, reasons)
    ordered = sorted(units.values(), key=lambda u: (u.verdict == "pass", u.order, u.serial))
    return LotStats(figures, tuple(ordered), trend_by, spec)
