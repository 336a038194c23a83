"""The demo and the report: content, embedded pictures, a real browser, start-up and progress."""

import base64
import io
import json
import os
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest
from support import in_chromium


@pytest.fixture(scope="module")
def demo_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo")
    res = subprocess.run([sys.executable, "-m", "align.cli", "demo", "--out", str(out)], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    return out, res.stdout


@pytest.mark.slow
def test_demo_summary_and_results(demo_dir):
    out, text = demo_dir
    assert "source total 1.3043 deg" in text and "binding phi_yz = 1.9102 deg" in text and "62.83 deg/h" in text
    for name in ("budget", "allowable", "allan", "plan", "alignment"):
        assert (out / f"{name}.json").exists()
    align = json.loads((out / "alignment.json").read_text())
    from align.present.story import demo_inputs

    again = out / "again"
    again.mkdir()
    truth = demo_inputs(again)["truth_M"]  # the demo's inputs are deterministic: the same truth
    assert np.all(np.abs(np.array(align["M"]) - truth) < 4 * np.array(align["uncertainty"]["M"]))


@pytest.mark.slow
def test_report_is_self_contained_and_every_picture_decodes(demo_dir):
    from PIL import Image

    page = (demo_dir[0] / "report.html").read_text()
    for title in ("Inputs", "Mounting-misalignment budget", "What the manoeuvre allows", "Noise and test planning",
                  "Electronic alignment"):
        assert f"<h2>{title}</h2>" in page
    assert "g = M w + b" in page and "<script" not in page
    assert not re.search(r'(src|href)="(?!data:)', page)  # nothing loaded from outside
    images = re.findall(r'src="data:image/png;base64,([^"]+)"', page)
    assert len(images) == 4  # histogram, assembly, Allan plot, segmentation of the rate-table log
    for data in images:
        img = Image.open(io.BytesIO(base64.b64decode(data)))
        img.load()
        assert img.size[0] > 300 and img.size[1] > 200


@pytest.mark.skipif(shutil.which("chromium") is None, reason="Chromium not installed (CI installs it)")
@pytest.mark.slow
def test_report_in_headless_chromium(demo_dir, tmp_path):
    shot = tmp_path / "shot.png"
    assert in_chromium(demo_dir[0] / "report.html", tmp_path, shot, "1100,2000") == "images 4 broken 0"
    from PIL import Image

    img = np.asarray(Image.open(shot).convert("L"))
    assert img.shape == (2000, 1100) and img.std() > 10  # something was drawn, not a blank page


def test_report_command_errors(tmp_path, run_cli):
    from align.present.story import DEMO

    res = run_cli("report", "--mount", DEMO / "mount.toml", "--manoeuvre", DEMO / "manoeuvre.toml",
                  "--log", tmp_path / "x.csv", "--out", tmp_path / "r.html")
    assert res.code == 2 and "--plan" in res.err and not (tmp_path / "r.html").exists()


def test_start_up_imports_nothing_heavy():
    heavy = ('numpy', 'scipy', 'matplotlib', 'numba', 'sympy', 'trimesh')
    code = f"import sys, align.cli; print(sorted(m for m in {heavy!r} if m in sys.modules))"
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert res.stdout.strip() == "[]"


@pytest.mark.slow
def test_progress_bar_only_on_a_terminal(tmp_path):
    from align.present.story import DEMO

    cmd = [sys.executable, "-m", "align.cli", "budget", str(DEMO / "mount.toml"), "--monte-carlo", "120000"]
    piped = subprocess.run(cmd, capture_output=True, text=True)
    assert piped.returncode == 0 and "Monte Carlo [" not in piped.stderr and piped.stderr == ""
    master, slave = os.openpty()
    proc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=slave, timeout=120)
    os.close(slave)
    seen = b""
    try:
        while True:
            chunk = os.read(master, 4096)
            if not chunk:
                break
            seen += chunk
    except OSError:
        pass
    os.close(master)
    assert proc.returncode == 0 and b"Monte Carlo [" in seen
