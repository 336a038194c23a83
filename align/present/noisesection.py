"""The report's noise section: the Allan deviation's fitted terms and IEEE point readouts with their
uncertainties, the noise figures of He, Li and Fu (2023: bias, bias stability, repeatability) and the test plan.

Public names
------------
allan_section, figure_rows, stability_sigma
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from align.present.html import Section, esc, image, table

if TYPE_CHECKING:
    from align.noise import AllanJob, PlanResult


def _term_cells(t: dict) -> list[str]:
    """Value and 1-sigma of an identifiable term; else "not identified" and its upper bound, with what would identify it."""
    if t["identifiable"]:
        return [f"{t['value']:.4g}", "" if t["sigma"] is None else f"± {t['sigma']:.2g} (1 sigma)"]
    bound = "" if t.get("upper_bound") is None else f"< {t['upper_bound']:.3g} (95 %)"
    if t.get("record_to_identify_h") is not None:
        bound += f"; about {t['record_to_identify_h']:.3g} h of record would identify it"
    elif t.get("sample_rate_to_identify_hz") is not None:
        bound += f"; a sample rate of about {t['sample_rate_to_identify_hz']:.3g} Hz would identify it"
    return ["not identified", bound.lstrip("; ")]


def _readout_rows(name: str, r: dict, term_unit: dict) -> list[list]:
    """The IEEE Std 952 point readouts of one channel with their 68 % intervals (N at 1 s, floor / 0.664, K at 3 s)."""
    rows = []
    for key, label, letter in (("N_at_tau_1s", "N read at tau = 1 s (IEEE point readout)", "N"),
                               ("K_at_tau_3s", "K read at tau = 3 s (IEEE point readout)", "K")):
        v, lo, hi = r.get(key), r.get(f"{key}_low"), r.get(f"{key}_high")
        if v is None:
            continue
        band = "" if lo is None or hi is None else f"68 %: {lo:.4g}-{hi:.4g}"
        rows.append([name, label, f"{v:.4g}", band, r.get(f"{letter}_unit") or term_unit.get(letter, "")])
    b = r.get("B_floor_over_0.664")
    if b is not None:
        lo, hi = r.get("B_floor_over_0.664_low"), r.get("B_floor_over_0.664_high")
        at = r.get("B_floor_tau_s")
        rows.append([name, "floor (IEEE point readout)", f"{0.664 * b:.4g}",
                     "" if lo is None or hi is None else f"68 %: {0.664 * lo:.4g}-{0.664 * hi:.4g}"
                     + ("" if at is None else f" at tau {at:.3g} s"), r["B_unit"]])
    return rows


def stability_sigma(value: float, record_s: float, period_s: float) -> float:
    """1-sigma of a bias stability read from ``K = floor(T / P)`` window means: ``value / sqrt(2 (K - 1))``
    (the standard deviation of ``K`` independent normal means; NaN for fewer than two windows)."""
    k = math.floor(record_s / period_s) if period_s > 0 else 0
    return value / math.sqrt(2 * (k - 1)) if k >= 2 else float("nan")


def figure_rows(d: dict) -> list[list]:
    """The seed's noise figures of every channel from an Allan file's dictionary: bias, bias stability per
    averaging period (with :func:`stability_sigma`), repeatability, or why one is not measured."""
    u = d["units"]["adev"]
    record = d["samples"] / d["fs_hz"]
    several = d.get("runs", 1) > 1
    rows = []
    for name, fig in d["figures"].items():
        rows.append([name, "bias (mean" + (f" of {d['runs']} runs)" if several else " of the record)"),
                     f"{fig['bias']:+.4g}", "-", u])
        for period, v in fig["bias_stability"].items():
            p = float(period.split()[0])
            s = stability_sigma(v, record, p)
            rows.append([name, f"bias stability: std of the {period} means", f"{v:.4g}",
                         "not enough windows" if not math.isfinite(s) else
                         f"± {s:.2g} (1 sigma, {math.floor(record / p)} windows)", u])
        rep = (d.get("repeatability") or {}).get(name)
        rows.append([name, "bias repeatability: std of the run biases",
                     "not measured" if rep is None else f"{rep:.4g}",
                     "one run only: record several runs (power cycles) to measure it" if rep is None else
                     f"std of {d['runs']} run biases", u])
    return rows


def allan_section(job: AllanJob | None, plot_png: bytes | None, plan: PlanResult | None) -> Section:
    """Allan deviation, fitted terms and point readouts with their uncertainties, noise figures, and the test plan."""
    body = ""
    allan_dict = None if job is None else job.to_dict()
    plan_dict = None if plan is None else plan.to_dict()
    if allan_dict is not None:
        u = allan_dict["units"]
        rows = []
        for name, fit in allan_dict["fit"].items():
            for t in fit["terms"].values():
                rows.append([name, f"{t['symbol']} {t['name']}", *_term_cells(t), t["unit"]])
            symbols = {t["symbol"]: t["unit"] for t in fit["terms"].values()}
            rows += _readout_rows(name, fit["ieee_point_readouts"], symbols)
        d = allan_dict
        runs = (f"pooled curve of {d['runs']} runs ({esc(d['pooled']['method'])}); " if "pooled" in d
                else f"{d['samples']:,} samples at {d['fs_hz']:g} Hz, ")
        body += (f"<p>{runs}data in {esc(u['adev'])}; confidence band {esc(u['ci'])}. A term's value is given only "
                 "where the record identifies it; otherwise its 95 % upper bound.</p>"
                 + table(["channel", "term", "value", "uncertainty or bound", "unit"], rows, left=2)
                 + "<p>Noise figures as He, Li and Fu define them (Electronics Optics &amp; Control 30(7), 2023, "
                 "pp. 15-20): the bias is the mean reading, the bias stability the spread of the means over windows "
                 "of the stated length, the repeatability the spread of the biases of separate runs.</p>"
                 + table(["channel", "figure", "value", "uncertainty", "unit"], figure_rows(d), left=2))
    if plot_png:
        body += image(plot_png, "Allan deviation with confidence band, fit, target and averaging time")
    if plan_dict is not None:
        p = plan_dict
        avg = "none" if p["averaging_time_s"] is None else f"{p['averaging_time_s']:.4g} s"
        floor = ("none (white noise alone)" if p["floor_deg_h"] is None else f"{p['floor_deg_h']:.4g} deg/h"
                 + (" (0.664 B, approached as tau grows)" if p["floor_tau_s"] is None else f" at tau {p['floor_tau_s']:.3g} s"))
        body += table(["test plan", "value"], [
            ["table rate", f"{p['rate_deg_s']:g} deg/s"], ["alignment goal", f"{p['accuracy_deg']:g} deg"],
            ["noise ratio", f"{p['noise_ratio']:g}"], ["noise target", f"{p['noise_target_deg_h']:.4f} deg/h"],
            ["curve floor", floor], ["averaging time per step", avg], ["reason", p["reason"]],
            ["total table time", "-" if p["test_plan"]["total_table_time_s"] is None
             else f"{p['test_plan']['total_table_time_s']:.4g} s"],
            ["noise source", p["noise_source"]]])
    return Section("Noise and test planning", body)
