"""simulate session | poses | lot, today's spelling (simulate DIR [--kind poses | --lot N]) giving the same files,
and no user's file replaced without --force (issue 28)."""

import pytest

from align.cli.simulate import old_spelling

SHORT = ["--dwell", "2 s", "--gap", "1 s", "--rate-hz", "50 Hz"]


def _files(folder):
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.parametrize("new, old", [
    (["session", "{d}", *SHORT, "--seed", "3"], ["{d}", *SHORT, "--seed", "3"]),
    (["session", "{d}", "--kind", "angle", *SHORT], ["{d}", "--kind", "angle", *SHORT]),
    (["poses", "{d}", "--poses", "3", "--seed", "2"], ["{d}", "--kind", "poses", "--poses", "3", "--seed", "2"]),
    (["poses", "{d}", "--poses", "3"], ["{d}", "--poses", "3", "--kind=poses"]),
    (["lot", "{d}", "--lot", "3", "--bad", "1", *SHORT], ["{d}", "--lot", "3", "--bad", "1", *SHORT]),
])
def test_the_new_and_the_old_spelling_write_the_same_files(tmp_path, run_cli, new, old):
    a, b = tmp_path / "new", tmp_path / "old"
    res = run_cli("simulate", *[str(a) if w == "{d}" else w for w in new])
    assert res.code == 0, res.err
    res = run_cli("simulate", *[str(b) if w == "{d}" else w for w in old])
    assert res.code == 0, res.err
    assert _files(a) == _files(b) and _files(a)


def test_a_folder_named_like_a_subcommand_is_the_old_spelling():
    assert old_spelling(["simulate", "lot", "--lot", "200", "--bad", "5"]) == \
        ["simulate", "lot", "lot", "--lot", "200", "--bad", "5"]
    assert old_spelling(["simulate", "lot", "out", "--lot", "2"]) == ["simulate", "lot", "out", "--lot", "2"]
    assert old_spelling(["simulate", "out", "--reorient", "--seed", "1"]) == \
        ["simulate", "session", "out", "--reorient", "--seed", "1"]
    assert old_spelling(["simulate", "--help"]) == ["simulate", "--help"]
    assert old_spelling(["simulate", "poses", "--help"]) == ["simulate", "poses", "--help"]
    assert old_spelling(["matrix", "log.csv"]) == ["matrix", "log.csv"]


@pytest.mark.parametrize("how", [["session", "{d}", *SHORT], ["{d}", *SHORT], ["{d}", "--kind", "poses", "--poses", "3"]])
def test_existing_files_are_not_replaced_without_force(tmp_path, run_cli, how):
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / "session.csv").write_text("my own log\n")
    (folder / "notes.txt").write_text("mine\n")
    args = [str(folder) if w == "{d}" else w for w in how]
    res = run_cli("simulate", *args)
    assert res.code == 2 and len(res.err.strip().splitlines()) == 1, res.err
    assert "session.csv" in res.err and "--force" in res.err
    assert (folder / "session.csv").read_text() == "my own log\n"
    res = run_cli("simulate", *args, "--force")
    assert res.code == 0, res.err
    assert (folder / "session.csv").read_text() != "my own log\n" and (folder / "notes.txt").read_text() == "mine\n"


def test_demo_refuses_to_replace_files_without_force(tmp_path, run_cli):
    folder = tmp_path / "demo"
    folder.mkdir()
    (folder / "report.html").write_text("my report")
    res = run_cli("demo", "--out", folder)
    assert res.code == 2 and "report.html" in res.err and "--force" in res.err
    assert len(res.err.strip().splitlines()) == 1 and (folder / "report.html").read_text() == "my report"


def test_help_lists_the_subcommands(run_cli):
    out = run_cli("simulate", "--help").out
    assert all(word in out for word in ("session", "poses", "lot"))
    assert "--lot" in run_cli("simulate", "lot", "--help").out


def test_a_subcommand_without_its_folder_is_a_usage_error_not_a_folder_named_after_it(run_cli, tmp_path,
                                                                                      monkeypatch):
    monkeypatch.chdir(tmp_path)
    for sub in ("session", "poses", "lot"):
        r = run_cli("simulate", sub)
        assert r.code == 2 and "missing argument OUT_DIR" in r.err and r.err.count("\n") == 1
    assert not any(tmp_path.iterdir())  # nothing written
