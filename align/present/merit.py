"""The figures of merit on the terminal and in the report: each figure's verdict against its limit.

Public names
------------
verdict_lines, figures_rows, shown_value, merit_parts
"""

from __future__ import annotations

import math

from align.judge import DEFAULT_WHERE, verdict_line
from align.keyfigures import shown_unit
from align.merit import Figure
from align.units import to_unit
from align.vocab import Status

#: the most figures listed one by one on the terminal
_LISTED = 12


def shown_value(f: Figure) -> tuple[str, str]:
    """``(value +/- sigma, unit)`` of a figure in the unit it is shown in (``deg``, ``deg/s``; a scale as a ratio, or
    in counts per the sensor's unit for a calibration in counts)."""
    unit = shown_unit(f.name, f.sensor)
    if f.unit == "count":
        unit = f"counts per {shown_unit('bias_x', f.sensor)}" if f.name.startswith("scale_") else "counts"
    conv = (lambda v: v) if unit == "1" or f.unit == "count" else (lambda v: float(to_unit(v, unit)))
    if not math.isfinite(f.value):
        return "not determined", unit
    text = f"{conv(f.value):.6g}"
    if math.isfinite(f.sigma):
        text += f" +/- {abs(conv(f.sigma)):.2g}"
    return text, unit


def verdict_lines(figures: tuple[Figure, ...] | list[Figure]) -> list[str]:
    """The terminal's lines: one per figure that is not PASS or INFO (the worst first, at most 12), then
    ``verdict: ...`` (:func:`align.judge.verdict_line`) and which limits judged (``default limits`` said so)."""
    figs = list(figures)
    if not figs:
        return []
    odd = sorted((f for f in figs if f.status not in (Status.PASS, Status.INFO)), key=lambda f: -f.status.rank)
    lines = []
    for f in odd[:_LISTED]:
        value, unit = shown_value(f)
        lines.append(f"  {f.status}: {f.sensor} {f.name} = {value} {'' if unit == '1' else unit}".rstrip()
                     + f" ({f.detail})")
    if len(odd) > _LISTED:
        lines.append(f"  ... and {len(odd) - _LISTED} more (the JSON's figures list them all)")
    sources = sorted({part.rsplit("(", 1)[-1].rstrip(")") for f in figs if f.limit for part in f.limit.split("; ")})
    said = f" (judged against {', '.join(sources)}" + (": is each figure determined well enough to use; a limits "
                                                       "file adds limits of your own)" if sources == [DEFAULT_WHERE]
                                                       else ")") if sources else ""
    return [*lines, f"verdict: {verdict_line(figs)}{said}"]


def figures_rows(figures: tuple[Figure, ...] | list[Figure]) -> list[list]:
    """The report's figures-of-merit table: figure, standard name, sensor, value +/- 1-sigma, unit, limit, verdict,
    detail, test."""
    rows = []
    for f in figures:
        value, unit = shown_value(f)
        cls = {"PASS": "pass", "FAIL": "fail", "NOT USABLE": "fail", "WARN": "warn", "NOT CHECKED": "warn"}.get(
            str(f.status), "info")
        rows.append([f.name, f.title, f.sensor, value, unit, f.limit or "none", (str(f.status), cls), f.detail, f.test])
    return rows


def merit_parts(label: str, result, limits=None) -> tuple | None:
    """The report's verdict and section of ``result``'s figures of merit, or None for a result that gives none.

    The figures are the result's own verdicts (judged when its job ran) or, with ``limits`` (a read
    :class:`align.limits.Limits`) or for a result written before verdicts existed, judged here
    (:func:`align.job.judged`).

    Returns
    -------
    (Verdict, Section) or None
    """
    from align.job import judged
    from align.present.html import Section, table
    from align.present.verdicts import Verdict

    figures = result.verdicts if limits is None and result.verdicts else judged(result, label, limits)
    if not figures:
        return None
    counted = [f for f in figures if f.status != Status.INFO]
    status = Status.worst(f.status for f in counted) if counted else Status.INFO
    number = ", ".join(f"{sum(f.status == s for f in counted)} {s}" for s in
                       (Status.FAIL, Status.NOT_USABLE, Status.WARN, Status.NOT_CHECKED, Status.PASS)
                       if any(f.status == s for f in counted)) or "no limit applies"
    verdict = Verdict(f"figures of merit ({label})", status, number, float(len(counted)), verdict_line(figures))
    head = ("<p>Each figure with its standard name, value and 1-sigma, the limit it was judged against and the "
            "verdict: NOT USABLE when its 1-sigma exceeds what its use needs, WARN within the guard band of a limit, "
            "NOT CHECKED when there is no value or no applicable limit (never counted as a pass).</p>")
    rows = figures_rows(figures)
    body = table(["figure", "name", "sensor", "value", "unit", "limit", "verdict", "detail", "test"], rows, left=9)
    return verdict, Section(f"Figures of merit: {label}", head + body)


def verify_lines(res, result: str, log: str) -> list[str]:
    """``verify``'s terminal lines: what was replayed where, then each residual figure, its value and verdict."""
    lines = [f"verify {result} on {log} (M estimated again on the corrected session; a working correction leaves "
             "M = I):"]
    for f in res.verdicts:
        value, unit = shown_value(f)
        lines.append(f"  {f.name:<18} {value:>28} {'' if unit == '1' else unit:<4} {f.status}")
    return lines
