"""Figures judged against limits: the verdict of every figure of merit, and the defaults when no limits are given.

Each :class:`~align.merit.Figure` is judged against the limits of :mod:`align.limits` that apply to its name
and sensor (the verdicts are those of :mod:`align.merit`):

1. its 1-sigma against ``sigma_max`` (a scale's relative to its value): above it, ``NOT USABLE``; unstated,
   ``NOT CHECKED``;
2. its value against the bounds: outside, ``FAIL``; inside but closer to a bound than the guard band (``guard``,
   else ``guard_sigmas`` x its 1-sigma), ``WARN``; else ``PASS``. A figure without a value (not determined), or in
   counts against an SI bound, is ``NOT CHECKED``.

The figure's verdict is the worst of these (FAIL, NOT USABLE, WARN, NOT CHECKED, PASS); a figure no limit names
stays ``INFO``.

Without a limits file a job judges with :data:`DEFAULT_LIMITS` (:data:`DEFAULT_TEXT`): whether the test
determined its figures well enough to be used at all. A limits file adds its own; the defaults' ``sigma_max``
stay for the figures whose 1-sigma the file does not limit (:func:`with_defaults`).

Public names
------------
judge, judge_figure, with_defaults, failures, verdict_line, DEFAULT_LIMITS, DEFAULT_TEXT, DEFAULT_WHERE
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import replace
from functools import cache

from align.keyfigures import si_unit
from align.limits import Limit, Limits, limits_from_text
from align.merit import Figure
from align.vocab import Status

#: the limits a job judges with when none are given: is each figure determined well enough to be used at all?
DEFAULT_TEXT = """\
# imu-align's default limits: the largest 1-sigma with which a calibration's figures are usable at all
"phi_*" = { sigma_max = "1 deg" }
"delta_*" = { sigma_max = "1 deg" }
"rotation_*" = { sigma_max = "1 deg" }
"scale_*" = { sigma_max = "1 %" }

[gyroscope]
"bias_?" = { sigma_max = "0.5 deg/s" }

[accelerometer]
"bias_?" = { sigma_max = "0.1 m/s^2" }

[magnetometer]
"bias_?" = { sigma_max = "5 uT" }
"""
#: how the defaults are named in verdicts and outputs
DEFAULT_WHERE = "default limits"


@cache
def _defaults() -> Limits:
    return limits_from_text(DEFAULT_TEXT, DEFAULT_WHERE)


def __getattr__(name: str) -> Limits:  # DEFAULT_LIMITS, parsed when first asked for
    if name == "DEFAULT_LIMITS":
        return _defaults()
    raise AttributeError(name)


def with_defaults(limits: Limits | None) -> Limits:
    """``limits`` (a file's) with the defaults' ``sigma_max`` for every figure and sensor the file does not limit
    in 1-sigma; the defaults alone for None."""
    base = _defaults()
    if limits is None:
        return base
    kept = tuple(d for d in base.usability
                 if not any(lim.figure == d.figure and (lim.sensor in ("", d.sensor) or d.sensor == "")
                            and lim.sigma_max is not None for lim in (*limits.limits, *limits.usability)))
    return Limits(limits.path, limits.limits, limits.usability + kept)


def _where(lim: Limit, limits: Limits) -> str:
    if lim in _defaults().usability and limits.path != DEFAULT_WHERE and lim not in limits.limits:
        return DEFAULT_WHERE
    return f"{limits.path}, {lim.key}" if lim.key.startswith("part ") else limits.path


def judge_figure(figure: Figure, limits: Limits) -> Figure:
    """``figure`` with its verdict, limit text and detail (module docstring)."""
    bounds = limits.limits_for(figure.name, figure.sensor)
    usable = limits.usability_for(figure.name, figure.sensor)
    if not bounds and not usable:
        return figure
    unit_si = si_unit(figure.name, figure.sensor) or "1"
    found: list[tuple[Status, str]] = []
    for lim in usable:
        assert lim.sigma_max is not None
        relative = figure.name.startswith("scale_")
        sigma = figure.sigma / abs(figure.value) if relative and figure.value else figure.sigma
        u = "" if lim.unit == "1" else f" {lim.unit}"
        if not relative and figure.unit != unit_si:
            found.append((Status.NOT_CHECKED, f"in {figure.unit}: a 1-sigma limit in {lim.unit} does not apply"))
        elif not math.isfinite(sigma):
            found.append((Status.NOT_CHECKED, "its 1-sigma is not stated, so whether it is usable is not checked"))
        elif sigma > lim.sigma_max:
            found.append((Status.NOT_USABLE, f"1-sigma {lim.shown_sigma(sigma):.3g}{u} above {lim.shown_sigma(lim.sigma_max):g}"
                                             f"{u}: not determined well enough to use"))
        else:
            found.append((Status.PASS, f"1-sigma {lim.shown_sigma(sigma):.3g}{u} within {lim.shown_sigma(lim.sigma_max):g}{u}"))
    for lim in bounds:
        u = "" if lim.unit == "1" else f" {lim.unit}"
        if not math.isfinite(figure.value):
            found.append((Status.NOT_CHECKED, "no value: the data did not determine it"))
        elif figure.unit != unit_si:
            found.append((Status.NOT_CHECKED, f"in {figure.unit}: a limit in {lim.unit} does not apply"))
        elif not lim.ok(figure.value):
            found.append((Status.FAIL, f"{lim.shown(figure.value):.4g}{u} outside {lim.describe()}"))
        else:
            margin = min(figure.value - lim.low if lim.low is not None else math.inf,
                         lim.high - figure.value if lim.high is not None else math.inf)
            guard = lim.guard if lim.guard is not None else \
                lim.guard_sigmas * (figure.sigma if math.isfinite(figure.sigma) else 0.0)
            if margin < guard:
                found.append((Status.WARN, f"{lim.shown(figure.value):.4g}{u} within the guard band "
                                           f"({f'{lim.guard_sigmas:g} sigma' if lim.guard is None else 'stated'}) "
                                           f"of {lim.describe()}"))
            else:
                found.append((Status.PASS, f"{lim.shown(figure.value):.4g}{u} within {lim.describe()}"))
    status = Status.worst(s for s, _ in found)
    detail = "; ".join(d for s, d in found if s == status)
    text = "; ".join(dict.fromkeys(f"{lim.describe()} ({_where(lim, limits)})" for lim in (*bounds, *usable)))
    return replace(figure, status=status, limit=text, detail=detail)


def judge(figures: Iterable[Figure], limits: Limits | None = None) -> tuple[Figure, ...]:
    """Every figure judged (:func:`judge_figure`) against ``limits`` with the defaults (:func:`with_defaults`).

    Examples
    --------
    >>> import math
    >>> f = Figure("phi_xy", "accelerometer", math.radians(3.4), math.radians(247), "rad")
    >>> g = judge([f])[0]
    >>> g.status.value, g.detail
    ('NOT USABLE', '1-sigma 247 deg above 1 deg: not determined well enough to use')
    """
    full = with_defaults(limits)
    return tuple(judge_figure(f, full) for f in figures)


def failures(figures: Iterable[Figure]) -> list[Figure]:
    """The figures whose verdict fails (FAIL, NOT USABLE): a command exits 4 on them."""
    return [f for f in figures if f.status.fails]


def verdict_line(figures: Iterable[Figure]) -> str:
    """One line: the worst verdict and the failing figures named (``"FAIL: 1 FAIL, 2 NOT USABLE (gyroscope scale_x,
    accelerometer phi_xy, ...)"``), or ``"PASS: 24 figures within their limits"``; the figures not checked after."""
    figs = list(figures)
    judged = [f for f in figs if f.status != Status.INFO]
    if not judged:
        return "no figure judged: no limit applies"
    bad = failures(judged)
    unchecked = [f for f in judged if f.status == Status.NOT_CHECKED]
    if bad:
        worst = Status.worst(f.status for f in bad)
        counts = ", ".join(f"{sum(f.status == s for f in bad)} {s}" for s in (Status.FAIL, Status.NOT_USABLE)
                           if any(f.status == s for f in bad))
        head = f"{worst}: {counts} ({', '.join(f'{f.sensor} {f.name}' for f in bad[:6])}" + \
            (f" and {len(bad) - 6} more)" if len(bad) > 6 else ")")
    else:
        warned = [f for f in judged if f.status == Status.WARN]
        passed = [f for f in judged if f.status == Status.PASS]
        many = len(passed) != 1
        head = (f"WARN: {', '.join(f'{f.sensor} {f.name}' for f in warned)} within the guard band" if warned
                else f"PASS: {len(passed)} figure{'s' if many else ''} within {'their' if many else 'its'} limits")
    if unchecked:
        head += f"; NOT CHECKED: {', '.join(f'{f.sensor} {f.name}' for f in unchecked[:6])}" + \
            (f" and {len(unchecked) - 6} more" if len(unchecked) > 6 else "")
    return head
