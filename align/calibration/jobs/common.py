"""What the calibration jobs share: a log given as a path with its source fields, one sensor's readings with
its option named, the columns, streams and reader notes a result records, the static detector the options set.

Public names
------------
SOURCE_FIELDS, log_source, read_sensor, shown_columns, same_file, accel_source, accel_stream, with_remarks, detector_dict,
static_detector
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from align.calibration.accel import StaticDetector
from align.errors import InputError
from align.io.logs import SensorLog
from align.io.source import LogSource, check_distinct
from align.vocab import Sensor

__all__ = ["SOURCE_FIELDS", "log_source", "read_sensor", "shown_columns", "same_file", "accel_source", "accel_stream",
           "with_remarks", "detector_dict", "static_detector"]

#: the fields of a :class:`LogSource` a convenience call takes beside a log given as a path
SOURCE_FIELDS = ("columns", "time_column", "rate_hz", "units", "format")

def log_source(log: LogSource | str | Path, fields: dict[str, Any]) -> LogSource:
    """``log`` as a :class:`LogSource`: a path with the source fields taken out of ``fields``."""
    given = {k: fields.pop(k) for k in SOURCE_FIELDS if k in fields}
    if isinstance(log, LogSource):
        if given:
            raise TypeError(f"give {', '.join(given)} inside the LogSource, not beside it")
        return log
    return LogSource(path=Path(log), **given)


def read_sensor(src: LogSource, sensor: Sensor, *, field: str, columns_field: str, counts: bool,
          expect: str | None = None) -> SensorLog:
    """One sensor's readings from ``src``, a wrong or missing column named with that sensor's option."""
    try:
        return src.read(sensor, expect=expect, counts=counts, field=field, columns_field=columns_field)
    except InputError as exc:
        if columns_field == "columns" or "{columns}" not in exc.message:
            raise
        raise InputError(exc.message.replace("{columns}", "{" + columns_field + "}"), exc.where) from None


def shown_columns(time: str | None, data: Sequence[str]) -> str:
    """The columns as a result's ``inputs`` records them: ``time,x,y,z``, or ``x,y,z`` read at a rate."""
    return ",".join(([time] if time else []) + list(data))


def same_file(a: LogSource, b: LogSource) -> bool:
    return Path(a.path) == Path(b.path)


def accel_source(log: LogSource, accel: LogSource | None) -> LogSource:
    """The accelerometer's source: ``accel``, or its default columns in m/s^2 in ``log``'s file; in one file, no
    column named for both sensors (:func:`align.io.source.check_distinct`)."""
    acc = accel if accel is not None else LogSource(path=log.path, time_column=log.time_column, rate_hz=log.rate_hz,
                                                    format=log.format)  # its unit: the file's, else m/s^2
    if same_file(log, acc) and (log.columns is not None or acc.columns is not None):
        check_distinct((Sensor.GYROSCOPE, log.data_names(Sensor.GYROSCOPE, "gyro_columns"), "gyro_columns"),
                       (Sensor.ACCELEROMETER, acc.data_names(Sensor.ACCELEROMETER, "accel_columns"), "accel_columns"))
    return acc


def accel_stream(acc: SensorLog, gyr: SensorLog) -> dict[str, Any]:
    """What a result records of the accelerometer's stream beside the gyro's (:meth:`SensorLog.stream_inputs`):
    ``accel_stream`` when it is another stream, ``accel_units_stated`` when the file states its unit."""
    said = acc.stream_inputs("accel_")
    if acc.source == gyr.source:
        said.pop("accel_stream", None)
    return said


def with_remarks(cal: Any, *logs: tuple[SensorLog, LogSource]) -> Any:
    """A calibration with its logs' reader notes (a truncated last record) added to its own, each after its file."""
    extra = tuple(n for got, src in logs for n in got.remarks(str(src.path)))
    return cal.replace(notes=tuple(cal.notes) + extra) if extra else cal


def detector_dict(o: Any) -> dict[str, Any]:
    return {"window_s": o.window_s, "factor": o.factor, "init_static_s": o.init_static_s,
            "min_static_s": o.min_static_s}


def static_detector(o: Any) -> StaticDetector:
    """The static detector the options set."""
    return StaticDetector(o.window_s, o.factor, o.init_static_s, o.min_static_s, getattr(o, "gyro_factor", 1000.0))
