"""The report's calibration sections: an accelerometer or gyro ``[M | b]`` (multi-position, Ferraris,
rate table) with its 1-sigma, scale factors and angles in degrees, residuals and held-out checks; a
magnetometer's hard and soft iron with its quality figures; each with its picture when one was drawn.

Public names
------------
calibration_section, magnetometer_section
"""

from __future__ import annotations

import numpy as np

from align.errors import AlignError
from align.model import angles
from align.present.html import Section, esc, image, table
from align.units import DEG, to_unit

_AXES = ("x", "y", "z")


def _values(v: np.ndarray, u: str, fmt: str = "+.6g") -> list[str]:
    """SI values in ``u`` (a unit or ``counts``; anything else shown as it is held), formatted with ``fmt``."""
    try:
        shown = to_unit(np.asarray(v, float), u)
    except AlignError:
        shown = np.asarray(v, float)
    return [format(float(x), fmt) for x in np.atleast_1d(shown)]


def calibration_section(cal, source: str, picture: bytes | None = None, picture_note: str = "") -> Section:
    """One sensor's calibration (``raw = M true + bias``) from a calibration file.

    Parameters
    ----------
    cal : Calibration
    source : str
        The file it came from.
    picture : bytes, optional
        The static intervals over time (:func:`align.present.calplots.accel_statics_png`).
    picture_note : str
        Why there is no picture, when there is none.
    """
    u = cal.units
    ang = angles(cal.M)
    m_rows = [[f"{a} axis"] + [f"{cal.M[i, j]:+.6f}" + ("" if not np.isfinite(cal.sigma_M[i, j])
                                                        else f" ± {cal.sigma_M[i, j]:.1e}") for j in range(3)]
              for i, a in enumerate(_AXES)]
    a_mat = np.linalg.inv(cal.M)
    a_rows = [[f"{a} axis"] + [f"{a_mat[i, j]:+.6f}" for j in range(3)] for i, a in enumerate(_AXES)]
    bias = [f"{b} ± {s}" for b, s in zip(_values(cal.bias, u), _values(cal.sigma_bias, u, ".2g"))]
    phi = [[f"{'xyz'[i]} axis"] + ["-" if i == j else f"{ang.phi[i, j] / DEG:+.4f}" for j in range(3)] for i in range(3)]
    body = (f"<p>From <code>{esc(source)}</code>: {esc(cal.sensor)}, method <b>{esc(cal.method)}</b>. "
            f"<code>raw = M true + bias</code>, corrected by <code>true = M<sup>-1</sup> (raw - bias)</code>; "
            f"M is dimensionless (unit 1), the bias in {esc(u)}.</p>"
            + "<p>M (1-sigma), dimensionless:</p>" + table(["", "x", "y", "z"], m_rows)
            + "<p>M<sup>-1</sup>, the correction:</p>" + table(["", "x", "y", "z"], a_rows)
            + table([f"bias [{u}]", "x", "y", "z"], [["bias ± 1-sigma"] + bias])
            + table(["per axis", "x", "y", "z"], [["scale factor"] + [f"{v:.6f}" for v in ang.scale],
                                                  ["psi: axis to frame [deg]"] + [f"{v / DEG:.4f}" for v in ang.psi]])
            + table(["phi_ij [deg]: axis i toward", "x", "y", "z"], phi)
            + table(["axis to axis [deg]", "delta_xy", "delta_xz", "delta_yz"],
                    [["delta_ij"] + [f"{v / DEG:+.4f}" for v in ang.delta]]))
    for what, rows in (("Residuals of the fit (reading - model)", cal.residuals),
                       ("Held-out checks (reading - model)", cal.checks)):
        if rows:
            body += f"<p>{what}, {esc(u)}:</p>" + table(["position", "x", "y", "z"],
                                                          [[k] + _values(v, u, "+.4g") for k, v in rows.items()])
    if cal.g_sensitivity is not None:
        body += table(["g-sensitivity K_ga", "x", "y", "z"],
                      [[f"{a} gyro"] + [f"{v:+.4g}" for v in cal.g_sensitivity[i]] for i, a in enumerate(_AXES)])
    if picture:
        body += image(picture, f"{cal.sensor} readings over time with the detected static intervals")
    elif picture_note:
        body += f'<p class="note">{esc(picture_note)}</p>'
    body += "".join(f'<p class="note">{esc(n)}</p>' for n in cal.notes)
    return Section(f"Calibration: {cal.sensor} ({source})", body)


def magnetometer_section(cal, source: str, picture: bytes | None = None, picture_note: str = "") -> Section:
    """A magnetometer calibration (``m_cal = W (m_raw - h)``) with its quality figures and picture.

    Parameters
    ----------
    cal : MagCalibration
    source : str
        The file it came from.
    picture : bytes, optional
        :func:`align.present.calplots.magnetometer_png` of its capture.
    picture_note : str
        Why there is no picture, when there is none.
    """
    u = cal.units
    hard = [f"{v} ± {s}" for v, s in zip(_values(cal.hard_iron, u), _values(cal.sigma_hard_iron, u, ".2g"))]
    soft = [[f"row {a}"] + [f"{cal.soft_iron[i, j]:+.6f}" for j in range(3)] for i, a in enumerate(_AXES)]
    assumed = any(n.startswith("dip not measured") for n in cal.notes)
    dip = "not known" if cal.dip is None else f"{cal.dip / DEG:.2f} deg" + (" (assumed, not measured)" if assumed else "")
    rows = [["model", cal.model], ["field after calibration", f"{_values([cal.field], u, '.6g')[0]} {u}"],
            ["field spread before (std |m| / mean |m|)", f"{100 * cal.spread_before:.2f} %"],
            ["field spread after", f"{100 * cal.spread_after:.2f} %"],
            ["coverage (1/3 for a full sphere)", f"{cal.coverage:.3f}"],
            ["predicted heading error (1 sigma)", f"{cal.heading_error / DEG:.3f} deg"], ["dip", dip]]
    body = (f"<p>From <code>{esc(source)}</code>: <code>m_cal = soft_iron (m_raw - hard_iron)</code>; hard iron in "
            f"{esc(u)}, soft iron dimensionless.</p>"
            + table([f"hard iron [{u}]", "x", "y", "z"], [["hard iron ± 1-sigma"] + hard])
            + "<p>Soft iron W:</p>" + table(["", "x", "y", "z"], soft)
            + table(["quality", "value"], rows, left=1))
    if cal.misalignment is not None:
        body += ("<p>Rotation to the accelerometer frame (<code>m_body = R m_cal</code>):</p>"
                 + table(["", "x", "y", "z"], [[f"row {a}"] + [f"{cal.misalignment[i, j]:+.6f}" for j in range(3)]
                                               for i, a in enumerate(_AXES)]))
    if picture:
        body += image(picture, "magnetometer capture before and after calibration with the predicted heading error")
    elif picture_note:
        body += f'<p class="note">{esc(picture_note)}</p>'
    body += "".join(f'<p class="note">{esc(n)}</p>' for n in cal.notes)
    return Section(f"Calibration: magnetometer ({source})", body)
