"""ArduPilot DataFlash logs (align.io.dataflash): what an independent writer wrote is read back exactly.

Truth from outside the reader: every log here is written by :class:`Writer`, a few lines of ``struct`` that
follow ArduPilot's documented layout (libraries/AP_Logger/LogStructure.h: a record is ``A3 95``, the message
id, the fields packed little-endian; FMT = type u8, length u8, name char[4], format char[16], labels
char[64]; FMTU, UNIT, MULT; the IMU message ``QBffffffIIfBBHH`` and the older ``IMU``/``IMU2`` ones), with
samples chosen here. The reader's code is not used to write them.
"""

from __future__ import annotations

import doctest
import math
import struct

import numpy as np
import pytest

from align.errors import InputError
from align.io import dataflash, dataflash_format, readers
from align.io.formats import LogFormat
from align.io.source import LogSource
from align.vocab import Sensor

#: format character -> struct code (LogStructure.h: c C e E are int16/uint16/int32/uint32 in hundredths,
#: L an int32 in 1e-7 degrees, M a uint8, a 32 int16, g a half float)
CODE = {"a": "32h", "b": "b", "B": "B", "h": "h", "H": "H", "i": "i", "I": "I", "f": "f", "d": "d", "g": "e",
        "n": "4s", "N": "16s", "Z": "64s", "c": "h", "C": "H", "e": "i", "E": "I", "L": "i", "M": "B", "q": "q",
        "Q": "Q"}
IMU_NEW = ("QBffffffIIfBBHH", "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,GHz,AHz")
IMU_OLD = ("QffffffIIfBBHH", "TimeUS,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,GHz,AHz")


class Writer:
    """A minimal DataFlash writer: FMT records from the documented layout, then records of the messages."""

    def __init__(self) -> None:
        self.parts: list[bytes] = []
        self.messages: dict[str, tuple[int, str]] = {}
        self.define(128, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns")

    def define(self, type_id: int, name: str, fmt: str, labels: str) -> None:
        self.messages[name] = (type_id, fmt)
        length = 3 + struct.calcsize("<" + "".join(CODE[c] for c in fmt))
        if type_id != 128:
            self.parts.append(self.packed(128, "BBnNZ", type_id, length, name.encode(), fmt.encode(), labels.encode()))
        else:
            self.parts.append(self.packed(128, "BBnNZ", 128, 89, b"FMT", fmt.encode(), labels.encode()))

    @staticmethod
    def packed(type_id: int, fmt: str, *values) -> bytes:
        flat = []
        for c, v in zip(fmt, values):
            flat.extend(v if c == "a" else [v])
        return b"\xa3\x95" + bytes([type_id]) + struct.pack("<" + "".join(CODE[c] for c in fmt), *flat)

    def write(self, name: str, *values) -> None:
        type_id, fmt = self.messages[name]
        self.parts.append(self.packed(type_id, fmt, *values))

    def units(self, name: str, unit_ids: str, mult_ids: str) -> None:
        """An FMTU record for ``name`` (the FMTU message defined first with :meth:`standard`)."""
        self.write("FMTU", 0, self.messages[name][0], unit_ids.encode(), mult_ids.encode())

    def standard(self) -> None:
        """FMTU, UNIT and MULT as ArduPilot defines them, with the UNIT and MULT records the IMU uses."""
        self.define(64, "FMTU", "QBNN", "TimeUS,FmtType,UnitIds,MultIds")
        self.define(177, "UNIT", "QbZ", "TimeUS,Id,Label")
        self.define(172, "MULT", "Qbd", "TimeUS,Id,Mult")
        for uid, label in (("s", "s"), ("E", "rad/s"), ("o", "m/s/s"), ("O", "degC"), ("k", "deg/s"), ("z", "Hz")):
            self.write("UNIT", 0, ord(uid), label.encode())
        for mid, mult in (("F", 1e-6), ("0", 1.0), ("C", 1e-3)):
            self.write("MULT", 0, ord(mid), mult)

    def save(self, path, cut: int = 0):
        data = b"".join(self.parts)
        path.write_bytes(data[: len(data) - cut])
        return path


def samples(n: int, seed: int, t0: int = 5_000_000, step: int = 2500) -> dict[str, np.ndarray]:
    """Known IMU samples: float32 values (exact in the log), time stamps in us."""
    rng = np.random.default_rng(seed)
    return {"TimeUS": t0 + step * np.arange(n, dtype=np.int64),
            "gyro": rng.normal(0, 0.3, (n, 3)).astype(np.float32),
            "accel": (rng.normal(0, 0.2, (n, 3)) + [0, 0, -9.81]).astype(np.float32),
            "T": (40 + np.linspace(0, 3, n) + rng.normal(0, 0.01, n)).astype(np.float32)}


def new_log(w: Writer, n: int = 200, instances: int = 2, imu_id: int = 131, extra: dict[int, bytes] | None = None
            ) -> list[dict[str, np.ndarray]]:
    """Records of IMU with its instance field I, interleaved, and an ATT message besides; ``extra``: bytes put
    before the records of a sample, by its index."""
    w.define(imu_id, "IMU", *IMU_NEW)
    w.define(133, "ATT", "QccccCCCCB", "TimeUS,DesRoll,Roll,DesPitch,Pitch,DesYaw,Yaw,ErrRP,ErrYaw,AEKF")
    if "FMTU" in w.messages:
        w.units("IMU", "s#EEEooo--O--zz", "F-000000-----00")
    truth = [samples(n, seed=k, t0=5_000_000 + 100 * k) for k in range(instances)]
    if n > 7:  # a gyro value whose bytes are A3 95 and the IMU's id: a record header inside a record's fields
        truth[0]["gyro"][7, 1] = struct.unpack("<f", b"\xa3\x95" + bytes([imu_id]) + b"\x3f")[0]
    for i in range(n):
        if extra and i in extra:
            w.parts.append(extra[i])
        for k, s in enumerate(truth):
            w.write("IMU", int(s["TimeUS"][i]), k, *s["gyro"][i].tolist(), *s["accel"][i].tolist(), 0, 0,
                    float(s["T"][i]), 1, 1, 400, 400)
        if i % 10 == 0:
            w.write("ATT", int(truth[0]["TimeUS"][i]), 100, -250, 0, 0, 18000, 35999, 0, 0, 3)
    return truth


@pytest.fixture
def registered():
    """The DataFlash reader registered for ``.bin`` (the registry restored afterwards)."""
    before = list(readers.READERS)
    readers.register(dataflash.READER)
    yield
    readers.READERS[:] = before


def read(path, topic=None, names=None):
    return dataflash.read(path, names, "time", LogFormat(topic=topic))


def expected(s: dict[str, np.ndarray], temperature: bool = True) -> np.ndarray:
    cols = [s["TimeUS"] * 1e-6, s["gyro"].astype(float), s["accel"].astype(float)]
    return np.column_stack(cols + ([s["T"].astype(float)] if temperature else []))


def test_instances_of_one_message_read_back_exactly_with_the_units_fmtu_states(tmp_path):
    w = Writer()
    w.standard()
    truth = new_log(w)
    path = w.save(tmp_path / "new.bin")
    for topic, k in ((None, 0), ("IMU", 0), ("IMU:0", 0), ("IMU:1", 1), ("IMU2", 1), ("imu:1", 1)):
        got = read(path, topic)
        assert got.names == ["time", "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z", "temperature"]
        np.testing.assert_array_equal(got.data, expected(truth[k]))
        assert got.units == {"time": "s", "gyro_x": "rad/s", "gyro_y": "rad/s", "gyro_z": "rad/s",
                             "accel_x": "m/s^2", "accel_y": "m/s^2", "accel_z": "m/s^2", "temperature": "degC"}
        assert got.source == {"format": "dataflash", "topic": "IMU", "instance": k}
        assert got.notes == ()
    got = read(path, "IMU:1", ["gyro_z", "time"])
    np.testing.assert_array_equal(got.data, np.column_stack([truth[1]["gyro"][:, 2], truth[1]["TimeUS"] * 1e-6]))


def test_old_logs_of_separate_messages_imu_imu2_without_fmtu_take_the_documented_units(tmp_path):
    w = Writer()
    w.define(131, "IMU", *IMU_OLD)
    w.define(132, "IMU2", *IMU_OLD)
    w.define(140, "IMU3", "Iffffff", "TimeMS,GyrX,GyrY,GyrZ,AccX,AccY,AccZ")  # the oldest logs: ms, no T
    truth = [samples(150, seed=10 + k) for k in range(3)]
    for i in range(150):
        for name, s in zip(("IMU", "IMU2"), truth):
            w.write(name, int(s["TimeUS"][i]), *s["gyro"][i].tolist(), *s["accel"][i].tolist(), 0, 0,
                    float(s["T"][i]), 1, 1, 400, 400)
        w.write("IMU3", 5000 + 5 * i, *truth[2]["gyro"][i].tolist(), *truth[2]["accel"][i].tolist())
    path = w.save(tmp_path / "old.bin")
    for topic, k in ((None, 0), ("IMU:1", 1), ("IMU2", 1), ("IMU3", 2)):
        got = read(path, topic)
        assert got.source == {"format": "dataflash", "topic": "IMU", "instance": k}
        if k < 2:
            np.testing.assert_array_equal(got.data, expected(truth[k]))
            assert got.units["gyro_x"] == "rad/s" and got.units["accel_z"] == "m/s^2" and got.units["temperature"] == "degC"
    got = read(path, "IMU:2")
    assert got.names == ["time", "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]
    np.testing.assert_allclose(got.data[:, 0], (5000 + 5 * np.arange(150)) * 1e-3, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(got.data[:, 1:], np.column_stack([truth[2]["gyro"], truth[2]["accel"]]))
    assert got.units["time"] == "s" and got.units["gyro_x"] == "rad/s"


def test_a_unit_and_multiplier_stated_by_fmtu_are_used(tmp_path):
    """GyrX.. logged in millidegrees per second (unit k = deg/s, multiplier C = 1e-3): read as deg/s."""
    w = Writer()
    w.standard()
    w.define(131, "IMU", *IMU_NEW)
    w.units("IMU", "s#kkkooo--O--zz", "F-CCC000-----00")
    gyro = np.array([[1000.0, -2000.0, 500.0], [1500.0, 250.0, -125.0], [10.0, 20.0, 30.0]], np.float32)
    for i, g in enumerate(gyro):
        w.write("IMU", 1000 + 2500 * i, 0, *g.tolist(), 0.0, 0.0, -9.81, 0, 0, 30.0, 1, 1, 400, 400)
    got = read(w.save(tmp_path / "mdeg.bin"), names=["gyro_x", "gyro_y", "gyro_z"])
    np.testing.assert_allclose(got.data, gyro.astype(float) * 1e-3, rtol=1e-15)
    assert got.units == {"gyro_x": "deg/s", "gyro_y": "deg/s", "gyro_z": "deg/s"}


def test_every_format_character_decodes_as_documented(tmp_path):
    w = Writer()
    w.define(150, "XA", "abBhHiIfdnNZ", "A,b,B,h,H,i,I,f,d,n,N,Z")
    w.define(151, "XB", "cCeELMqQg", "c,C,e,E,L,M,q,Q,g")
    row_a = (list(range(-16, 16)), -7, 250, -30000, 60000, -2_000_000_000, 4_000_000_000, 1.5, math.pi, b"ab",
             b"sixteen chars!!!", b"a string")
    row_b = (-12345, 54321, -123456789, 3_000_000_000, -353632620, 7, -(2 ** 62), 2 ** 63 + 5, 0.5)
    w.write("XA", *row_a)
    w.write("XB", *row_b)
    path = w.save(tmp_path / "chars.bin")
    buf = np.fromfile(path, np.uint8)
    layout = dataflash_format.scan(buf)
    xa, xb = layout.formats[150], layout.formats[151]
    assert xa.decodable and xb.decodable and xa.length == 3 + 64 + 1 + 1 + 2 + 2 + 4 + 4 + 4 + 8 + 4 + 16 + 64
    a = dataflash_format.decode(buf, xa, layout.of(150), list(xa.labels))
    b = dataflash_format.decode(buf, xb, layout.of(151), list(xb.labels))
    assert a["A"][0].tolist() == list(range(-16, 16))
    assert [float(a[k][0]) for k in "bBhHiIfd"] == [-7, 250, -30000, 60000, -2_000_000_000, 4_000_000_000, 1.5, math.pi]
    assert (a["n"][0], a["N"][0], a["Z"][0]) == (b"ab", b"sixteen chars!!!", b"a string")
    assert [float(b[k][0]) for k in "cCeEL"] == [-123.45, 543.21, -1234567.89, 30_000_000.0, -35.363262]
    assert float(b["M"][0]) == 7 and float(b["g"][0]) == 0.5
    assert float(b["q"][0]) == float(-(2 ** 62)) and float(b["Q"][0]) == float(2 ** 63 + 5)


def test_a_truncated_last_record_is_left_out_and_stated(tmp_path):
    w = Writer()
    truth = new_log(w, n=50)
    record = 3 + struct.calcsize("<QBffffffIIfBBHH")
    path = w.save(tmp_path / "cut.bin", cut=20)  # the last record is IMU:1's 50th sample
    got = read(path, "IMU:1")
    np.testing.assert_array_equal(got.data, expected(truth[1])[:-1])
    assert got.notes == (f"last record truncated ({record - 20} of {record} bytes), left out",)
    np.testing.assert_array_equal(read(path, "IMU:0").data, expected(truth[0]))
    got = read(w.save(tmp_path / "header.bin", cut=record - 2), "IMU:1")  # only A3 95 of the last record left
    assert got.notes == ("last record truncated (2 bytes of its header), left out",)


def test_garbage_between_records_and_record_headers_inside_fields_are_skipped(tmp_path):
    garbage = {8: bytes(5),  # right after the record of sample 7 that holds a record header in its fields
               20: b"\x00\xff\x13" + b"\xa3\x95\x83" + bytes(range(40, 80)) + b"\xa3\x95",  # a false header inside
               33: b"\xa3\x95\x05" + bytes(10),  # the header of a message no FMT describes
               45: b"\xa3\x95\x83" + bytes(30)}  # an IMU header, then garbage shorter than an IMU record
    w = Writer()
    truth = new_log(w, n=60, extra=garbage)
    path = w.save(tmp_path / "garbage.bin")
    assert b"\xa3\x95\x83\x3f" in path.read_bytes()
    for k in (0, 1):
        got = read(path, f"IMU:{k}")
        np.testing.assert_array_equal(got.data, expected(truth[k]))
        skipped = sum(map(len, garbage.values()))
        assert got.notes == (f"{skipped} bytes that are no record skipped (4 places)",)


def refusal(path, topic=None, names=None) -> str:
    with pytest.raises(InputError) as err:
        read(path, topic, names)
    message = err.value.message  # placeholders ({temperature_column}) as the library writes them
    assert "\n" not in message and err.value.where == str(path)
    return message


def test_each_malformed_log_or_request_is_refused_in_one_line_naming_the_file_and_stream(tmp_path):
    w = Writer()
    new_log(w, n=30)
    path = w.save(tmp_path / "two.bin")
    message = refusal(path, "IMU:3")
    assert "IMU:3" in message and "IMU:0, IMU:1" in message
    message = refusal(path, "GPS")
    assert "'GPS' is no message of this log" in message and "IMU:0, IMU:1" in message
    message = refusal(path, "ATT")
    assert "'ATT' is a message of this log but no IMU message" in message
    assert "names an instance twice" in refusal(path, "IMU2:1")
    message = refusal(path, "IMU:1", ["time", "gyro_x", "mag_x"])
    assert "IMU:1" in message and "'mag_x'" in message and "gyro_x" in message
    with pytest.raises(InputError, match="one time stamp"):
        dataflash.read(path, None, "time", LogFormat(stamps="record"))
    assert dataflash.read(path, None, "time", LogFormat(stamps="header")).data.shape == (30, 8)

    w = Writer()
    w.define(131, "IMU", "QffffffIIf", "TimeUS,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,Tx")  # no T
    w.write("IMU", 10, 0, 0, 0, 0, 0, 0, 0, 0, 0)
    w.write("IMU", 20, 0, 0, 0, 0, 0, 0, 0, 0, 0)
    message = refusal(w.save(tmp_path / "no_t.bin"), names=["time", "temperature"])
    assert "IMU:0" in message and "'temperature'" in message and "{temperature_column}" in message

    w = Writer()
    w.define(133, "ATT", "QccccCCCCB", "TimeUS,DesRoll,Roll,DesPitch,Pitch,DesYaw,Yaw,ErrRP,ErrYaw,AEKF")
    w.define(131, "IMU", *IMU_NEW)  # described, never written
    w.write("ATT", 1, 0, 0, 0, 0, 0, 0, 0, 0, 0)
    message = refusal(w.save(tmp_path / "no_imu.bin"))
    assert "no IMU message" in message and "ATT" in message

    w = Writer()
    w.define(131, "IMU", *IMU_NEW)
    for t in (1000, 3500, 6000, 4000, 8500):
        w.write("IMU", t, 0, 0.0, 0.0, 0.0, 0.0, 0.0, -9.8, 0, 0, 25.0, 1, 1, 400, 400)
    message = refusal(w.save(tmp_path / "back.bin"))
    assert "IMU:0" in message and "TimeUS goes back at sample 4 of 5" in message and "6000 to 4000" in message

    for name, content in (("random.bin", np.random.default_rng(1).normal(size=1000).tobytes()),
                          ("empty.bin", b""), ("text.bin", b"time,gx,gy,gz\n0,1,2,3\n")):
        (tmp_path / name).write_bytes(content)
        assert "is not an ArduPilot DataFlash log" in refusal(tmp_path / name)


def test_describe_lists_the_imu_streams_with_rates_and_temperatures_and_every_message(tmp_path):
    w = Writer()
    w.standard()
    truth = new_log(w, n=120)
    streams = dataflash.describe(w.save(tmp_path / "log.bin"), LogFormat())
    by_topic = {s.topic: s for s in streams}
    for k in (0, 1):
        s = by_topic[f"IMU:{k}"]
        assert (s.kind, s.count) == ("IMU", 120)
        assert s.columns == ("time", "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z", "temperature")
        assert s.units["gyro_x"] == "rad/s" and s.units["temperature"] == "degC"
        assert s.extra["rate_hz"] == pytest.approx(400.0, rel=1e-12)
        t = truth[k]["T"].astype(float)
        assert s.extra["temperature_degC"] == (t.min(), t.max())
    assert (by_topic["ATT"].count, by_topic["UNIT"].count, by_topic["MULT"].count, by_topic["FMTU"].count) == (12, 6, 3, 1)
    assert by_topic["FMT"].count == 6 and "IMU" not in by_topic


def test_sniff_knows_a_dataflash_head_and_rejects_float64_data(tmp_path):
    w = Writer()
    new_log(w, n=100)
    data = w.save(tmp_path / "log.bin").read_bytes()
    assert dataflash.sniff(data[:4096]) and dataflash.sniff(data[:89])
    rng = np.random.default_rng(7)
    heads = [rng.normal(0, 10.0 ** rng.integers(-3, 4), 512).tobytes() for _ in range(300)]
    heads += [np.cumsum(rng.normal(size=512)).tobytes(), np.arange(512.0).tobytes(), bytes(4096)]
    forged = bytearray(rng.normal(size=512).tobytes())
    forged[:3] = b"\xa3\x95\x80"  # a double whose first bytes are a FMT header
    heads.append(bytes(forged))
    assert not any(dataflash.sniff(h) for h in heads)
    assert not dataflash.sniff(data[:89] + b"\x00\x00" + data[91:4096])  # a FMT record, then no record


def test_a_log_source_reads_a_stream_in_the_units_the_log_states(tmp_path, registered):
    w = Writer()
    w.standard()
    truth = new_log(w, n=300)
    path = w.save(tmp_path / "flight.bin")
    assert readers.reader_for(path).name == "dataflash"
    src = LogSource(path=path, format=LogFormat(topic="IMU:1"), temperature_column="temperature")
    gyro = src.read(Sensor.GYROSCOPE)
    np.testing.assert_array_equal(gyro.t, truth[1]["TimeUS"] * 1e-6)
    np.testing.assert_array_equal(gyro.data, truth[1]["gyro"].astype(float))
    np.testing.assert_array_equal(gyro.temperature, truth[1]["T"].astype(float))
    assert gyro.units == "rad/s" and gyro.stated and gyro.rate_hz == pytest.approx(400.0)
    assert gyro.source == {"format": "dataflash", "topic": "IMU", "instance": 1}
    accel = LogSource(path=path).read(Sensor.ACCELEROMETER)
    np.testing.assert_array_equal(accel.data, truth[0]["accel"].astype(float))
    assert accel.units == "m/s^2" and accel.stated
    with pytest.raises(InputError, match="states its readings in rad/s"):
        LogSource(path=path, units="deg/s").read(Sensor.GYROSCOPE)


def test_the_modules_examples_run():
    for module in (dataflash, dataflash_format):
        failed, tried = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
        assert tried and not failed


def test_gps_records_date_the_stream_in_utc(tmp_path):
    """ArduPilot's GPS message (TimeUS, I, Status, GMS, GWk, ...: GPS week and ms of the week, since 1980-01-06
    without leap seconds): the first IMU sample's UTC from them, 18 leap seconds taken off (IERS Bulletin C)."""
    from datetime import UTC, datetime, timedelta

    w = Writer()
    truth = new_log(w, n=40)
    w.define(130, "GPS", "QBBIHBcLLeffffB", "TimeUS,I,Status,GMS,GWk,NSats,HDop,Lat,Lng,Alt,Spd,GCrs,VZ,Yaw,U")
    first = datetime(2024, 2, 6, 12, 0, 0, tzinfo=UTC)  # the UTC of the first IMU sample of instance 0 (at 5 s)
    for stamp in (6_000_000, 7_000_000, 8_000_000):  # fixes 1, 2, 3 s after it
        since = first + timedelta(microseconds=stamp - 5_000_000) - datetime(1980, 1, 6, tzinfo=UTC)
        gps_ms = round((since.total_seconds() + 18) * 1000)  # UTC + 18 s = GPS time (2017 on)
        w.write("GPS", stamp, 0, 3, gps_ms % 604_800_000, gps_ms // 604_800_000, 12, 90, 0, 0, 0, 0.0, 0.0, 0.0,
                0.0, 1)
    w.write("GPS", 9_000_000, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0.0, 0.0, 0.0, 0.0, 1)  # no fix: week 0, left out
    path = w.save(tmp_path / "gps.bin")
    assert read(path, "IMU:0").source["time_origin_utc_ns"] == int(first.timestamp()) * 10**9
    later = int((first + timedelta(microseconds=100)).timestamp() * 1e6) * 1000  # instance 1 starts 100 us later
    assert read(path, "IMU:1").source["time_origin_utc_ns"] == later
    assert "time_origin_utc_ns" not in read(path, "IMU:0", ["gyro_x"]).source  # no time column read
    assert truth[0]["TimeUS"][0] == 5_000_000
