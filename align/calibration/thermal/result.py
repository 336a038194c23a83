"""The thermal calibration file: the registered result ``imu-align.thermal``.

One key per sensor calibrated (``gyroscope``, ``accelerometer``), each with its reference temperature and valid
range, and per axis the model (coefficients about the reference, the lag coefficient, their covariance) and what
its fit found (order and cross-validation table, residual before and after, band, hysteresis, held-out branch
check). Readings in the file's unit (``units``), temperatures in degrees Celsius.

Public names
------------
ThermalCalibration, ThermalCorrection, FORMAT, CONVENTION, BAND, HYSTERESIS
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from align.calibration.results import by_sensor
from align.calibration.thermal.branches import Hysteresis
from align.calibration.thermal.model import AxisModel, Compensated, ThermalModel
from align.calibration.thermal.sensor import AxisReport, SensorThermal
from align.errors import InputError
from align.io.keys import check_keys
from align.results import Result
from align.units import parse_unit
from align.wellformed import malformed

__all__ = ["ThermalCalibration", "FORMAT", "CONVENTION", "BAND", "HYSTERESIS"]

FORMAT = "imu-align.thermal"
CONVENTION = ("bias(T, dT/dt) = sum_k c_k d^k + lag dT/dt, d = clip(T, tmin, tmax) - tref; compensated = raw - bias; "
              "T in degC; the firmware files carry the static curve (dT/dt = 0)")
#: how the band is made (written in the file)
BAND = ("1 sigma of the static curve: s^2 (X^T X)^-1 times the residuals' integrated autocorrelation time (blocking "
        "method over contiguous blocks); inflation = sqrt of that time")
#: what the hysteresis is (written in the file)
HYSTERESIS = ("heating minus cooling at equal temperature where largest in size over the range both branches cover, "
              "each branch fitted alone with the axis' order and no lag term (so it includes what a lag term "
              "explains); sigma at that temperature")
SENSORS = ("gyroscope", "accelerometer")
_SENSOR_KEYS = ("units", "reference_temperature", "valid_range", "samples", "temperature_resolution", "branches",
                "notes", "axes")
_AXIS_KEYS = ("axis", "order", "lag", "coefficients", "lag_coefficient", "covariance", "cross_validation", "residual",
              "band", "hysteresis", "branch_check")


def _axis_dict(model: AxisModel, rep: AxisReport, name: str, f: float) -> dict[str, Any]:
    h = rep.hysteresis
    return {
        "axis": name, "order": rep.order, "lag": rep.lag,
        "coefficients": (model.coefficients / f).tolist(),
        "lag_coefficient": None if model.lag is None else model.lag / f,
        "covariance": (model.covariance / (f * f)).tolist(),
        "cross_validation": [{"order": k, "lag": g, "rms": r / f} for k, g, r in rep.cv],
        "residual": {"before": {"rms": rep.rms_before / f, "largest": rep.max_before / f},
                     "after": {"rms": rep.rms_after / f, "largest": rep.max_after / f},
                     "one_cubic_rms": rep.rms_cubic / f},
        "band": {"largest_1sigma": rep.band_max / f, "inflation": rep.inflation},
        "hysteresis": None if h is None else {"value": h.value / f, "sigma": h.sigma / f, "at": h.at,
                                              "overlap": [h.lo, h.hi]},
        "branch_check": None if rep.crosscheck is None else {"heating_to_cooling_rms": rep.crosscheck[0] / f,
                                                             "cooling_to_heating_rms": rep.crosscheck[1] / f},
    }


def _axis_from(d: dict, f: float, where: str) -> tuple[AxisModel, AxisReport]:
    check_keys(d, _AXIS_KEYS, where)
    coef = np.array(d["coefficients"], float) * f
    lag = None if d["lag_coefficient"] is None else float(d["lag_coefficient"]) * f
    cov = np.array(d["covariance"], float) * f * f
    res, band, h, b = d["residual"], d["band"], d["hysteresis"], d["branch_check"]
    hyst = None if h is None else Hysteresis(float(h["value"]) * f, float(h["sigma"]) * f, float(h["at"]),
                                             float(h["overlap"][0]), float(h["overlap"][1]))
    cross = None if b is None else (float(b["heating_to_cooling_rms"]) * f, float(b["cooling_to_heating_rms"]) * f)
    rep = AxisReport(int(d["order"]), bool(d["lag"]),
                     tuple((int(r["order"]), bool(r["lag"]), float(r["rms"]) * f) for r in d["cross_validation"]),
                     float(res["before"]["rms"]) * f, float(res["before"]["largest"]) * f,
                     float(res["after"]["rms"]) * f, float(res["after"]["largest"]) * f,
                     float(res["one_cubic_rms"]) * f, float(band["largest_1sigma"]) * f, float(band["inflation"]),
                     hyst, cross)
    if len(coef) != rep.order + 1 or not np.all(np.isfinite(coef)):
        raise ValueError(f"{len(coef)} finite coefficients expected for order {rep.order}")
    return AxisModel(coef, lag, cov), rep


class ThermalCalibration(Result, format=FORMAT, convention=CONVENTION):
    """The thermal calibration of a log's sensors (module docstring).

    Attributes
    ----------
    sensors : dict of str -> SensorThermal
        Keys among ``gyroscope``, ``accelerometer``.
    inputs : dict
        The log and settings it came from.

    Examples
    --------
    >>> from align.calibration.thermal.simulate import Profile, random_truth, simulate
    >>> from align.calibration.thermal.sensor import Settings, fit_sensor
    >>> prof = Profile(-10.0, 50.0, 5 / 60, 5 / 60, 0.0, 1.0)
    >>> rng = np.random.default_rng(1)
    >>> run = simulate(prof, random_truth(rng, prof, 0.01), 2.0, 0.002, rng)
    >>> s = fit_sensor(run.t, run.temperature, run.data, "accelerometer", "m/s^2", 2.0, Settings(), "sim")
    >>> r = ThermalCalibration({"accelerometer": s})
    >>> back = ThermalCalibration.from_dict(r.to_dict())
    >>> bool(np.allclose(back.model("accelerometer").axes[0].coefficients, s.model.axes[0].coefficients))
    True
    """

    sensors: dict
    inputs: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "sensors", by_sensor(self.sensors, SENSORS, "a thermal calibration"))
        object.__setattr__(self, "inputs", dict(self.inputs))

    def model(self, sensor: str | None = None, where: str = "thermal calibration") -> ThermalModel:
        """The model of ``sensor`` (the only one when None)."""
        if sensor is None and len(self.sensors) == 1:
            return next(iter(self.sensors.values())).model
        if sensor not in self.sensors:
            raise InputError(f"holds {', '.join(self.sensors)}; choose one with {{sensor}}", where)
        return self.sensors[sensor].model

    def correction(self, sensor: str | None = None, where: str = "result") -> ThermalCorrection:
        """What compensates a log of ``sensor`` (the only one when None) with a temperature column: ``raw - (bias(T) -
        bias(Tref))`` (:class:`ThermalCorrection`)."""
        model = self.model(sensor, where)
        return ThermalCorrection(model, self.sensors[model.sensor].units,
                                 float(self.inputs.get("settings", {}).get("window_s", 20.0)))

    def figures_of_merit(self) -> tuple:
        """Per sensor and axis: ``hysteresis_i`` (heating minus cooling where largest, with its 1-sigma; not given
        when the branches were not compared) and ``thermal_residual_i`` (rms of the residual after compensation)."""
        from align.keyfigures import figures_from

        out: tuple = ()
        for key, s in self.sensors.items():
            values: dict[str, float] = {}
            for a, rep in zip("xyz", s.axes):
                if rep.hysteresis is not None:
                    values[f"hysteresis_{a}"] = rep.hysteresis.value
                    values[f"hysteresis_{a}_sigma"] = rep.hysteresis.sigma
                values[f"thermal_residual_{a}"] = rep.rms_after
            out += figures_from(values, key, method="bias against temperature: polynomial (order by blocked "
                                "cross-validation) and lag, heating and cooling compared at equal temperature")
        return out

    def to_dict(self) -> dict[str, Any]:
        """The versioned JSON form: the envelope, ``inputs``, ``band``, then one key per sensor."""
        out = {**self.envelope({**{k: s.units for k, s in self.sensors.items()}, "temperature": "degC"}),
               "inputs": self.inputs, "band": BAND, "hysteresis": HYSTERESIS}
        for key, s in self.sensors.items():
            f = parse_unit(s.units).factor
            m = s.model
            out[key] = {
                "units": {"readings": s.units, "coefficients": f"{s.units} per degC^k",
                          "lag": f"{s.units} per degC/s"},
                "reference_temperature": m.tref, "valid_range": [m.tmin, m.tmax], "samples": s.samples,
                "temperature_resolution": s.resolution, "branches": dict(s.branches), "notes": list(s.notes),
                "axes": [_axis_dict(ax, rep, "xyz"[i], f) for i, (ax, rep) in enumerate(zip(m.axes, s.axes))],
            }
        return out

    @classmethod
    def from_dict(cls, d: dict, where: str = "thermal calibration") -> ThermalCalibration:
        """Read the form written by :meth:`to_dict`."""
        cls.check_envelope(d, where, keys=["inputs", "band", "hysteresis", *SENSORS])
        sensors = {}
        for key in SENSORS:
            if key not in d:
                continue
            at = f"{where}: {key}"
            try:
                s = d[key]
                check_keys(s, _SENSOR_KEYS, at)
                units = s["units"]["readings"]
                f = parse_unit(units, None, f"{at}: units").factor
                pairs = [_axis_from(a, f, f"{at}: axis {i}") for i, a in enumerate(s["axes"])]
                if len(pairs) != 3:
                    raise ValueError("three axes expected")
                lo, hi = (float(v) for v in s["valid_range"])
                model = ThermalModel(key, float(s["reference_temperature"]), lo, hi, tuple(p[0] for p in pairs))
                sensors[key] = SensorThermal(model, units, tuple(p[1] for p in pairs), dict(s.get("branches") or {}),
                                             float(s["temperature_resolution"]), int(s["samples"]),
                                             tuple(s.get("notes") or ()))
            except InputError:
                raise
            except (KeyError, TypeError, ValueError, IndexError) as exc:
                raise InputError(f"malformed thermal calibration ({malformed(exc)}); regenerate it", at) from None
        if not sensors:
            raise InputError(f"holds no {' or '.join(SENSORS)} thermal calibration", where)
        inputs = d.get("inputs") or {}
        if not isinstance(inputs, dict):
            raise InputError("inputs must be an object", f"{where}: inputs")
        return cls(sensors, inputs)


@dataclass(frozen=True)
class ThermalCorrection:
    """A thermal calibration as :mod:`align.results`' correction of a log (``apply``): ``raw - (bias(T) - bias(Tref))``
    per axis, the temperature clamped to the valid range as firmware does, the lag term ``lag * dT/dt`` where the model
    has one (dT/dt over ``window_s``, as the fit took it). Only the change from the reference temperature is removed:
    the constant of a static session holds gravity (and Earth rate) in its orientation, which the session cannot
    tell from the bias (as ArduPilot drops the constant term and PX4 writes an accelerometer's X0 as 0); the bias
    at the reference is a calibration's.

    Attributes
    ----------
    model : ThermalModel
    units : str
        The unit of the readings in the result's file.
    window_s : float
        Window of the temperature rate, s.
    """

    model: ThermalModel
    units: str
    window_s: float = 20.0
    #: ``apply`` reads the log's temperature column for it
    needs_temperature: ClassVar[bool] = True

    @property
    def sensor(self) -> str:
        """The sensor it compensates."""
        return self.model.sensor

    def correct(self, raw: np.ndarray) -> np.ndarray:
        """Refused: a thermal correction needs the temperature of every sample (:meth:`compensate`)."""
        raise InputError("a thermal calibration compensates the bias against temperature: give the log's "
                         "temperature column with {temperature_column}")

    def compensate(self, raw: np.ndarray, temperature: np.ndarray, t: np.ndarray) -> Compensated:
        """``raw`` (n, 3), SI, compensated at ``temperature`` (n,), C, sampled at ``t`` (n,), s
        (:meth:`ThermalModel.compensate`)."""
        from align.calibration.thermal.branches import temperature_rate

        lagged = any(ax.lag is not None for ax in self.model.axes)
        rate = temperature_rate(np.asarray(t, float), np.asarray(temperature, float), self.window_s) if lagged else None
        comp = self.model.compensate(raw, temperature, rate)
        at_reference, _ = self.model.bias(np.array([self.model.tref]))
        return Compensated(comp.data + at_reference, comp.clamped, comp.note)

