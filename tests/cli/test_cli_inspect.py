"""``imu-align inspect LOG``: what a log holds before any job (issue 24).

Truth by construction: a CSV written here with samples dropped (two gaps of 5 and 2 samples), a stamp repeated,
two stamps swapped, a channel held at +/-250 for 20 and 10 samples, a temperature ramp; and a log of the fake
multi-stream format of ``tests/io/test_stream_logs.py`` with an empty topic, a camera topic and a truncated record.
"""

from __future__ import annotations

import importlib.util
import json

import numpy as np
import pytest
from support import ROOT, SHARED

from align.io import write_csv

_spec = importlib.util.spec_from_file_location("imujson_fake", ROOT / "tests" / "io" / "test_stream_logs.py")
fake_format = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(fake_format)


@pytest.fixture
def fake(monkeypatch):
    fake_format.install(monkeypatch)


def _flawed_log(path):
    """1000 samples at 100 Hz; then rows 200-204 and 500-501 dropped, the row at t=3 s repeated, the rows at
    t=8.00 and 8.01 s swapped. gyro_x held at +250 over rows 100-119 and at -250 over rows 600-609."""
    k = np.arange(1000)
    t = k / 100.0
    gx = 10 * np.sin(2 * np.pi * 0.3 * t)
    gx[100:120], gx[600:610] = 250.0, -250.0
    rows = np.column_stack([t, gx, 5 * np.cos(2 * np.pi * 0.37 * t), np.zeros(1000), 20.0 + t])
    keep = [i for i in k if not (200 <= i <= 204 or 500 <= i <= 501)]
    order = []
    for i in keep:
        order += [i, i] if i == 300 else [i]
    a, b = order.index(800), order.index(801)
    order[a], order[b] = order[b], order[a]
    write_csv(path, ["time", "gyro_x", "gyro_y", "gyro_z", "temperature"], rows[order])
    return path


def test_gaps_dropped_samples_time_out_of_order_clipping_and_temperature(tmp_path, run_cli):
    log = _flawed_log(tmp_path / "flawed.csv")
    out = tmp_path / "inspect.json"
    res = run_cli("inspect", log, "--json", out)
    assert res.code == 0, res.err
    d = json.loads(out.read_text())
    assert [d[k] for k in ("format", "version")] == ["imu-align.inspect", 1] and d["units"]["time"] == "s"
    assert d["reader"] == "csv" and d["streams"] == []
    (s,) = d["series"]
    f = s["time"]
    # gaps: the two drops (5 and 2 samples) and the two 20 ms steps around the swap (1 each); back: the swap
    assert (f["count"], f["gaps"], f["dropped"], f["backwards"], f["repeated"]) == (994, 4, 9, 1, 1)
    assert f["rate_hz"] == pytest.approx(100.0) and f["duration_s"] == pytest.approx(9.99)
    assert f["largest_gap_s"] == pytest.approx(0.06) and f["largest_gap_at_s"] == pytest.approx(1.99)
    assert f["out_of_order_at_s"] == pytest.approx(3.0)
    assert s["clipped"] == {"gyro_x": 30}
    assert s["temperature_c"] == {"min": pytest.approx(20.0), "max": pytest.approx(29.99)}
    assert s["units"] == {} and s["time_units"] == "s"
    text = " ".join(res.out.split())
    for words in ("994 samples; 100 Hz measured", "4 gaps", "about 9 samples dropped; largest 0.06 s at t=1.99 s",
                  "1 step back, 1 repeated stamp (first at t=3 s)", "temperature 20 to 29.99 C",
                  "clipped: gyro_x 30 samples", "(no units stated)"):
        assert words in text, (words, res.out)


def _stream_log(path):
    t = np.arange(500) / 200.0
    rng = np.random.default_rng(5)
    g, a = rng.normal(0, 1e-3, (500, 3)), rng.normal(0, 1e-2, (500, 3)) + [0, 0, 9.81]
    messages = fake_format.imu_messages(t, g, a, 30.0 + 0.01 * np.arange(500))
    messages += [{"s": "cam", "t": float(x)} for x in t[::10]]
    return fake_format.write_imujson(path, fake_format.stream_header(rate_hz=200.0), messages, truncated=True)


def test_a_log_of_several_streams_lists_them_and_reads_each_imu_stream(tmp_path, fake, run_cli):
    log = _stream_log(tmp_path / "flight.imujson")
    out = tmp_path / "inspect.json"
    res = run_cli("inspect", log, "--json", out)
    assert res.code == 0, res.err
    d = json.loads(out.read_text())
    assert [(s["topic"], s["kind"], s["count"]) for s in d["streams"]] == [("imu0", "Imu", 500), ("imu1", "Imu", 0),
                                                                           ("cam", "Image", 50)]
    imu0, imu1 = d["series"]
    assert imu1 == {**imu1, "name": "imu1", "empty": True}
    assert imu0["time"]["count"] == 500 and imu0["time"]["nominal_hz"] == 200.0
    assert imu0["time"]["rate_hz"] == pytest.approx(200.0) and imu0["time"]["gaps"] == 0
    assert imu0["units"]["gyro_x"] == "rad/s" and imu0["units"]["accel_z"] == "m/s^2"
    assert imu0["source"]["device_id"] == 7 and imu0["clipped"] == {}
    assert imu0["temperature_c"] == {"min": pytest.approx(30.0), "max": pytest.approx(34.99)}
    assert any("last record truncated" in n for n in imu0["notes"])
    lines = res.out.splitlines()
    assert "imu1 (Imu): no message" in lines and any("cam" in x and "50 messages" in x for x in lines)
    assert any("units stated: time s, gyro_x/gyro_y/gyro_z rad/s, accel_x/accel_y/accel_z m/s^2, temperature degC"
               in x for x in lines), res.out


def test_a_topic_asked_for_an_empty_one_and_one_that_is_not_there(tmp_path, fake, run_cli):
    log = _stream_log(tmp_path / "flight.imujson")
    res = run_cli("inspect", log, "--topic", "imu1")
    assert res.code == 0 and res.out.splitlines()[-1] == "imu1 (Imu): no message", res.out
    res = run_cli("inspect", log, "--topic", "imu0", "--stamps", "record")
    assert res.code == 0 and "500 samples" in res.out and "imu1" not in res.out.split("\n", 4)[-1]
    res = run_cli("inspect", log, "--topic", "/imu9")
    assert res.code == 2 and res.err.strip().count("\n") == 0 and "/imu9" in res.err and "imu0" in res.err
    res = run_cli("inspect", ROOT / "examples" / "alignment" / "session.csv", "--topic", "/imu0")
    assert res.code == 2 and "--topic" in res.err and res.err.strip().count("\n") == 0


def test_a_log_folder_is_inspected_and_another_folder_refused(tmp_path, fake, run_cli):
    folder = tmp_path / "bag"
    folder.mkdir()
    (folder / "imujson.meta").write_text("imujson folder 1\n")
    _stream_log(folder / "data.imujson")
    res = run_cli("inspect", folder)
    assert res.code == 0 and "imujson folder, 3 streams" in res.out, res.err
    res = run_cli("inspect", tmp_path)
    assert res.code == 2 and "not a log folder" in res.err and res.err.strip().count("\n") == 0


ULOG = SHARED / "data" / "logs" / "px4_ulog" / "sample_log_small.ulg"


@pytest.mark.skipif(not ULOG.is_file(), reason="../shared/data not present")
def test_a_real_ulog_shows_the_figures_its_source_states(monkeypatch, run_cli, tmp_path):
    """SOURCE.txt (pyulog and a separate parser): sensor_combined 1,298 samples over 20.327..26.823 s, median step
    4,888 us, one 161 ms gap after the first sample; sensor_gyro[0] device 2424842 at 40.025..40.361 C; no
    sensor_mag[2] message."""
    ulog = pytest.importorskip("align.io.ulog")
    from align.io import readers

    monkeypatch.setattr(readers, "READERS", list(readers.READERS))
    readers.register(ulog.READER)
    out = tmp_path / "ulog.json"
    res = run_cli("inspect", ULOG, "--json", out)
    assert res.code == 0, res.err
    series = {s["name"]: s for s in json.loads(out.read_text())["series"]}
    f = series["sensor_combined"]["time"]
    assert f["count"] == 1298 and f["rate_hz"] == pytest.approx(1e6 / 4888, rel=2e-3)
    assert f["duration_s"] == pytest.approx(26.823 - 20.327, abs=2e-3) and f["gaps"] == 1
    assert f["largest_gap_s"] == pytest.approx(0.161, abs=1e-3) and f["largest_gap_at_s"] == pytest.approx(20.327,
                                                                                                          abs=1e-3)
    gyro0 = series["sensor_gyro:0"]
    assert gyro0["source"]["device_id"] == 2424842 and gyro0["units"]["gyro_x"] == "rad/s"
    assert gyro0["temperature_c"] == {"min": pytest.approx(40.025, abs=1e-3), "max": pytest.approx(40.361, abs=1e-3)}
    assert series["sensor_mag:2"]["empty"] and "sensor_mag:2 (sensor_mag): no message" in res.out.splitlines()
    assert all(not s["clipped"] for s in series.values())  # a short flight, no sensor at its range
