"""PNG plots of results (matplotlib, Agg backend, imported on first use): the Allan deviation here; the
segmentation of a rate-table log in :mod:`align.present.segplot`, calibrations in :mod:`align.present.calplots`.

Public names
------------
allan_plot_png, allan_ylim, segmentation_plot_png, segmentation_spans, Span
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from align.noise.job import AllanJob
from align.noise.model import TERM_TABLE
from align.present.figures import COLOURS, png_bytes, pyplot
from align.units import to_unit

#: line styles of the five single-term asymptotes (Q, N, B, K, R)
_TERM_STYLES = (":", "-.", ":", "-.", ":")


def _term_label_at(y: np.ndarray, lo: float, hi: float, falling: bool, j: int) -> int | None:
    """Index of the tau where a term's asymptote is labelled (None when it never enters [lo, hi]): a flat or
    rising line at its last point inside (the right edge), a falling one near the bottom, a little higher
    for each channel ``j`` so that the labels of neighbouring lines do not overlap."""
    inside = np.flatnonzero((y >= lo) & (y <= hi))
    if not len(inside):
        return None
    if not falling:
        return int(inside[-1])
    level = lo * 1.4 * (hi / lo) ** (0.05 * j)
    return int(inside[np.argmin(np.abs(np.log(y[inside] / level)))])


def _short_names(names: tuple) -> list[str]:
    """Channel names without their common prefix and suffix (``gyro_x_dps`` -> ``x``), when that leaves them distinct."""
    full = [str(n) for n in names]
    if len(full) < 2:
        return full
    pre = len(os.path.commonprefix(full))
    suf = len(os.path.commonprefix([n[::-1] for n in full]))
    short = [n[pre : len(n) - suf] for n in full]
    return short if all(short) and len(set(short)) == len(short) else full


def allan_ylim(job: AllanJob, shown: str, target: float | None = None) -> tuple[float, float]:
    """The y range of the Allan plot in ``shown``: the curves (pooled and each run's) and their 68 % intervals,
    and the target (SI) when given, with a margin of 1.5x; never a term's asymptote."""
    data = [to_unit(f.ci_low, shown) for f in job.fits] + [to_unit(f.ci_high, shown) for f in job.fits]
    data += [to_unit(rr.adev, shown) for rr in (*job.run_results, job.result)]
    if target is not None:
        data.append(np.atleast_1d(to_unit(target, shown)))
    values = np.concatenate([np.ravel(v) for v in data])
    values = values[np.isfinite(values) & (values > 0)]
    return float(values.min()) / 1.5, float(values.max()) * 1.5


def allan_plot_png(job: AllanJob, target: float | None = None, chosen_tau: float | None = None) -> bytes:
    """Log-log Allan deviation with its confidence band, the fit, its identifiable terms and the planning target.

    With several runs each run's curve is drawn thin and the pooled curve (the one fitted) bold. The
    y range comes from the curves and their 68 % intervals (and the target); the single-term
    asymptotes of the identifiable terms only are drawn, each labelled with its channel and IEEE
    letter (``x N``, ``x B``, ...).

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
    plt = pyplot()
    r = job.result
    shown = "deg/h" if job.sensor == "gyroscope" else "ug"
    fig, ax = plt.subplots(figsize=(7.5, 5))
    lo, hi = allan_ylim(job, shown, target)
    level = None if target is None else float(to_unit(target, shown))
    runs_styles = ("-", "--", "-.", ":")
    for k, rr in enumerate(job.run_results):
        style = runs_styles[k % len(runs_styles)]
        for j in range(len(r.names)):
            ax.loglog(rr.tau, to_unit(rr.adev[j], shown), color=COLOURS[j % len(COLOURS)], lw=0.7, alpha=0.7, ls=style)
        name = Path(job.inputs[k]).name if k < len(job.inputs) else ""
        ax.plot([], [], color="0.4", lw=0.7, ls=style, label=f"run {k + 1} {name}".rstrip())
    for j, (name, short, f) in enumerate(zip(r.names, _short_names(r.names), job.fits)):
        c = COLOURS[j % len(COLOURS)]
        ax.loglog(r.tau, to_unit(r.adev[j], shown), color=c, lw=2.2 if job.pooled else 1.5,
                  label=f"{name} (pooled)" if job.pooled else name)
        ax.fill_between(r.tau, to_unit(f.ci_low, shown), to_unit(f.ci_high, shown), color=c, alpha=0.2, lw=0)
        ax.loglog(r.tau, to_unit(f.model(r.tau), shown), color=c, lw=0.8, ls="--")
        for k, t in enumerate(TERM_TABLE):
            if not (f.identifiable[k] and f.params[k] > 0):
                continue
            y = to_unit(f.model.only(t.key)(r.tau), shown)
            ax.loglog(r.tau, y, color=c, lw=0.8, ls=_TERM_STYLES[k], alpha=0.8)
            at = _term_label_at(y, lo, hi, t.alpha > 0 or t.key == "white", j)
            if at is not None:
                ax.text(r.tau[at], float(y[at]), f" {short} {t.symbol}", fontsize=7, color=c, va="center")
    if target is not None:
        ax.axhline(level, color="k", lw=1, ls="--", label=f"noise target {level:.4g} {shown}")
    if chosen_tau is not None:
        ax.axvline(chosen_tau, color="k", lw=1, ls=":", label=f"averaging time {chosen_tau:.4g} s")
    ax.set_ylim(lo, hi)
    ax.set_xlabel("averaging time tau [s]")
    ax.set_ylabel(f"Allan deviation [{shown}]")
    what = (f"pooled over {job.runs} runs (bold; thin: each run)" if job.pooled else f"{r.n:,} samples")
    ax.set_title(f"Overlapping Allan deviation, {what} at {r.fs:g} Hz\n(band: 68 % CI; dashed: fit; "
                 "dotted/dash-dot: identified terms, labelled channel and IEEE letter)", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return png_bytes(fig)


# the segmentation picture lives in its own module; its names are kept here for callers of this one
from align.present.segplot import Span, segmentation_plot_png, segmentation_spans  # noqa: E402

__all__ = ["allan_plot_png", "allan_ylim", "segmentation_plot_png", "segmentation_spans", "Span"]
