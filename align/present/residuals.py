"""A calibration's residuals as every output shows them: one figure, one definition, one unit.

The terminal (:func:`align.present.text.calibration_summary`), the report's section
(:func:`align.present.calsection.calibration_section`) and summary, and the picture of a gyro session
(:func:`align.present.gyroplot.gyro_session_png`) all take the largest residual from :func:`largest`:

* a gyro calibrated from rotations between poses (``calibrate gyro``): the angle between the predicted and
  the measured gravity direction at the pose after each rotation, in degrees (the rotation table's
  ``residual_deg``; rotations left out of the fit are its held-out checks);
* an accelerometer's ``|a| = g`` fit: ``|a| - g`` at each attitude, one number per attitude, in the readings'
  unit (the file holds it as ``[r, 0, 0]``: :func:`is_scalar`);
* otherwise: reading minus model at each position, the largest component, in the readings' unit.

Public names
------------
Largest, largest, largest_rotation, held_out_rows, is_scalar, residual_values, ROTATION_RESIDUAL
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.errors import AlignError
from align.units import to_unit

#: what a gyro's rotation residual is
ROTATION_RESIDUAL = "angle between the predicted and the measured gravity direction at the next pose"


@dataclass(frozen=True)
class Largest:
    """The largest residual (or held-out check) of a calibration.

    Attributes
    ----------
    kind : {"residual", "held-out check"}
    where : str
        Its position, attitude or rotation (``"rotation 2"``).
    value : float
        In :attr:`unit` (absolute value).
    unit : str
        ``"deg"`` for a gyro's rotations, else the readings' unit (``"m/s^2"``, ``"counts"``).
    definition : str
        What the figure is, in words.
    count : str
        How many there are (``"37 rotations"``).
    """

    kind: str
    where: str
    value: float
    unit: str
    definition: str
    count: str

    @property
    def number(self) -> str:
        """``largest residual 0.0378 deg`` (the summary's number)."""
        return f"largest {self.kind} {self.value:.3g} {self.unit}"

    def text(self) -> str:
        """``largest residual: rotation 2, 0.0378 deg (angle between ...; 37 rotations)``."""
        return f"largest {self.kind}: {self.where}, {self.value:.3g} {self.unit} ({self.definition}; {self.count})"


def is_scalar(pool: dict) -> bool:
    """Whether residuals held as 3-vectors are one number each (every y and z exactly zero: the ``|a| = g`` fit).

    Examples
    --------
    >>> is_scalar({"attitude 1": [0.2, 0.0, 0.0], "attitude 2": [-1.7, 0.0, 0.0]}), is_scalar({"a": [0.2, 0.1, 0]})
    (True, False)
    """
    values = [np.asarray(v, float) for v in pool.values()]
    return bool(values) and all(v.shape == (3,) and v[1] == 0 and v[2] == 0 for v in values)


def residual_values(pool: dict, units: str) -> tuple[dict, str]:
    """``(position -> values in the unit shown, that unit)``: SI residuals in ``units`` (a unit or ``counts``; a
    count size such as ``16384 LSB/g`` shown in its dimension's unit)."""
    from align.present.figures import display_unit

    try:
        return {k: np.atleast_1d(to_unit(np.asarray(v, float), units)) for k, v in pool.items()}, units
    except AlignError:
        factor, shown = display_unit(units)
        return {k: np.atleast_1d(np.asarray(v, float) / factor) for k, v in pool.items()}, shown


def _count(n: int, first: str, gyro: bool) -> str:
    word = first.split()[0] if " " in first and first.split()[-1].isdigit() else ("rotation" if gyro else "position")
    return f"{n} {word}{'' if n == 1 else 's'}"


def largest_rotation(rotations, held_out: bool = False) -> Largest | None:
    """The largest residual of a gyro's rotation table (``rotation``, ``residual_deg``, ``used``, as the
    calibration file holds it), in degrees; with ``held_out``, of the rotations left out of the fit.

    Examples
    --------
    >>> largest_rotation([{"rotation": 1, "residual_deg": 0.02, "used": True},
    ...                   {"rotation": 2, "residual_deg": 0.04, "used": True}]).number
    'largest residual 0.04 deg'
    """
    rows = [r for r in rotations if bool(r.get("used", True)) != held_out]
    if not rows:
        return None
    big = max(rows, key=lambda r: abs(float(r["residual_deg"])))
    return Largest("held-out check" if held_out else "residual", f"rotation {big['rotation']}",
                   abs(float(big["residual_deg"])), "deg", ROTATION_RESIDUAL, _count(len(rows), "rotation 1", True))


def largest(cal, held_out: bool = False) -> Largest | None:
    """The largest residual of a calibration's fit (or, with ``held_out``, of its held-out checks); None when it
    has none.

    Parameters
    ----------
    cal : Calibration
        :class:`align.calibration.results.Calibration` (``residuals``, ``checks``, ``rotations``, ``units``,
        ``sensor``).
    held_out : bool
        The checks left out of the fit instead of the fit's residuals.

    Returns
    -------
    Largest or None
    """
    if getattr(cal, "rotations", None):
        return largest_rotation(cal.rotations, held_out)
    pool = dict(cal.checks if held_out else cal.residuals)
    if not pool:
        return None
    shown, unit = residual_values(pool, cal.units)
    where = max(shown, key=lambda k: float(np.max(np.abs(shown[k]))))
    scalar = is_scalar(pool)
    gyro = cal.sensor == "gyroscope"
    if scalar:
        definition = "|a| - g at the attitude" if cal.sensor == "accelerometer" else "the residual at the position"
    elif gyro and "turn" in str(cal.method).lower() and not where.startswith("rotation"):
        definition = "reading - model at the static faces, where the bias is fitted (M is fitted from the turns)"
    else:
        definition = "reading - model, the largest component"
    return Largest("held-out check" if held_out else "residual", where, float(np.max(np.abs(shown[where]))), unit,
                   definition, _count(len(pool), next(iter(pool)), gyro))


def held_out_rows(cal) -> list[tuple[str, float, str]]:
    """Each held-out check as ``(where, largest |value|, unit)``, by :func:`largest`'s definition (a gyro's left-out
    rotations in degrees, other checks in the readings' unit)."""
    rotations = getattr(cal, "rotations", None) or ()
    if rotations:
        return [(f"rotation {r['rotation']}", abs(float(r["residual_deg"])), "deg") for r in rotations
                if not r.get("used", True)]
    shown, unit = residual_values(dict(cal.checks), cal.units)
    return [(k, float(np.max(np.abs(v))), unit) for k, v in shown.items()]
