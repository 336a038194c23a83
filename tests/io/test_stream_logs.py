"""Logs of several streams through the one log reader: stated units, the stream in the provenance, the reader's
notes, a DataFlash-like ``.bin`` deferred to its reader, folders as logs (align.io, align.provenance).

The format here is a fake of this module's own (``imujson``), registered for the test: the plumbing is tested
without any real format's reader. Its documentation, from which the tests write their files:

* UTF-8 text, one JSON object a line. Line 1, the header: ``{"imujson": 1, "streams": {TOPIC: {"kind": str,
  "device_id": int, "nominal_rate_hz": float, "units": {"t": "s", "g": "rad/s", "a": "m/s^2", "m": "gauss",
  "T": "degC"}}}}`` (a stream without ``g``, ``a`` and ``m`` is no IMU stream);
* then one message a line: ``{"s": TOPIC, "t": header stamp, "rt": record stamp, "g": [x, y, z], "a": [x, y, z],
  "m": [x, y, z], "T": temperature}``; a last line that is no JSON object is a truncated record, left out and
  reported;
* a ``.bin`` of the fake DataFlash kind is the same text after a first line ``FAKEBIN``; a log folder holds
  ``imujson.meta`` and ``data.imujson``.

The readers name the columns by the one convention (``time``, ``gyro_x`` ..., ``accel_x`` ..., ``temperature``).
Other test modules load this one by its path for the fake readers (:func:`install`).
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pytest
from support import SHARED

from align.errors import InputError
from align.io import readers
from align.io.formats import LogFormat
from align.io.readers import Columns, LogReader, Stream

MAGIC = b"FAKEBIN\n"
#: the last line of a truncated log: a record cut short
TRUNCATED = '{"s": "imu0", "t": 1'
UNITS = {"t": "s", "g": "rad/s", "a": "m/s^2", "m": "gauss", "T": "degC"}
_FIELDS = (("g", ("gyro_x", "gyro_y", "gyro_z")), ("a", ("accel_x", "accel_y", "accel_z")),
           ("m", ("mag_x", "mag_y", "mag_z")), ("T", ("temperature",)))


# ---------------------------------------------------------------- the fake format: writer and readers

def write_imujson(path: Path, streams: dict, messages: list[dict], truncated: bool = False, magic: bool = False) -> Path:
    """Write an imujson log (``streams``: topic -> its header entry; ``messages``: the records)."""
    lines = [json.dumps({"imujson": 1, "streams": streams})] + [json.dumps(m) for m in messages]
    text = "\n".join(lines) + "\n" + (TRUNCATED if truncated else "")
    path.write_bytes((MAGIC if magic else b"") + text.encode())
    return path


def imu_messages(t, g=None, a=None, temp=None, topic: str = "imu0", record_lag: float = 0.0, m=None) -> list[dict]:
    """Records of one stream from columns (n,) and (n, 3)."""
    out, mag = [], m
    for k, tk in enumerate(t):
        m: dict = {"s": topic, "t": float(tk), "rt": float(tk) + record_lag}
        if g is not None:
            m["g"] = [float(v) for v in g[k]]
        if a is not None:
            m["a"] = [float(v) for v in a[k]]
        if temp is not None:
            m["T"] = float(temp[k])
        if mag is not None:
            m["m"] = [float(v) for v in mag[k]]
        out.append(m)
    return out


def _parse(path: Path) -> tuple[dict, list[dict], list[str]]:
    raw = path.read_bytes()
    raw = raw[len(MAGIC):] if raw.startswith(MAGIC) else raw
    lines = [line for line in raw.split(b"\n") if line.strip()]
    head = json.loads(lines[0])
    records, notes = [], []
    for k, line in enumerate(lines[1:]):
        try:
            records.append(json.loads(line))
        except ValueError:
            if k != len(lines) - 2:
                raise InputError(f"line {k + 2} is no record", str(path)) from None
            notes.append(f"last record truncated ({len(line)} bytes), left out")
    return head, records, notes


def _columns_of(entry: dict) -> tuple[str, ...]:
    return ("time",) + tuple(c for key, cols in _FIELDS if key in entry["units"] for c in cols)


def _imu(entry: dict) -> bool:
    return any(k in entry["units"] for k in "gam")


def _data(path: Path) -> Path:
    return path / "data.imujson" if path.is_dir() else path


def read_imujson(path: Path, names, time_column, fmt: LogFormat) -> Columns:
    head, records, notes = _parse(_data(path))
    streams = head["streams"]
    topic = fmt.topic or next(t for t, e in streams.items() if _imu(e) and any(r["s"] == t for r in records))
    if topic not in streams:
        raise InputError(f"no topic '{topic}' (topics: {', '.join(streams)})", str(path))
    entry = streams[topic]
    mine = [r for r in records if r["s"] == topic]
    if not mine:
        raise InputError(f"topic '{topic}' holds no message", str(path))
    cols = {"time": np.array([r["rt" if fmt.stamps == "record" else "t"] for r in mine])}
    units = {"time": entry["units"]["t"]}
    for key, named in _FIELDS:
        if key in entry["units"] and key in mine[0]:  # a field the stream states and its records hold
            values = np.array([r[key] for r in mine], dtype=float).reshape(len(mine), -1)
            for j, c in enumerate(named):
                cols[c], units[c] = values[:, j], entry["units"][key]
    wanted = list(cols) if names is None else list(names)
    missing = [n for n in wanted if n not in cols]
    if missing:
        raise InputError(f"no column {', '.join(missing)} in topic '{topic}' (columns: {', '.join(cols)})", str(path))
    return Columns(wanted, np.column_stack([cols[n] for n in wanted]), {n: units[n] for n in wanted},
                   {"format": "imujson", "topic": topic, "instance": 0, "device_id": entry["device_id"]}, tuple(notes))


def describe_imujson(path: Path, fmt: LogFormat) -> list[Stream]:
    head, records, _ = _parse(_data(path))
    return [Stream(t, e["kind"], sum(r["s"] == t for r in records), _columns_of(e) if _imu(e) else (),
                   {c: u for c, u in zip(_columns_of(e), [e["units"]["t"]] + [e["units"][k] for k, cs in _FIELDS
                                                                          if k in e["units"] for _ in cs])},
                   {"device_id": e["device_id"], "nominal_rate_hz": e["nominal_rate_hz"]})
            for t, e in head["streams"].items()]


IMUJSON = LogReader("imujson", (".imujson",), read_imujson, lambda head: head.startswith(b'{"imujson"'),
                    streams=True, describe=describe_imujson)
FAKEBIN = LogReader("fakebin", (".bin",), read_imujson, lambda head: head.startswith(MAGIC), streams=True,
                    describe=describe_imujson)
FOLDER = LogReader("imujson folder", (), read_imujson, lambda listing: b"imujson.meta" in listing.split(b"\n"),
                   streams=True, describe=describe_imujson, folder=True)


def install(monkeypatch) -> None:
    """Register the fake readers for one test (the registry restored after it)."""
    monkeypatch.setattr(readers, "READERS", list(readers.READERS))
    for r in (IMUJSON, FAKEBIN, FOLDER):
        readers.register(r)


def stream_header(rate_hz: float = 100.0, units: dict | None = None) -> dict:
    """A header of an IMU stream ``imu0``, an empty IMU stream ``imu1`` and a camera stream ``cam``."""
    return {"imu0": {"kind": "Imu", "device_id": 7, "nominal_rate_hz": rate_hz, "units": units or UNITS},
            "imu1": {"kind": "Imu", "device_id": 9, "nominal_rate_hz": rate_hz, "units": UNITS},
            "cam": {"kind": "Image", "device_id": 3, "nominal_rate_hz": 20.0, "units": {"t": "s"}}}


@pytest.fixture
def fake(monkeypatch):
    install(monkeypatch)


def _static(n: int = 3000, fs: float = 100.0, seed: int = 1):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    g = rng.normal(0, 2e-3, (n, 3)) + [0.01, -0.02, 0.005]
    a = rng.normal(0, 0.01, (n, 3)) + [0.0, 0.0, 9.81]
    return t, g, a, 25.0 + 0.001 * np.arange(n)


# ---------------------------------------------------------------- the sensor reader: units the file states

def test_a_stream_is_read_in_the_unit_it_states_and_its_stream_is_recorded(tmp_path, fake):
    from align.io.source import LogSource
    from align.vocab import Sensor

    t, g, a, temp = _static(500)
    log = write_imujson(tmp_path / "s.imujson", stream_header(), imu_messages(t, g, a, temp), truncated=True)
    got = LogSource(path=log).read(Sensor.GYROSCOPE)
    np.testing.assert_array_equal(got.data, g)  # rad/s stated: SI as written
    np.testing.assert_array_equal(got.t, t)
    assert (got.units, got.stated, got.time_units) == ("rad/s", True, "s")
    said = got.inputs()
    assert said["stream"] == {"format": "imujson", "topic": "imu0", "instance": 0, "device_id": 7}
    assert said["units_stated"] == "rad/s"
    assert got.remarks("s.imujson") == (f"s.imujson: last record truncated ({len(TRUNCATED)} bytes), left out",)
    acc = LogSource(path=log).read(Sensor.ACCELEROMETER)  # the convention's accel_x, an old default name
    np.testing.assert_array_equal(acc.data, a)
    same = LogSource(path=log, units="rad/s").read(Sensor.GYROSCOPE)
    np.testing.assert_array_equal(same.data, g)


def test_a_typed_unit_the_file_contradicts_is_refused_naming_the_option(tmp_path, fake):
    from align.io.source import LogSource
    from align.vocab import Sensor

    t, g, a, _ = _static(200)
    log = write_imujson(tmp_path / "s.imujson", stream_header(), imu_messages(t, g, a))
    with pytest.raises(InputError) as err:
        LogSource(path=log, units="deg/s").read(Sensor.GYROSCOPE, field="gyro_units")
    assert err.value.fields == ["gyro_units", "gyro_units"] and "rad/s" in err.value.message
    with pytest.raises(InputError, match="topics: imu0, imu1, cam"):
        LogSource(path=log, format=LogFormat(topic="imu9")).read(Sensor.GYROSCOPE)


def test_a_topic_given_for_a_csv_is_refused(tmp_path):
    from align.io import write_csv
    from align.io.source import LogSource
    from align.vocab import Sensor

    log = tmp_path / "s.csv"
    write_csv(log, ["time", "gyro_x", "gyro_y", "gyro_z"], np.zeros((10, 4)) + np.arange(10)[:, None] / 100)
    with pytest.raises(InputError) as err:
        LogSource(path=log, format=LogFormat(topic="/imu0")).read(Sensor.GYROSCOPE)
    assert err.value.fields == ["topic"] and "has one" in err.value.message


# ---------------------------------------------------------------- the static reader (Allan)

def test_a_static_stream_reads_as_its_csv_copy_with_the_stated_unit(tmp_path, fake):
    from align.io import read_static_log, write_csv

    t, g, a, temp = _static(1000)
    log = write_imujson(tmp_path / "s.imujson", stream_header(), imu_messages(t, g, a, temp))
    copy = tmp_path / "s.csv"
    write_csv(copy, ["time", "gyro_x", "gyro_y", "gyro_z"], np.column_stack([t, g]))
    names = ["gyro_x", "gyro_y", "gyro_z"]
    got, ref = read_static_log(log, names, None), read_static_log(copy, names, None)
    np.testing.assert_array_equal(got.data, ref.data)
    assert got.rate_hz == ref.rate_hz == pytest.approx(100.0)
    assert (got.units, ref.units, got.time_units) == ("rad/s", None, "s")
    assert got.source["device_id"] == 7 and ref.source == {}
    at_rate = read_static_log(log, names, 100.0, time_step=True)
    assert at_rate.time_step == pytest.approx(0.01) and at_rate.units == "rad/s"


def test_a_bin_a_reader_claims_goes_to_it_and_raw_float64_stays_raw(tmp_path, fake):
    from align.io import NpyChunks, read_static_log
    from align.io.logs import chunked

    t, g, a, _ = _static(600)
    claimed = write_imujson(tmp_path / "flight.bin", stream_header(), imu_messages(t, g, a), magic=True)
    raw = tmp_path / "raw.bin"
    g.astype("<f8").tofile(raw)
    assert not chunked(claimed) and chunked(raw)
    got = read_static_log(claimed, ["gyro_x", "gyro_y", "gyro_z"], None)
    np.testing.assert_array_equal(got.data, g)
    assert got.units == "rad/s" and got.rate_hz == pytest.approx(100.0)
    plain = read_static_log(raw, ["x", "y", "z"], 100.0)
    assert isinstance(plain.data, NpyChunks) and plain.data.shape == (600, 3)
    with pytest.raises(InputError, match="apply to text logs or logs of several streams"):
        read_static_log(raw, ["x", "y", "z"], 100.0, LogFormat(topic="IMU:1"))


# ---------------------------------------------------------------- a folder as a log, and its provenance

def _bag_folder(root: Path, n: int = 300) -> Path:
    folder = root / "bag"
    folder.mkdir()
    (folder / "imujson.meta").write_text("imujson folder 1\n")
    t, g, a, _ = _static(n)
    write_imujson(folder / "data.imujson", stream_header(), imu_messages(t, g, a))
    return folder


def test_a_log_folder_a_reader_claims_is_a_log_and_other_folders_stay_refused(tmp_path, fake):
    from align.io.files import existing_file, existing_log
    from align.io.source import LogSource
    from align.vocab import Sensor

    folder = _bag_folder(tmp_path)
    assert existing_log(folder) == folder
    got = LogSource(path=folder).read(Sensor.GYROSCOPE)
    assert got.data.shape == (300, 3) and got.stated
    other = tmp_path / "plain"
    other.mkdir()
    (other / "notes.txt").write_text("x")
    with pytest.raises(InputError, match="not a log folder of a known kind .*imujson folder"):
        existing_log(other)
    with pytest.raises(InputError, match="is a folder, not a file"):
        existing_file(folder)  # a plan, a result...: still a file


def test_a_folder_s_record_is_the_hash_of_its_files_in_sorted_order(tmp_path):
    from align.provenance import file_record, prehashed_record, start_hashing

    folder = tmp_path / "bag"
    (folder / "sub").mkdir(parents=True)
    files = {"metadata.yaml": b"rosbag2_bagfile_information: {}\n", "sub/b.db3": b"\x00\x01" * 100,
             "a.db3": b"abc" * 50}
    for name, data in files.items():
        (folder / name).write_bytes(data)
    outer = hashlib.sha256()
    for name in sorted(files):  # the documented rule, computed here independently
        outer.update(name.encode() + b"\0" + hashlib.sha256(files[name]).digest())
    rec = file_record("log", folder)
    assert (rec.size, rec.sha256) == (sum(map(len, files.values())), outer.hexdigest())
    start_hashing([folder])
    assert prehashed_record("log", folder) == rec
    (folder / "sub" / "b.db3").write_bytes(b"\x00\x02" * 100)
    assert file_record("log", folder).sha256 != rec.sha256


def test_a_magnetometer_stream_is_calibrated_in_the_unit_it_states(tmp_path, fake):
    from align.calibration.jobs import calibrate_mag
    from align.io import write_csv

    v = np.random.default_rng(3).normal(size=(600, 3))
    m = 0.48 * v / np.linalg.norm(v, axis=1)[:, None] + [0.10, -0.05, 0.03]  # gauss
    log = write_imujson(tmp_path / "m.imujson", stream_header(), imu_messages(np.arange(600) / 50.0, m=m),
                        truncated=True)
    copy = tmp_path / "m.csv"
    write_csv(copy, ["mag_x", "mag_y", "mag_z"], m)
    got, ref = calibrate_mag(log=log), calibrate_mag(log=copy, units="gauss")
    np.testing.assert_allclose(got.hard_iron, ref.hard_iron, rtol=1e-12)
    np.testing.assert_allclose(np.asarray(got.hard_iron) * 1e6, [10.0, -5.0, 3.0], atol=1e-6)  # 1 gauss = 100 uT
    assert got.inputs["mag_units"] == got.inputs["units_stated"] == "gauss" and got.inputs["stream"]["topic"] == "imu0"
    assert "stream" not in ref.inputs and any("last record truncated" in n for n in got.notes)
    with pytest.raises(InputError) as err:
        calibrate_mag(log=log, units="uT")
    assert "mag_units" in err.value.fields and "gauss" in err.value.message


def test_a_stream_at_a_rate_no_job_takes_points_to_another_stream_not_to_a_time_unit():
    """The real ULog's sensor_gyro:1 is logged at 1 Hz: its time unit is the log's own (stated), so the refusal
    names --topic, never --time-units (which a ULog does not take)."""
    from align.io.formats import LogFormat
    from align.io.logs import read_static_log

    ulog = SHARED / "data" / "logs" / "px4_ulog" / "sample_log_small.ulg"
    with pytest.raises(InputError) as exc:
        read_static_log(ulog, ["gyro_x", "gyro_y", "gyro_z"], None, LogFormat(topic="sensor_gyro:1"))
    assert "{topic}" in exc.value.message and "time_units" not in exc.value.message
