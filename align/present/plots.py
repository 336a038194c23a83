"""PNG plots of results (matplotlib, Agg backend, imported on first use): the Allan deviation here; the
segmentation of a rate-table log in :mod:`align.present.segplot`, calibrations in :mod:`align.present.calplots`.

Public names
------------
allan_plot_png, allan_ylim, segmentation_plot_png, segmentation_spans, Span
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from align.noise.job import AllanJob
from align.noise.model import TERM_TABLE
from align.present.figures import COLOURS, png_bytes, pyplot
from align.units import to_unit

#: line styles of the five single-term asymptotes (Q, N, B, K, R)
_TERM_STYLES = (":", "-.", ":", "-.", ":")


def _term_label_at(y: np.ndarray, lo: float, hi: float, falling: bool) -> int | None:
    """Index of the tau where a term's asymptote is labelled first (None when it never enters [lo, hi]): a flat or
    rising line at its last point inside (the right edge), a falling one near the bottom."""
    inside = np.flatnonzero((y >= lo) & (y <= hi))
    if not len(inside):
        return None
    if not falling:
        return int(inside[-1])
    return int(inside[np.argmin(np.abs(np.log(y[inside] / (lo * 1.4))))])


@dataclass(frozen=True)
class _TermLabel:
    """One asymptote's label: its term symbol, the channels it names, its colour and where it may go."""

    symbol: str
    channels: tuple[str, ...]
    colour: object
    tau: np.ndarray
    y: np.ndarray
    first: int

    @property
    def text(self) -> str:
        return f" {' '.join(self.channels)} {self.symbol}"


def _term_labels(found: list[tuple]) -> list[_TermLabel]:
    """The labels of the asymptotes drawn, ``found`` as ``(symbol, channel, colour, tau, y, first)``: the channels'
    lines of one term that lie within 30 % of each other where labelled share one label (``x y z N``, dark grey)."""
    out: list[_TermLabel] = []
    for symbol in dict.fromkeys(f[0] for f in found):
        rest = sorted((f for f in found if f[0] == symbol), key=lambda f: float(f[4][f[5]]))
        while rest:
            head, rest = rest[0], rest[1:]
            level = float(head[4][head[5]])
            near = [f for f in rest if abs(np.log(float(f[4][head[5]]) / level)) < np.log(1.3)]
            rest = [f for f in rest if all(f is not g for g in near)]
            group = sorted([head, *near], key=lambda g: next(i for i, f in enumerate(found) if f is g))
            out.append(_TermLabel(symbol, tuple(g[1] for g in group), head[2] if len(group) == 1 else "0.15",
                                  head[3], head[4], head[5]))  # on the lowest line of the group
    return out


def _place_term_labels(ax, labels: list[_TermLabel], lo: float, hi: float) -> list:
    """Each label on its line, at the first point (from where :func:`_term_label_at` puts it, then along the line
    toward shorter tau) where it overlaps no label placed before, the legend nor the axes' edges."""
    from align.present.figures import overlapping, text_boxes

    renderer = ax.figure.canvas.get_renderer()
    frame = ax.get_window_extent(renderer)
    legend = ax.get_legend()
    keep_out = [] if legend is None else [legend.get_window_extent(renderer)]
    placed: list = []
    for lab in labels:
        inside = [i for i in range(lab.first, -1, -1) if lo <= lab.y[i] <= hi]
        text = None
        for i in inside[::max(1, len(inside) // 40)]:
            if text is not None:
                text.remove()
            text = ax.text(lab.tau[i], float(lab.y[i]), lab.text, fontsize=7, color=lab.colour, va="center",
                           bbox={"boxstyle": "square,pad=0.1", "fc": "white", "alpha": 0.75, "lw": 0})
            (box,) = text_boxes([text], renderer, 1.0)
            clear = (frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1
                     and not any(box.overlaps(k) for k in keep_out))
            if clear and not overlapping(placed + [text], renderer, gap=2.0):
                break
        if text is not None:
            placed.append(text)
    return placed


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
    letter (``x N``, ``x B``, ...; one label ``x y z N`` for the channels' lines of a term that lie within
    30 % of each other), each label on its line where it overlaps no other label nor the legend.

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
    found: list = []  # the asymptotes drawn, labelled once the figure is laid out
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
            at = _term_label_at(y, lo, hi, t.alpha > 0 or t.key == "white")
            if at is not None:
                found.append((t.symbol, short, c, np.asarray(r.tau, float), np.asarray(y, float), at))
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
    _place_term_labels(ax, _term_labels(found), lo, hi)
    return png_bytes(fig)


# the segmentation picture lives in its own module; its names are kept here for callers of this one
from align.present.segplot import Span, segmentation_plot_png, segmentation_spans  # noqa: E402

__all__ = ["allan_plot_png", "allan_ylim", "segmentation_plot_png", "segmentation_spans", "Span"]
