"""--help: every TOML section name survives, old spellings stay hidden, one spelling per concept."""

import re

import pytest
import typer

from align.cli import COMMANDS, app
from align.cli.options import ALIASES

PATHS = [(name,) if not subs else (name, sub) for name, subs in COMMANDS.items() for sub in (subs or (None,))]
SECTION = re.compile(r"\[\[?[a-z_]+\]\]?")


def _params(path):
    command = typer.main.get_command(app)
    for word in path:
        command = command.commands[word]
    return command


@pytest.mark.parametrize("path", PATHS, ids=" ".join)
def test_help_shows_every_toml_section_name(run_cli, path):
    command = _params(path)
    texts = [command.help or ""] + [getattr(p, "help", None) or "" for p in command.params]
    sections = {s for t in texts for s in SECTION.findall(t)}
    res = run_cli(*path, "--help")
    assert res.code == 0, res.err
    shown = " ".join(res.out.split())
    for s in sections:
        assert s in shown, (s, res.out)


def test_the_issue_example_budget_help(run_cli):
    shown = " ".join(run_cli("budget", "--help").out.split())
    assert "[imu], [package], [ledges] or [baseplate], [screws]" in shown
    for path, sections in ((("matrix",), ["[[step]]"]), (("allowable",), ["[[rotation]]", "[series]", "[limits]"]),
                           (("calibrate", "accel"), ["[[position]]"])):
        shown = " ".join(run_cli(*path, "--help").out.split())
        for s in sections:
            assert s in shown, (path, s)


@pytest.mark.parametrize("command", sorted(ALIASES))
def test_old_spellings_are_hidden_but_today_s_are_shown(run_cli, command):
    out = run_cli(*command.split(), "--help").out
    for old, new in ALIASES[command].items():
        assert re.search(rf"(?<![\w-]){re.escape(new)}(?![\w-])", out), (command, new)
        assert not re.search(rf"(?<![\w-]){re.escape(old)}(?![\w-])", out), (command, old)


@pytest.mark.slow
def test_one_spelling_per_concept():
    """No command offers a retired spelling; units, columns and the sample rate are spelled one way."""
    retired = {"--gyr-units", "--acc-units", "--allan-units", "--gyr-columns", "--acc-columns", "--allan-columns",
               "--allan-rate-hz", "--fs"}
    units = {"--gyro-units", "--accel-units", "--mag-units", "--units", "--time-units", "--temperature-units"}
    for path in PATHS:
        opts = {o for p in _params(path).params for o in getattr(p, "opts", []) if o.startswith("--")}
        assert not opts & retired, (path, opts & retired)
        assert all(o in units for o in opts if o.endswith("-units") or o == "--units"), path
        assert all(o in ("--columns", "--gyro-columns", "--accel-columns") for o in opts if o.endswith("columns")), path
        # report reads two files: --rate-hz is its static record's, --log-rate-hz its rate-table log's
        assert not any("rate-hz" in o and o != "--rate-hz" for o in opts
                       if (tuple(path), o) != (("report",), "--log-rate-hz")), path
