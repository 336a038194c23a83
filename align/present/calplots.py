"""Pictures of calibrations and corrections: the accelerometer's static intervals, the magnetometer before
and after (projections of the ellipsoid and the sphere, predicted heading error over heading), and the
traces of a log before and after ``apply``.

Every function returns PNG bytes (matplotlib, Agg backend, imported on first use) and is deterministic
for given inputs; readings come in SI and are shown in the unit given.

Public names
------------
accel_statics_png, magnetometer_png, apply_traces_png, heading_errors, ellipse_outline
"""

from __future__ import annotations

import numpy as np

from align.errors import InputError
from align.present.figures import COLOURS, display_unit, place_labels, png_bytes, pyplot, trace
from align.units import DEG

#: most points drawn of a scatter (a regular subsample beyond it)
_SCATTER = 4000
#: the coordinate planes of the projections: (first axis, second axis)
_PLANES = ((0, 1), (0, 2), (1, 2))


def _series(t, x, what: str) -> tuple[np.ndarray, np.ndarray]:
    """``t`` (n,) and ``x`` (n, 3) as float arrays, refused (naming ``what``) when their shapes differ."""
    t, x = np.asarray(t, float), np.asarray(x, float)
    if t.ndim != 1 or x.shape != (len(t), 3) or len(t) < 2:
        raise InputError(f"time of shape {t.shape} and readings of shape {x.shape}: expected (n,) and (n, 3), n >= 2",
                         what)
    return t, x


def accel_statics_png(t: np.ndarray, acc: np.ndarray, intervals: list, units: str, *, calibration=None,
                      gravity: float | None = None) -> bytes:
    """The accelerometer's detected static intervals over time.

    Top: the three axes as read, in ``units``; bottom: ``|a|`` of the calibrated readings in m/s^2
    (``M^-1 (a - b)`` of ``calibration``; the readings' own ``|a|`` in ``units`` when no calibration is given)
    with each interval's mean (a position whose mean is off local gravity is not at rest or not gravity alone).
    Every static interval is shaded in both panels and numbered, in the order
    :func:`align.calibration.statics.static_intervals` found them (the numbers never overlap:
    :func:`align.present.figures.place_labels`).

    Parameters
    ----------
    t : ndarray, shape (n,)
        Time, s.
    acc : ndarray, shape (n, 3)
        Readings, SI (m/s^2) or counts.
    intervals : list of (int, int)
        Static intervals as sample indices ``(start, stop)``, stop exclusive.
    units : str
        Display unit (``"m/s^2"``, ``"g"``, ``"counts"``, or a count size such as ``"16384 LSB/g"``).
    calibration : Calibration, optional
        The accelerometer's calibration (``correct`` maps the readings to m/s^2).
    gravity : float, optional
        Local gravity, m/s^2, drawn as a line with a calibration.

    Returns
    -------
    bytes
        The PNG file.

    Raises
    ------
    InputError
        Arrays of other shapes, or an interval outside the record.
    """
    t, acc = _series(t, acc, "static-interval picture")
    n = len(t)
    spans = [(int(a), int(b)) for a, b in intervals]
    for a, b in spans:
        if not 0 <= a < b <= n:
            raise InputError(f"interval {a}..{b} lies outside the record's {n} samples", "static-interval picture")
    factor, shown = display_unit(units, ("acceleration",))
    shown_acc = acc / factor
    if calibration is not None:
        norm, norm_unit, what = np.linalg.norm(calibration.correct(acc), axis=1), "m/s^2", "|a| calibrated"
    else:
        norm, norm_unit, what = np.linalg.norm(shown_acc, axis=1), shown, "|a| as read (not calibrated)"
    plt = pyplot()
    fig, (ax, lg) = plt.subplots(2, 1, figsize=(11.0, 6.0), sharex=True, gridspec_kw={"height_ratios": [2.2, 1.3]})
    x, y = trace(t, np.column_stack([shown_acc, norm]))
    for j in range(3):
        ax.plot(x, y[:, j], color=COLOURS[j], lw=0.8, label=f"{'xyz'[j]} axis")
    lg.plot(x, y[:, 3], color="0.25", lw=0.8, label=what)
    if calibration is not None and gravity is not None:
        lg.axhline(gravity, color="tab:blue", lw=1.0, ls="--", label=f"local gravity {gravity:.5g} m/s^2")
    mids = []
    for k, (a, b) in enumerate(spans):
        t0, t1 = float(t[a]), float(t[b - 1])
        for panel in (ax, lg):
            panel.axvspan(t0, t1, color="#8fd1c4", alpha=0.4, lw=0, label="static interval" if k == 0 else None)
        mean = float(norm[a:b].mean())
        lg.plot([t0, t1], [mean, mean], color="tab:orange", lw=2.2, zorder=5,
                label="mean |a| of the interval" if k == 0 else None)
        mids.append(0.5 * (t0 + t1))
    if spans:
        means = np.array([norm[a:b].mean() for a, b in spans])
        spread = float(means.max() - means.min())
        off = "" if calibration is None or gravity is None else \
            f", within {float(np.max(np.abs(means - gravity))):.3g} m/s^2 of gravity"
        lg.set_title(f"{what} at rest: {means.min():.5g} to {means.max():.5g} {norm_unit} over the intervals "
                     f"(spread {spread:.3g} {norm_unit}{off})", fontsize=9)
    ax.set_title(f"{len(spans)} static interval{'s' if len(spans) != 1 else ''} detected in {t[-1] - t[0]:.4g} s "
                 f"({n:,} samples), numbered; the readings as read", fontsize=10, pad=24)
    ax.set_ylabel(f"acceleration [{shown}]")
    lg.set_ylabel(f"|a| [{norm_unit}]")
    lg.set_xlabel("time [s]")
    lg.set_xlim(float(t[0]), float(t[-1]))
    for panel in (ax, lg):
        panel.grid(True, alpha=0.3)
    handles = ax.get_legend_handles_labels()[0] + [h for h in lg.get_legend_handles_labels()[0]
                                                   if h.get_label() != "static interval"]
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, frameon=False)
    place_labels(ax, mids, [[str(k + 1) for k in range(len(spans))]], 1.0, "bottom", fontsize=8, color="#1f6f63")
    return png_bytes(fig)


def ellipse_outline(centre: np.ndarray, shape: np.ndarray, plane: tuple[int, int], k: int = 181) -> np.ndarray:
    """The outline of the shadow of the ellipsoid ``{centre + shape u : |u| = 1}`` on a coordinate plane.

    The projection ``P`` onto the plane's two axes maps the ellipsoid onto the ellipse
    ``P centre + C v``, ``|v| = 1``, with ``C C^T = P shape shape^T P^T`` (Cholesky).

    Parameters
    ----------
    centre : ndarray, shape (3,)
    shape : ndarray, shape (3, 3)
    plane : (int, int)
        The two axes kept.
    k : int
        Points of the outline.

    Returns
    -------
    ndarray, shape (k, 2)
    """
    p = np.eye(3)[list(plane)]
    c = np.linalg.cholesky(p @ shape @ shape.T @ p.T)
    a = np.linspace(0, 2 * np.pi, k)
    return (p @ centre)[None, :] + np.column_stack([np.cos(a), np.sin(a)]) @ c.T


def heading_errors(cal, heading: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Heading error of a level magnetometer over heading, without and after the calibration ``cal``.

    The device is level (x forward, y right, z down), the field ``F`` has dip ``cal.dip`` (60 deg when
    unknown): body field ``m_b = (H cos psi, -H sin psi, V)``, ``H = F cos dip``, ``V = F sin dip``; the
    heading is read as ``atan2(-m_y, m_x)``.

    * Without calibration the reading is ``W^-1 m_b + h`` (``h`` hard iron, ``W`` soft iron): the error is
      the heading read from it minus ``psi``.
    * After it, what remains is the uncertainty of ``h``: ``d psi = -(sin psi dm_x + cos psi dm_y) / H`` with
      ``dm = W dh``, so its 1 sigma is ``sqrt(c^T W S W^T c) / H``, ``c = (sin psi, cos psi, 0)``,
      ``S = diag(sigma_h^2)``.

    Parameters
    ----------
    cal : MagCalibration
    heading : ndarray, shape (k,)
        rad.

    Returns
    -------
    before, after : ndarray, shape (k,)
        rad: the signed error without the calibration, and the 1-sigma error after it.
    """
    psi = np.asarray(heading, float)
    dip = 60 * DEG if cal.dip is None else cal.dip
    h_field, v_field = cal.field * np.cos(dip), cal.field * np.sin(dip)
    body = np.column_stack([h_field * np.cos(psi), -h_field * np.sin(psi), np.full(len(psi), v_field)])
    raw = np.linalg.solve(cal.soft_iron, body.T).T + cal.hard_iron
    before = np.angle(np.exp(1j * (np.arctan2(-raw[:, 1], raw[:, 0]) - psi)))
    c = np.column_stack([np.sin(psi), np.cos(psi), np.zeros(len(psi))]) @ cal.soft_iron
    after = np.sqrt(np.sum(c**2 * np.square(cal.sigma_hard_iron), axis=1)) / h_field
    return before, after


def _subsample(x: np.ndarray) -> np.ndarray:
    return x if len(x) <= _SCATTER else x[np.linspace(0, len(x) - 1, _SCATTER).astype(np.intp)]


def magnetometer_png(raw: np.ndarray, cal) -> bytes:
    """The magnetometer capture before and after calibration, and the predicted heading error over heading.

    Top row: the raw readings projected on the xy, xz and yz planes with the outline of the fitted
    ellipsoid's shadow (:func:`ellipse_outline`, ``m = h + F W^-1 u``) and its centre, the hard iron.
    Middle row: the calibrated readings ``W (m - h)`` with the sphere ``|m| = F``. Bottom: the heading
    error of a level device over heading (:func:`heading_errors`) without the calibration and, after it,
    the 1 sigma left by the hard iron's uncertainty beside the calibration's predicted heading error.

    Parameters
    ----------
    raw : ndarray, shape (n, 3)
        Raw readings, SI (tesla) or counts.
    cal : MagCalibration
        Its calibration (``cal.units`` is the display unit).

    Returns
    -------
    bytes
        The PNG file.
    """
    raw = np.asarray(raw, float)
    if raw.ndim != 2 or raw.shape[1] != 3 or len(raw) < 3:
        raise InputError(f"readings of shape {raw.shape}: expected (n, 3)", "magnetometer picture")
    factor, shown = display_unit(cal.units, ("magnetic_field",))
    calibrated = cal.correct(raw)
    inverse = np.linalg.inv(cal.soft_iron) * cal.field
    plt = pyplot()
    from matplotlib.lines import Line2D

    fig = plt.figure(figsize=(12.0, 10.5))
    grid = fig.add_gridspec(3, 6, height_ratios=[1.0, 1.0, 0.8], hspace=0.42, wspace=0.9)
    rows = ((raw, cal.hard_iron, inverse, "raw", "fitted ellipsoid"),
            (calibrated, np.zeros(3), np.eye(3) * cal.field, "calibrated", f"sphere |m| = {cal.field / factor:.4g} {shown}"))
    handles: list = []
    for r, (data, centre, shape, what, outline) in enumerate(rows):
        pts = _subsample(data) / factor
        lines = [ellipse_outline(centre, shape, pl) / factor for pl in _PLANES]
        lo = min(pts.min(), min(ln.min() for ln in lines))
        hi = max(pts.max(), max(ln.max() for ln in lines))
        pad = 0.06 * (hi - lo)
        for c, pl in enumerate(_PLANES):
            ax = fig.add_subplot(grid[r, 2 * c: 2 * c + 2])
            i, j = pl
            ax.scatter(pts[:, i], pts[:, j], s=2, color=COLOURS[2 if r else 0], alpha=0.35, lw=0, rasterized=True)
            ax.plot(lines[c][:, 0], lines[c][:, 1], color="k", lw=1.2)
            ax.plot([centre[i] / factor], [centre[j] / factor], "k+", ms=9)
            mid_i, mid_j = 0.5 * (lines[c].max(axis=0) + lines[c].min(axis=0))
            half = 0.5 * (hi - lo) + pad
            ax.set_xlim(mid_i - half, mid_i + half)
            ax.set_ylim(mid_j - half, mid_j + half)
            ax.set_aspect("equal", adjustable="box")
            ax.set_xlabel(f"m_{'xyz'[i]} [{shown}]", fontsize=8)
            ax.set_ylabel(f"m_{'xyz'[j]} [{shown}]", fontsize=8)
            ax.tick_params(labelsize=7)
            ax.set_title(f"{what}, {'xyz'[i]}{'xyz'[j]} plane", fontsize=9)
            ax.grid(True, alpha=0.3)
            if c == 0:  # the legend's own marks: a readable dot for the scatter, a small cross for the centre
                handles += [Line2D([], [], ls="none", marker="o", ms=4, color=COLOURS[2 if r else 0], label=f"{what} readings"),
                            Line2D([], [], color="k", lw=1.2, label=outline),
                            Line2D([], [], ls="none", marker="+", ms=7, color="k", label="hard iron" if r == 0 else "origin")]
    psi = np.linspace(0, 2 * np.pi, 361)
    before, after = heading_errors(cal, psi)
    assumed = cal.dip is None or any(n.startswith("dip not measured") for n in cal.notes)
    dip_text = "dip 60 deg assumed" if assumed else f"dip {cal.dip / DEG:.1f} deg measured"
    left = fig.add_subplot(grid[2, :3])
    left.plot(psi / DEG, before / DEG, color="tab:red", lw=1.4)
    left.axhline(0, color="0.4", lw=0.6)
    left.set_title(f"without calibration: heading error (level, {dip_text})\nlargest {np.abs(before).max() / DEG:.3g} deg",
                   fontsize=9)
    right = fig.add_subplot(grid[2, 3:])
    right.plot(psi / DEG, after / DEG, color="tab:blue", lw=1.4, label="from the hard iron's uncertainty")
    right.axhline(cal.heading_error / DEG, color="k", ls="--", lw=1.0,
                  label=f"predicted from the field scatter {cal.heading_error / DEG:.3g} deg")
    right.set_ylim(0, 1.3 * max(float(after.max()), cal.heading_error) / DEG or 1.0)
    right.set_title("after calibration: heading error, 1 sigma", fontsize=9)
    right.legend(fontsize=7, loc="lower right")
    for ax in (left, right):
        ax.set_xlim(0, 360)
        ax.set_xticks(range(0, 361, 45))
        ax.set_xlabel("heading [deg]")
        ax.set_ylabel("heading error [deg]")
        ax.grid(True, alpha=0.3)
    fig.suptitle(f"Magnetometer calibration ({cal.model} model, {len(raw):,} samples): field spread "
                 f"{100 * cal.spread_before:.2f} % before, {100 * cal.spread_after:.2f} % after", fontsize=10, y=0.955)
    fig.legend(handles=handles, loc="upper center", ncol=len(handles), fontsize=8, frameon=False,
               bbox_to_anchor=(0.5, 0.94))
    return png_bytes(fig)


def apply_traces_png(t: np.ndarray, raw: np.ndarray, corrected: np.ndarray, units: str) -> bytes:
    """A log before and after its correction (``apply``): each axis raw and corrected, and their difference.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Time, s.
    raw, corrected : ndarray, shape (n, 3)
        Readings before and after the correction, SI (or counts).
    units : str
        Display unit (a unit, ``"counts"``, or the size of one count).

    Returns
    -------
    bytes
        The PNG file.
    """
    t, raw = _series(t, raw, "apply picture")
    _, corrected = _series(t, corrected, "apply picture")
    factor, shown = display_unit(units)
    plt = pyplot()
    fig, axes = plt.subplots(4, 1, figsize=(11.0, 8.5), sharex=True, gridspec_kw={"height_ratios": [1, 1, 1, 1.1]})
    x, y = trace(t, np.column_stack([raw, corrected, corrected - raw]) / factor)
    for j in range(3):
        ax = axes[j]
        ax.plot(x, y[:, j], color="0.55", lw=0.9, label="raw" if j == 0 else None)
        ax.plot(x, y[:, 3 + j], color=COLOURS[j], lw=0.8, label=f"corrected {'xyz'[j]}")
        ax.set_ylabel(f"{'xyz'[j]} [{shown}]")
    for j in range(3):
        axes[3].plot(x, y[:, 6 + j], color=COLOURS[j], lw=0.8)
    axes[3].axhline(0, color="0.4", lw=0.5)
    axes[3].set_ylabel(f"corrected - raw\n[{shown}]")
    axes[3].set_xlabel("time [s]")
    axes[3].set_xlim(float(t[0]), float(t[-1]))
    for ax in axes:
        ax.grid(True, alpha=0.3)
    change = np.abs(corrected - raw).max(axis=0) / factor
    axes[0].set_title(f"Before and after the correction, {len(t):,} samples; largest change per axis "
                      + ", ".join(f"{'xyz'[j]} {change[j]:.3g}" for j in range(3)) + f" {shown}", fontsize=10)
    handles = [h for ax in axes[:3] for h in ax.get_legend_handles_labels()[0]]
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, frameon=False)
    return png_bytes(fig)
