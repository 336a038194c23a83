"""Readable text summaries of results (pure functions returning strings).

Each function takes a result value and returns the text a command prints; display units
are the result's file units.

Public names
------------
matrix_text, angle_lines, alignment_summary, budget_summary, allowable_summary, margin_summary,
allan_summary, plan_summary, calibration_summary, magnetometer_summary, thermal_summary, positions_summary,
preset_lines (from :mod:`align.present.presets`)
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from align.alignment.result import AlignmentResult
from align.present.angles import AngleRow, angle_rows, number
from align.present.digits import with_sigma
from align.present.presets import preset_lines
from align.present.residuals import held_out_rows, largest
from align.units import DEG, to_unit

if TYPE_CHECKING:
    from align.noise import AllanJob, PlanResult


def matrix_text(m: np.ndarray, sigma: np.ndarray | None = None, digits: int = 6, indent: str = "  ") -> str:
    """Rows of a 3x3 matrix, each element with its 1-sigma when given."""
    lines = []
    for i in range(3):
        cells = []
        for j in range(3):
            cell = f"{m[i, j]:+.{digits}f}"
            if sigma is not None:
                cell += f" ± {sigma[i, j]:.1e}"
            cells.append(cell)
        lines.append(indent + "[" + ",  ".join(cells) + "]")
    return "\n".join(lines)


def _assumed_gyro(r: AlignmentResult) -> int | None:
    """The gyro whose scale the two-axis shortcut assumed (None when every scale was measured)."""
    return None if r.inferred_axis is None else int(np.argmax(np.abs(r.mounting[:, r.inferred_axis])))


def angle_lines(rows: list[AngleRow], indent: str = "  ") -> list[str]:
    """Scale factors and the misalignment angles in degrees (reference section 1), one line per row of
    :func:`align.present.angles.angle_rows` (the one layout every output uses), with the 1-sigma when known.

    The scale line ends with M's unit when M is not dimensionless (``(counts per m/s^2)``).
    """
    out = []
    for r in rows:
        tail = {"rotation": "  (rotation vector)"}.get(r.key, "")
        if r.key == "scale" and r.unit != "1":
            tail = f"  ({r.unit})"
        out.append(f"{indent}{r.label:<19}" + "  ".join(r.text()) + tail)
    return out


def alignment_summary(r: AlignmentResult) -> str:
    """The summary ``imu-align matrix`` prints: M, A, bias, angles, segments, checks."""
    u = r.units
    out = [f"Electronic alignment ({r.method}), convention g = M w + b, w = A (g - b)", "",
           "M (1-sigma):", matrix_text(r.M, r.sigma_M), "",
           "A = M^-1 (1-sigma):", matrix_text(r.A, r.sigma_A), "",
           "bias [" + u + "]: " + ", ".join(f"{b:+.5g} ± {s:.2g}" for b, s in zip(to_unit(r.bias, u), to_unit(r.sigma_bias, u))),
           "",
           "angles [deg]" + ("" if np.allclose(r.mounting, np.eye(3)) else ", relative to the nominal mounting") + ":",
           *angle_lines(angle_rows(r.M, r.sigma_M, r.mounting, assumed=_assumed_gyro(r))),
           "",
           f"design condition number {r.condition_number:.3g}, {r.dof} degrees of freedom per gyro",
           "", "segments (residual / noise, per gyro):"]
    for s in r.segments:
        scale = DEG if s.kind == "angle" else None
        res = np.array(s.residual) / scale if scale else to_unit(np.array(s.residual), u)
        nz = np.array(s.noise) / scale if scale else to_unit(np.array(s.noise), u)
        unit = "deg" if scale else u
        out.append(f"  {s.name:<32} {s.t_start:9.2f}-{s.t_end:9.2f} s  "
                   + " ".join(f"{a:+.2e}" for a in res) + f"  / {np.max(nz):.1e} {unit}")
    out += ["", r.linearity.summary(u)] if r.linearity is not None else []
    out += ["", "checks:"] + [f"  [{c.status}] {c.name}: {c.detail}" for c in r.checks]
    out += ["", "notes:"] + [f"  - {n}" for n in r.notes]
    return "\n".join(out)


def budget_summary(b) -> str:
    """The table ``imu-align budget`` prints: source, per-axis, worst case and Monte Carlo."""
    d = b.to_dict()
    m = d["mount"]
    lines = [
        "Mounting-misalignment budget (angle between each gyro axis and its system axis)",
        "",
        f"  part {m['part'] or 'not named'}, axis-to-package {', '.join(f'{v:.3g}' for v in m['axis_to_package_deg'])} deg, "
        f"package {m['package_mm'][0]:g} x {m['package_mm'][1]:g} mm, ledges {m['ledge_size_mm']:g} mm, "
        f"height band {m['height_tolerance_mm']:g} mm, "
        f"screws {m['screw_diameter_mm']:g} mm in {m['hole_diameter_mm']:g} mm holes, "
        f"R_S {m['screw_radius_mm']:.4f} mm",
        *preset_lines(b, "    "),
        "",
        "  source (Eq 1-4)                        deg",
        f"    tilt about x   (Eq 2)           {d['tilt_x_deg']:10.5f}",
        f"    tilt about y   (Eq 3)           {d['tilt_y_deg']:10.5f}",
        f"    skew about z   (Eq 4)           {d['skew_z_deg']:10.5f}",
        f"    mounting = largest              {d['mounting_deg']:10.5f}",
        f"    total, RSS with datasheet (Eq 1){d['total_deg']:10.5f}",
        f"    plain sum                       {d['sum_deg']:10.5f}",
        "",
        "  per gyro axis                x          y          z",
        "    RSS                  " + "".join(f"{d['per_axis_deg'][a]:11.5f}" for a in "xyz"),
        "    worst case (3-D)     " + "".join(f"{d['worst_case_per_axis_deg'][a]:11.5f}" for a in "xyz"),
    ]
    mc = d.get("monte_carlo")
    if mc:
        for p, vals in mc["percentiles_deg"].items():
            lines.append(f"    Monte Carlo p{p:<6}  " + "".join(f"{vals[a]:11.5f}" for a in "xyz")
                         + f"   any axis {vals['any']:.5f}")
        lines.append("    Monte Carlo max      " + "".join(f"{mc['max_deg'][a]:11.5f}" for a in "xyz")
                     + f"   ({mc['draws']:,} draws, seed {mc['seed']})")
    lines += ["", f"  worst case over all axes {d['worst_case_deg']:.5f} deg; source total {d['total_deg']:.5f} deg"]
    return "\n".join(lines)


def _deg(v: float) -> str:
    return "unconstrained" if not np.isfinite(v) else f"{v / DEG:.4f}"


def allowable_summary(a) -> str:
    """The table ``imu-align allowable`` prints."""
    lim = ", ".join(f"{k} {v / DEG:g} deg" for k, v in a.manoeuvre.limits.items())
    lines = [f"Allowable misalignment for: {a.manoeuvre.description} (limits: {lim})", "",
             "  element      allowable [deg]   method"]
    for e, v in a.allowable.items():
        lines.append(f"  {e:<10} {_deg(v):>17}   {a.method[e]}")
    ag = a.agreement
    lines += ["", f"  binding element: {a.binding} = {_deg(a.binding_value)} deg",
              f"  largest rigid misalignment cone (any direction): {a.cone / DEG:.4f} deg",
              "", f"  check at {ag['element']} = "
              f"{ag['element_deg'] if ag['element_deg'] is None else round(ag['element_deg'], 6)} deg"
              " (per-gyro integrated-angle error, deg):",
              "    closed form (Eq 11-13)  " + "  ".join(f"{k}={v:+.6f}" for k, v in ag["closed_form_deg"].items()),
              "    attitude propagation    " + "  ".join(f"{k}={v:+.6f}" for k, v in ag["propagated_deg"].items()),
              f"    ({ag['note']})"]
    return "\n".join(lines)


def margin_summary(rows, basis: str) -> str:
    """The table ``imu-align check`` prints."""
    lines = [f"Budget ({basis}) against the allowance, element by element [deg]", "",
             "  element     predicted      allowed       margin   result"]
    for r in rows:
        margin = "-" if not np.isfinite(r.allowed) else f"{r.margin / DEG:+.4f}"
        verdict = "pass" if r.ok else "FAIL"
        lines.append(f"  {r.element:<10} {r.predicted / DEG:10.4f} {_deg(r.allowed):>13} {margin:>12}   {verdict}")
    failed = [r.element for r in rows if not r.ok]
    lines += ["", "  result: " + ("PASS" if not failed else f"FAIL ({', '.join(failed)})")]
    return "\n".join(lines)


def _num(v) -> str:
    return "-" if v is None else f"{v:.4g}"


def _term_line(t: dict, notes: list[str]) -> str:
    """One term: its value ± 1-sigma when identifiable; else why not, its upper bound and what would identify it."""
    head = f"    {t['symbol']}  {t['name']:<25}"
    if t["identifiable"]:
        sig = "" if t["sigma"] is None else f" ± {t['sigma']:.2g}"
        return f"{head} {t['value']:.4g}{sig} {t['unit']}"
    own = next((n for n in notes if n.startswith(f"{t['symbol']} (")), "")
    why = re.search(r"record \(([^()]*)\)", own)
    line = f"{head} not identified" + (f" ({why.group(1)})" if why else "")
    if t.get("upper_bound") is not None:
        line += f"; < {t['upper_bound']:.3g} {t['unit']} (95 % upper bound)"
    if t.get("record_to_identify_h") is not None:
        line += f"; about {t['record_to_identify_h']:.3g} h of record would identify it"
    elif t.get("sample_rate_to_identify_hz") is not None:
        line += f"; a sample rate of about {t['sample_rate_to_identify_hz']:.3g} Hz would identify it"
    return line


def _readouts_line(r: dict) -> str:
    """The IEEE point readouts: N at tau = 1 s, the floor with its 68 % interval and tau, K at tau = 3 s."""
    b = r.get("B_floor_over_0.664")
    floor = "-" if b is None else f"{0.664 * b:.4g} {r['B_unit']}"
    lo, hi = r.get("B_floor_over_0.664_low"), r.get("B_floor_over_0.664_high")
    if b is not None and lo is not None and hi is not None:
        floor += f" (68 %: {0.664 * lo:.4g}-{0.664 * hi:.4g})"
    if b is not None and r.get("B_floor_tau_s") is not None:
        floor += f" at tau {r['B_floor_tau_s']:.3g} s"
    return (f"    IEEE point readouts: N (line at tau = 1 s) {_num(r['N_at_tau_1s'])} {r['N_unit']}; "
            f"floor {floor}, B = floor/0.664 {_num(b)} {r['B_unit']}; "
            f"K (line at tau = 3 s) {_num(r['K_at_tau_3s'])} {r['K_unit']}")


#: the start of a note on one term: "N (angle random walk): " (this version) or "white: " (version 1 files)
_TERM_NOTE = re.compile(r"^([QNBKR] \([a-z ]+\)|quantization|white|flicker|random_walk|ramp): ")


def _fit_lines(fit: dict) -> list[str]:
    """The five terms, the readouts, and the notes that are not about one term (those are on its line)."""
    notes = list(fit["notes"])
    lines = [_term_line(t, notes) for t in fit["terms"].values()]
    lines.append(_readouts_line(fit["ieee_point_readouts"]))
    lines += [f"    note: {n}" for n in notes if not _TERM_NOTE.match(n)]
    return lines


def _noise_types(tau: list[float], alpha: list[int], sensor: str) -> str:
    """``"N angle random walk 0.01-12.6 s; B bias instability 15.8-398 s"``: the power-law noise identified per
    range of tau (alpha 2 Q, 0 N, -1 B, -2 K; alpha 1, flicker phase noise, has no IEEE 952 term)."""
    from align.noise.model import term

    keys = {2: "quantization", 0: "white", -1: "flicker", -2: "random_walk"}
    parts, start = [], 0
    for k in range(1, len(alpha) + 1):
        if k == len(alpha) or alpha[k] != alpha[start]:
            a = int(alpha[start])
            what = (f"{term(keys[a]).symbol} {term(keys[a]).name(sensor)}" if a in keys
                    else "alpha 1 (between Q and N)")
            span = f"{tau[start]:.3g}" + (f"-{tau[k - 1]:.3g}" if k - 1 > start else "")
            parts.append(f"{what} {span} s")
            start = k
    return "; ".join(parts)


def allan_summary(job: AllanJob) -> str:
    """The table ``imu-align allan`` prints (values in the job's file units, terms in engineering units).

    With several runs: each run's line, then the pooled curve's terms (the fit and the plan use it).
    """
    from align.noise.model import term

    d = job.to_dict()
    u = d["units"]
    tau = d["tau"]
    hours = (d["per_run"][0]["samples"] if job.pooled else d["samples"]) / d["fs_hz"] / 3600
    lines = [f"Allan deviation: {d['runs']} run(s) of {hours:.3g} h at {d['fs_hz']:g} Hz, {len(tau)} taus "
             f"({tau[0]:.3g}-{tau[-1]:.3g} s); {d['sensor']} data in {u['adev']}"]
    if job.pooled:
        lines.append(f"  pooled curve: {d['pooled']['method']}; the fit and the plan use it")
        n_key = term("white").json_key(job.sensor)
        for p in d["per_run"]:
            ns = ", ".join(f"{name} {_num(f['terms'][n_key]['estimate'])}" for name, f in p["fit"].items())
            lines.append(f"  run {Path(p['input']).name}: {p['samples']:,} samples; N fitted {ns} {d['units']['terms'][n_key]}")
    lines.append("")
    for name, fit in d["fit"].items():
        lines.append(f"  {name}" + (" (pooled curve)" if job.pooled else ""))
        lines += _fit_lines(fit)
        if d.get("noise_type_alpha"):
            lines.append("    noise type by tau (lag-1 autocorrelation, B1 ratio): "
                         + _noise_types(tau, d["noise_type_alpha"][name], job.sensor))
        fig = d["figures"][name]
        stab = ", ".join(f"{p}: {v:.4g}" for p, v in fig["bias_stability"].items())
        lines.append(f"    bias {fig['bias']:.6g} {u['bias']}; bias stability ({stab}) {u['bias']}")
        if "repeatability" in d:
            lines.append(f"    bias repeatability over {d['runs']} runs: {d['repeatability'][name]:.4g} {u['bias']}")
        lines.append("")
    return "\n".join(lines).rstrip()


def plan_summary(plan: PlanResult) -> str:
    """The text ``imu-align plan`` prints."""
    d = plan.to_dict()
    tp = d["test_plan"]
    if d["floor_deg_h"] is None:
        floor = "none (white noise alone averages down without limit)"
    elif d["floor_tau_s"] is None:
        floor = f"{d['floor_deg_h']:.4g} deg/h (0.664 B, approached as tau grows)"
    else:
        floor = f"{d['floor_deg_h']:.4g} deg/h at tau {d['floor_tau_s']:.3g} s"
    lines = [f"Test plan: table rate {d['rate_deg_s']:g} deg/s, alignment goal {d['accuracy_deg']:g} deg, "
             f"noise {d['noise_ratio']:g}x below it ({d['noise_source']})",
             f"  noise target        {d['noise_target_deg_h']:.4f} deg/h  (rate x sin(goal) / ratio, Example 3)",
             f"  curve floor         {floor}"]
    if d["feasible"]:
        lines.append(f"  averaging time      {d['averaging_time_s']:.4g} s per step  ({d['reason']})")
        lines.append(f"  whole test          {tp['steps']} steps x "
                     f"({d['averaging_time_s']:.4g} s + {tp['settle_s']:g} s settling) = "
                     f"{tp['total_table_time_s']:.4g} s of table time")
    else:
        lines.append(f"  averaging time      none: {d['reason']}")
    turn = d["angle_method"]["longest_turn_s"]
    lines.append(f"  angle method        turns of {d['angle_method']['turn_angle_deg']:g} deg must last at most "
                 + ("(none meets it)" if turn is None else f"{turn:.4g} s"))
    return "\n".join(lines + preset_lines(plan))


def _unit_text(unit: str) -> str:
    return "dimensionless" if unit == "1" else unit


def calibration_summary(cals: dict) -> str:
    """Text for ``imu-align calibrate ferraris/accel/gyro``: per sensor ``M`` with its unit and 1-sigma, the bias,
    the misalignment angles of ``M``'s rows in degrees (as ``matrix``), residuals and notes."""
    out = []
    for name, c in cals.items():
        d = c.to_dict()
        u, mu = d["units"]["bias"], d["units"]["M"]  # mu: matrix_unit(c.units, c.sensor)
        out += [f"{name} ({d['method']}), convention {d['convention']}",
                f"  M [{_unit_text(mu)}] (1-sigma):", matrix_text(c.M, c.sigma_M, 6, "    "),
                f"  bias [{u}]: " + ", ".join(f"{b:+.6g} ± {s:.2g}" for b, s in zip(d["bias"], d["uncertainty"]["bias"]))]
        if "g_sensitivity" in d:
            out.append(f"  g-sensitivity [{d['units']['g_sensitivity']}]:")
            out.append(matrix_text(np.array(d["g_sensitivity"]), None, 6, "    "))
        out += ["  angles of M's rows (sensor axes) in the calibration frame [deg]:",
                *angle_lines(angle_rows(c.M, c.sigma_M, unit=mu), "    ")]
        big = largest(c)  # the one figure and definition of the report and the picture
        if big is not None:
            out.append("  " + big.text())
        for where, value, unit in held_out_rows(c):
            out.append(f"  held-out check {where}: residual {value:.3g} {unit}")
        out += [f"  note: {n}" for n in d["notes"]] + [""]
    return "\n".join(out).rstrip()


def magnetometer_summary(c) -> str:
    """Text for ``imu-align calibrate mag``: hard iron, soft iron (dimensionless), the rotation to the accelerometer
    when found, and the angles in degrees of ``M = (misalignment soft_iron)^-1`` (the model ``m_raw = M m + h``,
    rows the magnetometer axes), as ``matrix`` prints them."""
    d = c.to_dict()
    u, q = d["units"]["hard_iron"], d["quality"]
    frame = {"axis-down": " in the body (fixture) frame, from the axis-down turns",
             "gravity": " in the accelerometer frame"}.get(c.misalignment_method, " in the body frame")
    rot = d.get("misalignment_angles")
    rot_lines = [] if rot is None else [
        "  misalignment rotation (alpha, beta, gamma about x, y, z) [deg]: "
        + ", ".join(number(a, 3) if s is None else " ± ".join(with_sigma(a, s, 3, True))
                    for a, s in zip(rot["angles_deg"], rot["sigma_deg"] or [None] * 3))
        + ("" if rot["sigma_deg"] is None else " (1 sigma)")]
    lines = [f"magnetometer ({d['model']} soft iron), convention {d['convention']}",
             f"  hard iron [{u}]: "
             + ", ".join(f"{h:+.5g} ± {s:.2g}" for h, s in zip(d["hard_iron"], d["uncertainty"]["hard_iron"])),
             "  soft iron [dimensionless]" + ("" if c.sigma_soft_iron is None else " (± 1 sigma)") + ":",
             matrix_text(c.soft_iron, c.sigma_soft_iron, 5, "    "),
             *(["  misalignment (m_body = misalignment m_cal) [dimensionless]:", matrix_text(c.misalignment, None, 5, "    ")]
               if c.misalignment is not None else []),
             *rot_lines,
             "  angles of M = (" + ("misalignment " if c.misalignment is not None else "")
             + "soft_iron)^-1, rows the magnetometer axes"
             + (frame if c.misalignment is not None else "") + " [deg]:",
             *angle_lines(angle_rows(c.model_matrix), "    "),
             f"  field {d['field']:.5g} {u}; field-magnitude spread {100 * q['field_spread_before']:.2f} % before, "
             f"{100 * q['field_spread_after']:.2f} % after; direction coverage {q['coverage']:.3f} (full sphere 0.333)",
             f"  predicted heading error {q['predicted_heading_error_deg']:.2f} deg (1 sigma)"]
    return "\n".join(lines + [f"  note: {n}" for n in d["notes"]])


def thermal_summary(result) -> str:
    """The terminal's lines of a :class:`~align.calibration.thermal.result.ThermalCalibration`. Per sensor and axis:
    order, lag, residual before/after (rms, largest), one cubic, band, hysteresis, the
    held-out branch check; the reference temperature and the valid range."""
    from align.units import to_unit

    lines = []
    for name, s in result.sensors.items():
        u, m = s.units, s.model

        def v(x: float, u: str = u) -> str:
            return f"{to_unit(x, u):.3g}"

        lines.append(f"{name} ({u}): reference {m.tref:.2f} C, valid {m.tmin:.2f} to {m.tmax:.2f} C (clamped outside), "
                     f"{s.samples} samples" + (f", {s.branches['heating']} heating, {s.branches['cooling']} cooling"
                                               if s.branches else ""))
        lines.append("  axis order lag   rms before  rms after  largest after  one cubic  band 1s    hysteresis (1s) "
                     "at T      held-out h->c / c->h")
        for i, a in enumerate(s.axes):
            h = a.hysteresis
            hyst = f"{v(h.value)} ({v(h.sigma)}) at {h.at:.1f} C" if h is not None else "-"
            cross = f"{v(a.crosscheck[0])} / {v(a.crosscheck[1])}" if a.crosscheck is not None else "-"
            lines.append(f"  {'xyz'[i]:>4} {a.order:>5} {'yes' if a.lag else 'no':<4}  {v(a.rms_before):>10}  "
                         f"{v(a.rms_after):>9}  {v(a.max_after):>13}  {v(a.rms_cubic):>9}  {v(a.band_max):>8}  "
                         f"{hyst:<27} {cross}")
        lines += [f"  note: {n}" for n in s.notes]
    return "\n".join(lines)


def positions_summary(result) -> str:
    """The terminal's table: every parameter of both sensors with its 1-sigma and observability (deg/h, deg/h per g,
    m/s^2, ppm and deg as a test engineer reads them)."""
    from align.units import STANDARD_GRAVITY

    shown = {("gyroscope", "b"): (math.degrees(1) * 3600, "deg/h"),
             ("gyroscope", "K"): (math.degrees(1) * 3600 * STANDARD_GRAVITY, "deg/h/g"),
             ("gyroscope", "M"): (1.0, "1"), ("accelerometer", "b"): (1.0, "m/s^2"), ("accelerometer", "M"): (1.0, "1")}
    lines = [f"{len(result.positions)} positions at latitude {math.degrees(result.latitude):.6g} deg, gravity "
             f"{result.gravity:.6g} m/s^2 (Earth rate removed; M rows are sensor axes)"]
    for key in ("gyroscope", "accelerometer"):
        fit = getattr(result, key)
        lines.append(f"{key} (rank per axis {', '.join(str(a.rank) for a in fit.axes)}; chi-square/dof "
                     + ", ".join(f"{c:.3g}/{d}" for c, d in zip(fit.chi2, fit.dof)) + "):")
        for ax in fit.axes:
            for name, v, var, st in zip(ax.names, ax.value, np.diag(ax.cov), ax.status):
                f, unit = shown[(key, name[0])]
                text = "not observable" if not math.isfinite(v) else \
                    f"{v * f:.6g} +/- {math.sqrt(var) * f:.2g}" + ("" if unit == "1" else f" {unit}") + \
                    ("" if st == "observable" else f"  ({st})")
                lines.append(f"  {name:<5} {text}")
        lines += [f"  note: {n}" for n in fit.notes]
    return "\n".join(lines)
