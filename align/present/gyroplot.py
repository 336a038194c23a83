"""The picture of a multi-position gyro session (``calibrate gyro --plot``): poses and rotations, calibrated.

Top: ``|a|`` of the calibrated accelerometer (m/s^2, so raw counts look like gravity too) with the poses
shaded and numbered, each pose's mean and local gravity drawn: a pose off the line is not at rest or not
gravity alone.
Bottom: ``|w|`` of the calibrated gyro (deg/s) with every rotation shaded and labelled with its number,
turn and residual (the angle between the predicted and the measured gravity direction at the next pose);
rotations left out of the fit are grey.

Public names
------------
gyro_session_png
"""

from __future__ import annotations

import numpy as np

from align.errors import InputError
from align.present.figures import png_bytes, pyplot, trace
from align.units import DEG


def gyro_session_png(t: np.ndarray, acc: np.ndarray, rate: np.ndarray, poses: list, rotations: list,
                     gravity: float) -> bytes:
    """The session's poses and rotations (see the module).

    Parameters
    ----------
    t : ndarray, shape (n,)
        Time, s.
    acc : ndarray, shape (n, 3)
        Calibrated specific force, m/s^2 (``M_a^-1 (a - b_a)``).
    rate : ndarray, shape (n, 3)
        Calibrated angular rate, rad/s (``M_g^-1 (g - b_g)``).
    poses : list of (int, int)
        The poses as sample ranges, end exclusive.
    rotations : list of dict
        The rotation table (``rotation``, ``t_s``, ``turn_deg``, ``residual_deg``, ``used``), as the calibration
        file holds it.
    gravity : float
        Local gravity, m/s^2.

    Returns
    -------
    bytes
        The PNG file.
    """
    t, acc, rate = (np.asarray(x, float) for x in (t, acc, rate))
    n = len(t)
    if acc.shape != (n, 3) or rate.shape != (n, 3) or n < 2:
        raise InputError(f"time {t.shape}, accelerometer {acc.shape} and gyro {rate.shape}: expected (n,), (n, 3), "
                         "(n, 3)", "gyro session picture")
    norm = np.linalg.norm(acc, axis=1)
    speed = np.linalg.norm(rate, axis=1) / DEG
    plt = pyplot()
    fig, (top, low) = plt.subplots(2, 1, figsize=(11.0, 6.0), sharex=True, gridspec_kw={"height_ratios": [1.3, 1.6]})
    x, y = trace(t, np.column_stack([norm, speed]))
    top.plot(x, y[:, 0], color="0.25", lw=0.8, label="|a| calibrated")
    top.axhline(gravity, color="tab:blue", lw=1.0, ls="--", label=f"local gravity {gravity:.5g} m/s^2")
    means = []
    for k, (a, b) in enumerate(poses):
        t0, t1 = float(t[a]), float(t[b - 1])
        top.axvspan(t0, t1, color="#8fd1c4", alpha=0.4, lw=0, label="pose" if k == 0 else None)
        means.append(float(norm[a:b].mean()))
        top.plot([t0, t1], [means[-1]] * 2, color="tab:orange", lw=2.2, zorder=5,
                 label="mean |a| of the pose" if k == 0 else None)
        top.annotate(str(k + 1), (0.5 * (t0 + t1), 1.0), xycoords=("data", "axes fraction"), ha="center",
                     va="bottom", fontsize=7, color="#1f6f63")
    low.plot(x, y[:, 1], color="0.25", lw=0.8, label="|w| calibrated")
    for row in rotations:
        t0, t1 = row["t_s"]
        colour = "#f2b880" if row["used"] else "0.8"
        low.axvspan(t0, t1, color=colour, alpha=0.5, lw=0)
        low.annotate(f"{row['rotation']}\n{row['turn_deg']:.0f}\u00b0\n{row['residual_deg']:.2f}\u00b0",
                     (0.5 * (t0 + t1), 0.98), xycoords=("data", "axes fraction"), ha="center", va="top", fontsize=6)
    if means:
        worst = max(abs(m - gravity) for m in means)
        top.set_title(f"{len(poses)} poses; mean |a| per pose within {worst:.3g} m/s^2 of gravity", fontsize=9, pad=12)
    used = [r for r in rotations if r["used"]]
    if used:
        big = max(used, key=lambda r: r["residual_deg"])
        low.set_title(f"{len(rotations)} rotations (number, turn, residual); largest residual {big['residual_deg']:.3g} "
                      f"deg, rotation {big['rotation']}; grey: left out of the fit", fontsize=9)
    low.set_ylim(0.0, 1.45 * max(float(speed.max()), 1e-9))
    top.set_ylabel("|a| [m/s^2]")
    low.set_ylabel("|w| [deg/s]")
    low.set_xlabel("time [s]")
    low.set_xlim(float(t[0]), float(t[-1]))
    for panel in (top, low):
        panel.grid(True, alpha=0.3)
    handles = top.get_legend_handles_labels()[0] + low.get_legend_handles_labels()[0]
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, frameon=False)
    return png_bytes(fig)
