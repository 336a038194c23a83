"""Calibration values: one sensor's ``[M | b]`` and the file holding a session's sensors.

:class:`Calibration` is one sensor's calibration in the shared convention
``raw = M true + bias`` (corrected by ``true = M^-1 (raw - bias)``), with its
1-sigma, the residuals of the positions or faces it was fitted to, held-out
checks and, for a gyro, the g-sensitivity ``K_ga`` (``raw = M w + K_ga a + bias``).
:class:`CalibrationSet` is the registered result ``imu-align.calibration``: the
accelerometer and/or gyroscope of one session and the inputs they came from;
it also writes the pair as imucal's JSON (:meth:`CalibrationSet.as_imucal`).

Public names
------------
Calibration, CalibrationSet, SENSORS, SENSOR_KEYS, FORMAT, CONVENTION, PLAIN_LEVEL, by_sensor
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from align.errors import InputError
from align.io.consumers import imucal_dict, matrix_unit
from align.io.keys import check_keys
from align.plausible import check_usable_model
from align.results import Result, file_unit
from align.units import to_unit
from align.values import Value, frozen_array
from align.wellformed import array_field, check_inverse, malformed

FORMAT = "imu-align.calibration"
CONVENTION = "raw = M true + bias; true = M^-1 (raw - bias); rows of M are sensor axes"
#: the sensors a calibration file may hold, in the order they are written
SENSORS = ("accelerometer", "gyroscope")


def by_sensor(sensors: dict, kinds: tuple[str, ...], what: str) -> dict:
    """``sensors`` keyed by the sensor kinds ``kinds``, in their order; a result of ``what`` holding none of
    them, or another kind, is refused (ValueError: a program's mistake, not a user's)."""
    unknown = [k for k in sensors if k not in kinds]
    if unknown or not sensors:
        raise ValueError(f"{what} holds {' and/or '.join(kinds)}, not {unknown or 'nothing'}")
    return {k: sensors[k] for k in kinds if k in sensors}
#: the keys of one sensor's calibration in the file (unknown keys are refused: a misspelled key is not ignored)
SENSOR_KEYS = ("sensor", "method", "convention", "units", "M", "A", "bias", "uncertainty", "residuals", "checks", "notes",
               "g_sensitivity", "rotations")
#: the uncertainty level of a plain 1-sigma (a t-widened one says how it was widened)
PLAIN_LEVEL = "1 sigma"


@dataclass(frozen=True, eq=False)
class Calibration(Value):
    """One sensor's calibration (reference section 5).

    Attributes
    ----------
    sensor : str
        ``"accelerometer"`` or ``"gyroscope"``.
    M : ndarray, shape (3, 3)
        Dimensionless, or counts per SI unit for readings in counts (the file's ``units.M`` says which);
        row ``i`` is sensor axis ``i`` times its scale factor.
    bias : ndarray, shape (3,)
        SI (m/s^2, rad/s) or counts.
    sigma_M, sigma_bias : ndarray, shape (3, 3) and (3,)
        1-sigma of ``M`` and ``bias`` (NaN when unknown).
    units : str
        File and display unit of the readings (``"m/s^2"``, ``"deg/s"``, ``"counts"``).
    method : str
        How it was estimated.
    residuals, checks : dict of str -> ndarray, shape (3,)
        Fit residuals and held-out checks (reading minus model), SI.
    notes : tuple of str
    g_sensitivity : ndarray, shape (3, 3), optional
        Gyro ``K_ga``, (rad/s) per (m/s^2).
    sigma_g_sensitivity : ndarray, shape (3, 3), optional
        Its 1-sigma, when the method states one.
    level : str
        What the 1-sigma is (the file's ``uncertainty.level``): ``"1 sigma"``, or how it was widened for few
        degrees of freedom (the t distribution's 99.73 % bound over 3).
    rotations : tuple of dict
        A gyro calibrated from rotations between poses: one row per rotation (``rotation``, ``poses``, ``t_s``,
        ``turn_deg``, ``axis``, ``residual_deg``, ``used``), as written in the file; empty otherwise.
    """

    sensor: str
    M: np.ndarray
    bias: np.ndarray
    sigma_M: np.ndarray
    sigma_bias: np.ndarray
    units: str
    method: str
    residuals: dict = field(default_factory=dict)
    checks: dict = field(default_factory=dict)
    notes: tuple = ()
    g_sensitivity: np.ndarray | None = None
    level: str = PLAIN_LEVEL
    rotations: tuple = ()
    sigma_g_sensitivity: np.ndarray | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "residuals", {k: frozen_array(v) for k, v in self.residuals.items()})
        object.__setattr__(self, "checks", {k: frozen_array(v) for k, v in self.checks.items()})
        object.__setattr__(self, "notes", tuple(self.notes))
        object.__setattr__(self, "rotations", tuple(dict(r) for r in self.rotations))

    def figures_of_merit(self) -> tuple:
        """``M`` and its decomposition, and the bias, with their 1-sigma; a calibration in counts gives the scale in
        counts (per SI unit) and the bias in SI (``M^-1 b``, its 1-sigma ``sigma_b / |M_ii|``)."""
        from align.keyfigures import figures_from, matrix_figures, vector_figures

        counts = self.units.strip().lower() in ("count", "counts")
        bias, sigma = np.asarray(self.bias, float), np.asarray(self.sigma_bias, float)
        if counts:
            bias, sigma = np.linalg.solve(self.M, bias), sigma / np.abs(np.diag(self.M))
        out = (figures_from(matrix_figures(self.M, self.sigma_M, angle_sigmas_too=True), self.sensor,
                            method=self.method, counts=counts)
               + figures_from(vector_figures("bias", bias, sigma), self.sensor, method=self.method))
        if self.g_sensitivity is not None and not counts:  # K_ga: a gyro bias per m/s^2 of specific force
            k = np.asarray(self.g_sensitivity, float)
            s = np.full((3, 3), np.nan) if self.sigma_g_sensitivity is None else self.sigma_g_sensitivity
            values = {f"gsens_{a}{b}": float(k[i, j]) for i, a in enumerate("xyz") for j, b in enumerate("xyz")}
            values |= {f"gsens_{a}{b}_sigma": float(s[i, j]) for i, a in enumerate("xyz") for j, b in enumerate("xyz")}
            out += figures_from(values, self.sensor, method=self.method)
        return out

    def to_dict(self) -> dict:
        """The JSON form: matrices dimensionless, readings in ``self.units``."""
        u = self.units
        d = {
            "sensor": self.sensor, "method": self.method, "convention": CONVENTION,
            "units": {"M": matrix_unit(u, self.sensor), "bias": u, "residuals": u},
            "M": self.M.tolist(), "A": np.linalg.inv(self.M).tolist(),
            "bias": to_unit(self.bias, u).tolist(),
            "uncertainty": {"level": self.level, "M": self.sigma_M.tolist(), "bias": to_unit(self.sigma_bias, u).tolist()},
            "residuals": {k: to_unit(v, u).tolist() for k, v in self.residuals.items()},
            "checks": {k: to_unit(v, u).tolist() for k, v in self.checks.items()},
            "notes": list(self.notes),
        }
        if self.g_sensitivity is not None:
            d["g_sensitivity"] = (self.g_sensitivity * to_unit(1.0, u)).tolist()
            d["units"]["g_sensitivity"] = f"{u} per m/s^2"
            if self.sigma_g_sensitivity is not None:
                d["uncertainty"]["g_sensitivity"] = (self.sigma_g_sensitivity * to_unit(1.0, u)).tolist()
        if self.rotations:
            d["rotations"] = [dict(r) for r in self.rotations]
        return d

    @classmethod
    def from_dict(cls, d: dict, where: str = "calibration") -> Calibration:
        """Read the form written by :meth:`to_dict`."""
        if not isinstance(d, dict):
            raise InputError("malformed calibration: expected a JSON object", where)
        check_keys(d, SENSOR_KEYS, where)
        try:
            u, f = file_unit(d, "bias", None, where)
            unc = d.get("uncertainty", {})
            gs = d.get("g_sensitivity")
            m, bias = array_field(d, "M", (3, 3), "calibration", where), array_field(d, "bias", (3,), "calibration", where, f)
            kga = None if gs is None else array_field(d, "g_sensitivity", (3, 3), "calibration", where, f)
            return cls(
                sensor=d["sensor"], M=m, bias=bias,
                sigma_M=np.array(unc.get("M", np.full((3, 3), np.nan)), float).reshape(3, 3),
                sigma_bias=np.array(unc.get("bias", [np.nan] * 3), float).reshape(3) * f,
                units=u, method=d.get("method", ""),
                residuals={k: np.array(v, float) * f for k, v in d.get("residuals", {}).items()},
                checks={k: np.array(v, float) * f for k, v in d.get("checks", {}).items()},
                notes=tuple(d.get("notes", [])),
                g_sensitivity=kga,
                level=str(unc.get("level", PLAIN_LEVEL)),
                rotations=tuple(_rows(d.get("rotations", []), where)),
                sigma_g_sensitivity=None if kga is None or unc.get("g_sensitivity") is None else
                np.array(unc["g_sensitivity"], float).reshape(3, 3) * f,
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"malformed calibration ({malformed(exc)}); regenerate it", where) from None

    def correct(self, raw: np.ndarray, acc: np.ndarray | None = None) -> np.ndarray:
        """``true = M^-1 (raw - bias - K_ga acc)``.

        Parameters
        ----------
        raw : ndarray, shape (n, 3)
            Readings, SI (or counts).
        acc : ndarray, shape (n, 3), optional
            True specific force, m/s^2, for a gyro with a g-sensitivity.

        Returns
        -------
        ndarray, shape (n, 3)
        """
        off = self.bias if self.g_sensitivity is None or acc is None else self.bias + acc @ self.g_sensitivity.T
        return np.linalg.solve(self.M, (np.asarray(raw) - off).T).T


def _rows(rows: object, where: str) -> list[dict]:
    """The ``rotations`` table of a file: a list of objects."""
    if not isinstance(rows, list) or not all(isinstance(r, dict) for r in rows):
        raise InputError("malformed calibration: rotations must be a list of objects; regenerate it", where)
    return rows


class CalibrationSet(Result, format=FORMAT, convention=CONVENTION):
    """The calibration file: one session's accelerometer and/or gyroscope.

    Attributes
    ----------
    sensors : dict of str -> Calibration
        Keys among :data:`SENSORS`.
    inputs : dict
        The files and settings the calibration came from.
    """

    sensors: dict
    inputs: dict = field(default_factory=dict)

    def figures_of_merit(self) -> tuple:
        """Every sensor's figures (:meth:`Calibration.figures_of_merit`)."""
        return tuple(f for cal in self.sensors.values() for f in cal.figures_of_merit())

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "sensors", by_sensor(self.sensors, SENSORS, "a calibration set"))
        object.__setattr__(self, "inputs", dict(self.inputs))

    def to_dict(self) -> dict:
        """The versioned JSON form: the envelope, ``inputs``, then one key per sensor."""
        return {**self.envelope({k: c.units for k, c in self.sensors.items()}), "inputs": self.inputs,
                **{k: c.to_dict() for k, c in self.sensors.items()}}

    @classmethod
    def from_dict(cls, d: dict, where: str = "calibration") -> CalibrationSet:
        """Read the form written by :meth:`to_dict` (any version up to the current one)."""
        cls.check_envelope(d, where, keys=["inputs", *SENSORS])
        for k in SENSORS:  # a hand-edited A (the reader takes M) is refused, not ignored
            if isinstance(d.get(k), dict) and "M" in d[k] and "A" in d[k]:
                try:
                    m, a = np.array(d[k]["M"], dtype=float), np.array(d[k]["A"], dtype=float)
                except (TypeError, ValueError):
                    continue  # malformed: Calibration.from_dict says so
                check_inverse(m, a, where, f"{k}.")
        sensors = {k: Calibration.from_dict(d[k], f"{where}: {k}") for k in SENSORS if k in d}
        if not sensors:
            raise InputError(f"holds no {' or '.join(SENSORS)} calibration", where)
        inputs = d.get("inputs") or {}
        if not isinstance(inputs, dict):
            raise InputError("inputs must be an object", f"{where}: inputs")
        return cls(sensors, inputs)

    def sensor(self, kind: str | None = None, where: str = "calibration") -> Calibration:
        """The calibration of one sensor: ``kind``, or the only one the set holds.

        Raises
        ------
        InputError
            ``kind`` is not in the set, or it is None and the set holds both sensors.
        """
        held = ", ".join(self.sensors)
        if kind is None:
            if len(self.sensors) == 1:
                return next(iter(self.sensors.values()))
            raise InputError(f"holds {held}: choose one with {{sensor}}", where)
        if kind not in self.sensors:
            raise InputError(f"holds {held}, no {kind} calibration; choose another {{sensor}}", where)
        return self.sensors[kind]

    def correction(self, sensor: str | None = None, where: str = "calibration") -> Calibration:
        """The calibration that corrects logs of ``sensor`` (see :meth:`sensor`).

        Refuses (naming ``where`` and the sensor) an ``M`` that is not finite, singular or has
        ``det <= 0`` (:func:`align.plausible.check_usable_model`).
        """
        cal = self.sensor(sensor, where)
        check_usable_model(cal.M, f"{where}: {cal.sensor}")
        return cal

    def as_imucal(self) -> dict:
        """The pair as imucal's ``FerrarisCalibrationInfo`` JSON (see :func:`align.io.consumers.imucal_dict`)."""
        missing = [k for k in SENSORS if k not in self.sensors]
        if missing:
            raise InputError(f"imucal's format needs both sensors; this calibration has no {', '.join(missing)}")
        acc, gyr = self.sensors["accelerometer"], self.sensors["gyroscope"]
        return imucal_dict(acc.M, acc.bias, gyr.M, gyr.bias, gyr.g_sensitivity)
