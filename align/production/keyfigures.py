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

Public names
------------
FIGURES, KIND, si_unit, shown_unit, result_rows, matrix_figures, AXES
"""

from __future__ import annotations

from typing import Any

import numpy as np

from align.model import angles
from align.results import Result

AXES = "xyz"
_PAIRS = ("xy", "xz", "yz")
_CROSS = tuple(f"{a}{b}" for a in AXES for b in AXES if a != b)

#: figure -> its kind: "1" (a ratio), "angle", "reading" (the sensor's quantity), "white", "flicker", "walk"
KIND: dict[str, str] = {
    **{f"M_{a}{b}": "1" for a in AXES for b in AXES},
    **{f"M_{a}{b}_sigma": "1" for a in AXES for b in AXES},
    **{f"scale_{a}": "1" for a in AXES},
    **{f"phi_{p}": "angle" for p in _CROSS},
    **{f"delta_{p}": "angle" for p in _PAIRS},
    **{f"rotation_{a}": "angle" for a in AXES},
    **{f"bias_{a}": "reading" for a in AXES},
    **{f"bias_{a}_sigma": "reading" for a in AXES},
    **{f"arw_{a}": "white" for a in AXES},
    **{f"bi_{a}": "flicker" for a in AXES},
    **{f"rrw_{a}": "walk" for a in AXES},
    "field": "reading", "coverage": "1", "heading_error": "angle", "spread": "1",
}
#: every figure, in the table's column order
FIGURES: tuple[str, ...] = tuple(KIND)

#: kind -> sensor -> (SI unit, the unit a figure is shown in when no limit states one)
_UNITS: dict[str, dict[str, tuple[str, str]]] = {
    "1": {"": ("1", "1")},
    "angle": {"": ("rad", "deg")},
    "reading": {"gyroscope": ("rad/s", "deg/s"), "accelerometer": ("m/s^2", "m/s^2"), "magnetometer": ("T", "uT")},
    "white": {"gyroscope": ("rad/sqrt(s)", "deg/sqrt(h)"), "accelerometer": ("m/s/sqrt(s)", "m/s/sqrt(h)")},
    "flicker": {"gyroscope": ("rad/s", "deg/h"), "accelerometer": ("m/s^2", "ug")},
    "walk": {"gyroscope": ("rad/s/sqrt(s)", "deg/h/sqrt(h)"), "accelerometer": ("m/s^2/sqrt(s)", "ug/sqrt(h)")},
}


def _units_of(figure: str, sensor: str) -> tuple[str, str] | tuple[None, None]:
    units = _UNITS[KIND[figure]]
    return units.get("", units.get(sensor)) or (None, None)


def si_unit(figure: str, sensor: str) -> str | None:
    """The SI unit of ``figure`` for ``sensor`` (``"rad"``, ``"rad/s"``, ``"1"``); None: the sensor has no such figure."""
    return _units_of(figure, sensor)[0]


def shown_unit(figure: str, sensor: str) -> str:
    """The unit ``figure`` is shown in for ``sensor`` when no limit states one (``"deg"``, ``"deg/sqrt(h)"``)."""
    return _units_of(figure, sensor)[1] or "1"


def matrix_figures(m: np.ndarray, sigma: np.ndarray | None, mounting: np.ndarray | None = None) -> dict:
    """``M_ij``, their sigmas and the decomposition of ``M N^T`` (``N`` the nominal mounting, identity when None)."""
    out = {f"M_{a}{b}": float(m[i, j]) for i, a in enumerate(AXES) for j, b in enumerate(AXES)}
    if sigma is not None:
        out |= {f"M_{a}{b}_sigma": float(sigma[i, j]) for i, a in enumerate(AXES) for j, b in enumerate(AXES)}
    ang = angles(m if mounting is None else m @ mounting.T)
    out |= {f"scale_{a}": float(ang.scale[i]) for i, a in enumerate(AXES)}
    out |= {f"phi_{a}{b}": float(ang.phi[i, j]) for i, a in enumerate(AXES) for j, b in enumerate(AXES) if i != j}
    out |= {f"delta_{p}": float(v) for p, v in zip(_PAIRS, ang.delta)}
    out |= {f"rotation_{a}": float(v) for a, v in zip(AXES, ang.mounting_rotvec)}
    return out


def _vector(name: str, v, sigma=None) -> dict:
    out = {f"{name}_{a}": float(x) for a, x in zip(AXES, np.asarray(v, float))}
    if sigma is not None:
        out |= {f"{name}_{a}_sigma": float(x) for a, x in zip(AXES, np.asarray(sigma, float))}
    return out


def _reading_unit(sensor: str, units: str) -> str:
    """The unit of a row's reading figures: SI for the sensor, or ``count`` for a calibration in counts."""
    return "count" if units.strip().lower() in ("count", "counts") else _UNITS["reading"][sensor][0]


def result_rows(result: Result) -> list[dict]:
    """The key figures of a unit's result: one dict per sensor with ``sensor``, ``checks`` (text),
    ``verdict`` (``"pass"``, or ``"warn"`` when a check of the result warns), ``bias_unit`` and the
    figures of :data:`FIGURES` it has (SI).

    Parameters
    ----------
    result : Result
        An alignment (``imu-align.alignment``), a calibration (``imu-align.calibration``), a magnetometer
        calibration (``imu-align.magnetometer``) or an Allan job (``imu-align.allan``).

    Returns
    -------
    list of dict
        Empty for a result of any other kind (the unit's row then holds no figures).
    """
    kind = type(result).FORMAT
    res: Any = result  # one of the kinds below, told apart by its format
    if kind == "imu-align.alignment":
        warn = [c for c in res.checks if c.status == "warn"]
        row = {"sensor": "gyroscope", "checks": "; ".join(f"{c.name}: {c.status}" for c in res.checks),
               "verdict": "warn" if warn else "pass", "bias_unit": "rad/s",
               **matrix_figures(res.M, res.sigma_M, res.mounting),
               **_vector("bias", res.bias, res.sigma_bias)}
        return [row]
    if kind == "imu-align.calibration":
        rows = []
        for sensor, cal in res.sensors.items():
            held = ", ".join(f"{k}: {np.max(np.abs(v)):.3g}" for k, v in cal.checks.items())
            rows.append({"sensor": sensor, "checks": f"held out (largest |residual|, {cal.units}) {held}" if held else "",
                         "verdict": "pass", "bias_unit": _reading_unit(sensor, cal.units),
                         **matrix_figures(cal.M, cal.sigma_M), **_vector("bias", cal.bias, cal.sigma_bias)})
        return rows
    if kind == "imu-align.magnetometer":
        w = np.asarray(res.soft_iron, float)
        return [{"sensor": "magnetometer", "checks": "", "verdict": "pass",
                 "bias_unit": _reading_unit("magnetometer", res.units),
                 **matrix_figures(np.linalg.inv(w), None), **_vector("bias", res.hard_iron, res.sigma_hard_iron),
                 "field": float(res.field), "coverage": float(res.coverage),
                 "heading_error": float(res.heading_error), "spread": float(res.spread_after)}]
    if kind == "imu-align.allan":
        return [_allan_row(res)]
    return []


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
