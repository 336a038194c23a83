"""The key figures of a unit's result: one flat row per sensor, SI, for the lot's table.

Every result a unit's job writes (:func:`align.results.load_result`) gives one row per sensor it
holds (a Ferraris session: the accelerometer's and the gyroscope's). The figures share one
vocabulary across jobs, in the convention ``raw = M true + bias`` (rows of ``M`` are sensor axes):

* ``M_ij`` and ``M_ij_sigma`` (1-sigma): the whole matrix; for a magnetometer ``M = soft_iron^-1``
  (``m_raw = soft_iron^-1 m_cal + hard_iron``);
* ``scale_i``, ``phi_ij``, ``delta_ij``, ``rotation_i`` (the mounting rotation vector): the
  decomposition of ``M`` (reference section 1, :func:`align.model.angles`), for an alignment relative
  to its nominal mounting (``M N^T``);
* ``bias_i`` and ``bias_i_sigma``: the bias (an Allan job: the record's mean; a magnetometer: the hard iron);
* ``arw_i``, ``bi_i``, ``rrw_i``: the noise terms ``N``, ``B``, ``K`` of an Allan fit (NaN where a term is
  not identifiable from the record);
* ``field``, ``coverage``, ``heading_error``, ``spread``: a magnetometer's field strength, coverage of
  directions, predicted heading error (1 sigma) and ``std(|m|)/mean(|m|)`` after calibration.

Values are SI: angles in rad, readings in rad/s, m/s^2 or T (counts for a calibration in counts:
the row's ``bias_unit`` says which). :func:`si_unit` and :func:`shown_unit` give a figure's unit
for a sensor.

The vocabulary (names, kinds, units) is :mod:`align.keyfigures`, shared with results and limits.

Public names
------------
result_rows, and from :mod:`align.keyfigures`: FIGURES, KIND, si_unit, shown_unit, matrix_figures, AXES
"""

from __future__ import annotations

from typing import Any

import numpy as np

from align.keyfigures import _UNITS, AXES, FIGURES, KIND, matrix_figures, shown_unit, si_unit, vector_figures  # noqa: F401
from align.results import Result


def _reading_unit(sensor: str, units: str) -> str:
    """The unit of a row's reading figures: SI for the sensor, or ``count`` for a calibration in counts."""
    return "count" if units.strip().lower() in ("count", "counts") else _UNITS["reading"][sensor][0]


def result_rows(result: Result) -> list[dict]:
    """The key figures of a unit's result: one dict per sensor with ``sensor``, ``checks`` (text),
    ``verdict`` (``"pass"``; ``"warn"`` when a check of the result warns or a figure of merit is within its guard
    band; ``"fail"`` when a figure of merit FAILs or is NOT USABLE, named in ``checks``), ``bias_unit`` and the
    figures of :data:`FIGURES` it has (SI).

    Parameters
    ----------
    result : Result
        An alignment (``imu-align.alignment``), a calibration (``imu-align.calibration``), a magnetometer
        calibration (``imu-align.magnetometer``) or an Allan job (``imu-align.allan``).

        Any other result gives its figures of merit (:meth:`~align.results.Result.figures_of_merit`), one row per
        sensor.

    Returns
    -------
    list of dict
        Empty for a result that gives no figures (the unit's row then holds none).
    """
    return _with_merit(_rows(result), result)


def _with_merit(rows: list[dict], result: Result) -> list[dict]:
    """Each row's verdict with its sensor's judged figures of merit (``result.verdicts``)."""
    for row in rows:
        mine = [f for f in result.verdicts if f.sensor == row["sensor"]]
        bad = [f for f in mine if f.status.fails]
        if bad:
            named = ", ".join(f"{f.name} {f.status}" for f in bad[:6]) + (" ..." if len(bad) > 6 else "")
            row["verdict"] = "fail"
            row["message"] = f"figures of merit: {named}"
            row["checks"] = "; ".join(x for x in (row.get("checks"), row["message"]) if x)
        elif row["verdict"] == "pass" and any(f.status == "WARN" for f in mine):
            row["verdict"] = "warn"
    return rows


def _rows(result: Result) -> list[dict]:
    kind = type(result).FORMAT
    res: Any = result  # one of the kinds below, told apart by its format
    if kind == "imu-align.alignment":
        warn = [c for c in res.checks if c.status == "warn"]
        row = {"sensor": "gyroscope", "checks": "; ".join(f"{c.name}: {c.status}" for c in res.checks),
               "verdict": "warn" if warn else "pass", "bias_unit": "rad/s",
               **matrix_figures(res.M, res.sigma_M, res.mounting),
               **vector_figures("bias", res.bias, res.sigma_bias)}
        return [row]
    if kind == "imu-align.calibration":
        rows = []
        for sensor, cal in res.sensors.items():
            held = ", ".join(f"{k}: {np.max(np.abs(v)):.3g}" for k, v in cal.checks.items())
            rows.append({"sensor": sensor, "checks": f"held out (largest |residual|, {cal.units}) {held}" if held else "",
                         "verdict": "pass", "bias_unit": _reading_unit(sensor, cal.units),
                         **matrix_figures(cal.M, cal.sigma_M), **vector_figures("bias", cal.bias, cal.sigma_bias)})
        return rows
    if kind == "imu-align.magnetometer":
        w = np.asarray(res.soft_iron, float)
        return [{"sensor": "magnetometer", "checks": "", "verdict": "pass",
                 "bias_unit": _reading_unit("magnetometer", res.units),
                 **matrix_figures(np.linalg.inv(w), None), **vector_figures("bias", res.hard_iron, res.sigma_hard_iron),
                 "field": float(res.field), "coverage": float(res.coverage),
                 "heading_error": float(res.heading_error), "spread": float(res.spread_after)}]
    if kind == "imu-align.allan":
        return [_allan_row(res)]
    figures = result.verdicts or result.figures_of_merit()
    by_sensor: dict[str, dict] = {}
    for f in figures:
        row = by_sensor.setdefault(f.sensor, {"sensor": f.sensor, "checks": "", "verdict": "pass",
                                              "bias_unit": _UNITS["reading"].get(f.sensor, ("", ""))[0]})
        if f.name in KIND and f.unit != "count":
            row[f.name] = f.value
            if f"{f.name}_sigma" in KIND:
                row[f"{f.name}_sigma"] = f.sigma
    return list(by_sensor.values())


def _allan_row(job) -> dict:
    """An Allan job's noise terms (N, B, K) and mean per channel (the first three channels as x, y, z)."""
    row = {"sensor": job.sensor, "verdict": "pass", "bias_unit": _UNITS["reading"][job.sensor][0]}
    hidden = []
    for k, (fit, fig) in enumerate(zip(job.fits[:3], job.figures[:3])):
        a = AXES[k]
        for name, index, letter in (("arw", 1, "N"), ("bi", 2, "B"), ("rrw", 3, "K")):
            ok = bool(fit.identifiable[index])
            row[f"{name}_{a}"] = float(fit.params[index]) if ok else float("nan")
            if not ok:
                hidden.append(f"{letter}_{a}")
        if fig.get("bias") is not None:
            row[f"bias_{a}"] = float(fig["bias"])
    row["checks"] = f"not identifiable from the record: {', '.join(hidden)}" if hidden else ""
    return row
