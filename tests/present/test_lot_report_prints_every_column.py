"""The lot report as a colleague prints it (issue 28): no table wider than the page, no column hidden in a scroll box
(a printed page loses what a scroll box hides), and the units' failure messages without absolute paths."""

import base64
import os
import re
import shutil
import subprocess
from datetime import UTC, datetime, timedelta

import numpy as np
import pytest

from align.production import lot_statistics, read_spec
from align.units import DEG

T0 = datetime(2026, 1, 1, tzinfo=UTC)
#: the printable width of an A4 page with 12 mm margins (186 mm) at the browser's 96 px per inch
A4_PRINTABLE_PX = round(186 / 25.4 * 96)


def _lot(folder):
    """20 units of two jobs (gyro alignments, accelerometer calibrations), two of them refused with the messages a
    batch stores (absolute paths: one in the lot's folder, one elsewhere), and a spec with every kind of limit."""
    rng = np.random.default_rng(5)
    rows = []
    for k in range(20):
        common = {"serial": f"SN{k:04d}", "order": k, "time": T0 + timedelta(minutes=k), "run": "r1", "status": "ok",
                  "message": ""}
        rows.append({**common, "job": "matrix", "sensor": "gyroscope", "bias_unit": "rad/s",
                     **{f"phi_{p}": float(rng.normal(0, 0.04 * DEG)) for p in ("xy", "yz")},
                     "scale_x": float(rng.normal(1, 1e-3))})
        rows.append({**common, "job": "calibrate accel", "sensor": "accelerometer", "bias_unit": "m/s^2",
                     "scale_x": float(rng.normal(1, 2e-3)), "bias_x": float(rng.normal(0, 0.02))})
    for k, path in ((3, folder / "lot" / "sessions" / "SN0003.csv"), (8, folder / "elsewhere" / "SN0008.csv")):
        rows[2 * k].update(status="failed", message=f"imu-align: error: {path}: step 1 (+x at 100 deg/s) not found in "
                           "the log: planned 100 deg/s about +x, the next motion turned the wrong way; re-run the step")
    spec = folder / "spec.toml"
    spec.write_text('phi_xy = { abs_max = "0.1 deg" }\nphi_yz = { abs_max = "0.1 deg" }\n'
                    'scale_x = { min = 0.995, max = 1.005 }\n[accelerometer]\nbias_x = { abs_max = "0.05 m/s^2" }\n')
    return lot_statistics(rows, read_spec(spec))


#: a 1 x 1 PNG standing in for the histograms and control charts (not what these tests look at; drawn, they take 2 s)
DOT = base64.b64decode("iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAAAAAA6fptVAAAACklEQVR4nGNgAAAAAgABSK+kcQAAAABJRU5ErkJggg==")


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    import align.present.lot as lot

    folder = tmp_path_factory.mktemp("lotreport")
    stats = _lot(folder)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(lot, "histograms_png", lambda stats, start=0: DOT)
        mp.setattr(lot, "control_charts_png", lambda stats, start=0: DOT)
        page = lot.lot_report_html(stats, str(folder / "lot" / "results.parquet"))
    path = folder / "lot.html"
    path.write_text(page)
    return folder, stats, page, path


def test_failure_messages_name_their_files_relative_to_the_table_s_folder(report):
    folder, _, page, _ = report
    why = page.split("<h2>Units not passing")[1].split("</table>")[0]
    assert str(folder) not in why
    lot = folder / "lot"
    for path in (lot / "sessions" / "SN0003.csv", folder / "elsewhere" / "SN0008.csv"):
        assert f"imu-align: error: {os.path.relpath(path, lot)}: step 1" in why
    assert "sessions/SN0003.csv" in why and "../elsewhere/SN0008.csv" in why


def test_every_column_is_in_a_table_that_fits_the_page_not_in_a_scroll_box(report):
    _, stats, page, _ = report
    assert "overflow-x" not in page and "overflow:auto" not in page and "nowrap}" not in page.split("<style>")[0]
    heads = [re.findall(r"<th[^>]*>(.*?)</th>", t) for t in re.findall(r"<table[^>]*>(.*?)</table>", page)]
    shown = {h for head in heads for h in head}
    for column in ("figure", "sensor", "job", "limit", "unit", "n", "mean", "std", "min", "max", "Cpk", "yield",
                   "outliers", "trend per 100 units", "why"):
        assert column in shown, column
    assert max(len(h) for h in heads) <= 9  # no statistics table of 14 columns
    assert "@media print" in page


def _in_chromium(page: str, width: int, tmp_path) -> tuple[int, int, int]:
    """``(tables wider than the window, elements hiding content in a scroll box, tables)`` in headless Chromium."""
    probe = ("<script>window.addEventListener('load',()=>{const w=document.documentElement.clientWidth;"
             "const wide=[...document.querySelectorAll('table')].filter(t=>t.getBoundingClientRect().right>w+1);"
             "const hid=[...document.querySelectorAll('*')].filter(e=>{const s=getComputedStyle(e);"
             "return ['auto','scroll','hidden'].includes(s.overflowX)&&e.scrollWidth>e.clientWidth+1;});"
             "document.title='wide '+wide.length+' hidden '+hid.length+' tables '+"
             "document.querySelectorAll('table').length;});</script></body>")
    checked = tmp_path / f"checked{width}.html"
    checked.write_text(page.replace("</body>", probe))
    res = subprocess.run(["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
                          f"--user-data-dir={tmp_path / 'profile'}", f"--window-size={width},1000",
                          "--virtual-time-budget=3000", "--dump-dom", checked.as_uri()],
                         capture_output=True, text=True, timeout=120)
    title = re.search(r"<title>(.*?)</title>", res.stdout).group(1)
    return tuple(map(int, re.fullmatch(r"wide (\d+) hidden (\d+) tables (\d+)", title).groups()))


@pytest.mark.skipif(shutil.which("chromium") is None, reason="Chromium not installed (CI installs it)")
def test_in_a_browser_on_screen_and_as_printed_nothing_is_hidden_or_cut(report, tmp_path):
    """Headless Chromium: on a screen as wide as the page's text (1050 px), and with the page's print rules at an A4
    page's printable width (the rules applied to the screen: a headless browser cannot be asked for print media
    from its command line), every table ends within the page and no element hides content in a scroll box."""
    _, _, page, _ = report
    wide, hidden, tables = _in_chromium(page, 1050, tmp_path)
    assert (wide, hidden) == (0, 0) and tables >= 4
    printed = page.replace("@media print{", "@media all{")
    assert printed != page
    assert _in_chromium(printed, A4_PRINTABLE_PX, tmp_path) == (0, 0, tables)
