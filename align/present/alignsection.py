"""The report's electronic-alignment section: M and A with their 1-sigma, the bias, every angle of
reference section 1 (scale, psi, the cross-axis phi_ij, the axis-to-axis delta_ij) and the mounting
rotation, with their 1-sigma, the segmentation picture, the segments, the checks and the notes.

Public names
------------
alignment_section
"""

from __future__ import annotations

import numpy as np

from align.present.html import Section, angle_table, esc, image, table
from align.present.reread import in_words
from align.units import DEG, to_unit

_GYROS = ("x gyro", "y gyro", "z gyro")


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
    """Scale factors, psi, phi_ij, delta_ij and the mounting rotation with their 1-sigma
    (:func:`align.present.angles.angle_rows`, the layout ``matrix`` prints), relative to the nominal mounting."""
    from align.alignment.geometry import mounting_label
    from align.present.angles import angle_rows

    assumed = None if r.inferred_axis is None else int(np.argmax(np.abs(r.mounting[:, r.inferred_axis])))
    rows = angle_rows(r.M, r.sigma_M, r.mounting, "1", assumed)  # the gyro whose scale the two-axis shortcut assumed
    return (f"<p>Nominal mounting ({esc(r.mounting_source)}): {esc(mounting_label(r.mounting))}. The angles are "
            "those of <code>M N<sup>T</sup></code>, relative to it; the mounting rotation is the nearest proper "
            "rotation to it (the package relative to the system frame).</p>" + angle_table(rows, "gyro", mounting=True))


def alignment_section(r, segmentation_png: bytes | None = None, picture_note: str = "") -> Section:
    """The alignment matrix with uncertainties, angles, segment residuals, checks and the segmentation picture
    (:func:`align.present.segplot.segmentation_plot_png`) when given; else ``picture_note``, why there is none
    (a template: its placeholders put in plain words)."""
    u = r.units
    bias = ", ".join(f"{b:+.5g} ± {s:.2g}" for b, s in zip(to_unit(r.bias, u), to_unit(r.sigma_bias, u)))
    seg_rows = []
    for s in r.segments:
        scale = DEG if s.kind == "angle" else None
        res = np.array(s.residual) / scale if scale else to_unit(np.array(s.residual), u)
        seg_rows.append([s.name, s.kind, f"{s.t_start:.2f}-{s.t_end:.2f}"] + [f"{v:+.2e}" for v in res]
                        + ["deg" if scale else u])
    check_rows = [[c.name, (c.status.upper(), "pass" if c.status == "pass" else "warn"), c.detail] for c in r.checks]
    body = (f"<p>Method <b>{esc(r.method)}</b>; condition number {r.condition_number:.3g}; "
            f"{r.dof} degrees of freedom per gyro.</p>"
            "<p>M (1-sigma):</p>" + _matrix(r.M, r.sigma_M)
            + "<p>A = M<sup>-1</sup>, to load into firmware (1-sigma):</p>" + _matrix(r.A, r.sigma_A)
            + f"<p>bias [{esc(u)}]: {esc(bias)}</p>"
            + _angles(r)
            + (image(segmentation_png, "gyro traces with the plan steps, static periods, ignored motions and ramps "
                     "found in the log") if segmentation_png else
               f'<p class="note">{esc(in_words(picture_note))}</p>' if picture_note else "")
            + ("<p>Segments (residual per gyro):</p>"
               + table(["segment", "kind", "t [s]", "x", "y", "z", "unit"], seg_rows, left=2) if seg_rows else "")
            + _motions(getattr(r, "motions", ()))
            + table(["check", "status", "detail"], check_rows, left=3)
            + "".join(f'<p class="note">{esc(n)}</p>' for n in r.notes))
    return Section("Electronic alignment", body)
