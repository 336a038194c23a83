"""PNG plots of results (matplotlib, Agg backend, imported on first use).

Public names
------------
allan_plot_png, allan_ylim, segmentation_plot_png, segmentation_spans, Span
"""

from __future__ import annotations

import io
import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from align.errors import InputError
from align.io import check_log
from align.noise.job import AllanJob
from align.noise.model import TERM_TABLE
from align.units import DEG_S, parse_unit, to_unit

#: line colours of successive channels
_COLOURS = ("tab:red", "tab:green", "tab:blue", "tab:purple", "tab:orange", "tab:brown")
#: line styles of the five single-term asymptotes (Q, N, B, K, R)
_TERM_STYLES = (":", "-.", ":", "-.", ":")


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


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
    names = [str(n) for n in names]
    if len(names) < 2:
        return names
    pre = len(os.path.commonprefix(names))
    suf = len(os.path.commonprefix([n[::-1] for n in names]))
    short = [n[pre : len(n) - suf] for n in names]
    return short if all(short) and len(set(short)) == len(short) else names


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
    plt = _pyplot()
    r = job.result
    shown = "deg/h" if job.sensor == "gyroscope" else "ug"
    fig, ax = plt.subplots(figsize=(7.5, 5))
    lo, hi = allan_ylim(job, shown, target)
    level = None if target is None else float(to_unit(target, shown))
    runs_styles = ("-", "--", "-.", ":")
    for k, rr in enumerate(job.run_results):
        style = runs_styles[k % len(runs_styles)]
        for j in range(len(r.names)):
            ax.loglog(rr.tau, to_unit(rr.adev[j], shown), color=_COLOURS[j % len(_COLOURS)], lw=0.7, alpha=0.7, ls=style)
        name = Path(job.inputs[k]).name if k < len(job.inputs) else ""
        ax.plot([], [], color="0.4", lw=0.7, ls=style, label=f"run {k + 1} {name}".rstrip())
    for j, (name, short, f) in enumerate(zip(r.names, _short_names(r.names), job.fits)):
        c = _COLOURS[j % len(_COLOURS)]
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
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


# ---------------------------------------------------------------- the segmentation of an alignment log

#: colours (and hatch) of the spans of a segmentation picture, by kind
_SPAN_STYLE = {
    "step": {"facecolor": "#f6c343", "alpha": 0.35, "label": "plan step (dwell or turn)"},
    "static": {"facecolor": "#8fd1c4", "alpha": 0.35, "label": "static period"},
    "motion": {"facecolor": "#d9c2ec", "edgecolor": "#7b3f9e", "hatch": "///", "alpha": 0.55,
               "label": "motion no step claimed (ignored)"},
    "ramp": {"facecolor": "0.80", "alpha": 0.45, "label": "ramp (moving, not used)"},
}
#: drawing resolution: samples are reduced to a min/max envelope over this many columns
_COLUMNS = 2000
_STEP_NAME = re.compile(r"^step (\d+) \((.*)\)$")


@dataclass(frozen=True)
class Span:
    """A stretch of the log the segmentation picture shades.

    Attributes
    ----------
    kind : {"step", "static", "motion", "ramp"}
    label : str
        Short label drawn for it (empty for static periods and ramps).
    t_start, t_end : float
        s.
    name : str
        The segment's or motion's name (empty for ramps).
    """

    kind: str
    label: str
    t_start: float
    t_end: float
    name: str = ""


def _short(text: str) -> str:
    """``"+y at 100 deg/s"`` -> ``"+y 100 deg/s"``."""
    return text.replace(" at ", " ").replace(" through ", " ")


def _step_label(name: str) -> str:
    """``"step 3 (+y at 100 deg/s)"`` -> ``"3: +y 100 deg/s"``; other names (explicit segments) as they are."""
    m = _STEP_NAME.match(name)
    return f"{m.group(1)}: {_short(m.group(2))}" if m else name


def _motion_label(label: str) -> str:
    """``"+z through 90 deg"`` -> ``"ignored: about +z 90 deg"``."""
    text = label if label.startswith("about") else f"about {label}"
    return f"ignored: {_short(text)}"


def _moving(t: np.ndarray, g: np.ndarray, bias: np.ndarray) -> np.ndarray:
    """Samples where the table moves, shape (n,) bool: ``|mean(g - b)|`` over 0.1 s (``w`` samples, rad/s)
    exceeds ``6 |sigma| / sqrt(w) + 0.05 deg/s``, ``sigma`` (3,) the per-sample noise of each gyro
    (:func:`align.alignment.segment.noise_sigma`) and ``b`` (3,) the estimated bias."""
    from align.alignment.segment import noise_sigma

    n = len(t)
    fs = 1.0 / float(np.median(np.diff(t)))
    w = int(min(max(3, round(0.1 * fs)), max(1, n // 4)))
    c = np.cumsum(np.vstack([np.zeros((1, 3)), g - bias]), axis=0)
    mean = (c[w:] - c[:-w]) / w                                   # mean[k] = mean of samples k..k+w-1
    level = np.zeros(n)
    level[w // 2: w // 2 + len(mean)] = np.linalg.norm(mean, axis=1)
    level[: w // 2], level[w // 2 + len(mean):] = level[w // 2], level[w // 2 + len(mean) - 1]
    threshold = 6.0 * float(np.linalg.norm(noise_sigma(g))) / np.sqrt(w) + 0.05 * DEG_S
    return level > threshold


def segmentation_spans(t: np.ndarray, g: np.ndarray, result) -> list[Span]:
    """What :func:`segmentation_plot_png` shades, in time order.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Time, s.
    g : ndarray, shape (n, 3)
        Gyro readings, rad/s (the log the result came from).
    result : AlignmentResult

    Returns
    -------
    list of Span
        One per plan step segment (kind ``"rate"`` or ``"angle"`` -> ``"step"``), per static period,
        per motion no step claimed (``result.motions``) and per ramp: a run of moving samples
        (:func:`_moving`) inside no segment or motion, runs closer than 0.1 s joined.
    """
    spans = [Span("static" if s.kind == "static" else "step", "" if s.kind == "static" else _step_label(s.name),
                  float(s.t_start), float(s.t_end), s.name) for s in result.segments]
    spans += [Span("motion", _motion_label(m.label), float(m.t_start), float(m.t_end), m.name) for m in result.motions]
    n = len(t)
    free = _moving(t, g, result.bias)
    for a, b in [(s.start, s.end) for s in result.segments] + [(m.start, m.end) for m in result.motions]:
        free[max(a, 0): min(b, n)] = False
    edges = np.flatnonzero(np.diff(np.concatenate(([0], free.view(np.int8), [0]))))
    runs: list[list[int]] = []
    join = max(1, int(round(0.1 / float(np.median(np.diff(t))))))
    for a, b in zip(edges[::2].tolist(), edges[1::2].tolist()):
        if runs and a - runs[-1][1] <= join and not _claimed(result, runs[-1][1], a):
            runs[-1][1] = b
        else:
            runs.append([a, b])
    spans += [Span("ramp", "", float(t[a]), float(t[min(b, n - 1)])) for a, b in runs if b - a >= 2]
    return sorted(spans, key=lambda s: (s.t_start, s.t_end))


def _claimed(result, a: int, b: int) -> bool:
    """Whether a segment or motion lies between samples ``a`` and ``b`` (two ramps must not be joined across it)."""
    return any(a <= s.start < b for s in (*result.segments, *result.motions))


def _envelope(t: np.ndarray, y: np.ndarray, columns: int = _COLUMNS) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``y`` (n, k) reduced for drawing: each of ``columns`` equal runs of samples becomes its middle
    time, minimum and maximum (shapes (columns,), (columns, k), (columns, k)); short logs as they are."""
    n = len(t)
    if n <= 2 * columns:
        return t, y, y
    edges = np.linspace(0, n, columns + 1).astype(np.intp)
    lo = np.minimum.reduceat(y, edges[:-1], axis=0)
    hi = np.maximum.reduceat(y, edges[:-1], axis=0)
    return t[(edges[:-1] + edges[1:] - 1) // 2], lo, hi


def _zigzag(x: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One line through each column's minimum and maximum (a filled envelope at pixel resolution)."""
    y = np.empty((2 * len(x), lo.shape[1]))
    y[0::2], y[1::2] = lo, hi
    return np.repeat(x, 2), y


def _tiers(labels: list[tuple[float, float, str]], px_per_s: float, width_px, bounds: tuple[float, float],
           most: int = 4) -> list[tuple[int, str, float]]:
    """Rows for the labels so that none overlaps another or leaves the axes: (start, end, text) -> (row, text, left).

    ``width_px(text)`` is the text's width in pixels, ``px_per_s`` the horizontal scale and ``bounds``
    the time axis' limits (s). A label centred on its span that fits in none of ``most`` rows is cut to
    its step number, then put in the row that ends first.
    """
    ends: list[float] = []
    pad, edge = 14.0 / px_per_s, 3.0 / px_per_s
    out = []
    for a, b, text in labels:
        for candidate in dict.fromkeys((text, text.split(":")[0])):
            width = width_px(candidate) / px_per_s
            left = min(max(0.5 * (a + b) - width / 2, bounds[0] + edge), bounds[1] - edge - width)
            row = next((k for k, e in enumerate(ends) if e + pad <= left), None)
            if row is None and len(ends) < most:
                row = len(ends)
                ends.append(-np.inf)
            if row is not None:
                break
        if row is None:
            row = int(np.argmin(ends))
        ends[row] = left + width
        out.append((row, candidate, left))
    return out


def _bands(ax, spans: list[Span], kind: str, legend: bool = True) -> None:
    """Shade the spans of one kind over the whole height of ``ax``."""
    from matplotlib.collections import PolyCollection

    style = dict(_SPAN_STYLE[kind])
    label = style.pop("label")
    verts = [[(s.t_start, 0), (s.t_start, 1), (s.t_end, 1), (s.t_end, 0)] for s in spans if s.kind == kind]
    if verts:
        ax.add_collection(PolyCollection(verts, transform=ax.get_xaxis_transform(), linewidth=0, zorder=0,
                                         label=label if legend else None, **style), autolim=False)


def segmentation_plot_png(t: np.ndarray, g: np.ndarray, result, units: str = "deg/s") -> bytes:
    """The segmentation of a rate-table log: gyro traces, plan steps, static periods, ignored motions, ramps.

    Top: one labelled bar per plan step and per motion no step claimed, in rows so that no label overlaps.
    Middle: the three gyro traces in ``units``. Bottom: ``|g_i|`` on a log scale, so that a static
    period (bias and noise) reads as well as a 100 deg/s dwell. Every panel is shaded by
    :func:`segmentation_spans`; logs longer than 4000 samples are drawn as a min/max envelope per
    column (a 1e6-sample log takes well under a second).

    Parameters
    ----------
    t : ndarray, shape (n,)
        Time, s, increasing.
    g : ndarray, shape (n, 3)
        Gyro readings, rad/s, the log ``result`` was computed from.
    result : AlignmentResult
    units : str
        Rate unit of the traces.

    Returns
    -------
    bytes
        The PNG file (deterministic for given inputs).

    Raises
    ------
    InputError
        For arrays of other shapes, a log that is not one (:func:`align.io.check_log`) or a unit that is not a rate.
    """
    t, g = np.asarray(t, float), np.asarray(g, float)
    if t.ndim != 1 or g.shape != (len(t), 3):
        raise InputError(f"time of shape {t.shape} and gyro readings of shape {g.shape}: expected (n,) and (n, 3)",
                         "segmentation picture")
    check_log(t, g, "segmentation picture")
    scale = parse_unit(units, "angular_rate", "{gyro_units}").factor
    spans = segmentation_spans(t, g, result)
    plt = _pyplot()
    from matplotlib.font_manager import FontProperties
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    dpi, width_in, left, right = 110, 12.0, 0.075, 0.985
    fig = plt.figure(figsize=(width_in, 7.0), dpi=dpi)
    renderer = fig.canvas.get_renderer()
    font = FontProperties(size=9)
    px_per_s = width_in * dpi * (right - left) / max(float(t[-1] - t[0]), 1e-9)
    named = [(s.t_start, s.t_end, s.label) for s in spans if s.kind in ("step", "motion")]
    rows = _tiers(named, px_per_s, lambda s: renderer.get_text_width_height_descent(s, font, ismath=False)[0] + 2,
                  (float(t[0]), float(t[-1])))
    n_rows = max([r for r, _, _ in rows], default=0) + 1
    grid = fig.add_gridspec(3, 1, height_ratios=[0.28 * (n_rows + 1), 3.0, 1.7], hspace=0.08,
                            left=left, right=right, top=0.95, bottom=0.1)
    strip = fig.add_subplot(grid[0])
    ax = fig.add_subplot(grid[1], sharex=strip)
    lg = fig.add_subplot(grid[2], sharex=strip)
    x, lo, hi = _envelope(t, np.column_stack([g / scale, np.abs(g) / scale]))
    tx, trace = (x, lo[:, :3]) if len(x) == len(t) else _zigzag(x, lo[:, :3], hi[:, :3])
    mag = hi[:, 3:]                                 # |g_i|: the largest of each column
    top = float(mag.max()) or 1.0
    floor = max(float(np.percentile(mag, 1)) / 3, top * 1e-6)
    for j, c in enumerate(_COLOURS[:3]):
        ax.plot(tx, trace[:, j], color=c, lw=0.7)
        lg.plot(x, np.maximum(mag[:, j], floor), color=c, lw=0.8)
    lg.set_yscale("log")
    lg.set_ylim(floor, top * 3)
    for a in (strip, ax, lg):
        for kind in ("ramp", "static", "step", "motion"):
            _bands(a, spans, kind, legend=a is ax)
    for (row, text, x0), s in zip(rows, [s for s in spans if s.kind in ("step", "motion")]):
        y = n_rows - row - 0.5
        strip.plot([s.t_start, s.t_end], [y, y], color="#b8860b" if s.kind == "step" else "#7b3f9e", lw=2.5,
                   solid_capstyle="butt")
        strip.text(x0, y + 0.08, text, fontproperties=font, ha="left", va="bottom",
                   bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "none", "pad": 0.5})
    strip.set_ylim(0, n_rows + 0.3)
    strip.set_yticks([])
    strip.tick_params(labelbottom=False)
    ax.tick_params(labelbottom=False)
    ax.axhline(0.0, color="0.4", lw=0.5)
    ax.set_ylabel(f"gyro [{units}]")
    lg.set_ylabel(f"|gyro| [{units}]")
    lg.set_xlabel("time [s]")
    lg.set_xlim(float(t[0]), float(t[-1]))
    for a in (ax, lg):
        a.grid(True, which="major", alpha=0.3)
    count = {k: sum(s.kind == k for s in spans) for k in _SPAN_STYLE}
    strip.set_title(f"Segmentation of {len(t):,} samples: " + ", ".join(_count(count[k], *words) for k, words in (
        ("step", ("plan step", "plan steps")), ("static", ("static period", "static periods")),
        ("motion", ("motion no step claimed", "motions no step claimed")), ("ramp", ("ramp", "ramps")))), fontsize=9)
    handles = [Line2D([], [], color=c, lw=1.2, label=f"gyro {'xyz'[j]}") for j, c in enumerate(_COLOURS[:3])]
    handles += [Patch(**st) for k, st in _SPAN_STYLE.items() if count[k]]
    lg.legend(handles=handles, loc="upper center", ncol=len(handles), fontsize=9, frameon=False,
              bbox_to_anchor=(0.5, -0.32))
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


def _count(k: int, one: str, many: str) -> str:
    return f"{k} {one if k == 1 else many}"
