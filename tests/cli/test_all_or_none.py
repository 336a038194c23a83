"""A run's outputs are all or none: a failure after the first output was computed leaves no output at all
(nor a temporary file, nor a folder the run created), an output that existed keeps its old content, and the
inputs are untouched. Covers the issue's cases (``matrix --json`` then a failing ``--c-header``, ``budget
--json`` then ``--plot``, ``allan --json`` then ``--plot``, ``ferraris --json`` then ``--imucal-json``, ``demo``
when the report cannot be made) and :class:`align.io.outputs.Outputs` itself.
"""

import errno
import os
from pathlib import Path

import numpy as np
import pytest
from support import ROOT, SHARED, truth_model, write_session

from align.errors import InputError
from align.io.outputs import Outputs

MOUNT = ROOT / "examples" / "budget" / "example1.toml"
FERRARIS = SHARED / "data" / "multiposition" / "imucal_ferraris"


def _boom(*args, **kwargs):
    raise InputError("cannot make this output (a failure injected by the test)", "test")


def _interrupt(*args, **kwargs):
    raise KeyboardInterrupt


def _snapshot(folder: Path) -> dict:
    """Every file under ``folder`` (hidden temporaries too) and its bytes."""
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.fixture
def session(tmp_path):
    from align.alignment.plan import Plan
    from align.alignment.simulate import SessionSpec, simulate_session
    from align.units import DEG

    plan = Plan.standard_rate(100 * DEG)
    t, g, _ = simulate_session(plan, truth_model(1), SessionSpec(dwell_s=2.0, static_s=1.0), 1)
    inputs = tmp_path / "in"
    inputs.mkdir()
    return write_session(inputs, t, g, plan)


@pytest.fixture
def static_log(tmp_path):
    from align.noise.sim import NoiseSpec, simulate_noise

    folder = tmp_path / "in"
    folder.mkdir(exist_ok=True)
    path = folder / "static.npy"
    np.save(path, simulate_noise(20_000, 100.0, NoiseSpec(white=1e-4), 3, np.random.default_rng(0)))
    return path


def _fails_leaving_nothing(run_cli, out: Path, before: dict, *args, code: int = 2):
    res = run_cli(*args)
    assert res.code == code, (res.code, res.out, res.err)
    assert len(res.err.splitlines()) == 1 and "Traceback" not in res.err, res.err
    assert _snapshot(out) == before  # no new output, no temporary, old outputs unchanged
    return res


# ---- the cases: the second output fails after the first was computed ----

@pytest.mark.parametrize("failure,code", [(_boom, 2), (_interrupt, 130)], ids=["error", "ctrl-c"])
def test_matrix_json_then_a_failing_c_header(tmp_path, session, run_cli, monkeypatch, failure, code):
    from align.alignment.result import AlignmentResult

    log, plan = session
    out = tmp_path / "out"
    out.mkdir()
    (out / "old.json").write_text("an earlier result\n")
    before, inputs = _snapshot(out), _snapshot(log.parent)
    monkeypatch.setattr(AlignmentResult, "as_c_header", failure)
    res = _fails_leaving_nothing(run_cli, out, before, "matrix", log, "--plan", plan, "--json", out / "old.json",
                                 "--c-header", out / "a.h", code=code)
    assert _snapshot(log.parent) == inputs
    if code == 130:
        assert "interrupted" in res.err


def test_matrix_writes_both_when_nothing_fails(tmp_path, session, run_cli):
    log, plan = session
    out = tmp_path / "out"
    out.mkdir()
    res = run_cli("matrix", log, "--plan", plan, "--json", out / "r.json", "--c-header", out / "a.h")
    assert res.code == 0, res.err
    assert sorted(p.name for p in out.iterdir()) == ["a.h", "r.json"]  # and no temporary left
    assert oct((out / "a.h").stat().st_mode & 0o777) == oct(0o666 & ~_umask())


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@pytest.mark.parametrize("drawing", ["histogram_png", "assembly_png", "assembly_glb"])
def test_budget_json_then_a_failing_picture(tmp_path, run_cli, monkeypatch, drawing):
    import mechanics

    out = tmp_path / "out"
    out.mkdir()
    before = _snapshot(out)
    monkeypatch.setattr(mechanics, drawing, _boom)
    _fails_leaving_nothing(run_cli, out, before, "budget", MOUNT, "--monte-carlo", "200", "--json", out / "b.json",
                           "--plot", out / "h.png", "--picture", out / "p.png", "--glb", out / "a.glb")


def test_allan_json_then_a_failing_plot(tmp_path, static_log, run_cli, monkeypatch):
    import align.present.plots

    out = tmp_path / "out"
    out.mkdir()
    before, inputs = _snapshot(out), _snapshot(static_log.parent)
    monkeypatch.setattr(align.present.plots, "allan_plot_png", _boom)
    _fails_leaving_nothing(run_cli, out, before, "allan", static_log, "--rate-hz", "100", "--json", out / "a.json",
                           "--plot", out / "a.png")
    assert _snapshot(static_log.parent) == inputs


def test_ferraris_json_then_a_failing_imucal_json(tmp_path, run_cli, monkeypatch):
    from align.calibration.results import CalibrationSet

    out = tmp_path / "out"
    out.mkdir()
    before = _snapshot(out)
    monkeypatch.setattr(CalibrationSet, "as_imucal", _boom)
    _fails_leaving_nothing(run_cli, out, before, "calibrate", "ferraris", FERRARIS / "example_ferraris_session.csv",
                           "--sections", FERRARIS / "example_ferraris_session_list.json", "--rate-hz", "102.4",
                           "--json", out / "cal.json", "--imucal-json", out / "imucal.json")


@pytest.mark.slow
def test_demo_whose_report_fails_leaves_no_file_and_no_folder(tmp_path, run_cli, monkeypatch):
    import align.present.html

    monkeypatch.setattr(align.present.html, "html_report", _boom)
    _fails_leaving_nothing(run_cli, tmp_path, {}, "demo", "--out", tmp_path / "new" / "demo")
    assert list(tmp_path.iterdir()) == []  # the folders it would have created are gone too


@pytest.mark.slow
def test_demo_into_an_existing_folder_keeps_the_old_files_on_a_failure(tmp_path, run_cli, monkeypatch):
    import align.present.html

    out = tmp_path / "demo"
    out.mkdir()
    (out / "report.html").write_text("<p>last week's report</p>")
    (out / "notes.txt").write_text("mine")
    before = _snapshot(out)
    monkeypatch.setattr(align.present.html, "html_report", _boom)
    _fails_leaving_nothing(run_cli, out, before, "demo", "--out", out)


def test_simulate_that_fails_leaves_no_folder(tmp_path, run_cli, monkeypatch):
    from align.alignment.plan import Plan

    monkeypatch.setattr(Plan, "to_toml", _boom)
    _fails_leaving_nothing(run_cli, tmp_path, {}, "simulate", tmp_path / "a" / "b", "--dwell", "1 s", "--gap", "0.5 s")
    assert list(tmp_path.iterdir()) == []


def test_a_failed_rename_undoes_the_renames_done(tmp_path, session, run_cli, monkeypatch):
    """The last step can fail too (a file made read-only meanwhile): the outputs already renamed are put back."""
    log, plan = session
    out = tmp_path / "out"
    out.mkdir()
    (out / "r.json").write_text("old result\n")
    before = _snapshot(out)
    real = os.replace

    def replace(src, dst, *a, **k):
        if Path(dst).name == "a.h":
            raise OSError(errno.EACCES, "Permission denied")
        return real(src, dst, *a, **k)

    monkeypatch.setattr(os, "replace", replace)
    res = _fails_leaving_nothing(run_cli, out, before, "matrix", log, "--plan", plan, "--json", out / "r.json",
                                 "--c-header", out / "a.h")
    assert "a.h" in res.err and "nothing was written" in res.err


# ---- Outputs itself ----

def test_outputs_stage_then_commit(tmp_path):
    with Outputs() as out:
        out.write_text(tmp_path / "a.txt", "text")
        out.write_bytes(tmp_path / "b.bin", b"\x00\x01")
        out.write_json(tmp_path / "c.json", {"x": np.float64(1.5), "y": np.array([1, 2]), "z": float("nan")})
        out.write_csv(tmp_path / "d.csv", ["t", "x"], np.array([[0.0, 1.0], [1.0, 2.0]]))
        assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith(".")) == []  # nothing yet
        assert out.staged(tmp_path / "d.csv").suffix == ".csv"  # readers know a staged file by its suffix
        assert out.staged(tmp_path / "a.txt").read_text() == "text"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt", "b.bin", "c.json", "d.csv"]
    assert (tmp_path / "c.json").read_text() == '{\n  "x": 1.5,\n  "y": [\n    1,\n    2\n  ],\n  "z": null\n}\n'
    assert (tmp_path / "d.csv").read_text().splitlines()[1:] == ["0,1", "1,2"]


@pytest.mark.parametrize("exc", [ValueError, KeyboardInterrupt])
def test_outputs_discard_on_any_exception(tmp_path, exc):
    (tmp_path / "a.txt").write_text("old")
    with pytest.raises(exc):
        with Outputs() as out:
            out.folder(tmp_path / "new" / "deeper")
            out.write_text(tmp_path / "a.txt", "new")
            out.write_text(tmp_path / "new" / "deeper" / "b.txt", "new")
            raise exc()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"] and (tmp_path / "a.txt").read_text() == "old"


def test_outputs_staged_twice_keeps_the_last_and_no_temporary(tmp_path):
    with Outputs() as out:
        out.write_text(tmp_path / "a.txt", "first")
        out.write_text(tmp_path / "a.txt", "second")
    assert [p.name for p in tmp_path.iterdir()] == ["a.txt"] and (tmp_path / "a.txt").read_text() == "second"


def test_outputs_in_a_missing_folder_is_one_error_naming_the_file(tmp_path):
    out = Outputs()
    out.write_text(tmp_path / "a.txt", "x")
    with pytest.raises(InputError, match="nothing was written") as info:
        out.write_text(tmp_path / "missing" / "b.txt", "x")
    assert str(tmp_path / "missing" / "b.txt") in str(info.value)
    out.discard()
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(RuntimeError):
        out.commit()  # an Outputs is used once
