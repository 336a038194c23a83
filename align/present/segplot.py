"""The picture of a rate-table log's segmentation: gyro traces, plan steps, static periods, ignored motions, ramps.

Public names
------------
segmentation_plot_png, segmentation_spans, Span
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

import numpy as np

from align.errors import InputError
from align.io import check_log
from align.present.figures import COLOURS, envelope, png_bytes, pyplot, zigzag
from align.units import DEG_S, parse_unit

#: colours (and hatch) of the spans of a segmentation picture, by kind
_SPAN_STYLE: dict[str, dict[str, Any]] = {
    "step": {"facecolor": "#f6c343", "alpha": 0.35, "label": "plan step (dwell or turn)"},
    "static": {"facecolor": "#8fd1c4", "alpha": 0.35, "label": "static period"},
    "motion": {"facecolor": "#d9c2ec", "edgecolor": "#7b3f9e", "hatch": "///", "alpha": 0.55,
               "label": "motion that no step claimed (ignored)"},
    "ramp": {"facecolor": "0.80", "alpha": 0.45, "label": "ramp (moving, not used)"},
}
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
    plt = pyplot()
    from matplotlib.artist import Artist
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
    x, lo, hi = envelope(t, np.column_stack([g / scale, np.abs(g) / scale]))
    tx, trace = (x, lo[:, :3]) if len(x) == len(t) else zigzag(x, lo[:, :3], hi[:, :3])
    mag = hi[:, 3:]                                 # |g_i|: the largest of each column
    top = float(mag.max()) or 1.0
    floor = max(float(np.percentile(mag, 1)) / 3, top * 1e-6)
    for j, c in enumerate(COLOURS[:3]):
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
        ("motion", ("motion that no step claimed", "motions that no step claimed")), ("ramp", ("ramp", "ramps")))
        if count[k] or k == "step"), fontsize=9)  # kinds that are absent are left out (no "0 motions")
    handles: list[Artist] = [Line2D([], [], color=c, lw=1.2, label=f"gyro {'xyz'[j]}") for j, c in enumerate(COLOURS[:3])]
    handles += [Patch(**st) for k, st in _SPAN_STYLE.items() if count[k]]
    lg.legend(handles=handles, loc="upper center", ncol=len(handles), fontsize=9, frameon=False,
              bbox_to_anchor=(0.5, -0.32))
    return png_bytes(fig, dpi)


def _count(k: int, one: str, many: str) -> str:
    return f"{k} {one if k == 1 else many}"
