"""Plausibility: what physics allows a sensor's readings and a result's matrix to be.

A log read in the wrong unit is still a log of numbers; only physics tells.
At rest an accelerometer reads local gravity (9.78-9.83 m/s^2 on Earth), a
magnetometer Earth's field (20-70 uT), a gyro the table's rate (checked against
the plan by :func:`align.units.unit_mixup_hint`). When readings miss what
physics allows by about a unit factor (g read as m/s^2: 1/9.81; gauss read as
uT: 1/100), the refusal names the mix-up and the fix as a placeholder
(``{units=g}``); readings in counts are exempt, their scale is what a
calibration measures. A matrix that is to correct a log must be finite,
invertible and right-handed (``det > 0``, reference section 1); an
accelerometer calibrated from known orientations must read each axis on that
axis (a flipped axis or swapped positions is a handedness error). Whether a
result file is well formed is :mod:`align.wellformed`.

Public names
------------
check_gravity, check_at_rest, check_static_rates, check_field_strength, check_known_field, check_corrected, check_dip, check_axes,
check_scale_factors, scale_outside,
check_usable_model, check_positive_definite, mixup_hint,
ACCELERATION_UNITS, FIELD_UNITS, GRAVITY_RANGE, EARTH_FIELD, FIELD_RANGE, AT_REST_RANGE, MAX_CONDITION
"""

from __future__ import annotations

import math

import numpy as np

from align.errors import HandednessError, InputError, TestError, literal
from align.model import AXES
from align.units import DEG, DIMENSIONS, STANDARD_GRAVITY, parse_quantity, parse_unit, to_unit

#: units an acceleration log is commonly written in (the candidates of a mix-up)
ACCELERATION_UNITS = ("m/s^2", "g", "mg")
#: units a magnetometer log is commonly written in
FIELD_UNITS = ("uT", "nT", "mG", "gauss", "mT", "T")
#: local gravity anywhere on Earth's surface, with a margin, m/s^2 (9.764 on the highest peaks, 9.834 at the poles)
GRAVITY_RANGE = (9.7, 9.9)
#: Earth's field strength, T (20 uT near the magnetic equator, 70 uT near the poles)
EARTH_FIELD = (20e-6, 70e-6)
#: field strengths accepted as a magnetometer capture, T (Earth's with a factor of 2 either side for local iron)
FIELD_RANGE = (10e-6, 140e-6)
#: mean |a| at rest over local gravity accepted for an accelerometer in physical units
AT_REST_RANGE = (0.5, 2.0)
#: the largest mean rate a gyro at rest may read, rad/s (MEMS zero-rate offsets reach +/-20-30 deg/s; 50 deg/s)
STATIC_RATE_MAX = 50 * math.pi / 180
#: condition number beyond which a matrix is not a usable correction
MAX_CONDITION = 1e8


def _num(x: float) -> str:
    """A measured number for a message: 3 significant digits, no numpy repr."""
    return f"{float(x):#.3g}".rstrip(".")


def _declared_factor(units: str, expect: str) -> float | None:
    """The SI factor of the declared unit of readings, or None when they are counts (exempt)."""
    if units[:1].isdigit() or units[:1] == ".":  # the size of one count: readings were scaled to SI
        return parse_quantity(units, expect)
    unit = parse_unit(units)
    return unit.factor if unit.dim == DIMENSIONS[expect][0].dim else None


def mixup_hint(measured_si: float, units: str, expect: str, candidates: tuple[str, ...], plausible: tuple[float, float],
               field: str) -> str | None:
    """The unit mix-up that would put a measured value where physics allows it.

    Parameters
    ----------
    measured_si : float
        The value as read with the declared unit, SI.
    units : str
        The declared unit of the readings (a unit of ``expect``).
    expect : str
        The dimension, a key of :data:`align.units.DIMENSIONS`.
    candidates : tuple of str
        Units the readings may really be in (:data:`ACCELERATION_UNITS`, :data:`FIELD_UNITS`).
    plausible : (float, float)
        What physics allows, SI.
    field : str
        The library input holding the unit, for the placeholder of the fix.

    Returns
    -------
    str or None
        ``"the log looks like g read as m/s^2; set {units=g}"``, or None when no
        candidate puts the value inside ``plausible`` (the one nearest the middle wins).
    """
    factor = _declared_factor(units, expect)
    if factor is None or not measured_si > 0:
        return None
    lo, hi = plausible
    raw = measured_si / factor
    fits = [(abs(math.log(raw * parse_unit(c).factor / math.sqrt(lo * hi))), c) for c in candidates
            if c != units and lo <= raw * parse_unit(c).factor <= hi]
    if not fits:
        return None
    best = min(fits)[1]
    return f"the log looks like {best} read as {literal(units)}; set {{{field}={best}}}"


def check_gravity(gravity: float, where: str = "{gravity}") -> float:
    """Refuse a local gravity that is not finite, not positive or not Earth's (:data:`GRAVITY_RANGE`).

    Parameters
    ----------
    gravity : float
        m/s^2.
    where : str
        The input: a placeholder (``"{gravity}"``) or a file field (``"positions.toml: gravity"``).

    Returns
    -------
    float
        ``gravity``, checked.
    """
    lo, hi = GRAVITY_RANGE
    if not (isinstance(gravity, (int, float)) and math.isfinite(gravity) and gravity > 0):
        shown = _num(gravity) if isinstance(gravity, (int, float)) else literal(repr(gravity))
        raise InputError(f"local gravity must be a positive acceleration, not {shown} m/s^2 "
                         "(9.78-9.83 m/s^2 on Earth; standard gravity is 9.80665 m/s^2)", where)
    if not lo <= gravity <= hi:
        raise InputError(f"local gravity {gravity:.6g} m/s^2 is not Earth's ({lo:g}-{hi:g} m/s^2); "
                         "give it in m/s^2, e.g. '9.81 m/s^2'", where)
    return float(gravity)


def check_at_rest(norms: np.ndarray, gravity: float, units: str, field: str = "units", where: str | None = None,
                  over: str = "at rest") -> None:
    """Refuse accelerometer readings at rest whose mean ``|a|`` is not local gravity (a unit mix-up).

    Parameters
    ----------
    norms : ndarray, shape (k,)
        ``|a|`` of readings (or of static means) at rest, SI, read with ``units``.
    gravity : float
        Local gravity, m/s^2.
    units : str
        The declared unit of the readings; counts are exempt.
    field : str
        The library input holding ``units`` (the placeholder of the fix).
    where : str, optional
        The log, for the message.
    over : str
        What the mean is over, for the message.

    Raises
    ------
    TestError
        ``mean |a| at rest is 1.00 m/s^2, gravity is 9.81 m/s^2: the log looks like g read as m/s^2; set {units=g}``.
    """
    if _declared_factor(units, "acceleration") is None:
        return
    mean = float(np.mean(norms)) if len(norms) else 0.0
    lo, hi = AT_REST_RANGE
    if lo * gravity <= mean <= hi * gravity:
        return
    said = f"mean |a| {over} is {_num(mean)} m/s^2, gravity is {_num(gravity)} m/s^2"
    hint = mixup_hint(mean, units, "acceleration", ACCELERATION_UNITS, (lo * gravity, hi * gravity), field)
    if hint is None:
        hint = (f"not a known unit mix-up: check {{{field}}} and the columns (an accelerometer at rest reads gravity)"
                if mean > 0 else f"the readings are zero: check the columns and {{{field}}}")
    raise TestError(f"{said}: {hint}", where)


def check_static_rates(means: np.ndarray, units: str, names: list[str], field: str = "gyro_units",
                       where: str | None = None) -> None:
    """Refuse a static gyro record whose mean rate on a channel no gyro at rest reads (raw counts read as a rate).

    Parameters
    ----------
    means : ndarray, shape (C,)
        Mean reading of each channel, rad/s, read with ``units``.
    units : str
        The declared unit of the readings (a rate unit, or a count size).
    names : list of str
        Channel names, C of them.
    field : str
        The library input holding ``units`` (the placeholder of the fix).
    where : str, optional
        The record, for the message.

    Raises
    ------
    TestError
        ``channel gx reads -428 deg/s on average, beyond the 50 deg/s any MEMS gyro at rest reads: ...``.
    """
    big = np.flatnonzero(~(np.abs(np.asarray(means, float)) <= STATIC_RATE_MAX))
    if not len(big):
        return
    j = int(big[0])
    said = (f"channel {literal(names[j])} reads {_num(means[j] * 180 / math.pi)} deg/s on average, beyond the "
            f"{_num(STATIC_RATE_MAX * 180 / math.pi)} deg/s any MEMS gyro at rest reads")
    raise TestError(f"{said}: raw counts read as {literal(units)}? give the size of one count, e.g. "
                    f"{{{field}=131 LSB/(deg/s)}} for an MPU-6050 at +/-250 deg/s (or the record is not static)", where)


def check_field_strength(strength: float, units: str, field: str = "units", where: str | None = None) -> None:
    """Refuse magnetometer readings whose field strength is not Earth's (a unit mix-up).

    Parameters
    ----------
    strength : float
        Field strength of the readings as read with ``units`` (the radius of their ellipsoid), SI (T).
    units : str
        The declared unit of the readings; counts are exempt.
    field : str
        The library input holding ``units``.
    where : str, optional
        The log, for the message.

    Raises
    ------
    TestError
        ``the readings' field strength is 0.310 uT, Earth's field is 20-70 uT: the log looks like gauss read as uT;
        set {units=gauss}``.
    """
    if _declared_factor(units, "magnetic_field") is None or FIELD_RANGE[0] <= strength <= FIELD_RANGE[1]:
        return
    said = (f"the readings' field strength is {_num(to_unit(strength, 'uT'))} uT, Earth's field is "
            f"{EARTH_FIELD[0] * 1e6:g}-{EARTH_FIELD[1] * 1e6:g} uT")
    hint = mixup_hint(strength, units, "magnetic_field", FIELD_UNITS, FIELD_RANGE, field) or \
        f"not a known unit mix-up: check {{{field}}} and the columns, and keep the device away from iron and magnets"
    raise TestError(f"{said}: {hint}", where)


def check_known_field(known: float, strength: float, units: str, field: str = "units") -> None:
    """Refuse a known field strength that is not Earth's, or not the readings' (within a factor of 2).

    Parameters
    ----------
    known : float
        The field strength given, same unit as the readings (SI or counts).
    strength : float
        The readings' own field strength, same unit.
    units : str
        The declared unit of the readings (counts: only the factor of 2 is checked).
    field : str
        The library input holding ``units``.
    """
    if not (math.isfinite(known) and known > 0):
        raise InputError(f"the field strength must be positive, not {_num(known)}", "{field}")
    if _declared_factor(units, "magnetic_field") is not None and not FIELD_RANGE[0] <= known <= FIELD_RANGE[1]:
        raise InputError(f"{_num(to_unit(known, 'uT'))} uT is not Earth's field ({EARTH_FIELD[0] * 1e6:g}-"
                         f"{EARTH_FIELD[1] * 1e6:g} uT); give the local field, e.g. '48.5 uT'", "{field}")
    if not 0.5 <= known / strength <= 2.0:
        raise TestError(f"the field given is {known / strength:.3g}x the readings' own field strength: check "
                        f"{{field}} and {{{field}}}", None)


def check_corrected(sensor: str, corrected: np.ndarray, units: str, field: str = "units", where: str | None = None) -> None:
    """Readings corrected by a calibration must still be what physics allows: a log read in the wrong unit is refused.

    Over a whole log an accelerometer's mean ``|a|`` is gravity (within a factor of 2, :data:`AT_REST_RANGE`)
    and a magnetometer's mean ``|m|`` Earth's field (:data:`FIELD_RANGE`); a gyro's rates have no such bound.

    Parameters
    ----------
    sensor : str
        ``"accelerometer"``, ``"magnetometer"`` or ``"gyroscope"`` (not checked).
    corrected : ndarray, shape (n, 3)
        Corrected readings, SI (or counts: exempt).
    units : str
        The unit the log was read in.
    field : str
        The input holding ``units`` (the placeholder of the fix).
    where : str, optional
        The log.
    """
    norms = np.linalg.norm(np.asarray(corrected, float).reshape(-1, 3), axis=1)
    if sensor == "accelerometer":
        check_at_rest(norms, STANDARD_GRAVITY, units, field, where, "over the corrected log")
    elif sensor == "magnetometer" and len(norms):
        check_field_strength(float(np.mean(norms)), units, field, where)


def check_dip(dip: float, where: str = "{dip}") -> float:
    """Refuse a magnetic dip that is not finite or not within [-90, 90] deg; returns it (rad)."""
    if not (math.isfinite(dip) and abs(dip) <= 90 * DEG + 1e-12):
        raise InputError(f"a magnetic dip lies within -90..90 deg, not {_num(dip / DEG)} deg", where)
    return float(dip)


def _reads(m: np.ndarray, i: int) -> str | None:
    """What sensor axis ``i`` reads when it does not read its own axis: ``"-x"`` or ``"+y"``, else None."""
    j = int(np.argmax(np.abs(m[i])))
    sign = "+" if m[i, j] > 0 else "-"
    return None if j == i and sign == "+" else f"{sign}{AXES[j]}"


def check_axes(m: np.ndarray, positions: dict[int, list[str]], where: str | None = None,
               sensor: str = "accelerometer") -> None:
    """Each sensor axis must respond to its own axis with its sign, and ``det(M) > 0`` (reference section 1).

    For a calibration from known orientations (positions or Ferraris faces, stated
    in the sensor frame): row ``i`` of ``M`` must lie mostly along ``+e_i``.

    Parameters
    ----------
    m : ndarray, shape (3, 3)
        The fitted ``M`` (``raw = M true + bias``).
    positions : dict of int -> list of str
        For each axis, the positions (faces) with that axis up or down: what to check.
    where : str, optional
        The positions file or ``"{sections}"``.
    sensor : str
        The sensor, for the message.

    Raises
    ------
    HandednessError
        ``det(M) <= 0`` (a flipped axis, swapped positions, a negative gravity).
    TestError
        ``det(M) > 0`` but axes read the wrong way (two flipped axes, positions swapped between axes).
    """
    det = float(np.linalg.det(m))
    bad = [(i, r) for i in range(3) if (r := _reads(m, i)) is not None]
    said = "; ".join(f"the {AXES[i]} axis reads gravity when {r} is up" for i, r in bad)
    axes = sorted({i for i, _ in bad} | {AXES.index(r[1]) for _, r in bad})  # its own positions and those it reads
    names = [literal(n) for i in axes for n in positions.get(i, [])]
    check = (f"check the wiring or sign of the {sensor}'s {', '.join(AXES[i] for i, _ in bad)} axis and the up of "
             f"{', '.join(names) or 'its positions'} (swapped positions?); the tool does not 'fix' this")
    if not det > 0:
        raise HandednessError(f"det(M) = {det:.4g} <= 0, a handedness error: {said or 'an axis reads backwards'}; {check}",
                              where)
    if bad:
        raise TestError(f"{said}; {check}", where)


def check_scale_factors(m: np.ndarray, tolerance: float, units: str, expect: str, field: str = "units",
                        where: str | None = None) -> None:
    """Scale factors ``|M[i, :]|`` must lie within ``1 +/- tolerance`` (readings in counts are exempt).

    Parameters
    ----------
    m : ndarray, shape (3, 3)
    tolerance : float
    units : str
        The declared unit of the readings.
    expect : str
        Their dimension (``"acceleration"``), a key of :data:`align.units.DIMENSIONS`.
    field : str
        The library input holding ``units``.
    where : str, optional
    """
    if _declared_factor(units, expect) is None:
        return
    bad = scale_outside(m, tolerance)
    if bad is not None:
        i, s = bad
        raise TestError(f"{AXES[i]} scale factor {_num(s)} is outside 1 +/- {tolerance:g}: wrong {{{field}}}, "
                        "wrong columns, or a broken axis", where)


def scale_outside(m: np.ndarray, tolerance: float) -> tuple[int, float] | None:
    """The first row whose scale factor ``|M[i, :]|`` (reference section 1) is not within ``1 +/- tolerance``
    (NaN included), as ``(i, scale)``; None when every row is."""
    for i, s in enumerate(np.linalg.norm(m, axis=1)):
        if not abs(s - 1.0) <= tolerance:
            return i, float(s)
    return None


def check_usable_model(m: np.ndarray, where: str | None = None, name: str = "M") -> None:
    """Refuse to correct with a matrix that is not finite, not invertible or not right-handed.

    Parameters
    ----------
    m : ndarray, shape (3, 3)
        ``M`` of ``raw = M true + bias`` (or a magnetometer's soft iron).
    where : str, optional
        The result file (and sensor).
    name : str
        The matrix's name in the file.

    Raises
    ------
    InputError
        Not finite (a malformed result).
    TestError
        Condition number beyond :data:`MAX_CONDITION` (singular).
    HandednessError
        ``det <= 0``: ``alignment.json: M has det -0.998 <= 0: a handedness error; regenerate the result``.
    """
    m = np.asarray(m, float)
    if m.shape != (3, 3) or not np.all(np.isfinite(m)):
        raise InputError(f"{name} is not a finite 3x3 matrix (null or NaN entries): a malformed result; "
                         "regenerate the result", where)
    cond = float(np.linalg.cond(m))
    if not cond <= MAX_CONDITION:
        raise TestError(f"{name} is singular (condition number {_num(cond)} > {MAX_CONDITION:g}): it cannot be "
                        "inverted to correct a log; regenerate the result", where)
    det = float(np.linalg.det(m))
    if not det > 0:
        raise HandednessError(f"{name} has det {_num(det)} <= 0: a handedness error; regenerate the result", where)


def check_positive_definite(w: np.ndarray, where: str | None = None, name: str = "soft_iron") -> None:
    """A magnetometer's soft iron: usable (:func:`check_usable_model`) and positive definite (its symmetric part)."""
    check_usable_model(w, where, name)
    low = float(np.linalg.eigvalsh(0.5 * (w + w.T))[0])
    if not low > 0:
        raise TestError(f"{name} is not positive definite (smallest eigenvalue {_num(low)}): a reflected or "
                        "degenerate calibration; regenerate the result", where)
