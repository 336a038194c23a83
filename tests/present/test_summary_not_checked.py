"""The report's summary never counts a check that did not run as passed (issue 28: "PASS: all 2 checks passed"
above a table where saturation was not checked)."""

from align.present.verdicts import NOT_CHECKED, PASS, Verdict, summary_section
from align.vocab import Status


def test_not_checked_is_named_in_the_banner_and_not_counted_as_passed():
    html = summary_section([Verdict("alignment self-checks", PASS, "4 of 4 pass"),
                            Verdict("saturation", NOT_CHECKED, "no gyro range given")]).body
    assert "all 2 checks passed" not in html
    assert "NOT CHECKED (saturation)" in html
    assert "PASS on the 1 check that ran" in html


def test_only_unchecked_requirements_give_no_pass():
    html = summary_section([Verdict("saturation", "not checked", "no gyro range given")]).body
    assert "PASS" not in html.split("<table")[0]
    assert "NOT CHECKED" in html


def test_verdict_status_is_the_one_type_whatever_spelling_it_is_given_in():
    assert Verdict("x", "warn", "1").status is Status.WARN
    assert Verdict("x", "NOT_CHECKED", "1").status is Status.NOT_CHECKED
