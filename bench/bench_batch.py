"""Benchmark: `imu-align batch` on a simulated lot of 200 units (6-dwell sessions at 200 Hz, 10 s dwells, 3 s gaps).

Measures, on the same lot:
  1. the in-process cost of one unit's alignment: the library alone (read the log and the plan, align) and the
     single command in-process (`align.cli.run([...])`: parsing, the same alignment, the JSON, the summary);
  2. the whole `imu-align batch MANIFEST --workers N` process (start-up included) with 1 and 2 workers:
     throughput (units/s), per-unit wall time and its overhead over the library's alignment, and the scaling
     efficiency from 1 to 2 workers, T1 / (2 T2) (target >= 80 %);
  3. peak RSS (the largest process: the batch or one of its workers) with 200 and 1,000 units (the 1,000-unit
     manifest lists the 200 sessions five times under other serials: the batch keeps nothing per unit, so
     memory stays flat as the lot grows).
Every file is made in a temporary folder, removed at the end (also on a failure), unless --keep.

    python bench/bench_batch.py [--units 200] [--big 1000] [--repeat 1] [--dask] [--keep DIR]
"""

from __future__ import annotations

import argparse
import contextlib
import io
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from _measure import in_folder, measure  # noqa: E402

from align.alignment.simulate import SessionSpec  # noqa: E402
from align.production import simulate_lot  # noqa: E402

FULL = SessionSpec(fs=200.0, dwell_s=10.0, static_s=3.0)


def in_process(lot, k: int = 20) -> tuple[float, float]:
    """Mean seconds per unit of the library's alignment alone and of the single command in-process (warm)."""
    import align.io as fileio
    from align.alignment.job import AlignOptions, align
    from align.alignment.plan import Plan
    from align.cli import run

    serials = lot.serials("good")[:k]
    logs = [lot.folder / "sessions" / f"{s}.csv" for s in serials]

    def library(log):
        got = fileio.read_sensor_log(log, ["gyro_x", "gyro_y", "gyro_z"], "deg/s", "time", None)
        align(got.t, got.data, Plan.from_dict(fileio.read_toml(lot.plan), str(lot.plan)), AlignOptions())

    def command(log):
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            assert run(["matrix", str(log), "--plan", str(lot.plan), "--json", str(lot.folder / "one.json")]) == 0

    out = []
    for fn in (library, command):
        fn(logs[0])  # warm: imports, numba
        t0 = time.perf_counter()
        for log in logs:
            fn(log)
        out.append((time.perf_counter() - t0) / len(logs))
    return out[0], out[1]


def big_manifest(lot, n: int) -> Path:
    """A manifest of ``n`` units cycling over the lot's sessions (serials B00001 ...)."""
    rows = ["serial,job,log,plan,options,slot"]
    serials = lot.serials()
    for k in range(n):
        rows.append(f"B{k + 1:05d},matrix,sessions/{serials[k % len(serials)]}.csv,plan.toml,,{k % 4 + 1}")
    path = lot.folder / f"manifest{n}.csv"
    path.write_text("\n".join(rows) + "\n")
    return path


def batch(manifest: Path, out: Path, workers: int, repeat: int, scheduler: str | None = None) -> tuple[float, float]:
    """Best wall time and peak RSS of the whole batch process, each repeat into a fresh output folder."""
    best, peak = float("inf"), 0.0
    for r in range(repeat):
        cmd = [sys.executable, "-m", "align.cli", "batch", str(manifest), "--workers", str(workers),
               "--out", str(out / f"w{workers}{scheduler or ''}-{r}")]
        if scheduler:
            cmd += ["--scheduler", scheduler]
        wall, rss = measure(cmd)
        best, peak = min(best, wall), max(peak, rss)
    return best, peak


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--units", type=int, default=200)
    ap.add_argument("--big", type=int, default=1000, help="units of the memory run (0: skip)")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--dask", action="store_true", help="also a local Dask cluster of 2 workers")
    ap.add_argument("--keep", type=Path, default=None, help="keep the lot and the outputs here")
    in_folder(run, ap.parse_args(), "imu_align_bench_batch_")


def run(args: argparse.Namespace, folder: Path) -> None:
    t0 = time.perf_counter()
    lot = simulate_lot(folder / "lot", args.units, session=FULL, bad=0, seed=1)
    size = sum(p.stat().st_size for p in (lot.folder / "sessions").iterdir()) / 1e6
    rows = sum(1 for _ in open(lot.folder / "sessions" / "SN0001.csv")) - 1
    print(f"lot: {args.units} units, {rows} rows each (6 dwells of 10 s at 200 Hz), {size:.0f} MB of CSV, "
          f"simulated in {time.perf_counter() - t0:.1f} s")
    lib, cmd = in_process(lot)
    print(f"in-process, one unit: library alignment (read + align) {1e3 * lib:6.1f} ms; "
          f"single command via align.cli.run {1e3 * cmd:6.1f} ms")
    t1, m1 = batch(lot.manifest, folder / "out", 1, args.repeat)
    t2, m2 = batch(lot.manifest, folder / "out", 2, args.repeat)
    n = args.units
    for w, t, m in ((1, t1, m1), (2, t2, m2)):
        print(f"batch --workers {w}: {t:6.2f} s  {n / t:6.2f} units/s  {1e3 * t / n * w:6.1f} ms per unit per worker "
              f"(overhead over the library's alignment {1e3 * (t / n * w - lib):6.1f} ms)  peak RSS {m:6.1f} MB")
    print(f"scaling 1 -> 2 workers: {t1 / t2:.2f}x, efficiency {100 * t1 / (2 * t2):.0f} % (target >= 80 %)")
    if args.dask:
        td, md = batch(lot.manifest, folder / "out", 2, args.repeat, "local")
        print(f"batch --scheduler local --workers 2: {td:6.2f} s  {n / td:6.2f} units/s  peak RSS {md:6.1f} MB")
    if args.big:
        tb, mb = batch(big_manifest(lot, args.big), folder / "out", 2, 1)
        print(f"batch of {args.big} units, --workers 2: {tb:6.2f} s  {args.big / tb:6.2f} units/s  peak RSS {mb:6.1f} MB "
              f"(vs {m2:.1f} MB for {n}: {'flat' if mb < 1.15 * m2 else 'GROWS'})")


if __name__ == "__main__":
    main()
