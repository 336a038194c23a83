"""Shared test helpers, imported as a module (``from support import ROOT, truth_model``).

tests/ is on ``sys.path`` (pyproject's ``[tool.pytest.ini_options] pythonpath``); the fixtures in
``conftest.py`` are thin wrappers over what is here.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from align.model import SensorModel
from align.units import DEG

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"


def truth_model(seed: int = 0, rot_deg: float = 0.6, scale_sd: float = 3e-3, delta_deg: float = 0.05,
                bias_deg_s: float = 0.5) -> SensorModel:
    """A random but realistic true M and bias (rad/s)."""
    rng = np.random.default_rng(1000 + seed)
    return SensorModel.from_rotation(
        Rotation.from_rotvec(rng.normal(0, rot_deg * DEG, 3)),
        scale=1 + rng.normal(0, scale_sd, 3),
        delta=rng.normal(0, delta_deg * DEG, 3),
        bias=rng.normal(0, bias_deg_s * DEG, 3),
    )


def write_session(folder: Path, t: np.ndarray, g: np.ndarray, plan, units: str = "deg/s") -> tuple[Path, Path]:
    """Write a simulated session as the CLI reads it."""
    from align.io import write_csv, write_text
    from align.units import to_unit

    log, plan_path = folder / "session.csv", folder / "plan.toml"
    write_csv(log, ["time", "gyro_x", "gyro_y", "gyro_z"], np.column_stack([t, to_unit(g, units)]))
    write_text(plan_path, plan.to_toml())
    return log, plan_path


class CliResult:
    """Exit status, stdout and stderr of one in-process run of the command."""

    def __init__(self, code: int, out: str, err: str) -> None:
        self.code, self.out, self.err = code, out, err


def run_in_process(capsys, *args) -> CliResult:
    """Run ``imu-align ARGS`` in-process (the console script's ``main``), its output captured by ``capsys``."""
    from align.cli import main

    capsys.readouterr()  # drop what came before
    try:
        main([str(a) for a in args])
        code = 0
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    cap = capsys.readouterr()
    return CliResult(code, cap.out, cap.err)


def slow_beyond(n: int, cases: list) -> list:
    """``cases`` (tuples) for ``pytest.mark.parametrize``, all but the first ``n`` marked slow (test ids unchanged)."""
    import pytest

    return [c if i < n else pytest.param(*c, marks=pytest.mark.slow) for i, c in enumerate(cases)]


def imu_align_command() -> list[str]:
    """The installed ``imu-align`` console script beside this Python (``python -m align.cli`` without one)."""
    script = Path(sys.executable).with_name("imu-align")
    return [str(script)] if script.exists() else [sys.executable, "-m", "align.cli"]


def in_chromium(path, tmp_path, shot=None, size="1100,1800") -> str:
    """Render ``path`` in headless Chromium: the DOM's title counts the images and the broken ones; no console error."""
    page = path.read_text()
    probe = ("<script>window.addEventListener('load',()=>{"
             "const bad=[...document.images].filter(i=>!(i.complete&&i.naturalWidth>0));"
             "document.title='images '+document.images.length+' broken '+bad.length;});</script></body>")
    checked = tmp_path / "checked.html"
    checked.write_text(page.replace("</body>", probe))
    flags = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
             "--disable-background-networking", "--disable-component-update", "--disable-sync",
             f"--user-data-dir={tmp_path / 'profile'}", "--enable-logging=stderr", "--v=0"]
    res = subprocess.run(["chromium", *flags, "--virtual-time-budget=5000", "--dump-dom", checked.as_uri()],
                         capture_output=True, text=True, timeout=120)
    assert "CONSOLE" not in res.stderr and "Uncaught" not in res.stderr
    if shot is not None:
        subprocess.run(["chromium", *flags, f"--window-size={size}", f"--screenshot={shot}", path.as_uri()],
                       capture_output=True, timeout=120)
    return re.search(r"<title>(.*?)</title>", res.stdout).group(1)


def coning(t: np.ndarray, half: float = 0.05, rate: float = 2 * np.pi * 5) -> tuple[np.ndarray, np.ndarray]:
    """Classic coning (Savage, Strapdown Analytics 7.1): half-angle ``half`` about x, axis precessing at ``rate``.

    Returns the attitude q(t) = (cos a, 0, sin a cos(W t), sin a sin(W t)) and its body rate
    omega = 2 vec(q* (x) dq/dt), dq/dt differentiated by hand.
    """
    from align.attitude import quat_multiply

    c, s = np.cos(half), np.sin(half)
    q = np.stack([np.full_like(t, c), 0 * t, s * np.cos(rate * t), s * np.sin(rate * t)], -1)
    dq = np.stack([0 * t, 0 * t, -s * rate * np.sin(rate * t), s * rate * np.cos(rate * t)], -1)
    return q, 2 * quat_multiply(q * np.array([1, -1, -1, -1]), dq)[:, 1:]
