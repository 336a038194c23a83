"""Benchmark: the whole `imu-align matrix` process on a 2 kHz session of 18 dwells x 30 s.

Runs, in one go and on the same CSV (~1.1 M rows):
  1. pandas alone reading the CSV (the anchor: the least any CSV-based tool must do);
  2. `imu-align matrix LOG --plan PLAN --json OUT` as a whole process (start-up included).
Prints wall time and peak memory (max RSS of the child) of each, and the ratio.
Target (issue 2): the whole run within 2x the pandas read and under 3 s.

    python bench/bench_matrix.py [--repeat 3] [--keep DIR]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from align.alignment.plan import Plan, Step  # noqa: E402
from align.alignment.simulate import SessionSpec, simulate_session  # noqa: E402
from align.io import write_csv, write_text  # noqa: E402
from align.model import SensorModel  # noqa: E402
from align.units import DEG, to_unit  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _measure import in_folder, measure  # noqa: E402


def make_session(folder: Path) -> tuple[Path, Path, int]:
    steps = tuple(Step(a, 1, rate=s * r * DEG) for a in range(3) for r in (50, 100, 200) for s in (1, -1))
    plan = Plan(steps)
    spec = SessionSpec(fs=2000.0, dwell_s=30.0, static_s=0.5, accel=500 * DEG, noise_density=0.005 * DEG)
    model = SensorModel.from_small_angles(0.002, -0.001, 0.003, bias=[0.001, -0.002, 0.0005])
    t, g, _ = simulate_session(plan, model, spec, 0)
    log, plan_path = folder / "session.csv", folder / "plan.toml"
    write_csv(log, ["time", "gyro_x", "gyro_y", "gyro_z"], np.column_stack([t, to_unit(g, "deg/s")]))
    write_text(plan_path, plan.to_toml())
    return log, plan_path, len(t)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--keep", type=Path, default=None, help="keep the generated session here")
    in_folder(run, ap.parse_args(), "imu_align_bench_")


def run(args: argparse.Namespace, folder: Path) -> None:
    log, plan, rows = make_session(folder)
    size = log.stat().st_size / 1e6
    pandas_cmd = [sys.executable, "-c", f"import pandas as pd; df = pd.read_csv({str(log)!r}); print(len(df))"]
    ours_cmd = [sys.executable, "-m", "align.cli", "matrix", str(log), "--plan", str(plan), "--json", str(folder / "r.json")]
    t_pd, m_pd = measure(pandas_cmd, args.repeat)
    t_us, m_us = measure(ours_cmd, args.repeat)
    print(f"session: {rows} rows, {size:.1f} MB CSV")
    print(f"pandas.read_csv alone (whole process): {t_pd:6.3f} s   peak RSS {m_pd:7.1f} MB")
    print(f"imu-align matrix      (whole process): {t_us:6.3f} s   peak RSS {m_us:7.1f} MB")
    print(f"ratio imu-align / pandas read: {t_us / t_pd:.2f}  (target <= 2, and < 3 s)")


if __name__ == "__main__":
    main()
