"""Benchmark: `imu-align calibrate thermal` on 10^7 samples of a chamber record (one sensor, three axes).

The record: a static gyro in a chamber, -10 to 60 C up, down and up (the `simulate thermal` profile), at the
rate that makes ``--rows`` samples; columns ``time, gyro_x, gyro_y, gyro_z (deg/s), temperature (C)``
(``--sensors 2``: the accelerometer's three columns beside them, both sensors calibrated: 6 channels).
Written in a temporary folder (removed afterwards) as CSV, as Parquet (the same columns, float64), and as .npy
for the fit alone.

Each measured as a whole process (start-up included):
  1. `imu-align calibrate thermal LOG --temperature-column temperature --json OUT`: the command, on the CSV and
     on the Parquet file;
  2. the job's reading alone (`THERMAL.read`, the checked CSV reader of align.io);
  3. the fit alone: `fit_sensor` on the arrays loaded from .npy (what this module owns).
Prints wall time, CPU time, peak RSS, the input size (CSV bytes; the arrays' bytes in memory) and the ratio of
peak RSS to it. Target (issue 25): the command under 5 s, its memory under 3x the input.

    python bench/bench_thermal.py [--rows 10000000] [--sensors 1] [--repeat 1] [--keep DIR]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from align.calibration.thermal import simulate as sim  # noqa: E402
from align.io import write_csv  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _measure import in_folder, measure_cpu  # noqa: E402

#: the profile of `imu-align simulate thermal` (defaults)
PROFILE = sim.Profile(-10.0, 60.0, 4.0 / 60, 6.0 / 60, 60.0, 1.5)

READ = r"""
import sys
from pathlib import Path
from align.calibration.thermal.job import THERMAL, ThermalOptions, SENSORS
from align.io.source import LogSource
sensors = SENSORS[:int(sys.argv[2])]
o = ThermalOptions(log=LogSource(path=Path(sys.argv[1]), temperature_column="temperature"), sensors=sensors)
i = THERMAL.read(o)
print(sum(len(g.t) for g in i.logs.values()))
"""

FIT = r"""
import sys
from pathlib import Path
import numpy as np
from align.calibration.thermal.sensor import Settings, fit_sensor
folder, rate, k = Path(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
t, temperature = np.load(folder / "t.npy"), np.load(folder / "temperature.npy")
for name, unit in (("gyroscope", "deg/s"), ("accelerometer", "m/s^2"))[:k]:
    s = fit_sensor(t, temperature, np.load(folder / f"{name}.npy"), name, unit, rate, Settings(), "bench")
    print(name, [ax.order for ax in s.axes])
"""


def make_log(folder: Path, rows: int, sensors: int) -> tuple[Path, Path, float]:
    """The chamber record of ``rows`` samples as CSV, and as .npy (one file per array, readings in SI, for the fit
    alone); returns the CSV, the folder and the sample rate, Hz."""
    rate_hz = rows / PROFILE.duration
    rng = np.random.default_rng(0)
    truths = [sim.random_truth(rng, PROFILE, sim.GYRO_SIZE), sim.random_truth(rng, PROFILE, sim.ACCEL_SIZE)][:sensors]
    noises = (sim.GYRO_NOISE, sim.ACCEL_NOISE)[:sensors]
    run = sim.simulate(PROFILE, truths, rate_hz, noises, rng)
    data = run.data
    data[:, :3] *= 180.0 / np.pi
    if sensors > 1:
        data[:, 5] += sim.GRAVITY
    table = np.column_stack([run.t, data, run.temperature])
    del run, data
    names = ["time", "gyro_x", "gyro_y", "gyro_z"] + (["acc_x", "acc_y", "acc_z"] if sensors > 1 else []) + ["temperature"]
    log = folder / "thermal.csv"
    write_csv(log, names, table)
    import pyarrow as pa
    import pyarrow.parquet as pq

    pq.write_table(pa.table({n: table[:, k] for k, n in enumerate(names)}), folder / "thermal.parquet")
    np.save(folder / "t.npy", table[:, 0])
    np.save(folder / "temperature.npy", table[:, -1])
    np.save(folder / "gyroscope.npy", table[:, 1:4] * (np.pi / 180))  # SI, as the reader gives them
    if sensors > 1:
        np.save(folder / "accelerometer.npy", table[:, 4:7])
    return log, folder, rate_hz


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", type=int, default=10_000_000)
    ap.add_argument("--sensors", type=int, choices=(1, 2), default=1, help="1: gyro (3 channels); 2: gyro + accel (6)")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--keep", type=Path, default=None, help="keep the generated record here")
    in_folder(run, ap.parse_args(), "imu_align_bench_")


def run(args: argparse.Namespace, folder: Path) -> None:
    log, arrays, rate_hz = make_log(folder, args.rows, args.sensors)
    csv_mb = log.stat().st_size / 1e6
    arrays_mb = args.rows * (2 + 3 * args.sensors) * 8 / 1e6
    sensors = ["gyroscope", "accelerometer"][:args.sensors]
    cmds = {
        "calibrate thermal (command)": [sys.executable, "-m", "align.cli", "calibrate", "thermal", str(log),
                                        "--temperature-column", "temperature", "--sensors", ",".join(sensors),
                                        "--json", str(folder / "r.json")],
        "calibrate thermal (Parquet log)": [sys.executable, "-m", "align.cli", "calibrate", "thermal",
                                            str(folder / "thermal.parquet"), "--temperature-column", "temperature",
                                            "--sensors", ",".join(sensors), "--json", str(folder / "rp.json")],
        "reading alone (THERMAL.read)": [sys.executable, "-c", READ, str(log), str(args.sensors)],
        "fit alone (fit_sensor on .npy)": [sys.executable, "-c", FIT, str(arrays), repr(rate_hz), str(args.sensors)],
    }
    print(f"record: {args.rows:,} rows x {3 * args.sensors} channels at {rate_hz:.0f} Hz; CSV {csv_mb:.0f} MB, "
          f"arrays in memory {arrays_mb:.0f} MB")
    for what, cmd in cmds.items():
        wall, cpu, peak = measure_cpu(cmd, args.repeat)
        print(f"{what:32s} {wall:6.2f} s wall  {cpu:6.2f} s CPU  peak RSS {peak:7.0f} MB  "
              f"= {peak / csv_mb:.2f}x CSV, {peak / arrays_mb:.2f}x arrays")
    print("target: the command under 5 s, peak RSS under 3x the input")


if __name__ == "__main__":
    main()
