"""Every command that reads a log reads a stream of a log of several: ``--topic``, ``--stamps``, and the unit the
file states, never asked for (issue 24).

The log is the fake multi-stream format of ``tests/io/test_stream_logs.py`` (registered for each test); the truth
is the same samples written as a CSV by numpy/pyarrow and read with the unit given: ``matrix``, ``allan`` and
``calibrate accel`` give the same result on both, the stream's identity in the result's inputs.
"""

from __future__ import annotations

import hashlib
import importlib.util
import json

import numpy as np
import pytest
from support import ROOT

from align.io import write_csv
from align.results import load_result

PLAN = ROOT / "examples" / "alignment" / "plan.toml"
SESSION = ROOT / "examples" / "alignment" / "session.csv"
_spec = importlib.util.spec_from_file_location("imujson_fake", ROOT / "tests" / "io" / "test_stream_logs.py")
fake_format = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(fake_format)
GYRO = ["time", "gyro_x", "gyro_y", "gyro_z"]


@pytest.fixture
def fake(monkeypatch):
    fake_format.install(monkeypatch)


def _one_line(res, *words):
    assert res.code == 2, (res.code, res.out, res.err)
    line = res.err.strip()
    assert line.count("\n") == 0, line
    for w in words:
        assert w in line, (w, line)


def _session_in_rad_s():
    data = np.loadtxt(SESSION, delimiter=",", skiprows=1)  # the bundled session, deg/s
    return data[:, 0], np.deg2rad(data[:, 1:])


def test_matrix_on_a_stream_is_matrix_on_its_csv_copy_with_the_unit_given(tmp_path, fake, run_cli):
    t, g = _session_in_rad_s()
    log = fake_format.write_imujson(tmp_path / "session.imujson", fake_format.stream_header(),
                                    fake_format.imu_messages(t, g), truncated=True)
    copy = tmp_path / "session.csv"
    write_csv(copy, GYRO, np.column_stack([t, g]))
    res = run_cli("matrix", log, "--plan", PLAN, "--json", tmp_path / "stream.json")
    assert res.code == 0, res.err
    res = run_cli("matrix", copy, "--plan", PLAN, "--gyro-units", "rad/s", "--json", tmp_path / "csv.json")
    assert res.code == 0, res.err
    got, ref = load_result(tmp_path / "stream.json"), load_result(tmp_path / "csv.json")
    for name in ("M", "A", "bias", "sigma_M", "sigma_bias"):  # the same numbers (summed in another memory order)
        np.testing.assert_allclose(getattr(got, name), getattr(ref, name), rtol=1e-12, atol=1e-15)
    assert got.units == ref.units == "rad/s"
    assert got.inputs["stream"] == {"format": "imujson", "topic": "imu0", "instance": 0, "device_id": 7}
    assert got.inputs["units_stated"] == got.inputs["gyro_units"] == "rad/s"
    assert "stream" not in ref.inputs and "units_stated" not in ref.inputs and ref.inputs["gyro_units"] == "rad/s"
    assert set(ref.inputs) | {"stream", "units_stated"} == set(got.inputs)
    assert any(n.startswith(str(log)) and "last record truncated" in n for n in got.notes), got.notes
    assert [f.role for f in got.provenance.files][:1] == ["log"] and got.provenance.files[0].size == log.stat().st_size


def test_a_unit_the_file_contradicts_and_a_topic_on_a_csv_are_one_line(tmp_path, fake, run_cli):
    t, g = _session_in_rad_s()
    log = fake_format.write_imujson(tmp_path / "session.imujson", fake_format.stream_header(),
                                    fake_format.imu_messages(t[:500], g[:500]))
    _one_line(run_cli("matrix", log, "--plan", PLAN, "--gyro-units", "deg/s"), str(log), "--gyro-units", "rad/s")
    _one_line(run_cli("matrix", log, "--plan", PLAN, "--topic", "imu7"), str(log), "imu7", "imu0")
    _one_line(run_cli("matrix", SESSION, "--plan", PLAN, "--topic", "/imu0"), str(SESSION), "--topic")
    _one_line(run_cli("allan", SESSION, "--stamps", "record"), str(SESSION), "--stamps")
    _one_line(run_cli("matrix", SESSION, "--plan", PLAN, "--stamps", "sensor"), "--stamps", "give header", "record")


def _static_rad_s(n: int = 2000, fs: float = 100.0):
    rng = np.random.default_rng(11)
    return np.arange(n) / fs, rng.normal(0, 1e-3, (n, 3)) + [2e-3, -1e-3, 5e-4]


def _strip(d: dict) -> dict:
    return {k: v for k, v in d.items() if k not in ("provenance", "generator", "inputs", "adev_of")}


def test_allan_on_a_stream_is_allan_on_its_csv_copy(tmp_path, fake, run_cli):
    t, g = _static_rad_s()
    log = fake_format.write_imujson(tmp_path / "static.imujson", fake_format.stream_header(),
                                    fake_format.imu_messages(t, g))
    copy = tmp_path / "static.csv"
    write_csv(copy, GYRO, np.column_stack([t, g]))
    assert run_cli("allan", log, "--grid", "octave", "--json", tmp_path / "s.json").code == 0
    res = run_cli("allan", copy, "--grid", "octave", "--gyro-units", "rad/s", "--json", tmp_path / "c.json")
    assert res.code == 0, res.err
    got, ref = (json.loads((tmp_path / f).read_text()) for f in ("s.json", "c.json"))
    assert got["units"]["adev"] == "rad/s" and _strip(got) == {k: v for k, v in _strip(ref).items()} | {
        "streams": [{"stream": {"format": "imujson", "topic": "imu0", "instance": 0, "device_id": 7},
                     "units_stated": "rad/s"}]}
    _one_line(run_cli("allan", log, "--units", "deg/s"), str(log), "--units", "rad/s")
    folder = tmp_path / "bag"  # the same log as a log folder: read alike, its record the hash of its files
    folder.mkdir()
    (folder / "imujson.meta").write_text("imujson folder 1\n")
    (folder / "data.imujson").write_bytes(log.read_bytes())
    assert run_cli("allan", folder, "--grid", "octave", "--json", tmp_path / "f.json").code == 0
    by_folder = json.loads((tmp_path / "f.json").read_text())
    assert {k: v for k, v in _strip(by_folder).items() if k != "streams"} == _strip(ref)
    (rec,) = by_folder["provenance"]["files"]
    files = sorted(p for p in folder.iterdir())
    digest = hashlib.sha256(b"".join(p.name.encode() + b"\0" + hashlib.sha256(p.read_bytes()).digest() for p in files))
    assert (rec["path"], rec["size"], rec["sha256"]) == (str(folder), sum(p.stat().st_size for p in files),
                                                         digest.hexdigest())


def _positions(n: int = 300, seed: int = 2):
    rng = np.random.default_rng(seed)
    rows = [s * 9.80665 * np.eye(3)[k] + rng.normal(0, 1e-3, (n, 3)) for k in range(3) for s in (1, -1)]
    moves = [rng.normal(0, 3, (100, 3)) for _ in rows]
    a = np.vstack([x for pair in zip(rows, moves) for x in pair])
    return np.arange(len(a)) / 100.0, a


def test_calibrate_accel_on_a_stream_is_the_same_on_its_csv_copy(tmp_path, fake, run_cli):
    t, a = _positions()
    log = fake_format.write_imujson(tmp_path / "acc.imujson", fake_format.stream_header(),
                                    fake_format.imu_messages(t, a=a))
    copy = tmp_path / "acc.csv"
    write_csv(copy, ["time", "acc_x", "acc_y", "acc_z"], np.column_stack([t, a]))
    positions = tmp_path / "positions.toml"
    positions.write_text("".join(f'[[position]]\nup = "{u}"\n' for u in ("+x", "-x", "+y", "-y", "+z", "-z")))
    res = run_cli("calibrate", "accel", log, "--positions", positions, "--json", tmp_path / "s.json")
    assert res.code == 0, res.err
    res = run_cli("calibrate", "accel", copy, "--positions", positions, "--accel-units", "m/s^2", "--json",
                  tmp_path / "c.json")
    assert res.code == 0, res.err
    got, ref = load_result(tmp_path / "s.json"), load_result(tmp_path / "c.json")
    g_cal, r_cal = got.sensor("accelerometer"), ref.sensor("accelerometer")
    np.testing.assert_allclose(g_cal.M, r_cal.M, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(g_cal.bias, r_cal.bias, rtol=1e-12, atol=1e-12)
    assert got.inputs["stream"]["topic"] == "imu0" and got.inputs["accel_units"] == "m/s^2"
    assert got.inputs["columns"] == "time,accel_x,accel_y,accel_z" and "stream" not in ref.inputs


def test_a_batch_row_takes_topic_and_stamps_as_the_command_does(tmp_path, fake, run_cli):
    """A manifest row's --topic and --stamps reach the job as the single command's do: the row reads the second
    stream (twice the noise) at its record stamps (every 20 ms: half the rate of its header stamps)."""
    import dataclasses

    from align.api import job
    from align.cli.batch import _jobs
    from align.cli.batchjobs import check_options, prepare_unit
    from align.io.formats import LogFormat
    from align.production import read_manifest
    from align.values import approx_equal

    t, g = _static_rad_s(1500)
    second = fake_format.imu_messages(t, g * 2, topic="imu1")
    for m in second:
        m["rt"] = 2 * m["t"]  # the recorder's clock
    fake_format.write_imujson(tmp_path / "static.imujson", fake_format.stream_header(),
                              fake_format.imu_messages(t, g) + second)
    manifest = tmp_path / "lot.csv"
    manifest.write_text("serial,job,log,plan,options\nSN1,allan,static.imujson,,--topic imu1 --stamps record --grid octave\n")
    (unit,) = read_manifest(manifest, _jobs()).units
    check_options(unit, str(manifest))
    prepared = prepare_unit(unit, tmp_path, str(manifest))
    assert (prepared.options.format.topic, prepared.options.format.stamps) == ("imu1", "record")
    by_row = job("allan").run(prepared.options)
    res = run_cli("allan", tmp_path / "static.imujson", "--topic", "imu1", "--stamps", "record", "--grid", "octave",
                  "--json", tmp_path / "one.json")
    assert res.code == 0, res.err
    assert approx_equal(_strip(by_row.to_dict()), _strip(load_result(tmp_path / "one.json").to_dict()), rtol=1e-12)
    first = job("allan").run(dataclasses.replace(prepared.options, format=LogFormat(topic="imu0")))
    assert by_row.result.fs == pytest.approx(50.0) and first.result.fs == pytest.approx(100.0)
    assert by_row.result.adev[0, 0] == pytest.approx(2 * first.result.adev[0, 0], rel=1e-9)  # at one sample
