"""What every picture shares: matplotlib on the Agg backend, PNG bytes, long traces drawn as envelopes, display units.

Public names
------------
pyplot, png_bytes, envelope, zigzag, trace, display_unit, place_labels, text_boxes, overlapping, COLOURS, COLUMNS
"""

from __future__ import annotations

import io

import numpy as np

from align.errors import AlignError
from align.units import parse_scale, parse_unit

#: line colours of the x, y and z channels (and of further channels)
COLOURS = ("tab:red", "tab:green", "tab:blue", "tab:purple", "tab:orange", "tab:brown")
#: drawing resolution: longer traces are reduced to a min/max envelope over this many columns
COLUMNS = 2000


def pyplot():
    """``matplotlib.pyplot`` on the Agg backend (no display needed), imported on first use."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def png_bytes(fig, dpi: int = 110) -> bytes:
    """The figure as PNG bytes (tight bounding box); the figure is closed."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    pyplot().close(fig)
    return buf.getvalue()


def envelope(t: np.ndarray, y: np.ndarray, columns: int = COLUMNS) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``y`` (n, k) reduced for drawing: each of ``columns`` equal runs of samples becomes its middle
    time, minimum and maximum (shapes (columns,), (columns, k), (columns, k)); short traces as they are."""
    n = len(t)
    if n <= 2 * columns:
        return t, y, y
    edges = np.linspace(0, n, columns + 1).astype(np.intp)
    lo = np.minimum.reduceat(y, edges[:-1], axis=0)
    hi = np.maximum.reduceat(y, edges[:-1], axis=0)
    return t[(edges[:-1] + edges[1:] - 1) // 2], lo, hi


def zigzag(x: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One line through each column's minimum and maximum (a filled envelope at pixel resolution)."""
    y = np.empty((2 * len(x), lo.shape[1]))
    y[0::2], y[1::2] = lo, hi
    return np.repeat(x, 2), y


def trace(t: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(x, y)`` to draw a trace (n, k) of any length: as it is, or as its min/max envelope."""
    x, lo, hi = envelope(t, y)
    return (x, lo) if len(x) == len(t) else zigzag(x, lo, hi)


def display_unit(units: str, dimensions: tuple[str, ...] = ("acceleration", "magnetic_field", "angular_rate")
                 ) -> tuple[float, str]:
    """``(factor, label)``: SI values divided by ``factor`` read in the unit ``label``.

    ``units`` is a unit (``"m/s^2"``, ``"uT"``, ``"counts"``) or the size of one count / a datasheet
    sensitivity (``"16384 LSB/g"``: the readings are SI after reading, shown in the dimension's unit,
    ``m/s^2``), tried against each of ``dimensions`` in turn; anything else is shown in SI.
    """
    try:
        return parse_unit(units).factor, units
    except AlignError:
        pass
    for dim in dimensions:
        try:
            _, shown = parse_scale(units, dim)
            return parse_unit(shown).factor, shown
        except AlignError:
            continue
    return 1.0, "SI"


def text_boxes(artists, renderer=None, pad: float = 1.0) -> list:
    """The drawn extent (display pixels, widened by ``pad`` on every side) of each visible, non-empty text."""
    from matplotlib.transforms import Bbox

    out = []
    for a in artists:
        if not a.get_visible() or not a.get_text().strip():
            continue
        fig = a.get_figure()
        b = a.get_window_extent(renderer or fig.canvas.get_renderer())
        out.append(Bbox.from_extents(b.x0 - pad, b.y0 - pad, b.x1 + pad, b.y1 + pad))
    return out


def overlapping(artists, renderer=None, gap: float = 0.0) -> list[tuple[int, int]]:
    """Pairs ``(i, j)`` of the visible, non-empty texts among ``artists`` whose drawn extents overlap, or come closer
    than ``gap`` pixels."""
    boxes = text_boxes(artists, renderer, pad=gap / 2)
    return [(i, j) for i in range(len(boxes)) for j in range(i + 1, len(boxes))
            if boxes[i].x0 < boxes[j].x1 and boxes[j].x0 < boxes[i].x1
            and boxes[i].y0 < boxes[j].y1 and boxes[j].y0 < boxes[i].y1]


def place_labels(ax, xs, variants: list[list[str]], y: float = 1.0, va: str = "bottom", rows: int = 2,
                 step_pt: float = 8.0, **style) -> tuple[list, int]:
    """Labels at data ``xs`` along a horizontal line of ``ax`` (``y`` in axes fraction) that do not overlap.

    Tried in order, the first that fits is kept: each variant of the texts (``variants``, the richest first,
    e.g. number, turn and residual, then the number alone), in one row, then staggered over up to ``rows`` rows
    (each ``step_pt`` points further from the line, away from the axes when ``va="bottom"``, into it when
    ``"top"``); then every 2nd, 3rd, ... label of the plainest variant. Labels fit when no two come closer than
    0.4 of the font size. The figure's layout must be final (measured in its pixels).

    Parameters
    ----------
    ax : matplotlib Axes
    xs : sequence of float
        Data x of each label.
    variants : list of list of str
        Each a text per label.
    y : float
        Axes fraction of the line.
    va : {"bottom", "top"}
        Labels above the line (``bottom``) or hanging below it (``top``).
    rows : int
        Most staggered rows.
    step_pt : float
        Least distance between rows, points (at least a label's height).
    style
        Passed to ``annotate`` (``fontsize``, ``color``).

    Returns
    -------
    (list of Text, int)
        The labels drawn, and the stride (1: every label; 3: every 3rd).
    """
    renderer = ax.figure.canvas.get_renderer()
    n = len(xs)
    sign = 1.0 if va == "bottom" else -1.0
    tries = [(texts, r, 1) for texts in variants for r in range(1, rows + 1)]
    tries += [(variants[-1], rows, k) for k in range(2, max(n, 2) + 1)]
    drawn: list = []
    step = step_pt
    gap = 0.4 * style.get("fontsize", 8)  # points
    for texts, r, stride in tries:
        for a in drawn:
            a.remove()
        keep = list(range(0, n, stride))
        drawn = [ax.annotate(texts[i], (xs[i], y), xycoords=("data", "axes fraction"), ha="center", va=va,
                             xytext=(0.0, sign * step * (m % r)), textcoords="offset points", **style)
                 for m, i in enumerate(keep)]
        if not overlapping(drawn, renderer, gap=gap * ax.figure.dpi / 72.0):
            return drawn, stride
        if r == 1:  # the next rows a label's height apart
            step = max(step_pt, max(b.height for b in text_boxes(drawn, renderer, 0.0)) * 72.0 / ax.figure.dpi + gap + 1.0)
    return drawn, n
