"""Control charts across units, runs or lots: individuals and moving range (I-MR) with the Western Electric rules.

The individuals chart plots each value in order against the centre line and the limits
``centre -/+ k sigma`` with ``sigma = MR / d2`` (``MR`` the mean moving range ``|x_i - x_(i-1)|``,
``d2 = 1.128`` for ranges of two); the moving-range chart plots ``MR_i`` against ``D4 MR`` (``D4 = 3.267``).
Both come from a reference period: by default the lot's first :func:`baseline` units (the phase-I
period, as in Montgomery, Introduction to Statistical Quality Control, 6.4), so a drift later in the lot
is judged against the lot as it started; a reference lot's ``centre`` and ``sigma`` may be given instead.

The run rules (Western Electric Statistical Quality Control Handbook, 1956; Nelson's rules 1, 5, 6 and,
with 8 points instead of his 9, 2), each raised at the unit that completes the pattern:

1. one point beyond 3 sigma;
2. 2 of 3 successive points beyond 2 sigma on the same side;
3. 4 of 5 successive points beyond 1 sigma on the same side;
4. 8 successive points on the same side of the centre line;

and ``MR``: a moving range beyond ``D4 MR``. With known centre and sigma, rules 1-4 together raise a
false signal every 91.75 points on average in an in-control process (Champ and Woodall 1987,
Technometrics 29(4) 393-399); rule 1 alone every 370.4.

Public names
------------
Signal, ControlChart, control_chart, baseline, RULES, D2, D4, ARL0
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: ``d2`` for moving ranges of two: ``E[|x1 - x2|] = d2 sigma``
D2 = 1.128
#: ``D4`` for moving ranges of two: the moving range's upper control limit is ``D4 MR``
D4 = 3.267
#: the in-control average run length of rules 1-4 with known limits (Champ and Woodall 1987)
ARL0 = 91.75
#: the rules, by name: what each says
RULES = {
    "1": "one point beyond 3 sigma",
    "2": "2 of 3 points beyond 2 sigma on one side",
    "3": "4 of 5 points beyond 1 sigma on one side",
    "4": "8 points in a row on one side of the centre",
    "MR": "a moving range beyond D4 MR (3.267 MR)",
}


@dataclass(frozen=True)
class Signal:
    """A run rule firing: ``rule`` (a key of :data:`RULES`), the position ``index`` (0-based, in the chart's order)
    and ``unit`` (its serial) of the point completing the pattern, ``side`` (``"above"``/``"below"``; ``""`` for MR),
    and ``count``: how many more points after it the rule stays firing."""

    rule: str
    index: int
    unit: str
    side: str
    count: int = 0

    def describe(self) -> str:
        """``rule 2 (2 of 3 points beyond 2 sigma on one side, above) at unit SN0061 (point 61 of the chart)``: the
        point counted from 1, in the chart's order (units without the figure are not on it)."""
        side = f", {self.side}" if self.side else ""
        return f"rule {self.rule} ({RULES[self.rule]}{side}) at unit {self.unit} (point {self.index + 1} of the chart)"


@dataclass(frozen=True)
class ControlChart:
    """An I-MR chart: ``values`` and ``units`` in order, the centre line, ``sigma`` (``MR / d2``), the individuals'
    limits ``lcl``/``ucl`` (``centre -/+ 3 sigma``), the moving range's centre ``mr`` and limit ``mr_ucl``,
    ``reference`` the number of leading units they come from (0: given), and the rules' ``signals`` in order."""

    values: np.ndarray
    units: tuple
    centre: float
    sigma: float
    lcl: float
    ucl: float
    mr: float
    mr_ucl: float
    reference: int
    signals: tuple

    def first(self, rule: str) -> Signal | None:
        """The rule's first signal (None: it never fires)."""
        return next((s for s in self.signals if s.rule == rule), None)

    @property
    def in_control(self) -> bool:
        return not self.signals


def baseline(n: int) -> int:
    """The units a lot's chart takes its limits from: the first third, at least 20 (all, for fewer)."""
    return min(n, max(20, n // 3))


def _window(flags: np.ndarray, width: int, need: int) -> np.ndarray:
    """True at ``i`` when at least ``need`` of ``flags[i - width + 1 : i + 1]`` are True (False before ``width``)."""
    c = np.concatenate([[0], np.cumsum(flags, dtype=int)])
    out = np.zeros(len(flags), bool)
    if len(flags) >= width:
        out[width - 1:] = c[width:] - c[:-width] >= need
    return out


def _episodes(fires: np.ndarray) -> list[tuple[int, int]]:
    """(start, extra points) of each run of True in ``fires``."""
    out = []
    k = 0
    while k < len(fires):
        if fires[k]:
            j = k
            while j + 1 < len(fires) and fires[j + 1]:
                j += 1
            out.append((k, j - k))
            k = j + 1
        else:
            k += 1
    return out


def control_chart(values: np.ndarray, units: tuple | list | None = None, *, centre: float | None = None,
                  sigma: float | None = None, reference: int | None = None,
                  rules: tuple = ("1", "2", "3", "4", "MR")) -> ControlChart:
    """The I-MR chart of ``values`` in their order and the run rules that fire.

    Parameters
    ----------
    values : array_like, shape (n,)
        One figure per unit (or per run, or a lot's mean per lot), in the order they were made.
    units : sequence of str, optional
        Their names (serials); default their positions.
    centre, sigma : float, optional
        A reference's centre line and sigma (phase II); default from the first ``reference`` values: their mean
        and mean moving range over ``d2``.
    reference : int, optional
        How many leading values set the limits (default :func:`baseline`).
    rules : tuple of str
        Which of :data:`RULES` to apply.

    Returns
    -------
    ControlChart
        Sigma NaN (and no signals) for fewer than 2 reference values.

    Examples
    --------
    >>> x = np.r_[np.tile([0.1, -0.1], 20), [0.9, 1.1, 0.9, 1.2]]
    >>> [s.describe() for s in control_chart(x).signals][0]
    'rule 1 (one point beyond 3 sigma, above) at unit 40 (point 41 of the chart)'
    """
    x = np.asarray(values, float)
    n = len(x)
    names = tuple(str(u) for u in units) if units is not None else tuple(str(k) for k in range(n))
    ref = baseline(n) if reference is None else min(n, reference)
    mr_all = np.abs(np.diff(x))
    mr = float(np.mean(mr_all[:max(ref - 1, 0)])) if ref > 1 else math.nan
    if centre is None:
        centre = float(np.mean(x[:ref])) if ref else math.nan
    if sigma is None:
        sigma = mr / D2
    else:
        ref, mr = 0, sigma * D2
    if not (math.isfinite(sigma) and math.isfinite(centre)):
        return ControlChart(x, names, centre, sigma, math.nan, math.nan, mr, math.nan, ref, ())
    with np.errstate(invalid="ignore"):  # sigma 0: every value off the centre is infinitely far from it
        z = (x - centre) / sigma if sigma > 0 else np.where(x == centre, 0.0, np.sign(x - centre) * np.inf)
    fired: list[Signal] = []
    for rule in rules:
        for side, sgn in (("above", 1.0), ("below", -1.0)):
            if rule == "MR":
                continue
            s = sgn * z
            fires = {"1": s > 3, "2": _window(s > 2, 3, 2), "3": _window(s > 1, 5, 4), "4": _window(s > 0, 8, 8)}[rule]
            fired += [Signal(rule, k, names[k], side, extra) for k, extra in _episodes(fires)]
        if rule == "MR":
            over = np.r_[False, mr_all > D4 * mr] if n else np.zeros(0, bool)
            fired += [Signal("MR", k, names[k], "", extra) for k, extra in _episodes(over)]
    fired.sort(key=lambda s: (s.index, list(RULES).index(s.rule)))
    return ControlChart(x, names, float(centre), float(sigma), centre - 3 * sigma, centre + 3 * sigma, mr, D4 * mr,
                        ref, tuple(fired))
