"""The result of ``apply``: a log corrected with an alignment or a calibration, as a value with its file form.

Public names
------------
CorrectedLog, FORMAT
"""

from __future__ import annotations

from dataclasses import field
from typing import Any

import numpy as np

from align.errors import InputError
from align.results import Result
from align.wellformed import malformed

__all__ = ["CorrectedLog", "FORMAT"]

FORMAT = "imu-align.corrected"

#: what the corrected readings are, per sensor (the conventions of the results that correct them)
CONVENTION = ("gyroscope: w = A (g - b), A = M^-1; accelerometer: true = M^-1 (raw - b); "
              "magnetometer: m = soft_iron (raw - hard_iron)")

#: the keys of a corrected-log file after the envelope
FILE_KEYS = ("sensor", "columns", "time", "data", "scale", "time_units", "notes", "inputs")


class CorrectedLog(Result, format=FORMAT, convention=CONVENTION):
    """A log corrected by ``apply``: the readings in SI and how they are written back as a CSV.

    Attributes
    ----------
    sensor : str
        ``"gyroscope"``, ``"accelerometer"`` or ``"magnetometer"``.
    t : ndarray, shape (n,)
        Time, s.
    data : ndarray, shape (n, 3)
        Corrected readings, SI (rad/s, m/s^2, T), or counts for a magnetometer calibrated in counts.
    units : str
        The unit the readings are written in (the log's own unit as given, e.g. ``"deg/s"`` or
        ``"131 LSB/(deg/s)"``; the sensor's unit when a calibration in counts makes them physical).
    scale : float
        SI per written number (``data / scale`` is what the CSV holds).
    columns : tuple of str
        The CSV's columns: the time column (when the log had one) and the three data columns.
    time : ndarray, shape (n,) or None
        The time column as the log had it (in ``time_units``); None for a log read at a sample rate.
    time_units : str or None
        Unit of the written time column (``"s"``, ``"ms"``, ...).
    notes : tuple of str
        Sentences a reader of the CSV needs (the time unit, the unit of counts made physical).
    inputs : dict
        How the log and the result were given.
    """

    sensor: str
    t: np.ndarray
    data: np.ndarray
    units: str
    scale: float
    columns: tuple[str, ...]
    time: np.ndarray | None = None
    time_units: str | None = None
    notes: tuple[str, ...] = ()
    inputs: dict = field(default_factory=dict)

    def table(self) -> np.ndarray:
        """The CSV's numbers, shape (n, len(columns)): the time column as the log had it, then the readings in
        :attr:`units`."""
        parts = ([self.time] if self.time is not None else []) + [np.asarray(self.data) / self.scale]
        return np.column_stack(parts)

    def to_dict(self) -> dict[str, Any]:
        """The versioned JSON form (readings in SI)."""
        return {
            **self.envelope({"time": "s", "data": "SI", "written": self.units}),
            "sensor": str(self.sensor), "columns": list(self.columns),
            "time": np.asarray(self.t, float).tolist(), "data": np.asarray(self.data, float).tolist(),
            "scale": float(self.scale), "time_units": self.time_units,
            "notes": [str(n) for n in self.notes], "inputs": dict(self.inputs),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any], where: str = "corrected log") -> CorrectedLog:
        """Read back what :meth:`to_dict` wrote."""
        cls.check_envelope(d, where, FILE_KEYS)
        try:
            t = np.asarray(d["time"], float)
            data = np.asarray(d["data"], float).reshape(len(t), -1)
            tu = d.get("time_units")
            scale = float(d["scale"])
            from align.io.formats import TIME_UNITS

            columns = tuple(str(c) for c in d["columns"])
            time = t / TIME_UNITS[tu] if tu is not None else None
            return cls(str(d["sensor"]), t, data, str(d["units"]["written"]), scale, columns, time, tu,
                       tuple(str(n) for n in d.get("notes", [])), dict(d.get("inputs") or {}))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"malformed corrected log: {malformed(exc)}; regenerate it", where) from None
