"""Figures of merit: each figure a test gives, with its name, unit, value, 1-sigma, method and test, and its verdict.

A :class:`Figure` is one line of a unit's figures-of-merit table (JSON, terminal, report): the key figure's
name (``phi_xy``, ``scale_x``, ``bias_x``, ``nonlinearity_x``: the names of
:mod:`align.production.keyfigures`, shared with the lot's table and a limits file), its standard title, the
sensor, the value and its 1-sigma in SI, the method and the test it came from, and, once judged against a limit
(:func:`align.limits.judge`), the limit as written and the verdict:

* ``PASS``: within the limit, and beyond its guard band;
* ``WARN``: within the limit, but inside the guard band (by default two of the figure's own 1-sigma: the
  measurement does not show conformance at 95 %, ISO 14253-1);
* ``FAIL``: outside the limit;
* ``NOT USABLE``: the figure's 1-sigma exceeds what its use needs (``sigma_max``): the test did not determine
  it well enough to be used, whatever its value;
* ``NOT CHECKED``: no value (a term the data could not identify, a figure of another unit) or no limit that
  applies; never counted as a pass;
* ``INFO``: shown without a limit.

Public names
------------
Figure, FIGURE_KEYS
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from align.vocab import Status

#: the keys of a figure written to a file, in order
FIGURE_KEYS = ("name", "sensor", "value", "sigma", "unit", "title", "method", "test", "status", "limit", "detail")


@dataclass(frozen=True)
class Figure:
    """One figure of merit of a unit (see the module docstring).

    Attributes
    ----------
    name : str
        The key figure's name (``"phi_xy"``, ``"scale_x"``, ``"nonlinearity_x"``).
    sensor : str
        ``"gyroscope"``, ``"accelerometer"`` or ``"magnetometer"``.
    value : float
        SI (rad, rad/s, m/s^2, T, a ratio), or counts when ``unit`` is ``"count"``; NaN: not determined.
    sigma : float
        1-sigma of ``value``, same unit; NaN: not stated.
    unit : str
        The unit of ``value`` and ``sigma`` (``"rad"``, ``"rad/s"``, ``"1"``, ``"count"``).
    title : str
        The figure's standard name (``"cross-axis misalignment"``, ``"scale-factor nonlinearity"``).
    method : str
        How it was found (``"least-squares line over 12 rates (IEEE Std 1431)"``).
    test : str
        The test (job) it came from (``"matrix"``, ``"calibrate accel"``).
    status : Status
        The verdict (INFO until judged).
    limit : str
        The limit it was judged against, as written (``"|phi_xy| <= 0.1 deg (limits.toml)"``); ``""``: none.
    detail : str
        One line on the verdict (the value against the limit, or why not checked).
    """

    name: str
    sensor: str
    value: float
    sigma: float = math.nan
    unit: str = "1"
    title: str = ""
    method: str = ""
    test: str = ""
    status: Status = field(default=Status.INFO)
    limit: str = ""
    detail: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "status", Status.parse(self.status))
        object.__setattr__(self, "value", float(self.value))
        object.__setattr__(self, "sigma", float(self.sigma))

    def to_dict(self) -> dict[str, Any]:
        """The figure as JSON values (NaN as null)."""
        out: dict[str, Any] = {}
        for k in FIGURE_KEYS:
            v = getattr(self, k)
            out[k] = (None if not math.isfinite(v) else v) if isinstance(v, float) else str(v)
        return out

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Figure:
        """The figure :meth:`to_dict` wrote."""
        def num(key: str) -> float:
            return math.nan if d.get(key) is None else float(d[key])

        def text(key: str) -> str:
            return str(d.get(key, "") or "")

        return cls(text("name"), text("sensor"), num("value"), num("sigma"), text("unit") or "1", text("title"),
                   text("method"), text("test"), Status.parse(text("status") or "INFO"), text("limit"), text("detail"))
