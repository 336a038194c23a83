"""Every option is checked for its domain where it is parsed: a refusal is a usage error (status 2), one line,
naming the option and what to type; nothing is read or written before it.

The table is the issue's cases (``simulate --fs "0 Hz"``, ``--seed -1``, ``budget --exaggerate nan``, ``allan
--rate-hz 0|nan|1e300``, ``plan --steps 0``, a negative ``--settle``, ``allan --rate "0 deg/s"``, a negative
``--accuracy``, ``simulate --rate "0 deg/s"``, ...) and the other physical options of every command.
"""

import pytest

from align.cli.options import ACCURACY, DIP, NONNEGATIVE, NONZERO, POSITIVE, hertz, number, quantity, spell, whole
from align.units import DEG

# the inputs do not exist: a refused option is reported before any file is looked at
LOG, PLAN, MOUNT, MAN, SEC = "absent.csv", "absent.toml", "absent-mount.toml", "absent-man.toml", "absent.json"
REPORT = ("report", "--mount", MOUNT, "--manoeuvre", MAN, "--out", "r.html")
PLAN_CMD = ("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--arw", "0.3 deg/sqrt(h)")
FERRARIS = ("calibrate", "ferraris", LOG, "--sections", SEC, "--rate-hz", "100")

#: (arguments before the bad option, the option, the bad value, words the refusal must hold)
CASES = [
    # simulate
    (("simulate", "out"), "--rate-hz", "0 Hz", ["sample rate > 0"]),
    (("simulate", "out"), "--fs", "0 Hz", ["--rate-hz", "sample rate > 0"]),   # the old spelling of --rate-hz
    (("simulate", "out"), "--rate-hz", "nan", ["sample rate"]),
    (("simulate", "out"), "--rate-hz", "-200", ["sample rate"]),
    (("simulate", "out"), "--dwell", "-1 s", ["a time > 0", "e.g. '10 s'"]),
    (("simulate", "out"), "--dwell", "0 s", ["a time > 0"]),
    (("simulate", "out"), "--gap", "-1 s", ["a time >= 0"]),
    (("simulate", "out"), "--seed", "-1", ["a whole number >= 0"]),
    (("simulate", "out"), "--seed", "1.5", ["a whole number >= 0"]),
    (("simulate", "out"), "--rate", "0 deg/s", ["an angular rate > 0"]),
    (("simulate", "out"), "--rate", "-100 deg/s", ["an angular rate > 0"]),
    (("simulate", "out"), "--angle", "0 deg", ["an angle other than 0"]),
    (("simulate", "out"), "--noise", "-0.3 deg/sqrt(h)", [">= 0"]),
    (("simulate", "out"), "--bias-walk", "-1 deg/h/sqrt(h)", [">= 0"]),
    (("simulate", "out"), "--misalignment", "-1 deg", [">= 0"]),
    (("simulate", "out"), "--dwell", "nan s", ["--dwell"]),
    # budget
    (("budget", MOUNT), "--exaggerate", "nan", ["a number > 0", "e.g. 30"]),
    (("budget", MOUNT), "--exaggerate", "inf", ["a number > 0"]),
    (("budget", MOUNT), "--exaggerate", "0", ["a number > 0"]),
    (("budget", MOUNT), "--exaggerate", "-3", ["a number > 0"]),
    (("budget", MOUNT), "--exaggerate", "thirty", ["a number > 0"]),
    (("budget", MOUNT), "--monte-carlo", "-1", ["a whole number >= 0", "e.g. 100000"]),
    (("budget", MOUNT), "--monte-carlo", "1.5", ["a whole number"]),
    (("budget", MOUNT), "--monte-carlo", "ten", ["a whole number"]),
    (("budget", MOUNT), "--monte-carlo", "1e12", ["<= 100000000"]),
    (("budget", MOUNT), "--seed", "-1", ["a whole number >= 0"]),
    (("budget", MOUNT), "--seed", "x", ["a whole number >= 0"]),
    # allan
    (("allan", LOG), "--rate-hz", "0", ["sample rate > 0"]),
    (("allan", LOG), "--rate-hz", "nan", ["sample rate > 0"]),
    (("allan", LOG), "--rate-hz", "1e300", ["<= 1e7 Hz"]),
    (("allan", LOG), "--rate-hz", "inf", ["sample rate"]),
    (("allan", LOG), "--rate-hz", "-100", ["sample rate > 0"]),
    (("allan", LOG, "--accuracy", "0.1 deg"), "--rate", "0 deg/s", ["an angular rate > 0"]),
    (("allan", LOG, "--rate", "100 deg/s"), "--accuracy", "-0.1 deg", ["an angle > 0 and <= 90 deg"]),
    (("allan", LOG, "--rate", "100 deg/s"), "--accuracy", "100 deg", ["<= 90 deg"]),
    (("allan", LOG), "--per-decade", "0", ["a whole number >= 1"]),
    (("allan", LOG), "--per-decade", "ten", ["a whole number >= 1"]),
    (("allan", LOG), "--memory-limit-mb", "0", ["a number > 0"]),
    (("allan", LOG), "--memory-limit-mb", "nan", ["a number > 0"]),
    (("allan", LOG), "--noise-ratio", "0", ["a number > 0"]),
    (("allan", LOG), "--noise-ratio", "-10", ["a number > 0"]),
    (("allan", LOG), "--grid", "0,1", ["taus > 0"]),
    (("allan", LOG), "--grid", "nan,1", ["taus > 0"]),
    (("allan", LOG), "--grid", "weekly", ["dense, octave, decade"]),
    # plan
    (PLAN_CMD, "--steps", "0", ["a whole number >= 1", "e.g. 6"]),
    (PLAN_CMD, "--steps", "1.5", ["a whole number >= 1"]),
    (PLAN_CMD, "--settle", "-5 s", ["a time >= 0"]),
    (("plan", "--accuracy", "0.1 deg", "--arw", "0.3 deg/sqrt(h)"), "--rate", "0 deg/s", ["an angular rate > 0"]),
    (("plan", "--accuracy", "0.1 deg", "--arw", "0.3 deg/sqrt(h)"), "--rate", "-100 deg/s", ["> 0"]),
    (("plan", "--rate", "100 deg/s", "--arw", "0.3 deg/sqrt(h)"), "--accuracy", "-0.1 deg", ["an angle > 0"]),
    (("plan", "--rate", "100 deg/s", "--arw", "0.3 deg/sqrt(h)"), "--accuracy", "0 deg", ["an angle > 0"]),
    (PLAN_CMD, "--noise-ratio", "0", ["a number > 0"]),
    (PLAN_CMD, "--turn-angle", "0 deg", ["other than 0"]),
    (("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg"), "--arw", "0 deg/sqrt(h)", ["an angle random walk > 0"]),
    (("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg"), "--arw", "-0.3 deg/sqrt(h)", ["> 0"]),
    (PLAN_CMD, "--bias-instability", "-6 deg/h", [">= 0"]),
    (PLAN_CMD, "--rate-random-walk", "-3 deg/h/sqrt(h)", [">= 0"]),
    # matrix, apply
    (("matrix", LOG, "--plan", PLAN), "--rate-hz", "0", ["sample rate > 0"]),
    (("matrix", LOG, "--plan", PLAN), "--min-dwell", "0 s", ["a time > 0"]),
    (("matrix", LOG, "--plan", PLAN), "--window", "-0.1 s", ["a time > 0"]),
    (("matrix", LOG, "--plan", PLAN), "--margin", "-0.1 s", ["a time >= 0"]),
    (("matrix", LOG, "--plan", PLAN), "--gyro-range", "0 deg/s", ["an angular rate > 0"]),
    (("matrix", LOG, "--plan", PLAN), "--static-threshold", "-1 deg/s", ["> 0"]),
    (("matrix", LOG, "--plan", PLAN), "--rate-tolerance", "-10 %", ["> 0"]),
    (("matrix", LOG, "--plan", PLAN), "--scale-tolerance", "0 %", ["> 0"]),
    (("matrix", LOG, "--plan", PLAN), "--axis-to-axis", "-0.05 deg", ["an angle > 0"]),
    (("apply", LOG, "--alignment", SEC, "--out", "c.csv"), "--rate-hz", "0", ["sample rate > 0"]),
    # report
    (REPORT, "--rate", "0 deg/s", ["an angular rate > 0"]),
    (REPORT, "--accuracy", "-1 deg", ["an angle > 0"]),
    (REPORT, "--monte-carlo", "-5", ["a whole number >= 0"]),
    (REPORT, "--seed", "-1", ["a whole number >= 0"]),
    (REPORT, "--rate-hz", "0", ["sample rate > 0"]),
    # calibrate
    (("calibrate", "ferraris", LOG, "--sections", SEC), "--rate-hz", "0", ["sample rate > 0"]),
    (FERRARIS, "--turn-angle", "0 deg", ["other than 0"]),
    (FERRARIS, "--gravity", "0 m/s^2", ["an acceleration > 0"]),
    (FERRARIS, "--gravity", "-9.81 m/s^2", ["an acceleration > 0"]),
    (("calibrate", "accel", LOG), "--gravity", "-9.8 m/s^2", ["an acceleration > 0"]),
    (("calibrate", "accel", LOG), "--window", "0 s", ["a time > 0"]),
    (("calibrate", "accel", LOG), "--factor", "0", ["a number > 0"]),
    (("calibrate", "accel", LOG), "--factor", "nan", ["a number > 0"]),
    (("calibrate", "accel", LOG), "--init-static", "0 s", ["a time > 0"]),
    (("calibrate", "accel", LOG), "--min-static", "-1 s", ["a time > 0"]),
    (("calibrate", "accel", LOG), "--rate-hz", "nan", ["sample rate > 0"]),
    (("calibrate", "mag", LOG), "--dip", "120 deg", ["within -90 deg and 90 deg"]),
    (("calibrate", "mag", LOG), "--dip", "-91 deg", ["within -90 deg and 90 deg"]),
]


def _id(case):
    before, flag, bad, _ = case
    return f"{' '.join(w for w in before[:2] if not w.startswith('absent'))} {flag} {bad}"


@pytest.mark.parametrize("case", CASES, ids=[_id(c) for c in CASES])
def test_a_value_outside_its_domain_is_a_one_line_usage_error(tmp_path, monkeypatch, run_cli, case):
    before, flag, bad, words = case
    monkeypatch.chdir(tmp_path)
    res = run_cli(*before, flag, bad)
    assert res.code == 2, (res.code, res.out, res.err)
    lines = res.err.splitlines()
    assert len(lines) == 1 and "Traceback" not in res.err, res.err
    line = lines[0]
    assert line.startswith("imu-align ") and "invalid value" in line, line
    shown = "--rate-hz" if flag == "--fs" else flag
    assert f"for {shown}:" in line, line                          # names the option
    assert "give " in line or "write " in line, line              # and what to type
    for w in words:
        assert w in line, (w, line)
    assert "Input should be" not in line  # pydantic's words are never shown
    assert res.out == "" and list(tmp_path.iterdir()) == []  # nothing computed, nothing written


@pytest.mark.parametrize("text,hz", [("1e7", 1e7), ("10 kHz", 1e4), ("0.001", 0.001), (100, 100.0)])
def test_sample_rate_bounds_are_inclusive_at_the_top(text, hz):
    assert hertz(text) == pytest.approx(hz)


@pytest.mark.parametrize("text", ["1.1e7", "inf", "nan", "-0", "0 Hz", "1e300"])
def test_sample_rate_outside_the_bounds(text):
    with pytest.raises(ValueError, match="give a sample rate > 0 Hz and <= 1e7 Hz"):
        hertz(text)


def test_domains_of_quantities():
    assert quantity("time", NONNEGATIVE)("0 s") == 0.0
    assert quantity("time", POSITIVE)("1 ms") == pytest.approx(1e-3)
    assert quantity("angle", NONZERO)("-360 deg") == pytest.approx(-2 * 3.141592653589793)
    assert quantity("angle", DIP)("-90 deg") == pytest.approx(-90 * DEG)
    assert quantity("angle", ACCURACY)("90 deg") == pytest.approx(90 * DEG)
    for parse, text, words in ((quantity("time", POSITIVE, "'10 s'"), "0 s", "give a time > 0, e.g. '10 s'"),
                               (quantity("time", NONNEGATIVE), "-1 s", "give a time >= 0, e.g. '30 s'"),
                               (quantity("angle", DIP), "90.1 deg", "within -90 deg and 90 deg"),
                               (quantity("angle", ACCURACY), "90.1 deg", "> 0 and <= 90 deg"),
                               (quantity("angle", NONZERO), "0 deg", "other than 0")):
        with pytest.raises(ValueError, match=words.replace("(", r"\(")):
            parse(text)


def test_whole_numbers_and_plain_numbers():
    assert whole(1)("6") == 6 and whole(0)("1e5") == 100_000 and whole(0)(" 7 ") == 7 and whole(0)(3) == 3
    for text in ("1.5", "x", "nan", "-1", ""):
        with pytest.raises(ValueError, match="give a whole number >= 0, e.g. 100000"):
            whole(0)(text)
    with pytest.raises(ValueError, match="<= 10"):
        whole(1, 10)("11")
    assert number(POSITIVE)("2.5") == 2.5
    for text in ("0", "-1", "nan", "inf", "abc"):
        with pytest.raises(ValueError, match="give a number > 0, e.g. 10"):
            number(POSITIVE)(text)


def test_a_field_the_command_has_no_option_for_is_spelled_in_words():
    known = frozenset({"--rate-hz", "--accel-units", "--accel-columns", "--gyro-columns", "LOG"})
    assert spell("min_dwell", None, "calibrate ferraris", known) == "min dwell"
    assert spell("rate_hz", None, "calibrate ferraris", known) == "--rate-hz"
    assert spell("units", None, "calibrate ferraris", known) == "--accel-units"
    assert spell("columns", None, "calibrate ferraris", known) == "--accel-columns or --gyro-columns"
    assert spell("method", "lsq", "calibrate ferraris", known) == "method = lsq"
    assert spell("log", None, "calibrate ferraris", known) == "LOG"
    assert spell("earth_correction", "false", "matrix", frozenset({"--earth", "--no-earth"})) == "--no-earth"
    assert spell("earth_correction", "false", "report", frozenset({"--log"})) == "earth correction = false"
    assert spell("min_dwell", None, "matrix") == "--min-dwell"  # without the command's options: the table alone


def _library_fields() -> set[str]:
    """Every ``{field}`` / ``{field=value}`` placeholder in the library's string literals."""
    import ast
    import re

    from support import ROOT

    found = set()
    pattern = re.compile(r"(?<!\{)\{([a-z][a-z0-9_]*)(?:=[^{}]*)?\}(?!\})")
    for path in list((ROOT / "align").rglob("*.py")) + list((ROOT / "mechanics").glob("*.py")):
        if "cli" in path.parts:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Constant) and isinstance(node.value, str):
                found |= set(pattern.findall(node.value))
    return found


@pytest.mark.slow
def test_every_library_field_renders_as_an_option_of_the_command_or_in_words():
    """No message names an option the command does not have (``--units`` for ``--gyro-units``, ``--min-dwell``
    in ``ferraris``): each placeholder is spelled as one of the command's own options, or in plain words."""
    from align.cli import COMMANDS, _known

    fields = _library_fields()
    assert {"gyro_units", "rate_hz", "min_dwell"} <= fields
    for name, subs in COMMANDS.items():
        for path in ([name, s] for s in subs) if subs else [[name]]:
            known = _known(path)
            for field in fields:
                shown = spell(field, None, " ".join(path), known)
                if shown.startswith("--") or shown.isupper():
                    assert all(part in known for part in shown.split(" or ")), (path, field, shown)
                else:
                    assert "--" not in shown, (path, field, shown)
