"""PNG plots of results (matplotlib, Agg backend, imported on first use).

Public names
------------
allan_plot_png
"""

from __future__ import annotations

import io

from align.noise.job import AllanJob
from align.noise.model import TERMS
from align.units import to_unit

#: line colours of successive channels
_COLOURS = ("tab:red", "tab:green", "tab:blue", "tab:purple", "tab:orange", "tab:brown")
#: line styles of the five single-term curves
_TERM_STYLES = (":", "-.", ":", "-.", ":")


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def allan_plot_png(job: AllanJob, target: float | None = None, chosen_tau: float | None = None) -> bytes:
    """Log-log Allan deviation with its confidence band, the fitted terms, and the planning target.

    Parameters
    ----------
    job : AllanJob
    target : float, optional
        Noise target (SI, e.g. rad/s), drawn as a horizontal line.
    chosen_tau : float, optional
        Averaging time, s, drawn as a vertical line.

    Returns
    -------
    bytes
        The PNG file. Rates are shown in deg/h, accelerations in ug.
    """
    plt = _pyplot()
    r = job.result
    shown = "deg/h" if job.sensor == "gyroscope" else "ug"
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for j, (name, f) in enumerate(zip(r.names, job.fits)):
        c = _COLOURS[j % len(_COLOURS)]
        ax.loglog(r.tau, to_unit(r.adev[j], shown), color=c, lw=1.5, label=name)
        ax.fill_between(r.tau, to_unit(f.ci_low, shown), to_unit(f.ci_high, shown), color=c, alpha=0.2, lw=0)
        ax.loglog(r.tau, to_unit(f.model(r.tau), shown), color=c, lw=0.8, ls="--")
    model = job.fits[0].model
    for t, style in zip(TERMS, _TERM_STYLES):
        if getattr(model, t) > 0:
            alone = model.only(t)
            ax.loglog(r.tau, to_unit(alone(r.tau), shown), color="0.5", lw=0.8, ls=style)
            ax.text(r.tau[-1], float(to_unit(alone(r.tau[-1]), shown)), f" {t}", fontsize=7, color="0.4")
    if target is not None:
        level = float(to_unit(target, shown))
        ax.axhline(level, color="k", lw=1, ls="--", label=f"noise target {level:.4g} {shown}")
    if chosen_tau is not None:
        ax.axvline(chosen_tau, color="k", lw=1, ls=":", label=f"averaging time {chosen_tau:.4g} s")
    ax.set_xlabel("averaging time tau [s]")
    ax.set_ylabel(f"Allan deviation [{shown}]")
    ax.set_title(f"Overlapping Allan deviation, {r.n:,} samples at {r.fs:g} Hz (band: 68 % CI; dashed: fit)", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()
