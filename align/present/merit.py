"""The figures of merit on the terminal and in the report: each figure's verdict against its limit.

Public names
------------
verdict_lines, figures_rows, shown_value
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


def figures_rows(figures: tuple[Figure, ...] | list[Figure]) -> list[list[str]]:
    """The report's figures-of-merit table: figure, standard name, sensor, value +/- 1-sigma, unit, limit, verdict,
    detail, test."""
    rows = []
    for f in figures:
        value, unit = shown_value(f)
        rows.append([f.name, f.title, f.sensor, value, unit, f.limit or "none", str(f.status), f.detail, f.test])
    return rows
