"""One self-contained HTML report of a design and its test: pictures embedded, every input stated.

Each ``*_section`` function turns one result into an HTML fragment; :func:`html_report`
wraps them into a page with no external resource (PNG pictures as data URIs,
inline CSS, no script).

The sections of the other jobs live beside it: :mod:`align.present.noisesection` (Allan deviation and
test plan), :mod:`align.present.alignsection` (electronic alignment), :mod:`align.present.calsection`
(calibrations), :mod:`align.present.verdicts` (the summary and the measured misalignment against the allowance).

Public names
------------
Section, esc, image, table, angle_table, header_block, html_report, inputs_section, budget_section, allowance_section
"""

from __future__ import annotations

import base64
import html
from dataclasses import dataclass

import numpy as np

from align import CONVENTION, __version__
from align.units import DEG

_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;max-width:1000px;margin:2em auto;padding:0 1em;color:#222}
h1{font-size:1.6em}h2{font-size:1.25em;border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:2em}
table{border-collapse:collapse;margin:.6em 0}td,th{border:1px solid #ccc;padding:.25em .6em;text-align:right}
th{background:#f3f3f3}td.l,th.l{text-align:left}.pass{color:#070}.fail{color:#b00;font-weight:bold}.warn{color:#a60}
img{max-width:100%;border:1px solid #ddd;margin:.5em 0}code,pre{background:#f6f6f6;padding:.1em .3em}
.note{color:#555;font-size:.92em}.info{color:#345}
.banner{font-size:1.15em;padding:.5em .8em;border:2px solid;border-radius:4px}.banner.pass{background:#eef8ee}
.banner.fail{background:#fdeeee}.banner.info{background:#f2f5f8;border-color:#9ab}.banner.warn{background:#fdf6e8}
table.header td{text-align:left;border:none;padding:.1em 1em .1em 0}table.header td:first-child{color:#555}
table.fit{font-size:.9em;max-width:100%}table.fit td{white-space:nowrap}table.fit td.l{white-space:normal}
td.wrap{overflow-wrap:anywhere;min-width:12em}
@page{margin:12mm}
@media print{body{max-width:none;margin:0;padding:0;font-size:10pt}table{font-size:8.5pt;max-width:100%}
td,th{padding:.15em .35em;overflow-wrap:break-word}pre{white-space:pre-wrap;overflow-wrap:anywhere}
tr,img{break-inside:avoid}h2{break-after:avoid}img{max-width:100%}
.banner,th,.pass,.fail,.warn{-webkit-print-color-adjust:exact;print-color-adjust:exact}}
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


def angle_table(rows, sensor: str = "sensor", mounting: bool = False) -> str:
    """The scale factors and misalignment angles as :func:`align.present.angles.angle_rows` lays them out (the
    cells as the terminal prints them), then each row's definition.

    Parameters
    ----------
    rows : list of AngleRow
    sensor : str
        What the axes are (``"gyro"``, ``"accelerometer"``), for the definitions.
    mounting : bool
        Whether the angles are relative to a nominal mounting ``N`` (those of ``M N^T``).
    """
    from align.present.angles import DEFINITIONS

    width = max(len(r.names) for r in rows)
    body = [[r.label, "" if r.unit == "1" else r.unit] + r.text() + [""] * (width - len(r.names)) for r in rows]
    defs = "; ".join(DEFINITIONS[r.key] for r in rows if r.key in DEFINITIONS)
    sig = any(r.sigmas is not None for r in rows)
    return (table(["", "unit", "each element" + (" ± 1-sigma" if any(r.sigmas is not None for r in rows) else "")]
                  + [""] * (width - 1), body, left=2)
            + f'<p class="note">Rows of M are {esc(sensor)} axes; <code>u_i</code> is row i of '
            + ("M N<sup>T</sup>" if mounting else "M") + " scaled to unit length, <code>e_j</code> the reference "
            f"axes; {esc(defs)}"
            + (". The 1-sigma by first-order propagation of sigma(M), its elements taken independent." if sig else ".")
            + "</p>")


def header_block(header: dict | None) -> str:
    """The report's identification under its title: ``header`` maps a label (``"serial number"``,
    ``"operator"``, ``"date"``) to its text; empty values are left out; the tool's version is always given."""
    rows = [(k, v) for k, v in (header or {}).items() if v not in (None, "")]
    rows.append(("generated by", f"imu-align {__version__}"))
    cells = "".join(f"<tr><td>{esc(k)}</td><td>{esc(v)}</td></tr>" for k, v in rows)
    return f'<table class="header">{cells}</table>'


def html_report(title: str, sections: list[Section], header: dict | None = None,
                conventions: list[str] | None = None) -> str:
    """The whole page: title, identification (:func:`header_block`), the conventions of the results shown
    (default: the gyro alignment's, :data:`align.CONVENTION`), then the sections in order."""
    conventions = [CONVENTION] if conventions is None else conventions
    stated = ("Convention" + ("s" if len(conventions) > 1 else "") + ": "
              + "; ".join(f"<code>{esc(c)}</code>" for c in conventions) + ". ") if conventions else ""
    parts = [f"<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>{esc(title)}</title>",
             f"<style>{_CSS}</style></head><body><h1>{esc(title)}</h1>", header_block(header),
             f'<p class="note">{stated}Angles in degrees unless stated.</p>']
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
            + _presets(b)
            + "<p>Misalignment of each gyro axis from its system axis (a tilt about x moves the y and z gyros):</p>"
            + table(["deg", "x gyro", "y gyro", "z gyro"], axis_rows))
    if mc:
        body += (f'<p class="note">Monte Carlo: {mc["draws"]:,} assemblies, seed {mc["seed"]}; rest model on the ledges, '
                 "screws uniform over the poses that fit.</p>")
    if histogram_png:
        body += image(histogram_png, "Monte Carlo histogram of the per-axis misalignment")
    if assembly_png:
        body += image(assembly_png, "assembly resting on its ledges, tilt exaggerated")
    body += ('<p class="note">Equation numbers are those of M. Looney, "The Basics of MEMS IMU/Gyroscope Alignment", '
             "Analog Dialogue (Analog Devices).</p>")
    return Section("Mounting-misalignment budget", body)


def _presets(result) -> str:
    """The preset values a budget used, each with its source and whether the datasheet confirms it."""
    from align.present.presets import preset_rows

    rows = preset_rows(result)
    if not rows:
        return ""
    return "<p>Datasheet preset values used:</p>" + table(
        ["part", "figure", "value", "confirmed", "source"],
        [[r["part"], r["figure"], r["value"], "yes" if r["confirmed"] else "<b>NOT confirmed</b>", r["source"]]
         for r in rows], left=5)


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
                          ("PASS", "pass") if r.ok else ("FAIL", "fail")])
        ok = all(r.ok for r in margins)
        body += (f"<p>Budget ({esc(basis)}) against the allowance, a design check (what the mounting is predicted to "
                 "give, each element against its allowance alone): "
                 f"<b class=\"{'pass' if ok else 'fail'}\">{'PASS' if ok else 'FAIL'}</b></p>"
                 + table(["element", "predicted [deg]", "allowed [deg]", "margin [deg]", "result"], mrows))
    ag = d["agreement"]
    body += (f'<p class="note">At {esc(ag["element"])}: closed form (Looney\'s Eq 11-13) '
             + ", ".join(f"{k} {v:+.5f}" for k, v in ag["closed_form_deg"].items())
             + " deg; attitude propagation " + ", ".join(f"{k} {v:+.5f}" for k, v in ag["propagated_deg"].items())
             + f" deg ({esc(ag['note'])}).</p>")
    return Section("What the manoeuvre allows", body)
