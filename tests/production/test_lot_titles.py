"""Issue 26: the lot's terminal tables and HTML report show each figure by its standard title and unit, the key
kept as a short code (``cross-axis misalignment phi_xy``, deg)."""

from __future__ import annotations

import re

import numpy as np

from align.present.lot import lot_report_html, lot_summary
from align.production import lot_statistics, read_spec

#: the standard names (issue 26), written here, not read from the code
TITLES = {"phi_xy": "cross-axis misalignment", "scale_x": "scale factor", "bias_x": "bias",
          "arw_x": "angle (velocity) random walk N"}


def _stats(tmp_path):
    rng = np.random.default_rng(4)
    rows = [{"serial": f"U{k:03d}", "job": "matrix", "order": k, "time": None, "status": "ok", "sensor": "gyroscope",
             "message": "", "phi_xy": float(rng.normal(0, 3e-4)), "scale_x": float(1 + rng.normal(0, 1e-3)),
             "bias_x": float(rng.normal(0, 1e-3)), "arw_x": float(abs(rng.normal(1e-4, 1e-5)))} for k in range(50)]
    (tmp_path / "s.toml").write_text('phi_xy = { abs_max = "0.1 deg" }\nscale_x = { min = 0.99, max = 1.01 }\n'
                                     'bias_x = { abs_max = "1 deg/s" }\narw_x = { max = "1 deg/sqrt(h)" }\n')
    return lot_statistics(rows, read_spec(tmp_path / "s.toml"))


def test_the_terminal_table_shows_titles_units_and_keys(tmp_path):
    text = lot_summary(_stats(tmp_path), "lot.parquet")
    table = text.split("\n\n")[1].splitlines()
    assert table[0].startswith("figure ")
    for key, name in TITLES.items():
        row = next(r for r in table if re.search(rf"\b{key}\b", r.split("  ")[0]))
        assert row.startswith(f"{name} {key}"), row
    units = {"phi_xy": "deg", "scale_x": "ratio", "bias_x": "deg/s", "arw_x": "deg/sqrt(h)"}
    for key, unit in units.items():
        row = next(r for r in table if r.startswith(f"{TITLES[key]} {key}"))
        assert f"  {unit}  " in row, row
    assert f"{TITLES['phi_xy']} phi_xy (gyroscope, matrix): " in text  # the capability lines


def test_the_html_report_shows_titles(tmp_path, monkeypatch):
    import align.present.lot as present

    monkeypatch.setattr(present, "histograms_png", lambda stats, start=0: b"")  # the tables only: fast
    monkeypatch.setattr(present, "control_charts_png", lambda stats, start=0: b"")
    html = lot_report_html(_stats(tmp_path), str(tmp_path / "lot.parquet"))
    for key, name in TITLES.items():
        assert f'<td class="l">{name} {key}</td>' in html
    assert "<th class=\"l\">figure</th>" in html and ">deg/sqrt(h)</td>" in html
