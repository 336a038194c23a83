"""The story's jobs read their inputs only through the checked readers, and the demo's inputs are staged:
nothing is in the demo's folder before its run commits."""

import shutil

import pytest
from support import ROOT

from align.errors import InputError
from align.io.outputs import Outputs
from align.present.story import build_report, demo_inputs

MOUNT = ROOT / "examples" / "budget" / "example1.toml"
MANOEUVRE = ROOT / "examples" / "sensitivity" / "example2.toml"


@pytest.mark.parametrize("which", ["mount", "manoeuvre"])
def test_a_missing_input_is_one_input_error_naming_it(tmp_path, which):
    paths = {"mount": MOUNT, "manoeuvre": MANOEUVRE, which: tmp_path / "absent.toml"}
    with pytest.raises(InputError, match="file not found") as info:
        build_report(paths["mount"], paths["manoeuvre"], monte_carlo=0)
    assert str(tmp_path / "absent.toml") in str(info.value)


def test_an_input_that_is_not_utf8_is_one_input_error(tmp_path):
    bad = tmp_path / "mount.toml"
    bad.write_bytes(MOUNT.read_bytes() + "# caf\xe9\n".encode("latin-1"))
    with pytest.raises(InputError) as info:
        build_report(bad, MANOEUVRE, monte_carlo=0)
    assert "mount.toml" in str(info.value)


def test_report_shows_the_names_it_is_given_and_reads_the_source(tmp_path):
    copy = tmp_path / "elsewhere.toml"
    shutil.copy(MOUNT, copy)
    shown = tmp_path / "mount.toml"  # does not exist: only its copy is read
    page, _, results = build_report(shown, MANOEUVRE, monte_carlo=0,
                                    source=lambda p: copy if p == shown else p)
    assert str(shown) in page and str(copy) not in page
    assert results["budget"].total > 0


def test_demo_inputs_are_staged_until_the_commit(tmp_path):
    out = tmp_path / "demo"
    staged = Outputs()
    staged.folder(out)
    inp = demo_inputs(out, staged)
    assert [p for p in out.iterdir() if not p.name.startswith(".")] == []  # nothing under its own name yet
    assert staged.staged(inp["allan"]).suffix == ".npy" and staged.staged(inp["log"]).read_text().startswith('"time"')
    staged.discard()
    assert not out.exists()  # the folder it created is gone with the staged files


def test_demo_inputs_without_staging_are_written_at_once(tmp_path):
    inp = demo_inputs(tmp_path)
    assert {p.name for p in tmp_path.iterdir()} == {"mount.toml", "manoeuvre.toml", "static.npy", "session.csv",
                                                    "plan.toml"}
    assert inp["mount"].read_text() == (ROOT / "align" / "present" / "demo" / "mount.toml").read_text()
