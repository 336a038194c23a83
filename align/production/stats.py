"""Statistics of a lot against its spec: spread, capability, yield, outliers, trend, control limits.

For each figure (and sensor) over the units that gave it:

* count, mean, standard deviation (``ddof = 1``), min, max, median;
* process capability ``Cpk = min(USL - mean, mean - LSL) / (3 s)`` (one-sided: the side with a limit),
  with its standard error ``sqrt(1/(9n) + Cpk^2/(2(n-1)))`` (Bissell 1990);
* the figure's yield: the fraction of units within its limit;
* outliers by the robust z-score ``z = 0.6745 (x - median) / MAD`` (Iglewicz and Hoaglin), ``|z| > 3.5``,
  named only from :data:`OUTLIER_MIN_N` units on;
* the trend: least-squares slope of the figure over the lot's order (per unit) or time (per day),
  with its standard error ``s_res / sqrt(sum (x - mean x)^2)``;
* an individuals control chart: centre the mean, limits ``mean -/+ 3 MR/1.128`` (``MR`` the mean moving
  range in lot order), and the units outside them;
* with a limit, :class:`align.production.capability.Capability`: the percentile Cpk (ISO 22514-2) beside the
  normal one and which is shown (an Anderson-Darling test); an I-MR chart in lot order (limits from the lot's
  first units) with the Western Electric run rules that fire (:mod:`align.production.control`).

Populations are never pooled across jobs or units: a figure's statistics are grouped by (job, sensor,
the row's reading unit ``bias_unit``), so a calibration in counts is described in counts, apart from SI
rows, and a matrix ``M`` is not pooled with a Ferraris or ``calibrate gyro`` one.

A unit is a serial, judged by all its jobs' rows. It passes when every job ran (status ok) and every
limit that applies to one of its sensors was checked and held. A limit is not checked for a unit when
none of its rows gives the figure (a job that does not give it, an Allan term its record could not
identify: NaN) or the figure is count-valued (a calibration in counts: an SI limit is not applied to
it); such a unit's verdict is ``"unchecked"``, which is not a pass, and :attr:`LotStats.notes` states
each limit left unchecked. The lot's yield is the units passing over all units, with its Wilson 95 %
interval.

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

from align.limits import Limit, Spec
from align.production.capability import Capability, capability
from align.production.control import ControlChart, control_chart
from align.production.keyfigures import FIGURES, KIND, shown_unit, si_unit
from align.units import to_unit

#: the robust z-score beyond which a unit is an outlier (Iglewicz and Hoaglin)
OUTLIER_Z = 3.5
#: the fewest units from which outliers are named (a robust z of 3 units means little)
OUTLIER_MIN_N = 8
#: kinds of figure whose value is in counts on a row whose ``bias_unit`` is ``"count"``
_COUNTED_KINDS = ("reading", "white", "flicker", "walk")
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
    ``outliers`` and ``out_of_control`` name serials. ``capability`` (with a limit) holds both Cpk and the one
    shown; ``chart`` the I-MR chart in the order of ``x`` and its run rules' signals.
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
    job: str = ""
    reading_unit: str = ""
    capability: Capability | None = None
    chart: ControlChart | None = None

    @property
    def n(self) -> int:
        return len(self.values)

    @property
    def yield_(self) -> float:
        """Fraction of the units that gave the figure within its limit (NaN without one)."""
        return self.passed / self.n if self.limit is not None and self.n else math.nan

    def shown(self, value: float) -> float:
        """An SI value of this figure in :attr:`unit` (count-valued figures as they are)."""
        return float(to_unit(value, self.unit)) if self.unit != "1" and not self.unit.startswith("count") \
            else float(value)


@dataclass(frozen=True)
class UnitVerdict:
    """A unit (serial) of the lot: ``verdict`` ``"pass"``, ``"unchecked"`` (a limit could not be checked),
    ``"fail"`` (outside a limit), ``"failed"`` (a job refused it) or ``"error"``; ``job`` its jobs joined by
    ``", "``; ``reasons`` the limits it broke (``phi_xy = 0.31 deg: |phi_xy| <= 0.1 deg``), left unchecked, or
    its jobs' messages."""

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
    notes: tuple = ()

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
    def yield_interval(self) -> tuple[float, float]:
        """The Wilson score interval (95 %, ``z = 1.96``) of the yield:
        ``(p + z^2/2n -/+ z sqrt(p(1-p)/n + z^2/4n^2)) / (1 + z^2/n)``."""
        return wilson(self.passed, self.count)


def wilson(k: int, n: int, z: float = 1.959964) -> tuple[float, float]:
    """Wilson score interval of a proportion ``k / n`` (NaN for ``n = 0``)."""
    if not n:
        return math.nan, math.nan
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, centre - half), min(1.0, centre + half)


def counted(row: dict, figure: str) -> bool:
    """True when ``figure`` of ``row`` is in counts (a calibration in counts: readings, noise terms, ``M``)."""
    return (row.get("bias_unit") or "") == "count" and _in_counts(figure)


def _in_counts(figure: str) -> bool:
    """True when ``figure`` is in counts for a calibration in counts (readings, noise terms, ``M``)."""
    return KIND[figure] in _COUNTED_KINDS or figure.startswith(("M_", "scale_"))


def _group_unit(figure: str, sensor: str, reading_unit: str) -> str:
    """The unit a figure of a (job, sensor, reading unit) group is shown in when no limit states one."""
    if reading_unit != "count" or not _in_counts(figure):
        return shown_unit(figure, sensor)
    if KIND[figure] in _COUNTED_KINDS:
        return "count"
    return f"count/({si_unit('field' if sensor == 'magnetometer' else 'bias_x', sensor)})"


def _violations(row: dict, spec: Spec | None) -> list[str]:
    out: list[str] = []
    if spec is None:
        return out
    for lim in spec.limits:
        v = row.get(lim.figure)
        if (lim.applies(row.get("sensor")) and isinstance(v, float) and math.isfinite(v) and not counted(row, lim.figure)
                and not lim.ok(v)):
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
        said = "; ".join(filter(None, [r.get("message"), "outside the spec: " + "; ".join(broken)]))
        out.append({**r, "verdict": "fail", "message": said} if broken else r)
    return out


def rejudge_rows(rows: list[dict], spec: Spec | None) -> list[dict]:
    """Rows judged before (a previous run's, against its spec) judged again against ``spec``; a row that failed
    on its result's own figures of merit (``checks`` naming them: the single command's exit 4) stays failed."""
    fresh = []
    for r in rows:
        if r.get("verdict") == "fail" and "figures of merit: " not in (r.get("checks") or ""):
            said = r.get("message") or ""
            cut = said.find("outside the spec: ")  # the spec's part, last (judge_rows): what came before stays
            r = {**r, "verdict": "warn" if ": warn" in (r.get("checks") or "") else "pass",
                 "message": said[:cut].rstrip("; ") if cut >= 0 else said}
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


def _groups(rows: list[dict], figure: str, sensor: str) -> list[tuple[str, str]]:
    """The (job, reading unit) populations of ``figure`` for ``sensor``: never pooled with one another."""
    out: list[tuple[str, str]] = []
    for r in rows:
        if r.get("status") == "ok" and r.get("sensor") == sensor and isinstance(r.get(figure), float) \
                and math.isfinite(r[figure]):
            key = (r.get("job") or "", r.get("bias_unit") or "")
            if key not in out:
                out.append(key)
    return out


def _figure(rows: list[dict], figure: str, sensor: str, spec: Spec | None, xs: dict, job: str = "",
            reading_unit: str = "") -> FigureStats | None:
    got = [(r["serial"], xs[id(r)], r[figure]) for r in rows
           if r.get("status") == "ok" and r.get("sensor") == sensor and isinstance(r.get(figure), float)
           and math.isfinite(r[figure]) and (r.get("job") or "") == job and (r.get("bias_unit") or "") == reading_unit]
    if not got:
        return None
    serials = tuple(g[0] for g in got)
    x, v = np.array([g[1] for g in got], float), np.array([g[2] for g in got], float)
    in_counts = counted({"bias_unit": reading_unit}, figure)
    limits = spec.limits_for(figure, sensor) if spec is not None and not in_counts else []
    lim = limits[0] if limits else None  # one at most: read_spec refuses overlapping limits
    c, cs = cpk(v, lim.low, lim.high) if lim else (math.nan, math.nan)
    z = robust_z(v)
    slope, slope_s = trend(x, v)
    order = np.argsort(x, kind="stable")
    mr = np.abs(np.diff(v[order]))
    sigma = float(np.mean(mr)) / 1.128 if len(mr) else math.nan
    mean = float(np.mean(v))
    lcl, ucl = mean - 3 * sigma, mean + 3 * sigma
    outliers = tuple(s for s, zz in zip(serials, z) if abs(zz) > OUTLIER_Z) if len(v) >= OUTLIER_MIN_N else ()
    unit = lim.unit if lim else _group_unit(figure, sensor, reading_unit)
    return FigureStats(figure, sensor, lim, unit, serials, x, v, mean,
                       float(np.std(v, ddof=1)) if len(v) > 1 else math.nan, float(v.min()), float(v.max()),
                       float(np.median(v)), c, cs, int(sum(lim.ok(a) for a in v)) if lim else 0,
                       outliers, slope, slope_s, mean, lcl, ucl,
                       tuple(s for s, a in zip(serials, v) if not lcl <= a <= ucl) if math.isfinite(sigma) else (),
                       job, reading_unit,
                       capability(v, lim.low, lim.high)
                       if lim else None, control_chart(v[order], [serials[k] for k in order]))


def _unchecked(rows: list[dict], spec: Spec | None) -> list[tuple[Limit, str]]:
    """The limits that apply to a sensor of a unit's ``rows`` (all its jobs, status ok) but that none of them
    checks: (limit, why)."""
    if spec is None:
        return []
    out = []
    sensors = {r.get("sensor") for r in rows if r.get("sensor")}
    for lim in spec.limits:
        mine = [r for r in rows if r.get("sensor") in sensors and lim.applies(r.get("sensor"))]
        if not mine or (lim.sensor == "" and si_unit(lim.figure, mine[0]["sensor"]) is None):
            continue
        finite = [r for r in mine if isinstance(r.get(lim.figure), float) and math.isfinite(r[lim.figure])]
        if any(not counted(r, lim.figure) for r in finite):
            continue
        out.append((lim, "in counts" if finite else "not given"))
    return out


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
        ``"order"`` (the manifest's order; slope per unit) or ``"time"`` (when each unit was tested: its
        ``test_time``, else when its row was made; slope per day).

    Returns
    -------
    LotStats
    """
    if trend_by == "time":  # when the unit was tested (the manifest's test_time), else when its row was made
        when = {id(r): r.get("test_time") or r.get("time") for r in rows}
        t0 = min((t for t in when.values() if t is not None), default=None)
        xs = {k: (t - t0).total_seconds() / 86400.0 if t is not None else math.nan for k, t in when.items()}
    else:
        xs = {id(r): float(r["order"]) if r.get("order") is not None else math.nan for r in rows}
    figures = tuple(f for f in (_figure(rows, fig, s, spec, xs, job, unit) for fig, s in _figure_names(rows, spec)
                                for job, unit in _groups(rows, fig, s)) if f)
    by_serial: dict[str, list[dict]] = {}
    for r in rows:
        by_serial.setdefault(r["serial"], []).append(r)
    units: list[UnitVerdict] = []
    missing: dict[tuple, list[str]] = {}
    for serial, mine in by_serial.items():
        jobs = ", ".join(dict.fromkeys(r["job"] for r in mine))
        order = min((r.get("order") or 0) for r in mine)
        dead = [r for r in mine if r.get("status") != "ok"]
        if dead:
            verdict = "error" if any(r.get("status") == "error" for r in dead) else "failed"
            several = len({r["job"] for r in mine}) > 1
            reasons = tuple((f"{r['job']}: " if several else "") + (r.get("message") or "") for r in dead)
        else:
            broken = tuple(b for r in mine for b in _violations(r, spec))
            open_ = _unchecked(mine, spec)
            for lim, why in open_:
                missing.setdefault((lim.key or lim.figure, lim.figure, why), []).append(serial)
            if broken:
                verdict, reasons = "fail", broken
            elif open_:
                verdict = "unchecked"
                reasons = tuple(f"{lim.figure} not checked ({why})" for lim, why in open_)
            else:
                verdict, reasons = "pass", ()
        units.append(UnitVerdict(serial, jobs, order, verdict, reasons))
    notes = tuple(f"limit {key} ({figure}) not checked for {len(who)} of {len(by_serial)} units: "
                  + ("its figure is in counts (a calibration in counts): an SI limit is not applied to it" if why == "in counts"
                     else "no job of theirs gives it (or it is NaN: not identifiable)")
                  + f" (e.g. {', '.join(who[:3])}); they do not count as passing"
                  for (key, figure, why), who in missing.items())
    spread = [x for x in xs.values() if math.isfinite(x)]
    untimed = sorted({r["serial"] for r in rows if r.get("test_time") is None})
    if trend_by == "time" and len(by_serial) > 1 and spread and max(spread) == min(spread):
        notes += ("no trend over time: every unit has the same test time (the manifest's test_time, or the log's, "
                  "else when its row was made); give each unit its own, or trend over the lot's order",)
    elif trend_by == "time" and untimed:
        notes += (f"{len(untimed)} of {len(by_serial)} units have no test time (e.g. {', '.join(untimed[:3])}): the "
                  "trend places them when their row was made, which is when the batch ran, not when they were tested; "
                  "give test_time in the manifest (or logs that state it), or trend over the lot's order",)
    ordered = sorted(units, key=lambda u: (u.verdict == "pass", u.order, u.serial))
    return LotStats(figures, tuple(ordered), trend_by, spec, notes)
