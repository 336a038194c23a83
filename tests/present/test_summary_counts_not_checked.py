"""A summary never counts what was not checked as passed (issue 28: "PASS: all 2 checks passed" above a self-check
table where saturation was NOT CHECKED): a check made of parts names the parts that did not run, the page's banner and
the terminal's last line count them."""

import numpy as np
import pytest

from align.present.verdicts import PASS, Verdict, summary_section
from align.vocab import Status


@pytest.fixture(scope="module")
def aligned(tmp_path_factory):
    """A short simulated rate-table session aligned by the report (no gyro range given: saturation not checked)."""
    from support import truth_model, write_session

    from align.alignment.plan import Plan
    from align.alignment.simulate import SessionSpec, simulate_session
    from align.present.story import make_report
    from align.units import DEG

    folder = tmp_path_factory.mktemp("aligned")
    plan = Plan.standard_rate(100 * DEG)
    t, g, _ = simulate_session(plan, truth_model(3), SessionSpec(fs=200.0, dwell_s=2.0, static_s=1.0), 3)
    log, plan_path = write_session(folder, t, g, plan)
    return make_report(log=log, plan=plan_path, monte_carlo=0)


def _banner(html: str) -> str:
    return html.split("<table")[0]


def test_a_pass_with_a_part_not_checked_is_not_all_passed():
    """Two checks ran and passed, one of them without one of its parts: not "all 2 checks passed"."""
    from align.present.verdicts import summary_line

    verdicts = [Verdict("alignment self-checks", PASS, "4 of 5 pass", 4.0, unchecked=("saturation",)),
                Verdict("measured misalignment vs allowance", PASS, "output y margin +0.8441 deg")]
    head = _banner(summary_section(verdicts).body)
    assert "all 2 checks passed" not in head and 'class="banner pass"' not in head
    assert "NOT CHECKED (alignment self-checks: saturation)" in head and "PASS on the 2 checks that ran" in head
    line = summary_line(verdicts)
    assert line.startswith("PASS on the 2 checks that ran") and "NOT CHECKED: alignment self-checks: saturation" in line
    # everything checked: the plain PASS, in both
    whole = [Verdict("alignment self-checks", PASS, "5 of 5 pass"), verdicts[1]]
    assert "PASS: all 2 checks passed." in _banner(summary_section(whole).body) and summary_line(whole) == "PASS"


def test_the_alignment_s_own_checks_give_the_parts_not_checked(aligned):
    """The checks an alignment result holds (saturation NOT CHECKED without a gyro range): one verdict naming it."""
    from align.present.verdicts import checks_verdict

    checks = aligned.results["alignment"].checks
    statuses = {c.name: Status.parse(c.status) for c in checks}
    assert statuses["saturation"] is Status.NOT_CHECKED  # what the alignment itself says
    v = checks_verdict("alignment self-checks", checks, "durations, directions, scale, residuals")
    assert v.unchecked == ("saturation",) and v.status is PASS
    passed = sum(s is Status.PASS for s in statuses.values())
    assert v.number == f"{passed} of {len(checks)} pass, 1 not checked" and v.value == passed
    assert "not checked: saturation (" in v.detail
    assert "NOT CHECKED (alignment self-checks: saturation)" in _banner(summary_section([v]).body)


def test_a_check_made_of_parts_takes_the_worst_part():
    """WARN over PASS; FAIL over both; nothing judged: NOT CHECKED (never PASS)."""
    from align.present.verdicts import checks_verdict

    class C:
        def __init__(self, name, status):
            self.name, self.status, self.detail = name, status, ""

    assert checks_verdict("c", [C("a", "pass"), C("b", "warn")], "").status is Status.WARN
    assert checks_verdict("c", [C("a", "fail"), C("b", "warn"), C("s", "not checked")], "").status is Status.FAIL
    only = checks_verdict("c", [C("s", "not checked")], "")
    assert only.status is Status.NOT_CHECKED and "PASS" not in _banner(summary_section([only]).body)
    assert np.isclose(only.value, 0.0)


def test_the_report_of_an_alignment_says_saturation_was_not_checked(aligned):
    head = _banner(aligned.page.split("<h2>Summary</h2>")[1])
    assert "all 2 checks passed" not in head and "the one check passed" not in head
    assert "alignment self-checks: saturation" in head
    assert "NOT CHECKED: alignment self-checks: saturation" in aligned.text.splitlines()[-1]
