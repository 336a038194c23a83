"""What every picture shares: matplotlib on the Agg backend, PNG bytes, long traces drawn as envelopes, display units.

Public names
------------
pyplot, png_bytes, envelope, zigzag, trace, display_unit, COLOURS, COLUMNS
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
