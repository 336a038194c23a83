"""A simulated lot of 200 units with 5 bad ones, its spec, and the batch run in-process (shared by the lot tests)."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

from align.alignment.simulate import SessionSpec
from align.production import simulate_lot

#: short sessions keep the suite fast (the full-size 6-dwell lot is bench/bench_batch.py's)
SESSION = SessionSpec(fs=200.0, dwell_s=2.0, static_s=1.0)
SPEC = '''
"phi_*" = { abs_max = "0.1 deg" }
"scale_*" = { min = 0.997, max = 1.003 }
'''


def make_lot(folder: Path, n: int = 200, bad: int = 5, seed: int = 17):
    """The lot (sessions, plan, manifest, truth.csv) and its spec file."""
    truth = simulate_lot(folder / "lot", n, session=SESSION, bad=bad, seed=seed)
    spec = folder / "spec.toml"
    spec.write_text(SPEC)
    return truth, spec


def cli(*args) -> tuple[int, str, str]:
    """``imu-align ARGS`` in this process: (exit status, stdout, stderr)."""
    from align.cli import run

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = run([str(a) for a in args])
    return code, out.getvalue(), err.getvalue()
