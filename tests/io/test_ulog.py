"""PX4 ULog logs read by our own reader (align.io.ulog).

Truth from outside the reader: logs written here by a minimal writer of this module, made from the format's
documentation (https://docs.px4.io/main/en/dev_log/ulog_file_format.html: the 16-byte header, then messages of
a 3-byte header ``uint16 size, uint8 type``; ``F`` formats, ``A`` subscriptions, ``D`` samples packed with
``struct``), with known samples; the real log ../shared/data/logs/px4_ulog/sample_log_small.ulg against the
figures of its SOURCE.txt (measured with pyulog 1.3.0 and a separate parser).
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest
from support import SHARED

from align.errors import InputError
from align.io import readers, ulog, ulog_format
from align.io.formats import LogFormat
from align.io.source import LogSource
from align.vocab import Sensor

SAMPLE = SHARED / "data" / "logs" / "px4_ulog" / "sample_log_small.ulg"
GYRO_COLS, ACCEL_COLS = ["gyro_x", "gyro_y", "gyro_z"], ["accel_x", "accel_y", "accel_z"]
# the formats as PX4 v1.11 defines them (trailing _padding0 fields are not logged)
COMBINED = ("sensor_combined:uint64_t timestamp;float[3] gyro_rad;uint32_t gyro_integral_dt;int32_t "
            "accelerometer_timestamp_relative;float[3] accelerometer_m_s2;uint32_t accelerometer_integral_dt;"
            "uint8_t accelerometer_clipping;uint8_t[3] _padding0;")
GYRO = ("sensor_gyro:uint64_t timestamp;uint64_t timestamp_sample;uint32_t device_id;float x;float y;float z;"
        "float temperature;uint32_t error_count;")
ACCEL = ("sensor_accel:uint64_t timestamp;uint64_t timestamp_sample;uint32_t device_id;float x;float y;float z;"
         "float temperature;uint32_t error_count;uint8_t[3] clip_counter;uint8_t[5] _padding0;")
VIMU = ("vehicle_imu:uint64_t timestamp;uint64_t timestamp_sample;uint32_t accel_device_id;uint32_t gyro_device_id;"
        "float[3] delta_angle;float[3] delta_velocity;uint16_t delta_angle_dt;uint16_t delta_velocity_dt;"
        "uint8_t delta_velocity_clipping;uint8_t[3] _padding0;")
MAG = "sensor_mag:uint64_t timestamp;uint64_t timestamp_sample;uint32_t device_id;float x;float y;float z;"
BARO = "sensor_baro:uint64_t timestamp;float pressure;float temperature;"
VEC = "vec:float x;float y;float z;uint8_t[4] _padding0;"  # nested: its padding is kept inside a message
NESTED = "nested_test:uint64_t timestamp;vec[2] v;uint8_t flag;uint8_t[7] _padding0;"
INVALID_REL = 2**31 - 1
T0 = 20_000_000  # us
N_C, N_G, N_V = 6000, 300, 100
RNG = np.random.default_rng(24)
C_GYRO, C_ACC = RNG.normal(0, 0.1, (N_C, 3)).astype("f4"), (RNG.normal(0, 1, (N_C, 3)) + [0, 0, -9.8]).astype("f4")
C_REL = np.full(N_C, 1000, np.int64)
C_REL[[5, 77, 4000]] = INVALID_REL
G = {i: RNG.normal(0, 0.05, (N_G, 3)).astype("f4") for i in (0, 1)}
A = {i: (RNG.normal(0, 0.5, (N_G, 3)) + [0, 0, -9.8]).astype("f4") for i in (0, 1)}
TEMP = {0: (40 + 0.01 * np.arange(N_G)).astype("f4"), 1: (28 + 0.002 * np.arange(N_G)).astype("f4")}
DEVICE = {0: 2424842, 1: 3670050}
V_ANGLE, V_VEL = RNG.normal(0, 1e-3, (N_V, 3)).astype("f4"), RNG.normal(0, 0.1, (N_V, 3)).astype("f4")
GYRO0_LEFT_OUT = 10  # sensor_gyro:0 lacks its sample 10: imu:0 pairs 299 samples, one accelerometer sample alone


class Writer:
    """A minimal ULog writer, from the format's documentation."""

    def __init__(self, flags: bytes | None = None, version: int = 1) -> None:
        self.out = bytearray(b"ULog\x01\x12\x35" + bytes([version]) + struct.pack("<Q", 1234))
        if flags is not None:
            self.msg("B", flags)

    def msg(self, kind: str, body: bytes) -> None:
        self.out += struct.pack("<HB", len(body), ord(kind)) + body

    def format(self, text: str) -> None:
        self.msg("F", text.encode())

    def add(self, multi: int, msg_id: int, name: str) -> None:
        self.msg("A", struct.pack("<BH", multi, msg_id) + name.encode())

    def data(self, msg_id: int, payload: bytes) -> None:
        self.msg("D", struct.pack("<H", msg_id) + payload)


def gyro_times(i: int) -> np.ndarray:
    """Published stamps of sensor_gyro:i (its sample stamps are 400 us earlier), us."""
    t = T0 + 1000 + 5000 * np.arange(N_G) + 37 * i
    return np.delete(t, GYRO0_LEFT_OUT) if i == 0 else t


def write_log(path: Path) -> Path:
    """The known log: every IMU topic, two instances, a nested type, a late subscription, a msg_id reused after
    ``R``, info, parameter, text, sync and dropout messages, and a last record cut short."""
    w = Writer(flags=bytes(40))
    for text in (COMBINED, GYRO, ACCEL, VIMU, MAG, BARO, VEC, NESTED):
        w.format(text)
    w.msg("I", bytes([len("char[3] sys_name")]) + b"char[3] sys_namePX4")
    w.msg("P", bytes([len("int32_t SDLOG_PROFILE")]) + b"int32_t SDLOG_PROFILE" + struct.pack("<i", 11))
    for multi, msg_id, name in ((0, 1, "sensor_combined"), (0, 2, "sensor_gyro"), (0, 4, "sensor_accel"),
                                (1, 5, "sensor_accel"), (0, 6, "vehicle_imu"), (0, 9, "sensor_mag"),
                                (0, 8, "nested_test")):
        w.add(multi, msg_id, name)
    events = []  # (time us, order, callable writing the message)
    for k in range(N_C):
        t = T0 + 4000 * k
        events.append((t, 0, ("D", struct.pack("<H", 1) + struct.pack("<Q3fIi3fIB", t, *C_GYRO[k], 4000, C_REL[k],
                                                                     *C_ACC[k], 4000, 0))))
    for i, msg_id in ((0, 2), (1, 3)):
        for k, t in enumerate(gyro_times(i)):
            kk = k + (k >= GYRO0_LEFT_OUT) if i == 0 else k
            events.append((int(t), 1, ("D", struct.pack("<H", msg_id) + struct.pack(
                "<QQI4fI", t, t - 400, DEVICE[i], *G[i][kk], TEMP[i][kk], 0))))
    for i, msg_id in ((0, 4), (1, 5)):
        for k in range(N_G):
            ts = T0 + 1000 + 5000 * k + 37 * i - 400 + (100 if i == 1 else 0)  # imu:1's stamps 0.1 ms after the gyro's
            pad = bytes(5) if i == 1 else b""  # instance 1 logs the trailing padding too (a reader takes both)
            events.append((ts + 400, 2, ("D", struct.pack("<H", msg_id) + struct.pack(
                "<QQI4fI3B", ts + 400, ts, DEVICE[i], *A[i][k], TEMP[i][k] + 0.5, 0, 0, 0, 0) + pad)))
    for k in range(N_V):
        t = T0 + 10_000 * (k + 1)
        events.append((t, 3, ("D", struct.pack("<H", 6) + struct.pack("<QQII3f3fHHB", t, t - 200, DEVICE[0] + 1,
                                                                     DEVICE[0], *V_ANGLE[k], *V_VEL[k], 10_000,
                                                                     10_000, 0))))
    for k in range(10):
        events.append((T0 + 100_000 * k, 4, ("D", struct.pack("<H", 9) + struct.pack("<QQI3f", T0 + 100_000 * k,
                                                                                    T0 + 100_000 * k - 5, 777,
                                                                                    k, -k, 0.5))))
    events.append((T0 + 950_000, 5, ("R", struct.pack("<H", 9))))
    events.append((T0 + 950_001, 5, ("A", struct.pack("<BH", 0, 9) + b"sensor_baro")))
    for k in range(5):
        events.append((T0 + 1_000_000 + 100_000 * k, 5, ("D", struct.pack("<H", 9) + struct.pack(
            "<Qff", T0 + 1_000_000 + 100_000 * k, 101325.0, 25.0))))
    for k in range(4):
        v = [float(k + 0.5 * j) for j in range(6)]
        body = struct.pack("<Q", T0 + 7 * k) + struct.pack("<3f4x", *v[:3]) + struct.pack("<3f4x", *v[3:])
        events.append((T0 + 7 * k, 6, ("D", struct.pack("<H", 8) + body + struct.pack("<B", k))))
    events.append((T0 + 500_000, -1, ("A", struct.pack("<BH", 1, 3) + b"sensor_gyro")))  # a late subscription
    events.append((T0 + 600_000, 7, ("L", b"6" + struct.pack("<Q", T0 + 600_000) + b"Takeoff detected")))
    events.append((T0 + 700_000, 7, ("S", b"\x2f\x73\x13\x20\x25\x0c\xbb\x12")))
    events.append((T0 + 800_000, 7, ("O", struct.pack("<H", 20))))
    # sensor_gyro:1 is subscribed at T0 + 0.5 s: its earlier samples go after the subscription
    events = [(max(t, T0 + 500_000) if kind == "D" and body[:2] == struct.pack("<H", 3) else t, o, (kind, body))
              for t, o, (kind, body) in events]
    for _, _, (kind, body) in sorted(events, key=lambda e: (e[0], e[1])):
        w.msg(kind, body)
    cut = struct.pack("<HB", 2 + 40, ord("D")) + struct.pack("<H", 3) + bytes(10)  # 15 of its 45 bytes
    path.write_bytes(bytes(w.out) + cut)
    return path


@pytest.fixture(autouse=True)
def registered():
    """The ULog reader in the registry for these tests (and the registry as it was afterwards)."""
    saved = list(readers.READERS)
    readers.register(ulog.READER)
    yield
    readers.READERS[:] = saved


@pytest.fixture(scope="module")
def known(tmp_path_factory) -> Path:
    return write_log(tmp_path_factory.mktemp("ulog") / "known.ulg")


def read(path: Path, topic: str | None = None, names: list[str] | None = None, stamps: str | None = None):
    return ulog.read(path, names, "time", LogFormat(topic=topic, stamps=stamps))


def test_sensor_combined_read_back_exactly(known):
    got = read(known)
    ok = C_REL != INVALID_REL
    assert got.names == ["time", *GYRO_COLS, *ACCEL_COLS]
    np.testing.assert_array_equal(got.data[:, 0], (T0 + 4000 * np.arange(N_C))[ok] * 1e-6)
    np.testing.assert_array_equal(got.data[:, 1:4], C_GYRO[ok].astype(float))
    np.testing.assert_array_equal(got.data[:, 4:7], C_ACC[ok].astype(float))
    assert got.units == {"time": "s", **dict.fromkeys(GYRO_COLS, "rad/s"), **dict.fromkeys(ACCEL_COLS, "m/s^2")}
    assert got.source == {"format": "ulog", "topic": "sensor_combined", "instance": 0, "device_id": None}
    notes = " | ".join(got.notes)
    assert "last message truncated (15 of 45 bytes, a data record of sensor_gyro:1), left out" in notes
    assert "3 messages without an accelerometer sample left out" in notes and "stamped 1 ms (median)" in notes
    assert "dropped data 1 time (20 ms in all)" in notes and "no topic given: sensor_combined read" in notes
    gyro_only = read(known, "sensor_combined", ["time", "gyro_z"])  # every message has a gyro sample
    np.testing.assert_array_equal(gyro_only.data[:, 1], C_GYRO[:, 2].astype(float))
    accel_only = read(known, "sensor_combined:0", ["time", "accel_y"])  # the accelerometer's own time
    np.testing.assert_array_equal(accel_only.data[:, 0], ((T0 + 4000 * np.arange(N_C)) + C_REL)[ok] * 1e-6)


@pytest.mark.parametrize("i", [0, 1])
def test_sensor_gyro_and_accel_instances(known, i):
    keep = np.arange(N_G) != GYRO0_LEFT_OUT if i == 0 else np.ones(N_G, bool)
    gyro = read(known, f"sensor_gyro:{i}")
    assert gyro.names == ["time", *GYRO_COLS, "temperature"]
    np.testing.assert_array_equal(gyro.data[:, 0], (gyro_times(i) - 400) * 1e-6)  # timestamp_sample
    np.testing.assert_array_equal(gyro.data[:, 1:4], G[i][keep].astype(float))
    np.testing.assert_array_equal(gyro.data[:, 4], TEMP[i][keep].astype(float))
    assert gyro.units["temperature"] == "degC" and gyro.units["gyro_x"] == "rad/s"
    assert gyro.source == {"format": "ulog", "topic": "sensor_gyro", "instance": i, "device_id": DEVICE[i]}
    published = read(known, f"sensor_gyro:{i}", ["time"], stamps="record")
    np.testing.assert_array_equal(published.data[:, 0], gyro_times(i) * 1e-6)
    accel = read(known, f"sensor_accel:{i}", ["time", *ACCEL_COLS, "temperature"])
    np.testing.assert_array_equal(accel.data[:, 1:4], A[i].astype(float))
    np.testing.assert_array_equal(accel.data[:, 4], (TEMP[i] + np.float32(0.5)).astype(float))
    assert accel.source["device_id"] == DEVICE[i] and not any("wrong size" in n for n in accel.notes)


def test_joined_imu_pairs_gyro_and_accel_of_one_instance(known):
    imu0 = read(known, "imu:0")
    keep = np.arange(N_G) != GYRO0_LEFT_OUT
    assert imu0.names == ["time", *GYRO_COLS, *ACCEL_COLS, "temperature"] and len(imu0.data) == N_G - 1
    np.testing.assert_array_equal(imu0.data[:, 1:4], G[0][keep].astype(float))
    np.testing.assert_array_equal(imu0.data[:, 4:7], A[0][keep].astype(float))
    np.testing.assert_array_equal(imu0.data[:, 7], TEMP[0][keep].astype(float))  # the gyro's temperature
    assert imu0.source == {"format": "ulog", "topic": "imu", "instance": 0, "device_id": DEVICE[0],
                           "messages": ["sensor_gyro", "sensor_accel"], "accel_device_id": DEVICE[0]}
    assert any("0 gyro and 1 accelerometer samples without a partner" in n for n in imu0.notes)
    imu1 = read(known, "imu:1")
    np.testing.assert_array_equal(imu1.data[:, 0], (gyro_times(1) - 400) * 1e-6)  # the gyro's time
    np.testing.assert_array_equal(imu1.data[:, 4:7], A[1].astype(float))
    assert any("differ by 0.1 ms (median)" in n for n in imu1.notes)
    gyro_alone = read(known, "imu:0", ["time", "gyro_x"])  # one sensor: its topic in full, no pairing
    assert gyro_alone.source["messages"] == ["sensor_gyro"] and len(gyro_alone.data) == N_G - 1
    accel_alone = read(known, "imu:0", ["time", "accel_x"])
    assert len(accel_alone.data) == N_G and accel_alone.source["device_id"] == DEVICE[0]


def test_vehicle_imu_rates_from_deltas_over_microsecond_intervals(known):
    got = read(known, "vehicle_imu:0")
    np.testing.assert_allclose(got.data[:, 1:4], V_ANGLE.astype(float) / 0.01, rtol=1e-15)
    np.testing.assert_allclose(got.data[:, 4:7], V_VEL.astype(float) / 0.01, rtol=1e-15)
    np.testing.assert_array_equal(got.data[:, 0], (T0 + 10_000 * np.arange(1, N_V + 1) - 200) * 1e-6)
    assert got.source["device_id"] == DEVICE[0]
    assert read(known, "vehicle_imu", ["time", "accel_x"]).source["device_id"] == DEVICE[0] + 1


def test_nested_types_padding_and_reused_msg_id(known):
    scan = ulog_format.Scan(known)
    starts = {}
    for st, key in scan.windows():
        for k in set(key.tolist()):
            starts.setdefault(scan.keys[k], []).append(st[key == k])
    lay = scan.layouts[scan.keys.index(("nested_test", 0))]
    assert lay is not None and lay.size == 8 + 2 * 16 + 1 and lay.full == lay.size + 7
    rec = ulog_format.decode(scan.u8, np.concatenate(starts[("nested_test", 0)]), lay, ["v[0].x", "v[1].z", "flag"])
    np.testing.assert_array_equal(rec["v[1].z"], np.arange(4) + 2.5)
    np.testing.assert_array_equal(rec["flag"], np.arange(4))
    counts = dict(zip(scan.keys, scan.counts.tolist()))
    assert counts[("sensor_mag", 0)] == 10 and counts[("sensor_baro", 0)] == 5  # msg_id 9, before and after R
    scan.close()
    mag = read(known, "sensor_mag:0")
    assert mag.units["mag_x"] == "gauss" and mag.names == ["time", "mag_x", "mag_y", "mag_z"]
    np.testing.assert_array_equal(mag.data[:, 1], np.arange(10))


def test_describe_lists_every_topic_with_counts_and_rates(known):
    streams = {s.topic: s for s in ulog.describe(known, LogFormat())}
    assert streams["sensor_combined"].count == N_C and streams["sensor_gyro:1"].count == N_G
    assert streams["sensor_gyro:1"].extra["device_id"] == DEVICE[1]
    assert streams["sensor_gyro:0"].extra["median_rate_hz"] == pytest.approx(200.0)
    assert streams["sensor_combined"].extra["median_rate_hz"] == pytest.approx(250.0)
    assert streams["imu:0"].count == N_G - 1 and streams["nested_test"].columns == ()
    assert streams["sensor_baro"].count == 5 and streams["vehicle_imu:0"].units["gyro_x"] == "rad/s"


def test_small_windows_and_chunks_give_the_same_columns(known, monkeypatch):
    whole = {t: read(known, t) for t in (None, "imu:1", "sensor_gyro:1")}
    monkeypatch.setattr(ulog_format, "WINDOW", 1)  # one message window at a time (the least it takes)
    for topic, want in whole.items():
        again = read(known, topic)
        np.testing.assert_array_equal(again.data, want.data)
        assert again.notes == want.notes
        blocks = list(ulog.iter_chunks(known, LogFormat(topic=topic), None, rows=997))
        assert all(len(b.data) <= 997 for b in blocks) and blocks[-1].notes == want.notes
        np.testing.assert_array_equal(np.concatenate([b.data for b in blocks]), want.data)


def test_pairs_of_sensors_of_other_rates_in_one_read_and_in_chunks(tmp_path, monkeypatch):
    rng = np.random.default_rng(5)
    tg = 1_000_000 + 1000 * np.arange(2000) + rng.integers(-30, 30, 2000)  # a 1 kHz gyro, an 800 Hz accelerometer
    ta = 1_000_300 + 1250 * np.arange(1500) + rng.integers(-30, 30, 1500)
    w = Writer()
    w.format(GYRO)
    w.format(ACCEL)
    w.add(0, 0, "sensor_gyro")
    w.add(0, 1, "sensor_accel")
    for _, k, body in sorted([(t, 0, struct.pack("<QQI4fI", t, t, 7, k, 0, 0, 30.0, 0)) for k, t in enumerate(tg)]
                             + [(t, 1, struct.pack("<QQI4fI3B", t, t, 7, k, 0, 0, 30.0, 0, 0, 0, 0))
                                for k, t in enumerate(ta)]):
        w.data(k, body)
    (tmp_path / "rates.ulg").write_bytes(bytes(w.out))
    tol = 0.5 * min(np.median(np.diff(tg[:1000])), np.median(np.diff(ta[:1000])))
    dist = np.abs(tg[:, None] - ta[None, :])  # brute force: each sample's nearest partner (ties: the earlier)
    near_a, near_g = dist.argmin(1), dist.argmin(0)
    pairs = [(i, j) for i, j in enumerate(near_a) if near_g[j] == i and dist[i, j] <= int(tol)]
    whole = read(tmp_path / "rates.ulg", "imu:0", ["time", "gyro_x", "accel_x"])
    np.testing.assert_array_equal(whole.data, [[tg[i] * 1e-6, i, j] for i, j in pairs])
    monkeypatch.setattr(ulog_format, "WINDOW", 1)
    blocks = list(ulog.iter_chunks(tmp_path / "rates.ulg", LogFormat(topic="imu:0"), ["time", "gyro_x", "accel_x"],
                                   rows=500))
    assert len(blocks) > 1 and blocks[-1].notes == whole.notes
    np.testing.assert_array_equal(np.concatenate([b.data for b in blocks]), whole.data)


def test_the_compiled_walk_finds_the_same_messages(known, monkeypatch):
    want = read(known, "imu:1")
    monkeypatch.setattr(ulog_format, "COMPILED_ABOVE", 0)  # numba's walk, as for a file above 200 MB
    again = read(known, "imu:1")
    np.testing.assert_array_equal(again.data, want.data)
    assert again.notes == want.notes


def test_the_real_log_against_its_source_figures():
    streams = {s.topic: s for s in ulog.describe(SAMPLE, LogFormat())}
    logged = [s for s in streams.values() if s.kind != "sensor_gyro+sensor_accel" and s.count]
    assert len(logged) == 70 and len({s.kind for s in logged}) == 55
    assert streams["sensor_combined"].count == 1298
    assert 1e6 / streams["sensor_combined"].extra["median_rate_hz"] == pytest.approx(4888, abs=1)
    combined = read(SAMPLE)
    t = combined.data[:, 0]
    assert (round(t[0], 3), round(t[-1], 3), round(t[1] - t[0], 3)) == (20.327, 26.823, 0.161)
    np.testing.assert_allclose(combined.data[:1000, 1:4].mean(0), [0.0044806, 0.00029839, 0.0010117], rtol=1e-4)
    np.testing.assert_allclose(combined.data[:1000, 4:7].mean(0), [-0.017551, -0.16698, -9.62138], rtol=1e-4)
    truth = {0: (2424842, (40.025, 40.361), [-0.043132, 0.0070695, 0.032613], [0.67842, 0.26333, -9.75233]),
             1: (3670050, (28.246, 28.368), [0.017375, -0.00012675, -0.0055630], [0.35472, 0.30435, -9.90652]),
             2: (2621474, (29.434, 29.722), [-0.0068267, -0.019316, -0.0024580], [0.66977, 0.21742, -9.82568])}
    for i, (device, (lo, hi), gyro_mean, accel_mean) in truth.items():
        for kind, mean in (("sensor_gyro", gyro_mean), ("sensor_accel", accel_mean)):
            got = read(SAMPLE, f"{kind}:{i}")
            assert got.source["device_id"] == device and len(got.data) == 6
            assert (round(got.data[:, 4].min(), 3), round(got.data[:, 4].max(), 3)) == (lo, hi)
            np.testing.assert_allclose(got.data[:, 1:4].mean(0), mean, rtol=2e-4)
            assert streams[f"{kind}:{i}"].extra["median_rate_hz"] == pytest.approx(1.0, abs=0.01)
        assert streams[f"vehicle_imu:{i}"].count == 12 and streams[f"vehicle_imu:{i}"].extra["median_rate_hz"] == \
            pytest.approx(2.0, abs=0.02)
        assert len(read(SAMPLE, f"imu:{i}").data) == 6


def _cut_flags(incompat: int, offset: int = 0) -> bytes:
    return bytes(8) + bytes([incompat]) + bytes(7) + struct.pack("<3Q", offset, 0, 0)


def _small(path: Path, stamps: list[int], flags: bytes | None = None) -> Writer:
    w = Writer(flags)
    w.format(GYRO)
    w.add(0, 0, "sensor_gyro")
    for k, t in enumerate(stamps):
        w.data(0, struct.pack("<QQI4fI", t, t, 7, k, 0, 0, 30.0, 0))
    path.write_bytes(bytes(w.out))
    return w


def test_appended_data_and_bytes_that_are_no_message(tmp_path):
    w = _small(tmp_path / "a.ulg", [1000, 2000, 3000], flags=_cut_flags(1))
    w.out += struct.pack("<HB", 42, ord("D")) + bytes(6)  # cut where the appended data starts
    offset = len(w.out)
    w.data(0, struct.pack("<QQI4fI", 4000, 4000, 7, 3, 0, 0, 30.0, 0))
    struct.pack_into("<Q", w.out, 16 + 3 + 16, offset)
    (tmp_path / "a.ulg").write_bytes(bytes(w.out))
    got = read(tmp_path / "a.ulg", "sensor_gyro:0")
    np.testing.assert_array_equal(got.data[:, 1], [0, 1, 2, 3])
    w = _small(tmp_path / "b.ulg", [1000, 2000])
    w.out += bytes([7, 0, 0]) + b"garbage"  # no message: type 0
    w.msg("S", b"\x2f\x73\x13\x20\x25\x0c\xbb\x12")
    w.data(0, struct.pack("<QQI4fI", 3000, 3000, 7, 2, 0, 0, 30.0, 0))
    (tmp_path / "b.ulg").write_bytes(bytes(w.out))
    got = read(tmp_path / "b.ulg", "sensor_gyro")
    np.testing.assert_array_equal(got.data[:, 1], [0, 1, 2])
    assert any("bytes that are no ULog message skipped (one place)" in n for n in got.notes)


@pytest.mark.parametrize("topic, names, says", [
    ("sensor_gyro:5", None, "no instance 5 of sensor_gyro (instances: 0, 1)"),
    ("bogus_topic", None, "'bogus_topic' is not in the log; give one of its IMU topics with topic: sensor_combined (6000)"),
    ("sensor_baro", None, "'sensor_baro' is logged but is not an IMU topic"),
    ("sensor_combined", ["time", "temperature"], "sensor_combined has no column 'temperature' (columns: time, gyro_x"),
    ("sensor_combined", ["temperature"], "accel_z); sensor_gyro:0/1 (299/300), sensor_accel:0/1 (300/300), imu:0/1 "
                                         "(300/300) have it: give one with topic"),  # not sensor_mag: its format has none
    ("sensor_mag:0", ["time", "gyro_x"], "sensor_combined (6000), sensor_gyro:0/1 (299/300)"),
])
def test_refusals_name_the_file_topic_and_what_there_is(known, topic, names, says):
    with pytest.raises(InputError) as err:
        read(known, topic, names)
    assert says in str(err.value) and str(known) in str(err.value) and "\n" not in str(err.value)


def test_refusals_of_malformed_logs(tmp_path):
    cases = {"back.ulg": (lambda p: _small(p, [1000, 2000, 1500, 3000]), "sensor_gyro", "go back at sample 3"),
             "text.ulg": (lambda p: p.write_text("time,gyro_x\n0,1\n"), None, "is not a PX4 ULog file"),
             "empty.ulg": (lambda p: p.write_bytes(b""), None, "is not a PX4 ULog file"),
             "flags.ulg": (lambda p: _small(p, [1000], flags=_cut_flags(2)), None, "incompatible flag bits"),
             "nodata.ulg": (lambda p: _small(p, []), "sensor_gyro:0", "holds no sample")}
    for name, (make, topic, says) in cases.items():
        make(tmp_path / name)
        with pytest.raises(InputError, match=says) as err:
            read(tmp_path / name, topic)
        assert str(tmp_path / name) in str(err.value), name
    with pytest.raises(InputError, match="sensor_mag:2' is in the log but holds no sample"):
        read(SAMPLE, "sensor_mag:2")


def test_log_source_takes_the_units_the_log_states(known):
    log = LogSource(path=known, format=LogFormat(topic="sensor_gyro:1"), temperature_column="temperature"
                    ).read(Sensor.GYROSCOPE)
    assert log.units == "rad/s" and log.stated and log.time_units == "s"
    np.testing.assert_array_equal(log.data, G[1].astype(float))
    np.testing.assert_array_equal(log.temperature, TEMP[1].astype(float))
    assert log.source == {"format": "ulog", "topic": "sensor_gyro", "instance": 1, "device_id": DEVICE[1]}
    assert log.rate_hz == pytest.approx(200.0)
    accel = LogSource(path=known, format=LogFormat(topic="imu:0")).read(Sensor.ACCELEROMETER)
    assert accel.units == "m/s^2" and len(accel.data) == N_G
    np.testing.assert_array_equal(accel.data, A[0].astype(float))
    with pytest.raises(InputError, match="rad/s"):
        LogSource(path=known, units="deg/s", format=LogFormat(topic="sensor_gyro:1")).read(Sensor.GYROSCOPE)
    real = LogSource(path=SAMPLE).read(Sensor.GYROSCOPE)
    assert real.source["topic"] == "sensor_combined" and real.units == "rad/s" and len(real.data) == 1298
