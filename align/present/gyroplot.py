"""The picture of a multi-position gyro session (``calibrate gyro --plot``): poses and rotations, calibrated.

Top: ``|a|`` of the calibrated accelerometer (m/s^2, so raw counts look like gravity too) with the poses
shaded and numbered, each pose's mean and local gravity drawn: a pose off the line is not at rest or not
gravity alone.
Middle: ``|w|`` of the calibrated gyro (deg/s) with every rotation shaded and labelled with its number (and
its turn where there is room); rotations left out of the fit are grey.
Bottom: each rotation's residual (the angle between the predicted and the measured gravity direction at the
next pose, degrees: the figure and definition of :mod:`align.present.residuals`) as a bar over the rotation.
The labels never overlap (:func:`align.present.figures.place_labels`: staggered, then thinned).

Public names
------------
gyro_session_png
"""

from __future__ import annotations

import numpy as np

from align.errors import InputError
from align.present.figures import place_labels, png_bytes, pyplot, trace
from align.present.residuals import ROTATION_RESIDUAL, largest_rotation
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
    fig, (top, low, res) = plt.subplots(3, 1, figsize=(11.0, 7.6), sharex=True,
                                        gridspec_kw={"height_ratios": [1.3, 1.6, 1.0]})
    x, y = trace(t, np.column_stack([norm, speed]))
    top.plot(x, y[:, 0], color="0.25", lw=0.8, label="|a| calibrated")
    top.axhline(gravity, color="tab:blue", lw=1.0, ls="--", label=f"local gravity {gravity:.5g} m/s^2")
    means, pose_x = [], []
    for k, (a, b) in enumerate(poses):
        t0, t1 = float(t[a]), float(t[b - 1])
        top.axvspan(t0, t1, color="#8fd1c4", alpha=0.4, lw=0, label="pose" if k == 0 else None)
        means.append(float(norm[a:b].mean()))
        pose_x.append(0.5 * (t0 + t1))
        top.plot([t0, t1], [means[-1]] * 2, color="tab:orange", lw=2.2, zorder=5,
                 label="mean |a| of the pose" if k == 0 else None)
    low.plot(x, y[:, 1], color="0.25", lw=0.8, label="|w| calibrated")
    mid, spans = [], []
    for row in rotations:
        t0, t1 = row["t_s"]
        colour = "#f2b880" if row["used"] else "0.8"
        low.axvspan(t0, t1, color=colour, alpha=0.5, lw=0)
        mid.append(0.5 * (t0 + t1))
        spans.append((t0, t1))
        res.bar(0.5 * (t0 + t1), row["residual_deg"], width=max(t1 - t0, 1e-9), color="tab:orange" if row["used"]
                else "0.6", edgecolor="0.3", lw=0.4)
    big = largest_rotation(rotations)
    if means:
        worst = max(abs(m - gravity) for m in means)
        top.set_title(f"{len(poses)} poses (numbered); mean |a| per pose within {worst:.3g} m/s^2 of gravity",
                      fontsize=9, pad=24)
    low.set_title(f"{len(rotations)} rotations (numbered; turn in degrees where there is room); grey: left out of "
                  "the fit", fontsize=9)
    if big is not None:
        res.set_title(f"residual per rotation: the {ROTATION_RESIDUAL}; {big.number}, {big.where}", fontsize=9)
    low.set_ylim(0.0, 1.45 * max(float(speed.max()), 1e-9))
    if rotations:
        res.set_ylim(0.0, 1.25 * max(max(float(r["residual_deg"]) for r in rotations), 1e-9))
    top.set_ylabel("|a| [m/s^2]")
    low.set_ylabel("|w| [deg/s]")
    res.set_ylabel("residual [deg]")
    res.set_xlabel("time [s]")
    res.set_xlim(float(t[0]), float(t[-1]))
    for panel in (top, low, res):
        panel.grid(True, alpha=0.3)
    handles = top.get_legend_handles_labels()[0] + low.get_legend_handles_labels()[0]
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, frameon=False)
    # labels placed last, in the final layout's pixels, so that none overlaps another
    place_labels(top, pose_x, [[str(k + 1) for k in range(len(poses))]], 1.0, "bottom", fontsize=7,
                 color="#1f6f63")
    numbers = [str(r["rotation"]) for r in rotations]
    _, stride = place_labels(low, mid, [[f"{r['rotation']}\n{r['turn_deg']:.0f}\u00b0" for r in rotations], numbers],
                             0.98, "top", fontsize=6)
    if stride > 1:
        nth = {2: "2nd", 3: "3rd"}.get(stride, f"{stride}th")
        low.set_title(f"{len(rotations)} rotations (every {nth} numbered, no room for more); grey: left out of the fit",
                      fontsize=9)
    return png_bytes(fig)
