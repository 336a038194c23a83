"""The ``calibrate thermal-matrix`` job: every element of ``M`` and ``b`` against temperature from calibration or
alignment results made at several temperatures (:mod:`align.calibration.thermal.matrix_t`).

Each result gives one sensor's ``M``, ``b`` and their 1-sigma: an alignment (``imu-align matrix``), a calibration
(``calibrate accel | gyro | ferraris``) or a multi-position session (``calibrate positions``, its ``sensor``
chosen). Its temperature is the one given, else the session's that the result states in
``inputs["temperature"]`` (``{"mean": degC, "spread": degC}``, or a number).

Public names
------------
MatrixThermalOptions, MatrixThermalInputs, THERMAL_MATRIX, calibrate_thermal_matrix, parse_temperatures, calibration_of
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from align.calibration.thermal.matrix_t import Calibrated, MatrixThermal, fit_matrix
from align.errors import InputError, literal
from align.job import Job, Progress, fields_signature
from align.results import Result, load_result

__all__ = ["MatrixThermalOptions", "MatrixThermalInputs", "THERMAL_MATRIX", "calibrate_thermal_matrix",
           "parse_temperatures", "calibration_of"]

_NUMBER = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S*)\s*$")


def parse_temperatures(text: str, where: str = "{temperatures}") -> tuple[float, ...]:
    """Temperatures typed as ``"20 degC,40 degC,60 degC"`` (degC, C, K or degF; each with its unit), in degC.

    Examples
    --------
    >>> parse_temperatures("20 degC, 313.15 K,140 degF")
    (20.0, 40.0, 60.0)
    """
    from align.units import temperature_offset

    out = []
    for item in text.split(","):
        m = _NUMBER.match(item)
        if m is None:
            raise InputError(f"'{item.strip()}' is not a temperature; give numbers with a unit, separated by commas, "
                             "e.g. '20 degC,40 degC,60 degC'", where)
        if not m.group(2):
            raise InputError(f"'{item.strip()}' states no unit; give each temperature with its unit, e.g. "
                             f"'{item.strip()} degC' (or K, degF)", where)
        scale, offset = temperature_offset(m.group(2), where)
        out.append(round(scale * float(m.group(1)) + offset, 10))
    return tuple(out)


@dataclass(frozen=True, kw_only=True)
class MatrixThermalOptions:
    """Options of ``calibrate thermal-matrix``.

    Attributes
    ----------
    results : tuple of Path
        Calibration or alignment results (JSON) of one sensor, one per temperature.
    temperatures : tuple of float, str or None
        Their temperatures, degC, in the same order (or as typed: ``"20 degC,40 degC"``, :func:`parse_temperatures`);
        None: the ones the results state.
    temperature_sigma : float
        1-sigma of each given temperature, degC (the results' stated spread is used for theirs).
    sensor : str or None
        ``gyroscope`` or ``accelerometer``: the sensor read from results that hold both (None: the only one).
    order : int or None
        1 or 2 for every element; None: per element by the likelihood-ratio test (order 2 needs 4 results).
    reference : float or None
        Reference temperature, degC; None: the mean of the temperatures.
    """

    results: tuple[Path, ...]
    temperatures: tuple[float, ...] | str | None = None
    temperature_sigma: float = field(default=0.0, metadata={"ge": 0.0})
    sensor: str | None = None
    order: int | None = 1
    reference: float | None = None


@dataclass(frozen=True)
class MatrixThermalInputs:
    """The checked inputs: the calibrations with their temperatures, the sensor, the bias unit shown, the nominal
    mounting (identity unless the alignments state one), and where each temperature came from."""

    points: tuple[Calibrated, ...]
    sensor: str
    units: str
    mounting: np.ndarray
    temperature_source: str


def calibration_of(result: Result, sensor: str | None, where: str) -> tuple[str, str, np.ndarray, np.ndarray,
                                                                          np.ndarray, np.ndarray, np.ndarray | None]:
    """One sensor's ``(sensor, units, M, sigma_M, bias, sigma_bias, mounting)`` held by a result, SI.

    Raises
    ------
    InputError
        A result that holds no ``M`` with its 1-sigma (naming ``where``), or several sensors and none chosen.
    """
    if result.FORMAT == "imu-align.positions":
        if sensor is None:
            raise InputError("holds a gyroscope and an accelerometer; choose one with {sensor}", where)
        fit = getattr(result, sensor)

        def get(kind: str, i: int, j: int | None = None) -> tuple[float, float]:
            try:
                return fit.param(kind, i, j)[:2]
            except ValueError:  # not estimated (a gyro's M taken as known): refused by the fit, naming the file
                return math.nan, math.nan

        par = np.array([[get("M", i, j) for j in range(3)] for i in range(3)])
        b = np.array([get("b", i) for i in range(3)])
        return sensor, "rad/s" if sensor == "gyroscope" else "m/s^2", par[..., 0], par[..., 1], b[:, 0], b[:, 1], None
    cal: Any = result.correction(sensor, where)
    if not all(hasattr(cal, k) for k in ("M", "sigma_M", "bias", "sigma_bias")):
        raise InputError(f"holds an {result.FORMAT} result, which states no M and b with their 1-sigma; give "
                         "alignment or calibration results", where)
    return (str(cal.sensor), str(cal.units), np.asarray(cal.M, float), np.asarray(cal.sigma_M, float),
            np.asarray(cal.bias, float), np.asarray(cal.sigma_bias, float), getattr(cal, "mounting", None))


def _stated_temperature(result: Result, where: str) -> tuple[float, float]:
    """The session temperature a result states (``inputs["temperature"]``), degC, and its 1-sigma (the spread)."""
    got: Any = getattr(result, "inputs", {}).get("temperature")
    try:
        if isinstance(got, dict):
            mean, sigma = float(got["mean"]), float(got.get("spread", got.get("sigma", 0.0)) or 0.0)
        else:
            mean, sigma = float(got), 0.0
    except (KeyError, TypeError, ValueError):
        raise InputError("states no session temperature (made without a temperature column); give the results' "
                         "temperatures with {temperatures}", where) from None
    if not (math.isfinite(mean) and math.isfinite(sigma) and sigma >= 0):
        raise InputError(f"states a session temperature of {mean} +/- {sigma} degC, which is not usable; give the "
                         "results' temperatures with {temperatures}", where)
    return mean, sigma


def _read(o: MatrixThermalOptions) -> MatrixThermalInputs:
    paths = tuple(Path(p) for p in o.results)
    temps = parse_temperatures(o.temperatures) if isinstance(o.temperatures, str) else o.temperatures
    need = 4 if o.order == 2 else 2
    if len(paths) < need:
        raise InputError(f"{len(paths)} result{'s' if len(paths) != 1 else ''} given; a fit against temperature of "
                         f"order {o.order or 1} needs {need} or more, made at different temperatures", "{results}")
    if temps is not None and len(temps) != len(paths):
        raise InputError(f"{len(temps)} temperatures for {len(paths)} results; give one per result, in their "
                         "order", "{temperatures}")
    if o.sensor not in (None, "gyroscope", "accelerometer"):
        raise InputError(f"'{o.sensor}' is not gyroscope or accelerometer", "{sensor}")
    points, first, mountings = [], None, []
    seen: dict[str, bytes | None] = {}
    for k, path in enumerate(paths):
        where = str(path)
        data = path.read_bytes() if path.is_file() else None
        twin = next((w for w, d in seen.items() if data is not None and d == data), None)
        if twin is not None:
            raise InputError(f"is given twice (the same bytes as {literal(twin)}): one calibration is one temperature "
                             "point; give each result once", where)
        seen[f"{where} (result {k + 1})"] = data
        result = load_result(path)
        if result.FORMAT == "imu-align.thermal":
            raise InputError("is a thermal calibration (bias against temperature); thermal-matrix fits calibrations "
                             "made at several temperatures: give alignment or calibration results", where)
        sensor, units, m, sm, b, sb, mounting = calibration_of(result, o.sensor, where)
        if first is None:
            first = (sensor, units)
        elif sensor != first[0]:
            raise InputError(f"holds a {sensor} calibration, the first result a {first[0]} one; give results of one "
                             "sensor (and choose it with {sensor} where a result holds both)", where)
        elif (units.strip().lower() in ("count", "counts")) != (first[1].strip().lower() in ("count", "counts")):
            raise InputError(f"is in {units}, the first result in {first[1]}: counts and physical units cannot be "
                             "fitted together; give results in one kind of unit", where)
        temp = (float(temps[k]), o.temperature_sigma) if temps is not None else \
            _stated_temperature(result, where)
        points.append(Calibrated(temp[0], temp[1], m, sm, b, sb, where))
        mountings.append(np.eye(3) if mounting is None else np.asarray(mounting, float))
        if not np.allclose(mountings[-1], mountings[0], atol=1e-9):
            raise InputError("states another nominal mounting than the first result: results of one sensor, mounted "
                             "one way, are needed", where)
    assert first is not None
    return MatrixThermalInputs(tuple(points), first[0], first[1], mountings[0],
                               "given" if temps is not None else "stated by the results")


def _compute(i: MatrixThermalInputs, o: MatrixThermalOptions, progress: Progress | None) -> MatrixThermal:
    result = fit_matrix(i.points, i.sensor, i.units, order=o.order, reference=o.reference, mounting=i.mounting)
    if progress is not None:
        progress(len(i.points))
    inputs = {"results": [p.where for p in i.points], "temperatures": [p.temperature for p in i.points],
              "temperature_sigmas": [p.sigma_temperature for p in i.points],
              "temperature_source": i.temperature_source, "sensor": i.sensor,
              "order": "auto" if o.order is None else o.order, "reference": o.reference}
    return result.replace(inputs=inputs)


def _files(o: MatrixThermalOptions) -> dict[str, Path | None]:
    return {f"result_{k + 1}": Path(p) for k, p in enumerate(o.results)}


THERMAL_MATRIX: Job[MatrixThermalOptions, MatrixThermalInputs, MatrixThermal] = Job(
    "calibrate thermal-matrix", MatrixThermalOptions, _read, _compute, _files,
    "scale, misalignment and bias against temperature from calibrations at several temperatures")


@fields_signature(MatrixThermalOptions)
def calibrate_thermal_matrix(*, results: tuple[Path | str, ...] | list[Path | str], progress: Progress | None = None,
                             **fields: Any) -> MatrixThermal:
    """Every element of ``M`` and ``b`` against temperature (``imu-align calibrate thermal-matrix``).

    Parameters
    ----------
    results : sequence of Path or str
        Calibration or alignment results of one sensor, one per temperature.
    progress : callable, optional
        Called with the calibrations fitted.
    **fields
        The other fields of :class:`MatrixThermalOptions` (``temperatures``, ``sensor``, ``order``, ...).

    Returns
    -------
    MatrixThermal
    """
    return THERMAL_MATRIX.run(MatrixThermalOptions(results=tuple(Path(p) for p in results), **fields),
                              progress=progress)
