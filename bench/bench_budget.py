"""Benchmark: Monte Carlo of 1e6 draws of the full 3-D mounting model (reference Example 1).

Prints the wall time of the Monte Carlo alone (in-process, after imports) and of
the whole `imu-align budget --monte-carlo 1000000` process, each with its peak
memory (max RSS). There is no public 3-D anchor (anchors.md: none exists); the
reference point is a plain single-threaded loop-free numpy draw of the source's
2-D terms only, run in the same process for scale.
Target (issue 3): under 1 s and under 500 MB.

    python bench/bench_budget.py [--draws 1000000]
"""

from __future__ import annotations

import argparse
import resource
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from align.io import read_toml  # noqa: E402
from mechanics.montecarlo import monte_carlo  # noqa: E402
from mechanics.mount import mount_from_dict  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _measure import measure  # noqa: E402

MOUNT = ROOT / "examples" / "budget" / "example1.toml"


def naive_2d(n: int, seed: int) -> float:
    """The source's terms drawn independently and added by RSS (no 3-D, no rest model)."""
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    h = rng.uniform(0, 0.2e-3, (n, 4))
    tx = np.arctan((h[:, :2].mean(1) - h[:, 2:].mean(1)) / 0.038)
    skew = rng.uniform(-1, 1, n) * np.arcsin(0.425e-3 / 29.08e-3)
    np.percentile(np.hypot(tx, skew), [50, 95, 99.73])
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--draws", type=int, default=1_000_000)
    args = ap.parse_args()
    m = mount_from_dict(read_toml(MOUNT))
    monte_carlo(m, 10_000, 0)  # warm caches
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    t0 = time.perf_counter()
    mc = monte_carlo(m, args.draws, 1)
    t_mc = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    t_naive = naive_2d(args.draws, 1)
    wall, rss = measure([sys.executable, "-m", "align.cli", "budget", str(MOUNT), "--monte-carlo", str(args.draws)])
    print(f"Monte Carlo, {args.draws:,} draws of the 3-D model: {t_mc:.3f} s in-process, "
          f"peak RSS {peak:.0f} MB (before: {before / 1024:.0f} MB); "
          f"p99.73 any axis {np.degrees(mc.percentiles['99.73'][3]):.4f} deg")
    print(f"whole `imu-align budget --monte-carlo {args.draws}` process: {wall:.3f} s, peak RSS {rss:.0f} MB")
    print(f"naive 2-D RSS draw of the source terms (reference for scale): {t_naive:.3f} s; "
          f"ratio 3-D / naive {t_mc / t_naive:.1f}")
    print("target: under 1 s and under 500 MB")


if __name__ == "__main__":
    main()
