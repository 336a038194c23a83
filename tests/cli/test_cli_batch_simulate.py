"""The rehearsal lot (`imu-align simulate OUT --lot N`, through its body `simulate_lot_command`): files, truth, all or none."""

from __future__ import annotations

import numpy as np
import pytest

import align
from align.cli.batch import simulate_lot_command
from align.errors import InputError
from align.production.rehearsal import read_truth
from align.units import DEG


def _make(out, n=12, bad=5, **kw):
    args = dict(spread=0.03 * DEG, scale_spread=1e-3, bias_spread=0.2 * DEG, bad=bad, seed=4, rate=100 * DEG,
                dwell=2.0, gap=1.0, rate_hz=200.0, noise=0.3 * DEG / 60)
    args.update(kw)
    simulate_lot_command(out, n, **args)


def test_a_lot_is_written_with_its_truth_and_its_bad_units(tmp_path, capsys):
    out = tmp_path / "new" / "lot"
    _make(out)
    said = capsys.readouterr().out
    assert sorted(p.name for p in out.iterdir()) == ["manifest.csv", "plan.toml", "sessions", "truth.csv"]
    assert not [p for p in (tmp_path / "new").iterdir() if p.name != "lot"]  # no staging folder left
    head, truth = read_truth(out / "truth.csv")  # its first line states format, version, convention and units
    assert head["version"] == "1" and head["units"]["phi_"] == "rad" and "rows of M are sensor axes" in head["convention"]
    assert head["generator"] == f"imu-align {align.__version__}"
    kinds = [r["kind"] for r in truth]
    assert len(truth) == 12 and kinds.count("out of spec") == 2 and kinds.count("wrong direction") == 2 \
        and kinds.count("nan rows") == 1
    for r in truth:
        if r["kind"] != "good":
            assert f"{r['serial']} ({r['kind']})" in said
    good = [r for r in truth if r["kind"] == "good"]
    phis = np.array([[float(r[f"phi_{p}"]) for p in ("xy", "xz", "yx", "yz", "zx", "zy")] for r in good])
    assert 0.01 * DEG < phis.std() < 0.06 * DEG  # drawn around the nominal part with the spread asked for
    off = [r for r in truth if r["kind"] == "out of spec"]
    assert all(max(abs(float(r[f"phi_{p}"])) for p in ("xy", "xz", "yz")) > 0.2 * DEG for r in off)
    sessions = sorted(p.stem for p in (out / "sessions").iterdir())
    assert sessions == [r["serial"] for r in truth]
    nan_log = out / "sessions" / f"{[r for r in truth if r['kind'] == 'nan rows'][0]['serial']}.csv"
    assert "nan" in nan_log.read_text().lower()


def test_the_same_seed_gives_the_same_lot(tmp_path):
    _make(tmp_path / "a", n=3, bad=1)
    _make(tmp_path / "b", n=3, bad=1)
    assert (tmp_path / "a" / "truth.csv").read_text() == (tmp_path / "b" / "truth.csv").read_text()
    assert (tmp_path / "a" / "sessions" / "SN0002.csv").read_bytes() == (tmp_path / "b" / "sessions" /
                                                                         "SN0002.csv").read_bytes()


def test_a_failed_or_refused_lot_writes_nothing(tmp_path, monkeypatch):
    import align.production.rehearsal as rehearsal

    calls = []

    def failing(*args, **kw):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(*args, **kw)

    real = rehearsal.simulate_run
    monkeypatch.setattr(rehearsal, "simulate_run", failing)
    with pytest.raises(KeyboardInterrupt):
        _make(tmp_path / "lot", n=5)
    assert not (tmp_path / "lot").exists() and list(tmp_path.iterdir()) == []
    monkeypatch.setattr(rehearsal, "simulate_run", real)
    (tmp_path / "lot").mkdir()
    (tmp_path / "lot" / "manifest.csv").write_text("x")
    with pytest.raises(InputError, match="already holds manifest.csv; give an empty or new folder"):
        _make(tmp_path / "lot", n=2)
    with pytest.raises(InputError, match="13 bad units in a lot of 12"):
        _make(tmp_path / "other", bad=13)
    assert not (tmp_path / "other").exists()
