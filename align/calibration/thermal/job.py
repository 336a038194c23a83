"""The ``calibrate thermal`` job: each sensor axis' bias against temperature from a static log with a temperature
column (:mod:`align.calibration.thermal`).

Public names
------------
ThermalOptions, ThermalInputs, THERMAL, calibrate_thermal
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from align.calibration.jobs.common import accel_source, read_sensor, same_file, shown_columns
from align.calibration.thermal.result import ThermalCalibration
from align.calibration.thermal.sensor import Settings
from align.errors import InputError
from align.io.logs import SensorLog
from align.io.source import LogSource
from align.job import Job, Progress, fields_signature, quantity
from align.vocab import Sensor

__all__ = ["ThermalOptions", "ThermalInputs", "THERMAL", "calibrate_thermal"]

#: the sensors a thermal calibration fits, in the order they are read
SENSORS = (Sensor.GYROSCOPE.value, Sensor.ACCELEROMETER.value)


@dataclass(frozen=True, kw_only=True)
class ThermalOptions:
    """Options of ``calibrate thermal``.

    Attributes
    ----------
    log : LogSource
        The static log: its time column (or ``rate_hz``), format, ``temperature_column`` (required) and
        ``temperature_units`` (C, K or degF; None: the file's, else C), and the gyro's ``columns`` (default
        ``gyro_x, gyro_y, gyro_z``) and ``units`` (None: the file's, else deg/s).
    accel : LogSource or None
        The accelerometer's columns and unit in the same file (read with ``log``'s format, time column and
        temperature); None: ``acc_x, acc_y, acc_z`` (or the old names), in the file's unit, else m/s^2.
    sensors : tuple of str
        The sensors to calibrate: ``gyroscope`` and/or ``accelerometer``.
    order : int or None
        A fixed polynomial order; None: chosen per axis by blocked cross-validation up to ``max_order``.
    max_order : int
        Highest order tried (3 for the autopilots' files, which take a cubic).
    lag : bool or None
        The thermal-lag term in dT/dt: on, off, or chosen by cross-validation (None).
    window_s : float
        Window of the temperature rate (a straight line fitted over it), s.
    min_rate : float
        Slowest ``|dT/dt|`` that is a heating or cooling branch, C/s.
    min_branch_s : float
        Shortest run of one sign that is a branch, s.
    hysteresis : bool
        Detect the heating and cooling branches and report the hysteresis (both branches then needed).
    reference : float or None
        Reference temperature of the result, C; None: the middle of the range.
    motion_factor : float
        A window varying this many times the noise is motion (refused).
    """

    log: LogSource
    accel: LogSource | None = None
    sensors: tuple[str, ...] = SENSORS
    order: int | None = None
    max_order: int = 5
    lag: bool | None = None
    window_s: float = quantity(20.0, "time", gt=0)
    min_rate: float = 0.002
    min_branch_s: float = quantity(120.0, "time", gt=0)
    hysteresis: bool = True
    reference: float | None = None
    motion_factor: float = quantity(100.0, "dimensionless", gt=0)

    def __post_init__(self) -> None:
        names = tuple(Sensor.parse(s).value for s in ((self.sensors,) if isinstance(self.sensors, str)
                                                       else self.sensors))
        if not names or any(n not in SENSORS for n in names):
            raise InputError(f"give gyroscope and/or accelerometer, not {', '.join(names) or 'none'}", "{sensors}")
        object.__setattr__(self, "sensors", tuple(s for s in SENSORS if s in names))
        if self.order is not None and not 0 <= self.order <= 8:
            raise InputError(f"give an order from 0 to 8, not {self.order}", "{order}")
        if not 0 <= self.max_order <= 8:
            raise InputError(f"give a maximum order from 0 to 8, not {self.max_order}", "{max_order}")

    @property
    def settings(self) -> Settings:
        """The fit's settings these options make."""
        return Settings(self.order, self.max_order, self.lag, self.window_s, self.min_rate, self.min_branch_s,
                        self.hysteresis, self.reference, motion_factor=self.motion_factor)


@dataclass(frozen=True)
class ThermalInputs:
    """The checked inputs: each sensor's readings (SI) with the temperature (C), and the columns read.

    Attributes
    ----------
    logs : dict of str -> SensorLog
    columns : dict of str -> str
    """

    logs: dict
    columns: dict


def _source(o: ThermalOptions, sensor: str) -> LogSource:
    if sensor == Sensor.GYROSCOPE.value:
        return o.log
    acc = accel_source(o.log, o.accel)
    if same_file(o.log, acc):  # one file: its time column (or rate) and format
        acc = replace(acc, format=o.log.format)
        if acc.time_column is None and acc.rate_hz is None:
            acc = replace(acc, time_column=o.log.time_column, rate_hz=o.log.rate_hz)
    return replace(acc, temperature_column=o.log.temperature_column, temperature_units=o.log.temperature_units)


def _thermal_read(o: ThermalOptions) -> ThermalInputs:
    if o.log.temperature_column is None:
        raise InputError("a thermal calibration needs the temperature: name its column with {temperature_column}",
                         str(o.log.path))
    logs, columns = {}, {}
    for sensor in o.sensors:
        s = Sensor(sensor)
        src = _source(o, sensor)
        field = "gyro" if s is Sensor.GYROSCOPE else "accel"
        logs[sensor] = read_sensor(src, s, field=f"{field}_units", columns_field=f"{field}_columns", counts=False)
        time, cols = src.names(s, field=f"{field}_columns")
        columns[sensor] = shown_columns(time, src.data_names(s, f"{field}_columns"))
    return ThermalInputs(logs, columns)


def _thermal_compute(i: ThermalInputs, o: ThermalOptions, progress: Progress | None) -> ThermalCalibration:
    from align.calibration.thermal.sensor import fit_sensor

    where = str(o.log.path)
    sensors = {}
    first: SensorLog | None = None
    for name, got in i.logs.items():
        assert got.temperature is not None  # read with its temperature column
        sensors[name] = fit_sensor(got.t, got.temperature, got.data, name, got.shown, got.rate_hz, o.settings, where)
        first = first or got
        if progress is not None:
            progress(len(got.t))
    assert first is not None
    s = o.settings
    inputs: dict[str, Any] = {
        "log": where, "columns": dict(i.columns), "temperature_column": o.log.temperature_column,
        "temperature_units": o.log.temperature_units or "degC", "rate_hz": first.rate_hz,
        "settings": {"order": s.order, "max_order": s.max_order, "lag": s.lag, "window_s": s.window_s,
                     "min_rate": s.min_rate, "min_branch_s": s.min_branch_s, "hysteresis": s.hysteresis,
                     "reference": s.reference, "motion_factor": s.motion_factor},
        "device_ids": {name: got.source.get("device_id") for name, got in i.logs.items()},
        **first.inputs()}
    return ThermalCalibration(sensors, inputs)


def _thermal_files(o: ThermalOptions) -> dict[str, Path | None]:
    return {"log": o.log.path}


THERMAL: Job[ThermalOptions, ThermalInputs, ThermalCalibration] = Job(
    "calibrate thermal", ThermalOptions, _thermal_read, _thermal_compute, _thermal_files,
    "bias against temperature per sensor axis: order by cross-validation, thermal lag, hysteresis, firmware files")


@fields_signature(ThermalOptions)
def calibrate_thermal(*, log: LogSource | str | Path, progress: Progress | None = None,
                      **fields: Any) -> ThermalCalibration:
    """Thermal calibration of a static log (``imu-align calibrate thermal``).

    Parameters
    ----------
    log : LogSource or str or Path
        The log; a path takes ``columns``, ``time_column``, ``rate_hz``, ``units``, ``format``,
        ``temperature_column`` and ``temperature_units`` beside it.
    progress : callable, optional
        Called with the samples done.
    **fields
        The other fields of :class:`ThermalOptions`.

    Returns
    -------
    ThermalCalibration

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> from align.calibration.thermal.simulate import Profile, random_truth, simulate
    >>> prof = Profile(-10.0, 50.0, 5 / 60, 5 / 60, 0.0, 1.0)
    >>> rng = np.random.default_rng(2)
    >>> run = simulate(prof, random_truth(rng, prof, 0.01), 2.0, 0.002, rng)
    >>> d = Path(tempfile.mkdtemp())
    >>> np.savetxt(d / "log.csv", np.column_stack([run.t, run.data, run.temperature]), delimiter=",",
    ...            header="time,acc_x,acc_y,acc_z,temp", comments="")
    >>> from align.io.formats import LogFormat
    >>> r = calibrate_thermal(log=d / "log.csv", temperature_column="temp", format=LogFormat(time_units="s"),
    ...                       sensors=("accelerometer",))
    >>> r.sensors["accelerometer"].axes[0].order
    3
    """
    given = {k: fields.pop(k) for k in ("columns", "time_column", "rate_hz", "units", "format", "temperature_column",
                                        "temperature_units") if k in fields}
    if isinstance(log, LogSource):
        if given:
            raise TypeError(f"give {', '.join(given)} inside the LogSource, not beside it")
        src = log
    else:
        src = LogSource(path=Path(log), **given)
    return THERMAL.run(ThermalOptions(log=src, **fields), progress=progress)
