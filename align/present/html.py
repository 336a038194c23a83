"""One self-contained HTML report of a design and its test: pictures embedded, every input stated.

Each ``*_section`` function turns one result into an HTML fragment; :func:`html_report`
wraps them into a page with no external resource (PNG pictures as data URIs,
inline CSS, no script).

Public names
------------
Section, html_report, image, table, inputs_section, budget_section, allowance_section,
allan_section, alignment_section
"""

from __future__ import annotations

import base64
import html
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from align import CONVENTION, __version__
from align.units import DEG, to_unit

if TYPE_CHECKING:
    from align.noise import AllanJob, PlanResult

_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;max-width:1000px;margin:2em auto;padding:0 1em;color:#222}
h1{font-size:1.6em}h2{font-size:1.25em;border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:2em}
table{border-collapse:collapse;margin:.6em 0}td,th{border:1px solid #ccc;padding:.25em .6em;text-align:right}
th{background:#f3f3f3}td.l,th.l{text-align:left}.pass{color:#070}.fail{color:#b00;font-weight:bold}.warn{color:#a60}
img{max-width:100%;border:1px solid #ddd;margin:.5em 0}code,pre{background:#f6f6f6;padding:.1em .3em}
.note{color:#555;font-size:.92em}
"""


@dataclass(frozen=True)
class Section:
    """A titled HTML fragment of the report."""

    title: str
    body: str


def esc(x) -> str:
    return html.escape(str(x))


def image(png: bytes, alt: str) -> str:
    """An ``<img>`` with the PNG embedded as a data URI."""
    return f'<img alt="{esc(alt)}" src="data:image/png;base64,{base64.b64encode(png).decode()}">'


def table(header: list[str], rows: list[list], left: int = 1) -> str:
    """An HTML table; the first ``left`` columns are left-aligned text."""
    head = "".join(f'<th class="{"l" if i < left else ""}">{esc(h)}</th>' for i, h in enumerate(header))
    body = []
    for row in rows:
        cells = []
        for i, v in enumerate(row):
            cls = "l" if i < left else ""
            if isinstance(v, tuple):  # (text, css class)
                v, extra = v
                cls = f"{cls} {extra}".strip()
            cells.append(f'<td class="{cls}">{esc(v)}</td>')
        body.append("<tr>" + "".join(cells) + "</tr>")
    return f"<table><tr>{head}</tr>{''.join(body)}</table>"


def html_report(title: str, sections: list[Section]) -> str:
    """The whole page."""
    parts = [f"<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>{esc(title)}</title>",
             f"<style>{_CSS}</style></head><body><h1>{esc(title)}</h1>",
             f'<p class="note">imu-align {esc(__version__)}. Convention everywhere: <code>{esc(CONVENTION)}</code>; '
             "angles in degrees unless stated.</p>"]
    for s in sections:
        parts.append(f"<h2>{esc(s.title)}</h2>{s.body}")
    parts.append("</body></html>")
    return "\n".join(parts)


def inputs_section(inputs: dict) -> Section:
    """Every input file and its content (TOML shown verbatim)."""
    body = []
    for label, (path, text) in inputs.items():
        body.append(f"<p><b>{esc(label)}</b>: <code>{esc(path)}</code></p>")
        if text:
            body.append(f"<pre>{esc(text)}</pre>")
    return Section("Inputs", "".join(body))


def budget_section(b, histogram_png: bytes | None, assembly_png: bytes | None) -> Section:
    """The mounting budget: source table, per-axis, worst case, Monte Carlo, pictures."""
    d = b.to_dict()
    rows = [["tilt about x (Eq 2)", f"{d['tilt_x_deg']:.5f}"], ["tilt about y (Eq 3)", f"{d['tilt_y_deg']:.5f}"],
            ["skew about z (Eq 4)", f"{d['skew_z_deg']:.5f}"], ["mounting = largest", f"{d['mounting_deg']:.5f}"],
            ["datasheet axis-to-package", f"{d['imu_deg']:.5f}"], ["total, RSS (Eq 1)", f"{d['total_deg']:.5f}"],
            ["plain sum", f"{d['sum_deg']:.5f}"], ["worst case, 3-D, any axis", f"{d['worst_case_deg']:.5f}"]]
    axis_rows = [["RSS"] + [f"{d['per_axis_deg'][a]:.5f}" for a in "xyz"],
                 ["worst case (3-D)"] + [f"{d['worst_case_per_axis_deg'][a]:.5f}" for a in "xyz"]]
    mc = d.get("monte_carlo")
    if mc:
        for p, v in mc["percentiles_deg"].items():
            axis_rows.append([f"Monte Carlo p{p}"] + [f"{v[a]:.5f}" for a in "xyz"])
    m = d["mount"]
    body = (f"<p>Part {esc(m['part'] or '-')}, package {m['package_mm'][0]:g} x {m['package_mm'][1]:g} mm, ledges "
            f"{m['ledge_size_mm']:g} mm with a {m['height_tolerance_mm']:g} mm height band, screws {m['screw_diameter_mm']:g} mm "
            f"in {m['hole_diameter_mm']:g} mm holes at {m['spacing_mm'][0]:g} x {m['spacing_mm'][1]:g} mm "
            f"(R_S {m['screw_radius_mm']:.4f} mm).</p>"
            + table(["source budget", "deg"], rows)
            + "<p>Misalignment of each gyro axis from its system axis (a tilt about x moves the y and z gyros):</p>"
            + table(["deg", "x gyro", "y gyro", "z gyro"], axis_rows))
    if mc:
        body += (f'<p class="note">Monte Carlo: {mc["draws"]:,} assemblies, seed {mc["seed"]}; rest model on the ledges, '
                 "screws uniform over the poses that fit.</p>")
    if histogram_png:
        body += image(histogram_png, "Monte Carlo histogram of the per-axis misalignment")
    if assembly_png:
        body += image(assembly_png, "assembly resting on its ledges, tilt exaggerated")
    return Section("Mounting-misalignment budget", body)


def allowance_section(allow, margins=None, basis: str = "rss") -> Section:
    """Allowable misalignment per element, the binding one, and the margin against the budget."""
    d = allow.to_dict()
    lim = ", ".join(f"{k} {v:g} deg" for k, v in d["limits_deg"].items())
    rows = []
    for e, v in d["allowable_deg"].items():
        rows.append([e, "unconstrained" if v is None else f"{v:.4f}", d["method"][e]])
    body = (f"<p>Manoeuvre: {esc(d['manoeuvre'])}; limits: {esc(lim)}. Binding element <b>{esc(d['binding'])}</b> = "
            f"{d['binding_deg']:.4f} deg; largest rigid misalignment cone {d['cone_deg']:.4f} deg.</p>"
            + table(["element", "allowable [deg]", "method"], rows, left=1))
    if margins is not None:
        mrows = []
        for r in margins:
            allowed = "unconstrained" if not np.isfinite(r.allowed) else f"{r.allowed / DEG:.4f}"
            margin = "-" if not np.isfinite(r.allowed) else f"{r.margin / DEG:+.4f}"
            mrows.append([r.element, f"{r.predicted / DEG:.4f}", allowed, margin,
                          ("pass", "pass") if r.ok else ("FAIL", "fail")])
        ok = all(r.ok for r in margins)
        body += (f"<p>Budget ({esc(basis)}) against the allowance: <b class=\"{'pass' if ok else 'fail'}\">"
                 f"{'PASS' if ok else 'FAIL'}</b></p>"
                 + table(["element", "predicted [deg]", "allowed [deg]", "margin [deg]", "result"], mrows))
    ag = d["agreement"]
    body += (f'<p class="note">At {esc(ag["element"])}: closed form (Eq 11-13) '
             + ", ".join(f"{k} {v:+.5f}" for k, v in ag["closed_form_deg"].items())
             + " deg; attitude propagation " + ", ".join(f"{k} {v:+.5f}" for k, v in ag["propagated_deg"].items())
             + f" deg ({esc(ag['note'])}).</p>")
    return Section("What the manoeuvre allows", body)


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


def allan_section(job: AllanJob | None, plot_png: bytes | None, plan: PlanResult | None) -> Section:
    """Allan deviation, fitted terms and the test plan."""
    body = ""
    allan_dict = None if job is None else job.to_dict()
    plan_dict = None if plan is None else plan.to_dict()
    if allan_dict is not None:
        u = allan_dict["units"]
        rows = []
        for name, fit in allan_dict["fit"].items():
            for t in fit["terms"].values():
                rows.append([name, f"{t['symbol']} {t['name']}", *_term_cells(t), t["unit"]])
            r = fit["ieee_point_readouts"]
            b = r.get("B_floor_over_0.664")
            if b is not None:
                lo, hi = r.get("B_floor_over_0.664_low"), r.get("B_floor_over_0.664_high")
                at = r.get("B_floor_tau_s")
                rows.append([name, "floor (IEEE point readout)", f"{0.664 * b:.4g}",
                             "" if lo is None or hi is None else f"68 %: {0.664 * lo:.4g}-{0.664 * hi:.4g}"
                             + ("" if at is None else f" at tau {at:.3g} s"), r["B_unit"]])
        d = allan_dict
        runs = (f"pooled curve of {d['runs']} runs ({esc(d['pooled']['method'])}); " if "pooled" in d
                else f"{d['samples']:,} samples at {d['fs_hz']:g} Hz, ")
        body += (f"<p>{runs}data in {esc(u['adev'])}; confidence band {esc(u['ci'])}. A term's value is given only "
                 "where the record identifies it; otherwise its 95 % upper bound.</p>"
                 + table(["channel", "term", "value", "uncertainty or bound", "unit"], rows, left=2))
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


def _motions(motions) -> str:
    """The motions no plan step claimed (ignored by the fit), as a table; nothing when there are none."""
    if not motions:
        return ""
    rows = [[m.name, m.kind, f"{m.t_start:.2f}-{m.t_end:.2f}", m.label] for m in motions]
    return ("<p>Motions in the log that no plan step claimed (not used in the fit):</p>"
            + table(["motion", "kind", "t [s]", "what"], rows, left=4))


def alignment_section(r, segmentation_png: bytes | None = None) -> Section:
    """The alignment matrix with uncertainties, angles, segment residuals, checks and the segmentation picture
    (:func:`align.present.plots.segmentation_plot_png`) when given."""
    u = r.units
    def mat(m, s):
        return table(["", "x", "y", "z"], [[a] + [f"{m[i, j]:+.6f} ± {s[i, j]:.1e}" for j in range(3)]
                                         for i, a in enumerate(("x gyro", "y gyro", "z gyro"))])
    ang = r.angles
    bias = ", ".join(f"{b:+.5g} ± {s:.2g}" for b, s in zip(to_unit(r.bias, u), to_unit(r.sigma_bias, u)))
    seg_rows = []
    for s in r.segments:
        scale = DEG if s.kind == "angle" else None
        res = np.array(s.residual) / scale if scale else to_unit(np.array(s.residual), u)
        seg_rows.append([s.name, s.kind, f"{s.t_start:.2f}-{s.t_end:.2f}"] + [f"{v:+.2e}" for v in res]
                        + ["deg" if scale else u])
    check_rows = [[c.name, (c.status, "pass" if c.status == "pass" else "warn"), c.detail] for c in r.checks]
    body = (f"<p>Method <b>{esc(r.method)}</b>; condition number {r.condition_number:.3g}; "
            f"{r.dof} degrees of freedom per gyro.</p>"
            "<p>M (1-sigma):</p>" + mat(r.M, r.sigma_M)
            + "<p>A = M<sup>-1</sup>, to load into firmware (1-sigma):</p>" + mat(r.A, r.sigma_A)
            + f"<p>bias [{esc(u)}]: {esc(bias)}</p>"
            + table(["angle [deg]", "x", "y", "z"], [
                ["scale factor"] + [f"{v:.6f}" for v in ang.scale],
                ["psi (axis to frame)"] + [f"{v / DEG:.4f}" for v in ang.psi],
                ["delta (xy, xz, yz)"] + [f"{v / DEG:+.4f}" for v in ang.delta]])
            + (image(segmentation_png, "gyro traces with the plan steps, static periods, ignored motions and ramps "
                     "found in the log") if segmentation_png else "")
            + "<p>Segments (residual per gyro):</p>"
            + table(["segment", "kind", "t [s]", "x", "y", "z", "unit"], seg_rows, left=2)
            + _motions(getattr(r, "motions", ()))
            + table(["check", "status", "detail"], check_rows, left=3)
            + "".join(f'<p class="note">{esc(n)}</p>' for n in r.notes))
    return Section("Electronic alignment", body)
