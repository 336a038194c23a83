"""Benchmark: `imu-align allan` on a long 400 Hz, 6-channel recording in a ULog and in a ROS 2 MCAP bag (issue 24).

Writes, in a temporary folder (removed at the end, also on a failure, unless --keep):
  * a ULog of ``sensor_combined`` messages (gyro and accelerometer, 400 Hz), by a minimal writer from the format's
    documentation (https://docs.px4.io/main/en/dev_log/ulog_file_format.html; the idea of tests/io/test_ulog.py,
    its data messages packed by numpy in blocks);
  * a ROS 2 MCAP bag of ``sensor_msgs/Imu`` messages on /imu0 (rosbags' writer; each message's CDR bytes are one
    message serialised by rosbags with its stamp and six readings replaced).
Then, for each, measures whole processes side by side in one run:
  (a) reading the file alone: a script that iterates the reader's blocks (``iter_chunks``) of the columns allan
      reads, and sums one;
  (b) ``python -m align.cli allan FILE --topic T --json OUT`` (streamed: align.io.streamchunks);
and prints wall time, CPU time, peak RSS of each and the ratio (b) / (a). Targets: ratio <= 2, peak RSS < 1 GB.

    python bench/bench_allan_logs.py [--hours 24] [--bag-hours H] [--formats ulog,bag] [--columns all|gyro]
        [--memory-limit-mb MB] [--keep DIR]
"""

from __future__ import annotations

import argparse
import json
import struct
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))
from _measure import in_folder, measure_cpu  # noqa: E402

RATE, STEP_US, T0_US = 400.0, 2500, 10_000_000
BLOCK = 1 << 20  # samples generated and written at once
COMBINED = ("sensor_combined:uint64_t timestamp;float[3] gyro_rad;uint32_t gyro_integral_dt;int32_t "
            "accelerometer_timestamp_relative;float[3] accelerometer_m_s2;uint32_t accelerometer_integral_dt;"
            "uint8_t accelerometer_clipping;uint8_t[3] _padding0;")  # the trailing padding is not logged
COLUMNS = {"gyro": ["gyro_x", "gyro_y", "gyro_z"], "all": ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y",
                                                           "accel_z"]}


def samples(n: int, seed: int = 1):
    """Blocks (k, 6) float32 of white noise (gyro 0.01 rad/s, accelerometer 0.05 m/s^2 about gravity) and a slow
    gyro random walk; with their first sample's index."""
    rng = np.random.default_rng(seed)
    walk = np.zeros(3)
    for s in range(0, n, BLOCK):
        k = min(BLOCK, n - s)
        steps = np.cumsum(rng.normal(0, 1e-6, (k, 3)), axis=0) + walk
        walk = steps[-1]
        yield s, np.column_stack([rng.normal(0, 0.01, (k, 3)) + steps,
                                  rng.normal(0, 0.05, (k, 3)) + [0, 0, -9.80665]]).astype("f4")


def write_ulog(path: Path, n: int) -> None:
    """A ULog: header, the ``F`` format and ``A`` subscription of sensor_combined, then ``n`` ``D`` messages."""
    def msg(kind: str, body: bytes) -> bytes:
        return struct.pack("<HB", len(body), ord(kind)) + body

    dtype = np.dtype([("size", "<u2"), ("type", "u1"), ("id", "<u2"), ("t", "<u8"), ("gyro", "<f4", (3,)),
                      ("gdt", "<u4"), ("rel", "<i4"), ("acc", "<f4", (3,)), ("adt", "<u4"), ("clip", "u1")])
    with open(path, "wb") as fh:
        fh.write(b"ULog\x01\x12\x35\x01" + struct.pack("<Q", 0) + msg("F", COMBINED.encode())
                 + msg("A", struct.pack("<BH", 0, 1) + b"sensor_combined"))
        for s, v in samples(n):
            rec = np.zeros(len(v), dtype)
            rec["size"], rec["type"], rec["id"] = dtype.itemsize - 3, ord("D"), 1
            rec["t"] = T0_US + STEP_US * np.arange(s, s + len(v), dtype=np.uint64)
            rec["gyro"], rec["acc"], rec["gdt"], rec["adt"] = v[:, :3], v[:, 3:], STEP_US, STEP_US
            rec.tofile(fh)


def write_bag(folder: Path, n: int) -> Path:
    """A ROS 2 MCAP bag of ``n`` sensor_msgs/Imu messages on /imu0 (header stamps = record times, 400 Hz)."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts, kind = get_typestore(Stores.ROS2_HUMBLE), "sensor_msgs/msg/Imu"
    v3 = ts.types["geometry_msgs/msg/Vector3"]
    header = ts.types["std_msgs/msg/Header"](stamp=ts.types["builtin_interfaces/msg/Time"](sec=0, nanosec=0),
                                             frame_id="imu_link")
    template = bytes(ts.serialize_cdr(ts.types[kind](
        header=header, orientation=ts.types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
        orientation_covariance=np.zeros(9), angular_velocity=v3(0.0, 0.0, 0.0), angular_velocity_covariance=np.zeros(9),
        linear_acceleration=v3(0.0, 0.0, 0.0), linear_acceleration_covariance=np.zeros(9)), kind))
    size, end = len(template), len(template) - 37 * 8  # the 37 float64 fields last; readings at 13..15, 25..27
    path = folder / "bag"
    t0 = 1_700_000_000_000_000_000
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        conn = writer.add_connection("/imu0", kind, typestore=ts)
        for s, v in samples(n):
            ns = t0 + STEP_US * 1000 * np.arange(s, s + len(v), dtype=np.int64)
            raw = np.tile(np.frombuffer(template, np.uint8), (len(v), 1))
            raw[:, 4:8] = (ns // 10**9).astype("<i4").view(np.uint8).reshape(-1, 4)
            raw[:, 8:12] = (ns % 10**9).astype("<u4").view(np.uint8).reshape(-1, 4)
            for off, cols in ((13, v[:, :3]), (25, v[:, 3:])):
                a = end + 8 * off
                raw[:, a:a + 24] = cols.astype("<f8").view(np.uint8).reshape(-1, 24)
            for i in range(len(v)):
                writer.write(conn, int(ns[i]), raw[i].tobytes())
    assert size == raw.shape[1]
    return next(path.glob("*.mcap"))


READ_ALONE = """
import sys, importlib
from pathlib import Path
from align.io.formats import LogFormat
reader = importlib.import_module(sys.argv[1])
total, n = 0.0, 0
for got in reader.iter_chunks(Path(sys.argv[2]), LogFormat(topic=sys.argv[3]), sys.argv[4].split(","), 100_000):
    total += float(got.data[:, 1].sum())
    n += len(got.data)
print(n, total)
"""


def one(name: str, path: Path, module: str, topic: str, columns: list[str], folder: Path, limit: float | None) -> dict:
    size = path.stat().st_size / 1e6
    read = [sys.executable, "-c", READ_ALONE, module, str(path), topic, ",".join(["time", *columns])]
    out = folder / f"{name}.json"
    job = [sys.executable, "-m", "align.cli", "allan", str(path), "--topic", topic, "--columns", ",".join(columns),
           "--json", str(out), *(["--memory-limit-mb", f"{limit:g}"] if limit is not None else [])]
    wall_r, cpu_r, rss_r = measure_cpu(read)
    wall_a, cpu_a, rss_a = measure_cpu(job)
    result = json.loads(out.read_text())
    n = result.get("samples")
    print(f"{name}: {size:,.0f} MB; read alone {wall_r:.1f} s wall ({cpu_r:.1f} s CPU, {rss_r:.0f} MB peak RSS); "
          f"allan {wall_a:.1f} s wall ({cpu_a:.1f} s CPU, {rss_a:.0f} MB peak RSS); ratio {wall_a / wall_r:.2f} "
          f"(CPU {cpu_a / cpu_r:.2f}){'' if n is None else f'; n={n}'}", flush=True)
    return {"format": name, "mb": size, "read_s": wall_r, "allan_s": wall_a, "ratio": wall_a / wall_r,
            "read_rss_mb": rss_r, "allan_rss_mb": rss_a}


def run(args: argparse.Namespace, folder: Path) -> None:
    columns = COLUMNS[args.columns]
    for name in args.formats.split(","):
        hours = args.hours if name == "ulog" or args.bag_hours is None else args.bag_hours
        n = int(round(hours * 3600 * RATE))
        t0 = time.perf_counter()
        if name == "ulog":
            path, module, topic = folder / "long.ulg", "align.io.ulog", "sensor_combined"
            write_ulog(path, n)
        else:
            path, module, topic = write_bag(folder, n), "align.io.rosbag", "/imu0"
        print(f"{name}: wrote {hours:g} h at 400 Hz ({n:,} samples, 6 channels) in {time.perf_counter() - t0:.0f} s",
              flush=True)
        one(name, path, module, topic, columns, folder, args.memory_limit_mb)
        path.unlink()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=24.0, help="length of the recordings (default 24 h)")
    ap.add_argument("--bag-hours", type=float, default=None, help="length of the bag, when not --hours")
    ap.add_argument("--formats", default="ulog,bag", help="ulog, bag or both (default)")
    ap.add_argument("--columns", choices=sorted(COLUMNS), default="all", help="the columns allan reads (default all 6)")
    ap.add_argument("--memory-limit-mb", type=float, default=None, help="allan's --memory-limit-mb (default its own)")
    ap.add_argument("--keep", type=Path, default=None, help="write the files here and keep them")
    in_folder(run, ap.parse_args(), "imu_align_bench_allan_logs_")


if __name__ == "__main__":
    main()
