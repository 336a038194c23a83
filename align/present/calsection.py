"""The report's calibration sections: an accelerometer or gyro ``[M | b]`` (multi-position, Ferraris,
rate table) with its 1-sigma in M's own unit (counts per m/s^2 for readings in counts), the scale factors
and angles (:func:`align.present.angles.angle_rows`), residuals, held-out checks and a gyro's g-sensitivity in
the unit the calibration file gives it; a magnetometer's hard and soft iron with its quality figures and the
angles of its soft iron; each with its picture when one was drawn.

Public names
------------
calibration_section, magnetometer_section
"""

from __future__ import annotations

import numpy as np

from align.errors import AlignError
from align.present.angles import angle_rows
from align.present.html import Section, angle_table, esc, image, table
from align.present.residuals import ROTATION_RESIDUAL, is_scalar, largest, residual_values
from align.units import DEG, to_unit

_AXES = ("x", "y", "z")


def _values(v: np.ndarray, u: str, fmt: str = "+.6g") -> list[str]:
    """SI values in ``u`` (a unit or ``counts``; anything else shown as it is held), formatted with ``fmt``."""
    try:
        shown = to_unit(np.asarray(v, float), u)
    except AlignError:
        shown = np.asarray(v, float)
    return [format(float(x), fmt) for x in np.atleast_1d(shown)]


def _sig(v: float, digits: int = 6) -> str:
    """``v`` signed with ``digits`` significant digits (``+0.000601824``, ``-3.79613e-07``); never ``-0``."""
    return format(float(v) + 0.0, f"+.{digits}g")


def _inverse(unit: str) -> str:
    """The unit of M^-1 for M's unit: ``counts per m/s^2`` -> ``m/s^2 per count``; ``1`` stays ``1``."""
    if unit.startswith("counts per "):
        return unit[len("counts per "):] + " per count"
    return unit


def _rotation_table(cal) -> str:
    """A gyro calibrated from rotations between poses: its rotation table, as ``calibrate gyro`` prints it."""
    rows = []
    for r in cal.rotations:
        k, (t0, t1) = r["rotation"], r["t_s"]
        rows.append([str(k), f"{k}->{k + 1}", f"{t0:.1f}-{t1:.1f}", f"{r['turn_deg']:.1f}",
                     " ".join(f"{v:+.2f}" for v in r["axis"]), f"{r['residual_deg']:.3f}",
                     "fit" if r["used"] else "left out: a check"])
    return (f"<p>Rotations; residual: the {esc(ROTATION_RESIDUAL)}, in degrees:</p>"
            + table(["rotation", "poses", "t [s]", "turn [deg]", "axis (accelerometer frame)", "residual [deg]", "use"],
                    rows, left=0))


def _residuals(cal) -> str:
    """The residuals and held-out checks, then the largest residual, by :mod:`align.present.residuals` (the
    terminal's figure and definition): a gyro's rotations in degrees, a scalar residual in one column."""
    if cal.rotations:
        body = _rotation_table(cal)
    else:
        body = ""
        for what, pool in (("Residuals of the fit", cal.residuals), ("Held-out checks", cal.checks)):
            if not pool:
                continue
            shown, unit = residual_values(dict(pool), cal.units)
            if is_scalar(pool):  # one number per position (the |a| = g fit): one column
                name = "|a| - g" if cal.sensor == "accelerometer" else "residual"
                body += (f"<p>{what} ({esc(name)}, one number per position), {esc(unit)}:</p>"
                         + table(["position", f"{name} [{unit}]"], [[k, f"{v[0]:+.4g}"] for k, v in shown.items()]))
            else:
                body += (f"<p>{what} (reading - model), {esc(unit)}:</p>"
                         + table(["position", "x", "y", "z"], [[k] + [f"{x:+.4g}" for x in v] for k, v in shown.items()]))
    for big in (largest(cal), largest(cal, held_out=True)):
        if big is not None:
            body += f"<p>{esc(big.text()[0].upper() + big.text()[1:])}.</p>"
    return body


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
    d = cal.to_dict()
    m_unit = d["units"].get("M", "1")  # counts per m/s^2 for readings in counts
    inv_unit = _inverse(m_unit)
    m_rows = [[f"{a} axis"] + [_sig(cal.M[i, j]) + ("" if not np.isfinite(cal.sigma_M[i, j])
                                                   else f" ± {cal.sigma_M[i, j]:.2g}") for j in range(3)]
              for i, a in enumerate(_AXES)]
    a_mat = np.linalg.inv(cal.M)
    a_rows = [[f"{a} axis"] + [_sig(a_mat[i, j]) for j in range(3)] for i, a in enumerate(_AXES)]
    bias = [f"{b} ± {s}" for b, s in zip(_values(cal.bias, u), _values(cal.sigma_bias, u, ".2g"))]
    stated = "dimensionless" if m_unit == "1" else f"in {m_unit}"
    body = (f"<p>From <code>{esc(source)}</code>: {esc(cal.sensor)}, method <b>{esc(cal.method)}</b>. "
            f"<code>raw = M true + bias</code>, corrected by <code>true = M<sup>-1</sup> (raw - bias)</code>; "
            f"M {esc(stated)}, the bias in {esc(u)}.</p>"
            + f"<p>M (1-sigma), {esc(stated)}:</p>" + table(["", "x", "y", "z"], m_rows)
            + f"<p>M<sup>-1</sup>, the correction{'' if inv_unit == '1' else ', in ' + esc(inv_unit)}:</p>"
            + table(["", "x", "y", "z"], a_rows)
            + table([f"bias [{u}]", "x", "y", "z"], [["bias ± 1-sigma"] + bias])
            + angle_table(angle_rows(cal.M, cal.sigma_M, None, m_unit), cal.sensor))
    body += _residuals(cal)
    if cal.g_sensitivity is not None:  # as the calibration file and the terminal give it: the readings' unit per m/s^2
        kga, k_unit = np.array(d["g_sensitivity"], float), d["units"].get("g_sensitivity", "rad/s per m/s^2")
        body += (f"<p>g-sensitivity K_ga (<code>raw = M w + K_ga a + bias</code>), in {esc(k_unit)}:</p>"
                 + table(["", "x", "y", "z"], [[f"{a} gyro"] + [_sig(v, 4) for v in kga[i]] for i, a in enumerate(_AXES)]))
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
    rows = [["model", cal.model], ["field after calibration", f"{_values(np.array([cal.field]), u, '.6g')[0]} {u}"],
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
    model = getattr(cal, "model_matrix", None)
    if model is not None:  # as calibrate mag prints them: the angles of M of the model m_raw = M m + hard_iron
        body += ("<p>Angles of <code>M = (" + ("R " if cal.misalignment is not None else "")
                 + "soft_iron)<sup>-1</sup></code>, the model <code>m_raw = M m + hard_iron</code>:</p>"
                 + angle_table(angle_rows(model), "magnetometer"))
    if picture:
        body += image(picture, "magnetometer capture before and after calibration with the predicted heading error")
    elif picture_note:
        body += f'<p class="note">{esc(picture_note)}</p>'
    body += "".join(f'<p class="note">{esc(n)}</p>' for n in cal.notes)
    return Section(f"Calibration: magnetometer ({source})", body)
