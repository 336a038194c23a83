"""The lot's statistics as a versioned JSON document (``imu-align lot --json``), and reading one back.

The document (``format`` ``"imu-align.lot-statistics"``, ``version`` 1) holds every value SI, each figure stating
its SI unit (``unit``; ``"count"`` for a calibration in counts) and the unit the terminal and report show it in
(``shown_unit``); a value that does not exist (no limit, too few units) is ``null``::

    {"format", "version", "table", "spec", "trend_by",
     "lot": {"count", "passed", "yield", "yield_interval"},          # Wilson 95 % interval
     "units": [{"serial", "job", "order", "verdict", "reasons"}],    # failing first, then lot order
     "notes": [...],
     "figures": [{"figure", "title", "sensor", "job", "reading_unit", "unit", "shown_unit",
                  "limit": {"low", "high", "text"} | null,
                  "n", "mean", "std", "min", "max", "median", "passed", "yield",
                  "outliers": [serial, ...],                          # robust z beyond 3.5
                  "trend": {"slope", "sigma", "per"},                # per "unit" (lot order) or "day"
                  "capability": {"shown", "why", "cpk",
                                 "normal": {"cpk", "sigma", "applicable", "note"},
                                 "percentile": {"cpk", "interval", "level", "resamples", "quantiles"},
                                 "normality": {"test", "statistic", "p", "alpha"}} | null,
                  "control_chart": {"centre", "sigma", "lcl", "ucl", "mr", "mr_ucl", "reference",
                                    "signals": [{"rule", "rule_text", "index", "unit", "side", "count"}]} | null}],
     "thermal_groups": [{"sensor", "unit", "grid", "criterion", "bic", "dims",      # units grouped by thermal
                         "groups": [{"members", "tref", "coefficients", "spread"}]}]}   # profile, when there are any

``quantiles`` are ``(X0.135, X50, X99.865)``; a signal's ``unit`` is the serial where its rule rose and ``index`` its
place in the chart's order.

Public names
------------
lot_document, lot_json, read_lot_json, FORMAT, VERSION
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from align.errors import InputError

FORMAT = "imu-align.lot-statistics"
VERSION = 1


def _f(x: Any) -> float | None:
    """A float for JSON: NaN and infinities as null."""
    return float(x) if x is not None and math.isfinite(float(x)) else None


def _capability(cap) -> dict | None:
    if cap is None:
        return None
    return {"shown": cap.used, "why": cap.why, "cpk": _f(cap.cpk),
            "normal": {"cpk": _f(cap.cpk_normal), "sigma": _f(cap.cpk_normal_sigma), "applicable": cap.normal,
                       "note": cap.normal_note},
            "percentile": {"cpk": _f(cap.cpk_percentile), "interval": [_f(v) for v in cap.interval],
                           "level": cap.level, "resamples": cap.resamples, "quantiles": [_f(v) for v in cap.quantiles]},
            "normality": {"test": "Anderson-Darling", "statistic": _f(cap.ad_statistic), "p": _f(cap.ad_p),
                          "alpha": cap.alpha}}


def _chart(chart) -> dict | None:
    from align.production.control import RULES

    if chart is None:
        return None
    return {"centre": _f(chart.centre), "sigma": _f(chart.sigma), "lcl": _f(chart.lcl), "ucl": _f(chart.ucl),
            "mr": _f(chart.mr), "mr_ucl": _f(chart.mr_ucl), "reference": chart.reference,
            "signals": [{"rule": s.rule, "rule_text": RULES[s.rule], "index": s.index, "unit": s.unit, "side": s.side,
                         "count": s.count} for s in chart.signals]}


def _figure(fs, trend_by: str) -> dict:
    from align.keyfigures import si_unit, title

    unit = "count" if fs.reading_unit == "count" and fs.unit.startswith("count") else (
        si_unit(fs.figure, fs.sensor) or "1")
    lim = fs.limit
    return {"figure": fs.figure, "title": title(fs.figure), "sensor": fs.sensor, "job": fs.job,
            "reading_unit": fs.reading_unit, "unit": unit, "shown_unit": fs.unit,
            "limit": {"low": _f(lim.low), "high": _f(lim.high), "text": lim.describe()} if lim else None,
            "n": fs.n, "mean": _f(fs.mean), "std": _f(fs.std), "min": _f(fs.minimum), "max": _f(fs.maximum),
            "median": _f(fs.median), "passed": fs.passed if lim else None, "yield": _f(fs.yield_) if lim else None,
            "outliers": list(fs.outliers),
            "trend": {"slope": _f(fs.slope), "sigma": _f(fs.slope_sigma), "per": "day" if trend_by == "time" else "unit"},
            "capability": _capability(fs.capability), "control_chart": _chart(fs.chart)}


def _grouping(g) -> dict:
    from align.keyfigures import si_unit

    unit = si_unit("bias_x", g.sensor) or "1"
    return {"sensor": g.sensor, "unit": unit, "grid": [float(t) for t in g.grid], "criterion": g.criterion,
            "bic": {str(k): _f(v) for k, v in g.bic.items()}, "dims": g.dims,
            "groups": [{"members": list(grp.members), "tref": grp.tref, "coefficients": grp.coefficients.tolist(),
                        "spread": grp.spread.tolist()} for grp in g.groups]}


def lot_document(stats, source: str, thermal: tuple = ()) -> dict:
    """The JSON document (module docstring) of a lot's :class:`~align.production.stats.LotStats`.

    Parameters
    ----------
    stats : LotStats
    source : str
        The table it was computed from (as given).
    thermal : tuple of ThermalGrouping
        The units grouped by thermal profile, per sensor (:func:`align.production.thermal_groups.group_thermal`).

    Returns
    -------
    dict
        JSON-ready (no NaN: null).
    """
    lo, hi = stats.yield_interval
    return {"format": FORMAT, "version": VERSION, "table": source,
            "spec": str(stats.spec.path) if stats.spec is not None else None, "trend_by": stats.trend_by,
            "lot": {"count": stats.count, "passed": stats.passed, "yield": _f(stats.yield_),
                    "yield_interval": [_f(lo), _f(hi)]},
            "units": [{"serial": u.serial, "job": u.job, "order": u.order, "verdict": u.verdict,
                       "reasons": list(u.reasons)} for u in stats.units],
            "notes": list(stats.notes),
            "figures": [_figure(fs, stats.trend_by) for fs in stats.figures],
            "thermal_groups": [_grouping(g) for g in thermal]}


def lot_json(stats, source: str, thermal: tuple = ()) -> str:
    """:func:`lot_document` as JSON text (indented, strict: no NaN)."""
    return json.dumps(lot_document(stats, source, thermal), indent=1, allow_nan=False) + "\n"


def read_lot_json(path: str | Path) -> dict:
    """A lot's JSON document read back (numbers as written; null where none).

    Raises
    ------
    InputError
        Not JSON, not a lot's statistics, or a version this release does not read.
    """
    try:
        doc = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError) as e:
        raise InputError(f"not a lot's JSON statistics ({e})", str(path)) from None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise InputError(f"not a lot's JSON statistics (format {FORMAT!r} expected); give the file lot wrote with {{json}}",
                         str(path))
    if doc.get("version") != VERSION:
        raise InputError(f"lot statistics version {doc.get('version')!r}; this release reads version {VERSION}",
                         str(path))
    return doc
