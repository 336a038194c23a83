"""Benchmark: `imu-align batch` on a simulated lot of 200 units (6-dwell sessions at 200 Hz, 10 s dwells, 3 s gaps).

Measures, on the same lot:
  1. the in-process cost of one unit's alignment: the library job alone (`align.api.job("matrix").run(options)`:
     read the log and the plan, check, align, provenance) and the single command in-process (`align.cli.run([...])`:
     parsing, the same job, the JSON, the summary), in wall time and CPU time;
  2. the whole `imu-align batch MANIFEST --workers N` process (start-up included) with 1 and 2 workers:
     throughput (units/s), per-unit wall time and its overhead over the library job (target < 10 %), the same in
     CPU time (the whole process tree's: what other users of a shared machine inflate least; split into the batch
     process's own and its workers'), the same against the library job over the lot in one plain process (its
     start-up included), and the scaling efficiency from 1 to 2 workers, T1 / (2 T2) (target >= 80 %);
  3. with --big, the slope of the batch's wall and CPU time over the lot's size (start-up taken out: the per-unit
     overhead, target < 10 %), and peak RSS (the largest process: the batch or one of its workers) with 200 and
     1,000 units (the 1,000-unit manifest lists the 200 sessions five times under other serials: the batch keeps
     nothing per unit, so memory stays flat as the lot grows);
  4. with --store 200,2000,10000, the results store as a line fills it: ``batch --workers 2`` on lots of each size
     (throughput within 10 % of each other, peak RSS flat), then the largest lot run again into its full store (every
     unit skipped): the whole rerun, and the resume's start (the journal folded, the store's keys read, the latest
     row of each unit found) in-process (target < 2 s at 10,000 units).
Every file is made in a temporary folder, removed at the end (also on a failure), unless --keep.

    python bench/bench_batch.py [--units 200] [--big 1000] [--repeat 1] [--dask] [--store 200,2000,10000]
        [--keep DIR] [--no-bytecode]
"""

from __future__ import annotations

import argparse
import contextlib
import io
import subprocess
import sys
import time
from pathlib import Path
from typing import NamedTuple

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from _measure import in_folder, measure_cpu  # noqa: E402

from align.alignment.simulate import SessionSpec  # noqa: E402
from align.production import simulate_lot  # noqa: E402

FULL = SessionSpec(fs=200.0, dwell_s=10.0, static_s=3.0)


def worker_seconds(table: Path) -> float:
    """Mean seconds per unit inside the workers (the table's ``seconds``), the first unit of the run left out."""
    import pyarrow.parquet as pq

    seconds = sorted(pq.read_table(table).to_pydict()["seconds"])
    return sum(seconds[:-1]) / max(1, len(seconds) - 1)


def in_process(lot, k: int = 20, command: bool = True) -> tuple[tuple[float, float], tuple[float, float]]:
    """Mean (wall, CPU) seconds per unit of the library job alone and of the single command in-process (warm;
    without ``command``, the library job's only)."""
    from align.cli import run

    serials = lot.serials("good")[:k]
    logs = [lot.folder / "sessions" / f"{s}.csv" for s in serials]
    try:
        import align.api as ia

        job = ia.job("matrix")

        def library(log):
            job.run(ia.MatrixOptions(log=ia.LogSource(path=log), plan=lot.plan))
    except (ImportError, AttributeError):  # before the matrix job: the alignment functions themselves
        import align.io as fileio
        from align.alignment.job import AlignOptions, align
        from align.alignment.plan import Plan

        def library(log):
            got = fileio.read_sensor_log(log, ["gyro_x", "gyro_y", "gyro_z"], "deg/s", "time", None)
            align(got.t, got.data, Plan.from_dict(fileio.read_toml(lot.plan), str(lot.plan)), AlignOptions())

    def single(log):
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            assert run(["matrix", str(log), "--plan", str(lot.plan), "--json", str(lot.folder / "one.json")]) == 0

    out = [(float("nan"), float("nan"))] * 2
    for i, fn in enumerate((library, single) if command else (library,)):
        fn(logs[0])  # warm: imports, numba
        t0, c0 = time.perf_counter(), time.process_time()
        for log in logs:
            fn(log)
        out[i] = ((time.perf_counter() - t0) / len(logs), (time.process_time() - c0) / len(logs))
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


class Run(NamedTuple):
    """What :func:`run_tree` measured of one process tree."""

    wall: float  #: s
    cpu: float  #: s, user + system of every process (NaN without psutil)
    rss: float  #: MB, the largest process's peak
    own: float  #: s, CPU of the top process alone (the batch: reading, preparing, journaling, folding)


def run_tree(cmd: list[str]) -> Run:
    """Wall time (s), CPU time (user + system, s) and peak RSS (MB, the largest process) of ``cmd`` and every
    process under it: its workers are counted (a fork server's are not its children, so its own rusage misses
    them), sampled every 20 ms with psutil; without psutil, CPU is NaN and RSS the largest child's."""
    try:
        import psutil
    except ImportError:
        wall, _, rss = measure_cpu(cmd)
        return Run(wall, float("nan"), rss, float("nan"))
    seen: dict[int, float] = {}
    peak = 0
    t0 = time.perf_counter()
    proc = psutil.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    while proc.poll() is None:
        with contextlib.suppress(psutil.Error):
            for p in [proc, *proc.children(recursive=True)]:
                with contextlib.suppress(psutil.Error):
                    with p.oneshot():
                        t = p.cpu_times()
                        seen[p.pid] = t.user + t.system
                        peak = max(peak, p.memory_info().rss)
        time.sleep(0.02)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"failed: {' '.join(cmd)}\n{proc.stderr.read().decode()}")
    return Run(wall, sum(seen.values()), peak / 2**20, seen.get(proc.pid, float("nan")))


_PLAIN = (
    "import sys\n"
    "from pathlib import Path\n"
    "import align.api as ia\n"
    "folder = Path(sys.argv[1])\n"
    "job = ia.job('matrix')\n"
    "for log in sorted((folder / 'sessions').glob('*.csv')):\n"
    "    job.run(ia.MatrixOptions(log=ia.LogSource(path=log), plan=folder / 'plan.toml'))\n"
)


def plain_process(lot) -> Run:
    """Wall and CPU time of the library job over every unit of the lot in one plain Python process (its start
    and imports included; no JSON, no table): what any process of the jobs costs."""
    return run_tree([sys.executable, "-c", _PLAIN, str(lot.folder)])


def batch(manifest: Path, out: Path, workers: int, scheduler: str | None = None, tag: str = "0") -> Run:
    """Wall time, CPU time (every process) and peak RSS of one whole batch process into a fresh output folder."""
    cmd = [sys.executable, "-m", "align.cli", "batch", str(manifest), "--workers", str(workers)]
    cmd += ["--scheduler", scheduler] if scheduler else []
    return run_tree([*cmd, "--out", str(out / f"w{workers}{scheduler or ''}-{tag}")])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--units", type=int, default=200)
    ap.add_argument("--big", type=int, default=1000, help="units of the memory run (0: skip)")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--dask", action="store_true", help="also a local Dask cluster of 2 workers")
    ap.add_argument("--store", type=str, default="", help="lot sizes of the store run, e.g. 200,2000,10000 (empty: "
                    "skip); with it, the other runs are skipped unless --units is also given")
    ap.add_argument("--keep", type=Path, default=None, help="keep the lot and the outputs here")
    ap.add_argument("--no-bytecode", action="store_true", help=(
        "run the batches as this environment says (PYTHONDONTWRITEBYTECODE: every process compiles imu-align's "
        "modules again); default: their bytecode cached in the bench's folder, as an installed package has it"))
    in_folder(run, ap.parse_args(), "imu_align_bench_batch_")


def run(args: argparse.Namespace, folder: Path) -> None:
    import os

    t0 = time.perf_counter()
    lot = simulate_lot(folder / "lot", args.units, session=FULL, bad=0, seed=1)
    if not args.no_bytecode:  # the batches' processes (started below) write and read their bytecode here
        os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
        os.environ["PYTHONPYCACHEPREFIX"] = str(folder / "pycache")
        batch(big_manifest(lot, 2), folder / "warm", 1)
    if args.store:
        store_run(lot, [int(x) for x in args.store.split(",")], folder)
        return
    size = sum(p.stat().st_size for p in (lot.folder / "sessions").iterdir()) / 1e6
    rows = sum(1 for _ in open(lot.folder / "sessions" / "SN0001.csv")) - 1
    print(f"lot: {args.units} units, {rows} rows each (6 dwells of 10 s at 200 Hz), {size:.0f} MB of CSV, "
          f"simulated in {time.perf_counter() - t0:.1f} s")
    (lib0, cpu0), (cmd, cmd_cpu) = in_process(lot)
    print(f"in-process, one unit: library job (read + check + align + provenance) {1e3 * lib0:6.1f} ms "
          f"(CPU {1e3 * cpu0:6.1f} ms); single command via align.cli.run {1e3 * cmd:6.1f} ms (CPU {1e3 * cmd_cpu:6.1f} ms)")
    # side by side, the best of --repeat rounds of: the library job, a batch of 1 worker, the library job, a batch
    # of 2 workers (a shared machine's load drifts: each ratio is of figures taken minutes apart at most)
    lib, cpu = [lib0], [cpu0]
    runs: dict[int, list[Run]] = {1: [], 2: []}
    for r in range(args.repeat):
        for w in (1, 2):
            if r or w == 2:
                (t, c), _ = in_process(lot, command=False)
                lib.append(t)
                cpu.append(c)
            runs[w].append(batch(lot.manifest, folder / "out", w, tag=str(r)))
    n = args.units
    lib_best, cpu_best = min(lib), min(cpu)
    best = {w: _best(rs) for w, rs in runs.items()}
    for w, b in best.items():
        per, per_cpu = b.wall / n * w, b.cpu / n
        print(f"batch --workers {w}: {b.wall:6.2f} s  {n / b.wall:6.2f} units/s  {1e3 * per:6.1f} ms per unit per "
              f"worker, library job {1e3 * lib_best:6.1f} ms: overhead {1e3 * (per - lib_best):+6.1f} ms, "
              f"{100 * (per / lib_best - 1):+5.1f} %; CPU (every process) {1e3 * per_cpu:6.1f} ms per unit vs "
              f"{1e3 * cpu_best:6.1f} ms: {100 * (per_cpu / cpu_best - 1):+5.1f} % (the batch process "
              f"{1e3 * b.own / n:4.1f} ms, its workers {1e3 * (b.cpu - b.own) / n:5.1f} ms); "
              f"peak RSS {max(x.rss for x in runs[w]):6.1f} MB")
    inside = worker_seconds(folder / "out" / "w1-0" / "results.parquet")
    print(f"in a worker (--workers 1, the table's seconds, first unit left out): {1e3 * inside:6.1f} ms per unit "
          f"(job + JSON + rows)")
    plain = plain_process(lot)
    pw, t1, t2 = plain.wall, best[1].wall, best[2].wall
    print(f"the library job over the lot in one plain process (start-up included, no JSON, no table): {pw:6.2f} s, "
          f"{1e3 * pw / n:6.1f} ms per unit ({100 * (pw / n / lib_best - 1):+5.1f} % over the library job in-process), "
          f"CPU {plain.cpu:6.2f} s; batch --workers 1 over it: {t1 - pw:+5.2f} s, {100 * (t1 / pw - 1):+5.1f} % "
          f"(CPU {best[1].cpu - plain.cpu:+5.2f} s, {100 * (best[1].cpu / plain.cpu - 1):+5.1f} %)")
    print(f"scaling 1 -> 2 workers: {t1 / t2:.2f}x, efficiency {100 * t1 / (2 * t2):.0f} % (target >= 80 %)")
    print("rounds (wall s, w1 / w2; library ms): " + "; ".join(
        f"{a.wall:.2f} / {b.wall:.2f}" for a, b in zip(runs[1], runs[2])) + "; " + ", ".join(f"{1e3 * x:.1f}" for x in lib))
    if args.dask:
        d = batch(lot.manifest, folder / "out", 2, "local")
        print(f"batch --scheduler local --workers 2: {d.wall:6.2f} s  {n / d.wall:6.2f} units/s  peak RSS {d.rss:6.1f} MB")
    if args.big:
        # the per-unit cost with the fixed start-up (interpreter, imports, pool, the table's first write) taken
        # out: the slope of the batch's wall time over the lot's size, one worker, against the library job
        big = big_manifest(lot, args.big)
        b1 = _best([batch(big, folder / "out", 1, tag=f"big1-{r}") for r in range(args.repeat)])
        slope, slope_cpu = (b1.wall - t1) / (args.big - n), (b1.cpu - best[1].cpu) / (args.big - n)
        print(f"batch --workers 1, {n} and {args.big} units: {t1:.2f} s and {b1.wall:.2f} s; per unit beyond the "
              f"start-up (the slope) {1e3 * slope:6.1f} ms vs the library job {1e3 * lib_best:6.1f} ms: overhead "
              f"{100 * (slope / lib_best - 1):+5.1f} % (target < 10 %); fixed start-up {t1 - n * slope:.2f} s; "
              f"in CPU {1e3 * slope_cpu:6.1f} ms vs {1e3 * cpu_best:6.1f} ms: {100 * (slope_cpu / cpu_best - 1):+5.1f} %")
        bb = batch(big, folder / "out", 2, tag="big")
        m2 = max(x.rss for x in runs[2])
        print(f"batch of {args.big} units, --workers 2: {bb.wall:6.2f} s  {args.big / bb.wall:6.2f} units/s  peak RSS "
              f"{bb.rss:6.1f} MB (vs {m2:.1f} MB for {n}: {'flat' if bb.rss < 1.15 * m2 else 'GROWS'})")


_RESUME = (
    "import sys, time\n"
    "t0 = time.perf_counter()\n"
    "from align.production.batch import TABLE\n"
    "from align.production.store import Journal, read_table\n"
    "from align.production.table import META, latest_rows\n"
    "from pathlib import Path\n"
    "t1 = time.perf_counter()\n"
    "store = Path(sys.argv[1]) / TABLE\n"
    "Journal(store).recover()\n"
    "rows = latest_rows(read_table(store, [n for n, _ in META]))\n"
    "print(len(rows), t1 - t0, time.perf_counter() - t1)\n"
)


def store_run(lot, sizes: list[int], folder: Path) -> None:
    """Throughput and peak RSS of ``batch --workers 2`` on lots of ``sizes`` units (each into a fresh store), then
    the largest run again into its store: every unit skipped (the whole rerun, and the resume's start)."""
    from align.production.store import read_table

    rates, steady = {}, {}
    for n in sizes:
        b = batch(big_manifest(lot, n), folder / "out", 2, tag=f"store{n}")
        stamps = sorted(read_table(folder / "out" / f"w2-store{n}" / "results.parquet", ["time"]).column("time")
                        .cast("int64").to_pylist())  # when each unit's row was made, microseconds
        rates[n], steady[n] = n / b.wall, (n - 1) / ((stamps[-1] - stamps[0]) / 1e6)
        print(f"store: {n:6d} units, batch --workers 2: {b.wall:7.2f} s  {rates[n]:6.2f} units/s (start-up "
              f"included), {steady[n]:6.2f} units/s from the first unit's row to the last's; peak RSS {b.rss:6.1f} MB",
              flush=True)
    for name, r in (("whole", rates), ("steady", steady)):
        lo, hi = min(r.values()), max(r.values())
        print(f"store: {name} throughput {lo:.2f} to {hi:.2f} units/s, spread {100 * (hi / lo - 1):.1f} % "
              "(target within 10 %)")
    n = max(sizes)
    out = folder / "out" / f"w2-store{n}"
    again = run_tree([sys.executable, "-m", "align.cli", "batch", str(lot.folder / f"manifest{n}.csv"), "--workers",
                      "2", "--out", str(out)])
    got = subprocess.run([sys.executable, "-c", _RESUME, str(out)], capture_output=True, text=True, check=True)
    count, imports, start = got.stdout.split()
    print(f"store: rerun of {n} units (every unit skipped: inputs hashed, nothing run): {again.wall:.2f} s, peak RSS "
          f"{again.rss:.1f} MB; the resume's start (journal, the store's keys, {count} latest rows): {float(start):.3f} s "
          f"(+ {float(imports):.2f} s of imports; target < 2 s)")


def _best(runs: list[Run]) -> Run:
    """The run of the least wall time."""
    return min(runs, key=lambda r: r.wall)

if __name__ == "__main__":
    main()
