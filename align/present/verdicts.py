"""The report's verdicts: each check with its outcome and the one number behind it, and the measured
misalignment against what the manoeuvre allows, element by element.

A :class:`Verdict` is one line of the summary at the top of the report (``PASS``, ``FAIL``, ``WARN``
for a result within its guard band of a limit or a caution, or ``INFO`` for a result that has no requirement
to meet). A design check (the mounting budget against the allowance) governs the report's outcome only
when no measured misalignment is checked: the measured unit governs, and the budget's outcome is shown
labelled as a design check. :func:`angle_sigmas` gives the 1-sigma of every angle of reference section 1;
the measured misalignment against the manoeuvre is :mod:`align.present.measured`.

Public names
------------
Verdict, checks_verdict, not_checked, summary_line, angle_vector, angle_sigmas, summary_section, worst, ANGLE_NAMES,
PASS, FAIL, WARN, INFO, NOT_CHECKED
(the members of :class:`align.vocab.Status`, the one verdict type)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.keyfigures import ANGLE_NAMES, angle_sigmas, angle_vector  # noqa: F401  (their home before)
from align.present.html import Section, esc, table
from align.vocab import Status

PASS, FAIL, WARN, INFO, NOT_CHECKED = Status.PASS, Status.FAIL, Status.WARN, Status.INFO, Status.NOT_CHECKED


@dataclass(frozen=True)
class Verdict:
    """One check of the report's summary.

    Attributes
    ----------
    check : str
        What was checked (``"measured misalignment vs allowance"``).
    status : Status
        ``WARN``: a caution that fails nothing; ``NOT CHECKED``: a requirement that could not be judged (never
        counted as passed); ``INFO``: a result shown without a requirement to meet.
    number : str
        The one number behind the verdict, with its unit, as shown.
    value : float
        That number, in the unit shown (for tests and machine readers; NaN when there is none).
    detail : str
        One line: which element, against what.
    design : bool
        A design-stage check (the mounting budget against the allowance), not a measurement of the unit.
    governs : bool
        Whether a FAIL fails the report (False for a design check when a measurement is checked too).
    unchecked : tuple of str
        The parts of a check made of several (an alignment's self-checks) that could not be judged
        (``("saturation",)``): the summary names them and never counts the check as passed in full.
    """

    check: str
    status: Status
    number: str
    value: float = float("nan")
    detail: str = ""
    design: bool = False
    governs: bool = True
    unchecked: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "status", Status.parse(self.status))
        object.__setattr__(self, "unchecked", tuple(self.unchecked))

    @property
    def failed(self) -> bool:
        """A FAIL that fails the report (a design check's FAIL does not when a measurement governs)."""
        return self.status.fails and self.governs

    @property
    def shown(self) -> str:
        """The status as the summary shows it: ``FAIL (design check)`` when it does not govern."""
        return f"{self.status} (design check)" if self.design and not self.governs and self.status != INFO \
            else self.status


def checks_verdict(check: str, checks, what: str) -> Verdict:
    """One verdict of the summary from a result's own checks (an alignment's durations, saturation, ...).

    FAIL when one failed, else WARN when one warned, else PASS; NOT CHECKED when none could be judged. The
    checks that could not be judged are named in :attr:`Verdict.unchecked`, so that the summary does not
    count the whole as passed.

    Parameters
    ----------
    check : str
        The summary's name of the whole (``"alignment self-checks"``).
    checks : sequence
        Objects with ``name``, ``status`` (a :class:`~align.vocab.Status` or its word, ``"not checked"``) and
        ``detail`` (:class:`align.alignment.checks.Check`).
    what : str
        What the checks are, for the summary's detail.

    Returns
    -------
    Verdict
        ``number``: ``"4 of 5 pass, 1 not checked"``; ``value``: the count that passed.

    Examples
    --------
    >>> from types import SimpleNamespace as C
    >>> v = checks_verdict("self-checks", [C(name="durations", status="pass", detail=""),
    ...                                    C(name="saturation", status="not checked", detail="no gyro range given")],
    ...                    "durations and saturation")
    >>> v.status.value, v.number, v.unchecked
    ('PASS', '1 of 2 pass, 1 not checked', ('saturation',))
    """
    got = [(c.name, Status.parse(c.status), str(getattr(c, "detail", "") or "")) for c in checks]
    judged = [s for _, s, _ in got if s.judged]
    unchecked = tuple(n for n, s, _ in got if s == NOT_CHECKED)
    passed = sum(s == PASS for s in judged)
    number = f"{passed} of {len(got)} pass" + (f", {len(unchecked)} not checked" if unchecked else "")
    parts = [what]
    for word, status in (("failed", FAIL), ("warnings", WARN)):
        names = [n for n, s, _ in got if s == status]
        if names:
            parts.append(f"{word}: {', '.join(names)}")
    if unchecked:
        parts.append("not checked: " + "; ".join(f"{n} ({d})" if d else n for n, s, d in got if s == NOT_CHECKED))
    return Verdict(check, Status.worst(judged) if judged else NOT_CHECKED, number, float(passed), "; ".join(parts),
                   unchecked=unchecked)


def worst(rows: list) -> object:
    """The row of smallest margin (the binding one), constrained rows first."""
    bounded = [r for r in rows if np.isfinite(r.allowed)]
    return min(bounded or rows, key=lambda r: r.margin if np.isfinite(r.allowed) else np.inf)


def _cls(status: str) -> str:
    return {PASS: "pass", FAIL: "fail", Status.NOT_USABLE: "fail", WARN: "warn", NOT_CHECKED: "warn"}.get(
        Status.parse(status), "info")


def not_checked(verdicts: list[Verdict]) -> list[str]:
    """What the report could not judge: each governing check that did not run (``saturation``), and each part of a
    check that ran without all of its parts (``alignment self-checks: saturation``); never counted as passed."""
    governing = [v for v in verdicts if v.governs]
    return ([v.check for v in governing if v.status == NOT_CHECKED]
            + [f"{v.check}: {', '.join(v.unchecked)}" for v in governing if v.status.judged and v.unchecked])


def summary_line(verdicts: list[Verdict]) -> str:
    """The terminal's last line, as the page's banner judges: FAIL (the failed checks), WARN (the cautions), PASS on
    the checks that ran, or no requirement checked; then what was not checked, and a failed design check that
    governs nothing.

    Examples
    --------
    >>> summary_line([Verdict("self-checks", PASS, "4 of 5 pass", unchecked=("saturation",))])
    'PASS on the 1 check that ran; NOT CHECKED: self-checks: saturation'
    """
    governing = [v for v in verdicts if v.governs]
    failed = [v for v in governing if v.status.fails]
    warned = [v for v in governing if v.status == WARN]
    checked = [v for v in governing if v.status.judged]
    missing = not_checked(verdicts)
    if failed:
        out = "FAIL (" + "; ".join(f"{v.check}: {v.number}" for v in failed) + ")"
    elif warned:
        out = "WARN (" + "; ".join(f"{v.check}: {v.number}" for v in warned) + ")"
    elif checked:
        out = f"PASS on the {len(checked)} check{'s' if len(checked) != 1 else ''} that ran" if missing else "PASS"
    else:
        out = "no requirement checked"
    if missing:
        out += "; NOT CHECKED: " + "; ".join(missing)
    design = [v for v in verdicts if not v.governs and v.status.fails]
    if design:
        out += "; design check " + ", ".join(f"{v.check} FAIL ({v.number})" for v in design) + \
            ": the measured unit governs"
    return out


def summary_section(verdicts: list[Verdict]) -> Section:
    """The summary: the overall outcome in one line, then each check, its verdict, its number and what it means."""
    if not verdicts:
        return Section("Summary", "<p>No check: no input was given that a requirement applies to.</p>")
    governing = [v for v in verdicts if v.governs]
    failed = [v for v in governing if v.status.fails]
    warned = [v for v in governing if v.status == WARN]
    checked = [v for v in governing if v.status.judged]
    unchecked = not_checked(verdicts)  # never counted as passed
    n = f"{len(checked)} check{'s' if len(checked) != 1 else ''}"
    cautions = "" if not warned else (f" {len(warned)} WARN ({esc(', '.join(v.check for v in warned))}): within the "
                                      "guard band of a limit, or a caution.")
    if unchecked:  # never counted as passed, and said in the banner
        cautions += (f" {len(unchecked)} NOT CHECKED ({esc('; '.join(unchecked))}): "
                     "the data or the limit to judge it were not there.")
    if failed:
        head = (f'<p class="banner fail">FAIL: {len(failed)} of {n} failed ({esc(", ".join(v.check for v in failed))}).'
                f"{cautions}</p>")
    elif warned:
        head = f'<p class="banner warn">WARN: none of {n} failed;{cautions}</p>'
    elif checked and unchecked:
        head = f'<p class="banner warn">PASS on the {n} that ran, but not everything was checked:{cautions}</p>'
    elif checked:
        head = ('<p class="banner pass">PASS: ' + ("the one check passed" if len(checked) == 1
                                                   else f"all {len(checked)} checks passed") + ".</p>")
    elif unchecked:
        head = f'<p class="banner warn">NOT CHECKED: no requirement could be judged.{cautions}</p>'
    else:
        head = '<p class="banner info">No requirement was given: the results below are reported without a verdict.</p>'
    design = [v for v in verdicts if not v.governs and v.status in (FAIL, WARN)]
    if design:
        head += (f'<p class="note">Design check{"s" if len(design) > 1 else ""} '
                 f"{esc(', '.join(v.check for v in design))}: {esc(', '.join(v.status for v in design))}. A design check "
                 "(what the mounting is predicted to give) does not set this report's outcome when the unit's "
                 "misalignment is measured: the measurement governs.</p>")
    rows = [[v.check, (v.shown, _cls(v.status)), v.number, v.detail] for v in verdicts]
    return Section("Summary", head + table(["check", "verdict", "number", "what it means"], rows, left=4))
