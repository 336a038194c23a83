"""The unit of a log's readings: typed, stated by the file, or a sensor's default; and its temperature.

A unit becomes the factor to SI once, here (:func:`sensor_scale`); a unit the file states (a ULog, a bag)
is used without being asked for, and a typed unit that disagrees with it is refused (:func:`units_of`);
a temperature column is taken to degrees Celsius (:func:`celsius`).

Public names
------------
sensor_scale, units_of, celsius
"""

from __future__ import annotations

import numpy as np

from align.errors import InputError, UnitError, literal
from align.units import COUNT_EXAMPLES, DIMENSIONS, parse_scale, parse_unit, temperature_offset

__all__ = ["sensor_scale", "units_of", "celsius"]


def sensor_scale(units: str, expect: str | None, field: str = "units", counts: bool = False) -> tuple[float, str]:
    """The factor that takes a log's numbers to SI, and the unit its readings are shown in.

    Parameters
    ----------
    units : str
        A unit of ``expect`` (``"deg/s"``), the size of one count (``"0.0076336 deg/s"``) or a
        datasheet sensitivity (``"131 LSB/(deg/s)"``), or ``"counts"`` (see :func:`align.units.parse_scale`).
    expect : str or None
        A key of :data:`align.units.DIMENSIONS` (``"angular_rate"``, ``"acceleration"``,
        ``"magnetic_field"``, ``"counts"``); None: any unit.
    field : str
        The input that gave ``units``, for messages (``{gyro_units}``).
    counts : bool
        Whether readings may stay in raw counts; when not, ``"counts"`` is refused with the advice
        to give the size of one count.

    Returns
    -------
    factor : float
        Multiplies a number of the log into SI (or counts).
    shown : str
        The unit results show the readings in: ``units`` itself, or for a count size the dimension's
        unit (``deg/s``, ``m/s^2``, ``uT``).
    """
    where = "{" + field + "}"
    if expect is None or expect == "counts" or expect not in COUNT_EXAMPLES:
        return parse_unit(units, expect, where).factor, units
    factor, unit = parse_scale(units, expect, where)
    if not counts and parse_unit(unit).dim == DIMENSIONS["counts"][0].dim:
        size, sensitivity, part = COUNT_EXAMPLES[expect]
        what = DIMENSIONS[expect][1].split(",")[0]
        why = " (a gyro's M = g/w is dimensionless only then)" if expect == "angular_rate" else ""
        raise UnitError(f"'{literal(units)}' leaves the readings in raw counts, but they are needed as {what} here{why}; "
                        f"give the size of one count, e.g. {{{field}={size}}} or {{{field}={sensitivity}}} for {part}",
                        where)
    return factor, unit


def units_of(units: str | None, stated: str | None, default: str | None, expect: str | None, field: str,
              where: str) -> tuple[str, bool]:
    """The unit of the readings: the one given, else the file's, else ``default``; a given unit that disagrees
    with the file's is refused (a unit the file states is never asked for)."""
    if units is None:
        if stated is not None:
            return stated, True
        if default is None:
            raise InputError("the file does not state the unit of its readings; give it with {" + field + "}", where)
        return default, False
    if stated is not None:
        mine = parse_unit(stated).factor
        theirs = sensor_scale(units, expect, field, True)[0]
        if not np.isclose(mine, theirs, rtol=1e-9):
            raise InputError(f"the file states its readings in {stated}, and {{{field}}} says '{literal(units)}'; "
                             f"leave {{{field}}} out", where)
    return units, False


def celsius(values: np.ndarray, unit: str | None, where: str) -> np.ndarray:
    """A temperature column in degrees Celsius (its unit given, else stated, else Celsius), checked for a
    reading no sensor makes (below absolute zero, above 300 C)."""
    scale, offset = temperature_offset(unit or "degC", "{temperature_units}")
    c = values * scale + offset
    finite = c[np.isfinite(c)]
    if finite.size and (finite.min() < -273.15 or finite.max() > 300.0):
        raise InputError(f"temperature from {finite.min():.6g} to {finite.max():.6g} C is no sensor's; check "
                         "{temperature_units} (degC, K or degF) and {temperature_column}", where)
    return c
