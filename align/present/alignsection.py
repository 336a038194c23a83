"""The report's electronic-alignment section: M and A with their 1-sigma, the bias, every angle of
reference section 1 (scale, psi, the cross-axis phi_ij, the axis-to-axis delta_ij) and the mounting
rotation, with their 1-sigma, the segmentation picture, the segments, the checks and the notes.

Public names
------------
alignment_section
"""

from __future__ import annotations

import numpy as np

from align.present.html import Section, esc, image, table
from align.present.verdicts import angle_sigmas
from align.units import DEG, to_unit

_GYROS = ("x gyro", "y gyro", "z gyro")


def _pm(v: float, s: float, digits: int = 4) -> str:
    """``+0.4213 ± 0.0021`` (degrees in, the sigma left out when unknown)."""
    return f"{v:+.{digits}f}" + ("" if not np.isfinite(s) else f" ± {s:.{digits}f}")


def _matrix(m: np.ndarray, s: np.ndarray) -> str:
    return table(["", "x", "y", "z"], [[a] + [f"{m[i, j]:+.6f} ± {s[i, j]:.1e}" for j in range(3)]
                                      for i, a in enumerate(_GYROS)])


def _motions(motions) -> str:
    """The motions no plan step claimed (ignored by the fit), as a table; nothing when there are none."""
    if not motions:
        return ""
    rows = [[m.name, m.kind, f"{m.t_start:.2f}-{m.t_end:.2f}", m.label] for m in motions]
    return ("<p>Motions in the log that no plan step claimed (not used in the fit):</p>"
            + table(["motion", "kind", "t [s]", "what"], rows, left=4))


def _angles(r) -> str:
    """Scale and psi per gyro, phi_ij (gyro i toward system axis j), delta per pair, and the mounting rotation."""
    from align.alignment.geometry import mounting_label

    ang = r.angles
    sig = {k: v / DEG for k, v in angle_sigmas(r.M, r.sigma_M, r.mounting).items()}
    per_gyro = table(["per gyro [deg]", "x gyro", "y gyro", "z gyro"], [
        ["scale factor"] + [f"{v:.6f}" for v in ang.scale],
        ["psi: axis to frame"] + [_pm(v / DEG, sig[f"psi_{a}"]).lstrip("+") for v, a in zip(ang.psi, "xyz")]])
    phi_rows = [[f"{'xyz'[i]} gyro"] + ["-" if i == j else _pm(ang.phi[i, j] / DEG, sig[f"phi_{'xyz'[i]}{'xyz'[j]}"])
                                       for j in range(3)] for i in range(3)]
    phi = table(["phi_ij [deg]: gyro i toward", "system x", "system y", "system z"], phi_rows)
    delta = table(["axis to axis [deg]", "delta_xy", "delta_xz", "delta_yz"],
                  [["delta_ij = asin(u_i . u_j)"]
                   + [_pm(v / DEG, sig[f"delta_{p}"]) for v, p in zip(ang.delta, ("xy", "xz", "yz"))]])
    rot = ang.mounting_rotvec / DEG
    size = float(np.linalg.norm(rot))
    mount = table(["mounting rotation [deg]", "about x", "about y", "about z", "angle"],
                  [["rotation vector"] + [_pm(v, sig[f"rot_{a}"]) for v, a in zip(rot, "xyz")] + [f"{size:.4f}"]])
    return (per_gyro + "<p>Signed cross-axis angles <code>phi_ij = asin(u_i . e_j)</code>:</p>" + phi + delta
            + f"<p>Nominal mounting ({esc(r.mounting_source)}): {esc(mounting_label(r.mounting))}. The angles are "
            "those of <code>M N<sup>T</sup></code>, relative to it; the mounting rotation is the nearest proper "
            "rotation to it (the package relative to the system frame), 1-sigma by first-order propagation of "
            "sigma(M), its elements taken independent.</p>" + mount)


def alignment_section(r, segmentation_png: bytes | None = None) -> Section:
    """The alignment matrix with uncertainties, angles, segment residuals, checks and the segmentation picture
    (:func:`align.present.segplot.segmentation_plot_png`) when given."""
    u = r.units
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
            "<p>M (1-sigma):</p>" + _matrix(r.M, r.sigma_M)
            + "<p>A = M<sup>-1</sup>, to load into firmware (1-sigma):</p>" + _matrix(r.A, r.sigma_A)
            + f"<p>bias [{esc(u)}]: {esc(bias)}</p>"
            + _angles(r)
            + (image(segmentation_png, "gyro traces with the plan steps, static periods, ignored motions and ramps "
                     "found in the log") if segmentation_png else "")
            + ("<p>Segments (residual per gyro):</p>"
               + table(["segment", "kind", "t [s]", "x", "y", "z", "unit"], seg_rows, left=2) if seg_rows else "")
            + _motions(getattr(r, "motions", ()))
            + table(["check", "status", "detail"], check_rows, left=3)
            + "".join(f'<p class="note">{esc(n)}</p>' for n in r.notes))
    return Section("Electronic alignment", body)
