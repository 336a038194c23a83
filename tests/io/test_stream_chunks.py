"""Long stream logs (a ULog, a ROS 2 bag) read in blocks for the Allan deviation (align.io.streamchunks).

Truth from outside the code: a ULog written here from the format's documentation
(https://docs.px4.io/main/en/dev_log/ulog_file_format.html: the 16-byte header, ``F`` format, ``A``
subscription and ``D`` data messages packed with ``struct``) and an MCAP bag written by rosbags' own writer,
with known samples; the blocks read back to those samples, and the Allan result through the blocks is the one
of the whole-file path, to the bit.
"""

from __future__ import annotations

import gc
import struct
from pathlib import Path

import numpy as np
import pytest

from align.errors import InputError
from align.io import streamchunks
from align.io.formats import LogFormat
from align.io.logs import read_static_log
from align.io.streamchunks import StreamChunks
from align.noise.allan import allan

COMBINED = ("sensor_combined:uint64_t timestamp;float[3] gyro_rad;uint32_t gyro_integral_dt;int32_t "
            "accelerometer_timestamp_relative;float[3] accelerometer_m_s2;uint32_t accelerometer_integral_dt;"
            "uint8_t accelerometer_clipping;uint8_t[3] _padding0;")
NAMES = ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]
N, STEP_US, T0 = 3000, 2500, 10_000_000  # 400 Hz
RNG = np.random.default_rng(7)
VALUES = np.column_stack([RNG.normal(0, 0.01, (N, 3)), RNG.normal(0, 0.1, (N, 3)) + [0, 0, -9.8]]).astype("f4")


def write_ulog(path: Path, drop: int | None = None) -> Path:
    """``N`` sensor_combined samples every 2.5 ms (sample ``drop`` left out: a gap)."""
    out = bytearray(b"ULog\x01\x12\x35\x01" + struct.pack("<Q", 1234))

    def msg(kind: str, body: bytes) -> None:
        out.extend(struct.pack("<HB", len(body), ord(kind)) + body)

    msg("F", COMBINED.encode())
    msg("A", struct.pack("<BH", 0, 1) + b"sensor_combined")
    for k in range(N):
        if k != drop:
            t = T0 + STEP_US * k
            msg("D", struct.pack("<H", 1) + struct.pack("<Q3fIi3fIB3x", t, *VALUES[k, :3], STEP_US, 0,
                                                         *VALUES[k, 3:], STEP_US, 0))
    path.write_bytes(bytes(out))
    return path


def write_bag(folder: Path, drop: int | None = None) -> Path:
    """``N`` sensor_msgs/Imu messages on /imu0 every 2.5 ms in an MCAP file (message ``drop`` left out)."""
    rosbag2 = pytest.importorskip("rosbags.rosbag2")
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    v3, q, kind = ts.types["geometry_msgs/msg/Vector3"], ts.types["geometry_msgs/msg/Quaternion"], "sensor_msgs/msg/Imu"
    path = folder / "run"
    with rosbag2.Writer(path, version=9, storage_plugin=rosbag2.StoragePlugin.MCAP) as writer:
        conn = writer.add_connection("/imu0", kind, typestore=ts)
        for k in range(N):
            if k == drop:
                continue
            ns = 1_700_000_000_000_000_000 + STEP_US * 1000 * k
            header = ts.types["std_msgs/msg/Header"](stamp=ts.types["builtin_interfaces/msg/Time"](
                sec=ns // 10**9, nanosec=ns % 10**9), frame_id="imu")
            g, a = VALUES[k].astype(float)[:3], VALUES[k].astype(float)[3:]
            msg = ts.types[kind](header=header, orientation=q(x=0.0, y=0.0, z=0.0, w=1.0),
                                 orientation_covariance=np.zeros(9), angular_velocity=v3(*g),
                                 angular_velocity_covariance=np.zeros(9), linear_acceleration=v3(*a),
                                 linear_acceleration_covariance=np.zeros(9))
            writer.write(conn, ns, ts.serialize_cdr(msg, kind))
    return next(path.glob("*.mcap"))


@pytest.fixture(autouse=True)
def registered():
    """The ULog and bag readers registered for these tests (the registry restored after each)."""
    from align.io import readers, rosbag, ulog

    saved = list(readers.READERS)
    readers.register(ulog.READER)
    readers.register(rosbag.READER)
    yield
    readers.READERS[:] = saved


@pytest.fixture(params=["ulog", "bag"])
def write(request):
    """The writer of a format; its ``t0``: the time of the first sample as read (a ULog's: since boot, 10 s)."""
    if request.param == "ulog":
        write_ulog.t0 = T0 / 1e6
        return write_ulog
    bag = lambda p, drop=None: write_bag(p.parent, drop)  # noqa: E731
    bag.t0 = 0.0  # a bag's time counts from its first sample
    return bag


def _read(path: Path, chunked: bool, monkeypatch, rows: int = 700):
    monkeypatch.setattr(streamchunks, "CHUNKED_BYTES", 0 if chunked else 1 << 62)
    monkeypatch.setattr(streamchunks, "ROWS", rows)
    return read_static_log(path, NAMES, None, LogFormat())


def test_blocks_read_back_the_samples_written_and_give_the_whole_files_allan_result(tmp_path, monkeypatch, write):
    path = write(tmp_path / "run.ulg")
    got = _read(path, True, monkeypatch)
    assert isinstance(got.data, StreamChunks) and got.data.shape == (N, 6)
    assert got.rate_hz == pytest.approx(400.0, rel=1e-9) and got.units is None and got.time_units == "s"
    assert [len(b) for b in got.data.chunks(rows=1100)] == [1100, 1100, 800]
    np.testing.assert_array_equal(np.concatenate(list(got.data.chunks(rows=1100))), VALUES.astype(np.float64))
    np.testing.assert_array_equal(np.concatenate(list(got.data.chunks(rows=999, columns=[4]))), VALUES[:, [4]])
    whole = _read(path, False, monkeypatch)
    assert isinstance(whole.data, np.ndarray) and whole.rate_hz == got.rate_hz and whole.source.keys() <= {
        *got.source.keys(), "time_origin_ns"}
    a, b = allan(got.data, got.rate_hz, NAMES), allan(whole.data, whole.rate_hz, NAMES)
    np.testing.assert_array_equal(a.adev, b.adev)
    np.testing.assert_array_equal(a.tau, b.tau)
    np.testing.assert_array_equal(a.bias, b.bias)
    assert a.n == b.n == N
    spill = Path(got.data.path)  # the temporary file of the blocks' data: removed once released
    assert spill.exists() and spill.stat().st_size == N * 6 * 8
    del got, a
    gc.collect()
    assert not spill.exists()


def test_a_gap_in_the_middle_is_refused_with_its_position(tmp_path, monkeypatch, write):
    path = write(tmp_path / "gap.ulg", drop=2100)  # in the fourth block of 700
    at = f"{write.t0 + 2099 * STEP_US / 1e6:.6g}"  # the sample before the one left out
    with pytest.raises(InputError, match=r"1 time gaps or jitter beyond 50 % of the 0.0025 s median step: gap in the "
                                         rf"time series at t={at} s \(step 0.005 s\); resample or split") as err:
        _read(path, True, monkeypatch)
    assert err.value.where == str(path)


def test_time_going_back_between_blocks_is_refused_naming_its_row(monkeypatch):
    from align.io.readers import Columns

    t = np.arange(20) * 0.01
    t[10:] -= 0.5  # the third block of 5 starts before the second ends

    def blocks(path, fmt, names, rows):
        for s in range(0, 20, rows):
            yield Columns(names, np.column_stack([t[s:s + rows], np.ones(len(t[s:s + rows]))]), {"time": "s"})

    with pytest.raises(InputError, match=r"time does not increase at data row 11 \(t=-0.4 s after 0.09 s\)"):
        StreamChunks(Path("x.ulg"), ["gyro_x"], LogFormat(), blocks, rows=5)
