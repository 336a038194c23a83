"""Seed 002's static-navigation experiment (its section 3.1, Eq 19-21, Table 2) on the real ADIS16405 records.

Figures (bias, bias stability over 1 s, repeatability, ARW, bias instability) are measured on one
run (``--figures-run``, cut into segments standing for the seed's calibrations); static records are
simulated from them by methods A, B and statistics restoring, navigated from the same initial state
as a real record (``--real-run``) and compared with it (Eq 19-21, each the mean over 5 repetitions).
The first real segment gives the table and the picture; the ranking is then checked on
``--segments`` consecutive real segments (each with its own 5 repetitions per method).

    python examples/navigation/seed_experiment.py [--duration 60] [--segments 20] [--out examples/navigation]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from align.io import read_static_log, write_bytes, write_text
from align.navigation.experiment import METHODS, seed_experiment, seed_figures, table_rows
from align.present.navigation import experiment_png
from align.units import DEG, STANDARD_GRAVITY

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT.parent / "shared/data/static/adis16405_smac"
COLUMNS = ["gyro_x_dps", "gyro_y_dps", "gyro_z_dps", "acc_x_g", "acc_y_g", "acc_z_g"]
ROWS = [f"{kind} {out}" for out in ("east", "north", "heading") for kind in ("abs", "rel")]


def _run(name: str) -> tuple[np.ndarray, np.ndarray]:
    """Gyro (rad/s) and accelerometer (m/s^2) of one run: the files hold deg/s and g at 100 Hz (SOURCE.txt)."""
    raw = read_static_log(DATA / f"adis_16405_{name}.csv.gz", COLUMNS, 100.0).data
    return raw[:, :3] * DEG, raw[:, 3:] * STANDARD_GRAVITY


def _md_table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return "\n".join(lines + ["| " + " | ".join(r) + " |" for r in rows])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--figures-run", default="imu1")
    ap.add_argument("--real-run", default="imu2")
    ap.add_argument("--segment", type=float, default=600.0, help="length of the figures run's segments, s")
    ap.add_argument("--duration", type=float, default=60.0, help="navigation time, s")
    ap.add_argument("--segments", type=int, default=20, help="real segments the ranking is checked on")
    ap.add_argument("--repetitions", type=int, default=5)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parent)
    args = ap.parse_args()
    t0 = time.perf_counter()
    fg, fa = _run(args.figures_run)
    fig = seed_figures(fg, fa, 100.0, args.segment)
    rg, ra = _run(args.real_run)
    n = int(round(args.duration * 100)) + 1
    exps = []
    for s in range(args.segments):
        a = s * (n - 1)
        if a + n > len(rg):
            break
        exps.append(seed_experiment(rg[a:a + n], ra[a:a + n], 100.0, fig, args.repetitions, args.seed + s))
    first = exps[0]
    write_bytes(args.out / "experiment.png", experiment_png(first))

    gy, ac = 3600 / DEG, 1 / STANDARD_GRAVITY
    fig_rows = [["bias (Eq 5-6)"] + [f"{v:.5g}" for v in np.r_[fig.bias[:3] * gy, fig.bias[3:] * ac]],
                [f"bias stability, P = {fig.period:g} s (Eq 7-8)"]
                + [f"{v:.4g}" for v in np.r_[fig.stability[:3] * gy, fig.stability[3:] * ac]],
                [f"repeatability over {fig.segments} segments (Eq 9)"]
                + [f"{v:.4g}" for v in np.r_[fig.repeatability[:3] * gy, fig.repeatability[3:] * ac]],
                ["ARW (deg/sqrt(h)) / VRW (m/s/sqrt(h)), Allan fit"]
                + [f"{v:.4g}" for v in np.r_[fig.white[:3] / DEG * 60, fig.white[3:] * 60]],
                ["bias instability B, Allan fit"]
                + [f"{v:.4g}" for v in np.r_[fig.instability[:3] * gy, fig.instability[3:] * ac]]]
    wins = np.zeros((6, 3), int)
    for e in exps:
        for r, order in enumerate(e.ranking()):
            wins[r, METHODS.index(order[0])] += 1
    mean_abs = np.mean([[e.mean_abs(m) for m in METHODS] for e in exps], axis=0)  # (3 methods, 3 outputs)
    mean_rel = np.mean([[e.mean_rel(m) for m in METHODS] for e in exps], axis=0)
    over = []
    for k, out in enumerate(("east (m)", "north (m)", "heading (deg)")):
        f = 1 / DEG if k == 2 else 1.0
        over.append([f"largest absolute {out}"] + [f"{mean_abs[j, k] * f:.4g}" for j in range(3)])
        over.append([f"largest relative {out.split()[0]} (%)"] + [f"{mean_rel[j, k]:.4g}" for j in range(3)])
    text = "\n\n".join([
        f"Figures measured on run {args.figures_run} ({len(fg) / 100:g} s; gyro deg/h, accelerometer g):",
        _md_table(["figure", "gyro x", "gyro y", "gyro z", "acc x", "acc y", "acc z"], fig_rows),
        f"Table 2 on the first {args.duration:g} s of run {args.real_run} (mean over {args.repetitions} repetitions "
        "+/- their standard deviation):",
        _md_table(["Eq 20 / Eq 21"] + list(METHODS), table_rows(first)),
        f"Real drift at {args.duration:g} s: east {first.real[-1, 0]:.5g} m, north {first.real[-1, 1]:.5g} m, "
        f"heading {first.real[-1, 2] / DEG:.5g} deg.",
        f"Over {len(exps)} consecutive {args.duration:g}-s segments of run {args.real_run} (each with its own "
        f"{args.repetitions} repetitions): the mean of the table's entries",
        _md_table(["Eq 20 / Eq 21, mean over segments"] + list(METHODS), over),
        "and how often each method is the smallest (best) of the three:",
        _md_table(["row"] + list(METHODS), [[r] + [str(v) for v in w] for r, w in zip(ROWS, wins)]),
        f"(computed in {time.perf_counter() - t0:.0f} s)",
    ])
    write_text(args.out / "results.md", text + "\n")
    print(text)


if __name__ == "__main__":
    main()
