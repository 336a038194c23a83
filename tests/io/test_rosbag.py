"""ROS bags read without ROS (align.io.rosbag).

Truth from outside the reader: every bag is written here by rosbags' own writers (ROS 1 Writer, ROS 2 Writer with
sqlite3 and mcap storage) from known samples: gyro and accel values, header stamps and record times, a
Temperature topic at 10 Hz that is a straight line in time (so its interpolation to the IMU's times is the line
itself), a MagneticField topic at 50 Hz. Malformed bags are cut, overwritten or written with stamps that go back.
"""

from __future__ import annotations

import sys

import numpy as np
import pytest

pytest.importorskip("rosbags")

from rosbags.rosbag1 import Writer as Writer1  # noqa: E402
from rosbags.rosbag2 import StoragePlugin  # noqa: E402
from rosbags.rosbag2 import Writer as Writer2  # noqa: E402
from rosbags.typesys import Stores, get_types_from_msg, get_typestore  # noqa: E402

from align.errors import InputError  # noqa: E402
from align.io import readers, rosbag  # noqa: E402
from align.io.formats import LogFormat  # noqa: E402
from align.io.logs import read_sensor_log  # noqa: E402
from align.io.tables import read_table  # noqa: E402

T0 = 1_700_000_000_000_000_000  # ns, the first header stamp
N_IMU, N_TEMP, N_MAG = 200, 20, 50
STEP_IMU, STEP_TEMP, STEP_MAG = 5_000_000, 100_000_000, 20_000_000  # ns: 200 Hz, 10 Hz, 50 Hz
DELAY = 1_500_000  # ns: the recorder writes each message 1.5 ms after its header stamp
RNG = np.random.default_rng(24)
GYRO, ACCEL, MAG = RNG.normal(0, 0.3, (N_IMU, 3)), RNG.normal(0, 3, (N_IMU, 3)), RNG.normal(0, 4e-5, (N_MAG, 3))
TS1, TS2 = get_typestore(Stores.ROS1_NOETIC), get_typestore(Stores.ROS2_HUMBLE)
IMU_COLUMNS = ["time", "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]
KINDS = ["ros1", "sqlite3-folder", "sqlite3-file", "mcap-folder", "mcap-file"]


def temperature_at(ns):
    """The Temperature topic's truth: 30 degC rising 2 degC per second from T0."""
    return 30.0 + 2.0 * (np.asarray(ns, dtype=np.int64) - T0) / 1e9


def _header(ts, ns: int, ros1: bool):
    stamp = ts.types["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)
    header = ts.types["std_msgs/msg/Header"]
    return header(seq=0, stamp=stamp, frame_id="imu_link") if ros1 else header(stamp=stamp, frame_id="imu_link")


def _imu(ts, ns, ros1, i):
    v3, q = ts.types["geometry_msgs/msg/Vector3"], ts.types["geometry_msgs/msg/Quaternion"]
    return ts.types["sensor_msgs/msg/Imu"](
        header=_header(ts, ns, ros1), orientation=q(x=0.0, y=0.0, z=0.0, w=1.0), orientation_covariance=np.full(9, -1.0),
        angular_velocity=v3(*GYRO[i]), angular_velocity_covariance=np.full(9, 7.0),
        linear_acceleration=v3(*ACCEL[i]), linear_acceleration_covariance=np.full(9, 8.0))


def _temperature(ts, ns, ros1, i):
    return ts.types["sensor_msgs/msg/Temperature"](header=_header(ts, ns, ros1), temperature=float(temperature_at(ns)),
                                                   variance=0.01)


def _mag(ts, ns, ros1, i):
    v3 = ts.types["geometry_msgs/msg/Vector3"]
    return ts.types["sensor_msgs/msg/MagneticField"](header=_header(ts, ns, ros1), magnetic_field=v3(*MAG[i]),
                                                     magnetic_field_covariance=np.zeros(9))


def standard_topics(imu_stamps=None):
    """(topic, type, [(record ns, header ns, message maker, index)]) of the standard test bag."""
    imu_stamps = [T0 + i * STEP_IMU for i in range(N_IMU)] if imu_stamps is None else imu_stamps
    return [
        ("/imu0", "sensor_msgs/msg/Imu", [(T0 + i * STEP_IMU + DELAY, s, _imu, i) for i, s in enumerate(imu_stamps)]),
        ("/imu0/temperature", "sensor_msgs/msg/Temperature",
         [(T0 + 50_000_000 + i * STEP_TEMP + DELAY, T0 + 50_000_000 + i * STEP_TEMP, _temperature, i)
          for i in range(N_TEMP - 2)]),   # 0.05 s to 1.75 s: the IMU's first and last samples are outside its span
        ("/board/temperature", "sensor_msgs/msg/Temperature",
         [(T0 + i * STEP_TEMP + DELAY, T0 + i * STEP_TEMP, _temperature, i) for i in range(3)]),
        ("/mag", "sensor_msgs/msg/MagneticField",
         [(T0 + i * STEP_MAG + DELAY, T0 + i * STEP_MAG, _mag, i) for i in range(N_MAG)]),
        ("/chatter", "std_msgs/msg/String", [(T0 + DELAY, None, None, 0)]),
        ("/imu_idle", "sensor_msgs/msg/Imu", []),
    ]


def write_bag(folder, kind: str, topics, typestore=None):
    """The topics written by rosbags' writer of ``kind``; returns the path to read (a file or a bag folder)."""
    ros1 = kind == "ros1"
    ts = typestore or (TS1 if ros1 else TS2)
    path = folder / ("run.bag" if ros1 else "run")
    plugin = StoragePlugin.MCAP if kind.startswith("mcap") else StoragePlugin.SQLITE3
    writer = Writer1(path) if ros1 else Writer2(path, version=9, storage_plugin=plugin)
    messages = []
    with writer:
        for topic, msgtype, rows in topics:
            conn = writer.add_connection(topic, msgtype, typestore=ts)
            for record, stamp, make, i in rows:
                msg = ts.types["std_msgs/msg/String"](data="hello") if make is None else make(ts, stamp, ros1, i)
                messages.append((record, conn, ts.serialize_ros1(msg, msgtype) if ros1 else
                                 ts.serialize_cdr(msg, msgtype)))
        for record, conn, data in sorted(messages, key=lambda m: m[0]):
            writer.write(conn, record, data)
    if kind.endswith("-file"):
        return next(p for p in path.iterdir() if p.suffix in (".db3", ".mcap"))
    return path


@pytest.fixture(autouse=True)
def registered():
    """The rosbag reader registered for these tests (the registry restored after each)."""
    saved = list(readers.READERS)
    readers.register(rosbag.READER)
    yield
    readers.READERS[:] = saved


@pytest.fixture(scope="module")
def bags(tmp_path_factory):
    """The standard bag in each storage, written once for the module."""
    root = tmp_path_factory.mktemp("bags")
    out = {}
    for kind in KINDS:
        (root / kind).mkdir()
        out[kind] = write_bag(root / kind, kind, standard_topics())
    return out


# ---------------------------------------------------------------- reading back


@pytest.mark.parametrize("kind", KINDS)
def test_every_storage_reads_back_the_samples_written(bags, kind, monkeypatch):
    monkeypatch.setattr(rosbag, "_deserialised", None)  # the fast path reads these messages (a call would fail)
    got = read_table(bags[kind])  # the registry finds the reader: a .bag, .db3, .mcap file or a bag folder
    assert got.names == IMU_COLUMNS + ["temperature"]
    np.testing.assert_array_equal(got.data[:, 1:4], GYRO)
    np.testing.assert_array_equal(got.data[:, 4:7], ACCEL)
    header = T0 + np.arange(N_IMU) * STEP_IMU
    np.testing.assert_allclose(got.data[:, 0], (header - T0) / 1e9, rtol=0, atol=1e-12)  # from the first sample
    assert got.units["gyro_x"] == "rad/s" and got.units["accel_z"] == "m/s^2" and got.units["time"] == "s"
    assert got.units["temperature"] == "degC"
    ros1 = kind == "ros1"
    assert dict(got.source) == {"format": "rosbag", "topic": "/imu0", "stamps": "header", "time_origin_ns": T0,
                                "type": "sensor_msgs/Imu" if ros1 else "sensor_msgs/msg/Imu",
                                "storage": "ros1" if ros1 else kind.split("-")[0],
                                "temperature_topic": "/imu0/temperature"}  # under /imu0, not /board/temperature
    # the temperature is a straight line in time: interpolated, it is the line; held outside its span
    first, last = T0 + 50_000_000, T0 + 50_000_000 + (N_TEMP - 3) * STEP_TEMP
    inside = (header >= first) & (header <= last)
    np.testing.assert_allclose(got.data[inside, 7], temperature_at(header[inside]), rtol=0, atol=1e-9)
    assert np.all(got.data[header < first, 7] == temperature_at(first))
    assert np.all(got.data[header > last, 7] == temperature_at(last))
    held = int(np.sum(~inside))
    assert got.notes and "linearly interpolated" in got.notes[0] and f"for {held} samples" in got.notes[0]


@pytest.mark.parametrize("kind", ["ros1", "mcap-file"])
def test_record_stamps_are_the_times_the_recorder_wrote(bags, kind):
    got = read_table(bags[kind], ["time", "gyro_z"], "time", LogFormat(stamps="record"))
    np.testing.assert_allclose(got.data[:, 0], np.arange(N_IMU) * STEP_IMU / 1e9, rtol=0, atol=1e-12)
    assert got.source["time_origin_ns"] == T0 + DELAY
    np.testing.assert_array_equal(got.data[:, 1], GYRO[:, 2])
    assert got.source["stamps"] == "record"


@pytest.mark.parametrize("kind", ["ros1", "sqlite3-folder"])
def test_the_magnetometer_topic_in_tesla(bags, kind):
    named = read_table(bags[kind], None, None, LogFormat(topic="/mag"))
    assert named.names == ["time", "mag_x", "mag_y", "mag_z"]  # no Temperature topic under /mag or in its namespace
    assert "no temperature column" in named.notes[0]
    np.testing.assert_array_equal(named.data[:, 1:4], MAG)
    assert named.units["mag_x"] == "T"
    # asked for magnetometer columns alone, the bag's only MagneticField topic is read
    chosen = read_table(bags[kind], ["time", "mag_x", "mag_y", "mag_z"], "time")
    assert chosen.source["topic"] == "/mag"
    np.testing.assert_allclose(chosen.data[:, 0], np.arange(N_MAG) * STEP_MAG / 1e9, rtol=0, atol=1e-12)


def test_a_sensor_log_takes_the_units_the_bag_states(bags):
    log = read_sensor_log(bags["mcap-folder"], ["gyro_x", "gyro_y", "gyro_z"], None, "time",
                          log_format=LogFormat(topic="/imu0"), temperature_column="temperature")
    np.testing.assert_array_equal(log.data, GYRO)  # rad/s stated, so no factor
    assert log.stated and log.units == "rad/s" and log.source["topic"] == "/imu0"
    np.testing.assert_allclose(log.rate_hz, 200.0, rtol=1e-12)
    assert log.temperature is not None and log.temperature.shape == (N_IMU,)


def test_describe_lists_topics_types_counts_and_rates(bags):
    streams = {s.topic: s for s in rosbag.describe(bags["ros1"], LogFormat())}
    assert set(streams) == {"/imu0", "/imu0/temperature", "/board/temperature", "/mag", "/chatter", "/imu_idle"}
    assert (streams["/imu0"].kind, streams["/imu0"].count) == ("sensor_msgs/Imu", N_IMU)
    assert streams["/imu0"].columns == tuple(IMU_COLUMNS)
    assert streams["/imu0"].extra["rate_hz"] == pytest.approx(200.0, rel=1e-9)
    assert streams["/mag"].extra["rate_hz"] == pytest.approx(50.0, rel=1e-9)
    assert streams["/imu0/temperature"].extra["rate_hz"] == pytest.approx(10.0, rel=1e-9)
    assert (streams["/chatter"].kind, streams["/chatter"].count, streams["/chatter"].columns) == ("std_msgs/String", 1, ())
    assert streams["/imu_idle"].count == 0
    assert {s.topic: s.count for s in rosbag.describe(bags["mcap-file"], LogFormat())}["/mag"] == N_MAG


def test_a_layout_the_fast_path_does_not_know_is_deserialised_by_rosbags(tmp_path, monkeypatch):
    """An Imu of another definition: the bytes cut by the fast path differ from rosbags' deserialiser's values,
    so every message is deserialised instead (and the values are still the ones written)."""
    ts = get_typestore(Stores.EMPTY)
    ts.register({k: v for k, v in TS2.fielddefs.items() if k != "sensor_msgs/msg/Imu"})
    ts.register(get_types_from_msg("std_msgs/Header header\ngeometry_msgs/Vector3 angular_velocity\n"
                                   "geometry_msgs/Vector3 linear_acceleration\nfloat64[40] spare", "sensor_msgs/msg/Imu"))

    def odd(ts, ns, ros1, i):
        v3 = ts.types["geometry_msgs/msg/Vector3"]
        return ts.types["sensor_msgs/msg/Imu"](header=_header(ts, ns, ros1), angular_velocity=v3(*GYRO[i]),
                                               linear_acceleration=v3(*ACCEL[i]), spare=np.arange(40.0))

    path = write_bag(tmp_path, "mcap-folder", [("/imu0", "sensor_msgs/msg/Imu",
                                                [(T0 + i * STEP_IMU, T0 + i * STEP_IMU, odd, i) for i in range(30)])], ts)
    original, calls = rosbag._deserialised, []
    monkeypatch.setattr(rosbag, "_deserialised", lambda *args: calls.append(args[2]) or original(*args))
    got = read_table(path)
    assert calls == ["sensor_msgs/msg/Imu"]  # the cut bytes did not match rosbags' values: deserialised instead
    np.testing.assert_array_equal(got.data[:, 1:4], GYRO[:30])
    np.testing.assert_array_equal(got.data[:, 4:7], ACCEL[:30])


# ---------------------------------------------------------------- refusals


def _refused(path, fmt=None, names=None, time_column="time") -> str:
    with pytest.raises(InputError) as err:
        read_table(path, names, time_column, fmt)
    text = str(err.value)
    assert "\n" not in text and str(path) in text
    return text


def test_an_unknown_topic_is_refused_listing_the_topics_with_types_and_counts(bags):
    text = _refused(bags["ros1"], LogFormat(topic="/imu9"))
    assert "'/imu9'" in text and "/imu0 (sensor_msgs/Imu, 200)" in text and "/mag (sensor_msgs/MagneticField, 50)" in text


def test_a_topic_of_another_type_is_refused(bags):
    text = _refused(bags["sqlite3-folder"], LogFormat(topic="/chatter"))
    assert "std_msgs/msg/String" in text and "sensor_msgs/msg/Imu" in text


def test_an_empty_topic_is_refused(bags):
    assert "'/imu_idle' holds no message" in _refused(bags["mcap-file"], LogFormat(topic="/imu_idle"))


def test_several_imu_topics_without_a_topic_are_refused_naming_them(tmp_path):
    topics = standard_topics()[:1] + [("/imu1", "sensor_msgs/msg/Imu", [(T0, T0, _imu, 0), (T0 + 1, T0 + 1, _imu, 1)])]
    text = _refused(write_bag(tmp_path, "ros1", topics))
    assert "2 sensor_msgs/Imu topics (/imu0, /imu1)" in text and "topic='/imu0'" in text


def test_header_stamps_that_go_back_are_refused_and_record_stamps_read(tmp_path):
    stamps = [T0 + i * STEP_IMU for i in range(N_IMU)]
    stamps[120] = stamps[118]
    path = write_bag(tmp_path, "mcap-folder", standard_topics(stamps)[:1])
    text = _refused(path)
    assert "message 121" in text and "earlier than the one before" in text and "stamps='record'" in text
    got = read_table(path, None, "time", LogFormat(stamps="record"))
    np.testing.assert_array_equal(got.data[:, 1:4], GYRO)


def test_header_stamps_left_at_zero_are_refused(tmp_path):
    path = write_bag(tmp_path, "ros1", standard_topics([0] * N_IMU)[:1])
    assert "all zero" in _refused(path) and "stamps='record'" in _refused(path)


@pytest.mark.parametrize("kind, cut", [("ros1", 0.6), ("ros1", 0.999), ("mcap-file", 0.6), ("sqlite3-file", 0.5),
                                       ("ros1", 0.0)])
def test_a_truncated_or_damaged_bag_is_refused(bags, tmp_path, kind, cut):
    data = bags[kind].read_bytes()
    path = tmp_path / bags[kind].name
    path.write_bytes(data[: int(len(data) * cut)] if cut else b"not a bag at all" * 64)
    assert "damaged or truncated" in _refused(path)


def test_several_temperature_topics_without_one_near_are_refused_when_asked_for(tmp_path):
    imu = ("/imu0", "sensor_msgs/msg/Imu", [(T0 + i, T0 + i, _imu, i) for i in range(3)])
    temps = [(t, "sensor_msgs/msg/Temperature", [(T0 + i, T0 + i, _temperature, i) for i in range(3)])
             for t in ("/a/temperature", "/b/temperature")]
    path = write_bag(tmp_path, "ros1", [imu, *temps])
    text = _refused(path, None, ["time", "gyro_x", "temperature"])
    assert "2 sensor_msgs/Temperature topics (/a/temperature, /b/temperature)" in text and "temperature_column" in text
    all_columns = read_table(path)  # not asked for by name: left out, saying why
    assert all_columns.names == IMU_COLUMNS and "no temperature column" in all_columns.notes[0]


def test_a_column_the_topic_does_not_give_is_refused_naming_the_columns(bags):
    text = _refused(bags["ros1"], LogFormat(topic="/imu0"), ["time", "mag_x"])
    assert "no column 'mag_x'" in text and "gyro_x" in text and "/mag" in text
    assert "{time_column=time}" not in text
    assert "time_column='time'" in _refused(bags["ros1"], None, ["stamp", "gyro_x"], "stamp")


def test_without_rosbags_a_bag_is_one_line_saying_how_to_install_it(bags, monkeypatch):
    monkeypatch.setitem(sys.modules, "rosbags.highlevel", None)  # an import of it now fails
    assert "pip install 'imu-align[logs]'" in _refused(bags["ros1"])


def test_the_reader_owns_bag_files_and_bag_folders(bags, tmp_path):
    for kind in KINDS:
        assert readers.reader_for(bags[kind]) is rosbag.READER
    (tmp_path / "metadata.yaml").write_text("not a bag\n")
    with pytest.raises(InputError, match="not a log folder"):
        readers.reader_for(tmp_path)  # metadata.yaml without a storage file is no bag
