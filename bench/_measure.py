"""Measure a whole process: wall time, CPU time and its own peak RSS (through a small launcher process)."""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

_LAUNCHER = (
    "import resource, subprocess, sys, time\n"
    "t0 = time.perf_counter()\n"
    "p = subprocess.run(sys.argv[1:], capture_output=True, text=True)\n"
    "wall = time.perf_counter() - t0\n"
    "sys.stderr.write(p.stderr)\n"
    "u = resource.getrusage(resource.RUSAGE_CHILDREN)\n"
    "print(p.returncode, wall, u.ru_maxrss, u.ru_utime + u.ru_stime)\n"
)


def measure_cpu(cmd: list[str], repeat: int = 1) -> tuple[float, float, float]:
    """Best wall time (s) over ``repeat`` runs, that run's CPU time (user + system, s: what a loaded machine
    cannot inflate the way it inflates wall time) and the peak RSS (MB) of ``cmd`` alone.

    The launcher's RUSAGE_CHILDREN describes this command and nothing else.
    """
    best, cpu, peak = float("inf"), 0.0, 0.0
    for _ in range(repeat):
        out = subprocess.run([sys.executable, "-c", _LAUNCHER, *cmd], capture_output=True, text=True)
        code, wall, rss_kb, used = out.stdout.split()
        if code != "0":
            raise SystemExit(f"failed: {' '.join(cmd)}\n{out.stderr}")
        if float(wall) < best:
            best, cpu = float(wall), float(used)
        peak = max(peak, float(rss_kb) / 1024.0)
    return best, cpu, peak


def measure(cmd: list[str], repeat: int = 1) -> tuple[float, float]:
    """Best wall time (s) over ``repeat`` runs and the peak RSS (MB) of ``cmd`` alone."""
    best, _, peak = measure_cpu(cmd, repeat)
    return best, peak


def in_folder(run: Callable[[argparse.Namespace, Path], None], args: argparse.Namespace, prefix: str) -> None:
    """``run(args, folder)`` in ``args.keep`` when given (created, kept), else in a temporary folder removed
    afterwards, also on a failure."""
    if args.keep:
        args.keep.mkdir(parents=True, exist_ok=True)
        run(args, args.keep)
        return
    with tempfile.TemporaryDirectory(prefix=prefix) as tmp:
        run(args, Path(tmp))
