"""A log source, and the one column convention of every command that reads a log.

A :class:`LogSource` says where a sensor's readings are and how to read them: the file, its data
columns, its time column (or a sample rate), the unit of the readings and the logger's format
options. Every job reads its logs through :meth:`LogSource.read`, so a column, time or unit
option means the same on every command:

* ``columns``: the data columns, three names (``x,y,z``; six for a job that reads two sensors
  from one file). Four names (seven, ...) keep their old meaning: the time column first. None:
  the sensor's default names (:attr:`align.vocab.Sensor.columns`), or, when the file has none of
  them, the old defaults it has (``gyr_x``; :attr:`~align.vocab.Sensor.old_columns`).
* ``time_column``: the time column's name (default ``time``); not read when ``rate_hz`` is given.
* a name given twice, a time column among the data columns, or a name the file lacks is one
  :class:`~align.errors.InputError` naming ``{columns}`` or ``{time_column}`` (exit 2).

Public names
------------
LogSource, column_names, check_distinct, DEFAULT_TIME, STREAM_COLUMNS
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from align.errors import InputError, literal
from align.io.formats import LogFormat
from align.io.logs import SensorLog, read_sensor_log
from align.vocab import Sensor

__all__ = ["LogSource", "column_names", "check_distinct", "DEFAULT_TIME", "STREAM_COLUMNS"]

#: the time column's name when none is given
DEFAULT_TIME = "time"
#: the columns a reader of several streams (a bag, a ULog, DataFlash) or of a log folder names, by the one convention
#: (:mod:`align.io.readers`): time in s, gyro, accelerometer (an old default name of the accelerometer), magnetometer
STREAM_COLUMNS = (DEFAULT_TIME, *Sensor.GYROSCOPE.columns, "accel_x", "accel_y", "accel_z", *Sensor.MAGNETOMETER.columns,
                  "temperature")


def _names(columns: str | Sequence[str]) -> list[str]:
    items = columns.split(",") if isinstance(columns, str) else list(columns)
    return [str(c).strip() for c in items if str(c).strip()]


def column_names(columns: str | Sequence[str] | None, time_column: str | None, rate_hz: float | None,
                 defaults: Sequence[str], field: str = "columns") -> tuple[str | None, list[str]]:
    """The time column (None: read at ``rate_hz``) and the data columns, by the one convention.

    Parameters
    ----------
    columns : str or sequence of str or None
        ``"x,y,z"`` (data), ``"time,x,y,z"`` (time first, the old spelling), or None for ``defaults``.
    time_column : str or None
        The time column's name; None: ``"time"`` unless four names put another first.
    rate_hz : float or None
        A sample rate: then no time column is read (the first of four names is dropped).
    defaults : sequence of str
        The data columns when ``columns`` is None; their count is the count expected.
    field : str
        The option that gave ``columns``, for messages.

    Returns
    -------
    time : str or None
    data : list of str

    Raises
    ------
    InputError
        A wrong count, a name given twice, or the time column among the data columns.

    Examples
    --------
    >>> column_names("gx,gy,gz", None, None, ("gyro_x", "gyro_y", "gyro_z"))
    ('time', ['gx', 'gy', 'gz'])
    >>> column_names("t,gx,gy,gz", None, None, ("gyro_x", "gyro_y", "gyro_z"))
    ('t', ['gx', 'gy', 'gz'])
    >>> column_names(None, "stamp", 100.0, ("gyro_x", "gyro_y", "gyro_z"))
    (None, ['gyro_x', 'gyro_y', 'gyro_z'])
    """
    k = len(defaults)
    where = "{" + field + "}"
    given = list(defaults) if columns is None else _names(columns)
    if len(given) == k + 1:  # time first: the old spelling of every command
        first, given = given[0], given[1:]
        if time_column is not None and time_column != first and rate_hz is None:
            raise InputError(f"names '{literal(first)}' as the time column, but {{time_column}} says "
                             f"'{literal(time_column)}'; give the data columns alone with {{time_column}}", where)
        time_column = time_column or first
    if len(given) != k:
        raise InputError(f"give {k} names ({','.join(defaults)}), or {k + 1} with the time column first; got "
                         f"{len(given)} ({literal(','.join(given)) or 'none'})", where)
    seen: set[str] = set()
    for name in given:
        if name in seen:
            raise InputError(f"'{literal(name)}' is named twice; name each data column once", where)
        seen.add(name)
    if rate_hz is not None:
        return None, given
    time = time_column or DEFAULT_TIME
    if time in seen:
        raise InputError(f"'{literal(time)}' is both the time column and a data column; name another "
                         "{time_column}, or give {rate_hz} for a log without time", where)
    return time, given


@dataclass(frozen=True, kw_only=True)
class LogSource:
    """Where a sensor's readings are and how to read them.

    Attributes
    ----------
    path : Path
        The log file (any registered format, :mod:`align.io.readers`).
    columns : tuple of str or None
        Data columns (see the module docstring); None: the sensor's defaults.
    time_column : str or None
        The time column (None: ``time``, or the first of four names).
    rate_hz : float or None
        Sample rate, Hz, for a log read without its time column.
    units : str or None
        Unit of the readings as typed (``"deg/s"``, ``"131 LSB/(deg/s)"``); None: the unit the file states
        (ULog, bags, DataFlash), else the sensor's default.
    format : LogFormat
        Preamble, comment, delimiter, time unit of a text log; the topic of a log of several streams.
    temperature_column : str or None
        A temperature column read beside the readings (``SensorLog.temperature``, degrees Celsius).
    temperature_units : str or None
        Its unit (``degC``, ``K``, ``degF``); None: the file's, else degrees Celsius.

    Examples
    --------
    >>> src = LogSource(path=Path("session.csv"), columns=("gx", "gy", "gz"), units="deg/s")
    >>> src.names(Sensor.GYROSCOPE)
    ('time', ['gx', 'gy', 'gz'])
    """

    path: Path
    columns: tuple[str, ...] | None = None
    time_column: str | None = None
    rate_hz: float | None = None
    units: str | None = None
    format: LogFormat = field(default_factory=LogFormat)
    temperature_column: str | None = None
    temperature_units: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "path", Path(self.path))
        if isinstance(self.columns, str):
            object.__setattr__(self, "columns", tuple(_names(self.columns)))

    def names(self, sensor: Sensor, defaults: Sequence[str] | None = None, field: str = "columns"
              ) -> tuple[str | None, list[str]]:
        """The time and data columns for ``sensor`` (:func:`column_names`), before the file is looked at."""
        return column_names(self.columns, self.time_column, self.rate_hz, defaults or sensor.columns, field)

    def read(self, sensor: Sensor, *, expect: str | None = None, counts: bool = False, field: str | None = None,
             defaults: Sequence[str] | None = None, columns_field: str = "columns",
             default_units: str | None = None) -> SensorLog:
        """The readings of ``sensor``: time in s, data in SI (or counts), and how the file was read.

        With no columns given, the sensor's default names are read, or the first set of its old default
        names (:attr:`~align.vocab.Sensor.old_columns`) the file holds instead.

        Parameters
        ----------
        sensor : Sensor
        expect : str, optional
            The dimension the unit must have (default: the sensor's; ``"counts"`` for raw counts).
        counts : bool
            Whether the readings may stay in raw counts.
        field : str, optional
            The option that gave the unit, for messages (default ``gyro_units`` for a gyro, else ``units``).
        defaults : sequence of str, optional
            Data columns when none are given (default: the sensor's).
        columns_field : str
            The option that gave the columns, for messages.
        default_units : str, optional
            The unit when neither :attr:`units` nor the file gives one (default: the sensor's, ``deg/s``, ...).

        Returns
        -------
        SensorLog
            ``t`` (n,) s, ``data`` (n, k) SI.
        """
        expect = expect or sensor.dimension
        time, cols = self.names(sensor, defaults, columns_field)
        if self.columns is None and defaults is None:
            cols = self._defaults_present(sensor, cols, time)
        if self.temperature_column is not None and self.temperature_column in cols + [time]:
            raise InputError(f"'{literal(self.temperature_column)}' is both the temperature column and a "
                             f"{'time' if self.temperature_column == time else 'data'} column; name each once",
                             "{temperature_column}")
        return read_sensor_log(self.path, cols, self.units, time, self.rate_hz, expect=expect, log_format=self.format,
                               counts=counts, field=field or ("gyro_units" if sensor is Sensor.GYROSCOPE else "units"),
                               default_units=default_units or sensor.unit, temperature_column=self.temperature_column,
                               temperature_units=self.temperature_units)

    def data_names(self, sensor: Sensor, field: str = "columns") -> list[str]:
        """The data columns :meth:`read` reads for ``sensor``: those given, or the defaults the file holds."""
        time, cols = self.names(sensor, field=field)
        return cols if self.columns is not None else self._defaults_present(sensor, cols, time)

    def _defaults_present(self, sensor: Sensor, cols: list[str], time: str | None) -> list[str]:
        """The default names, or the first old set the file's header holds when it lacks the defaults."""
        header = self.header()
        if header is None or all(c in header for c in cols):
            return cols
        for old in sensor.old_columns:
            if all(c in header for c in old):
                return list(old)
        return cols

    def header(self) -> list[str] | None:
        """The column names of the file (None for a format without names, or a file that cannot be read:
        the reader then says why); for a log of several streams or a log folder, the names of the one
        convention (:data:`STREAM_COLUMNS`: its reader names what it reads so)."""
        try:
            from align.io.readers import reader_for

            p = self.path
            reader = reader_for(p, self.format)
            if reader.streams or reader.folder:
                return list(STREAM_COLUMNS)
            if reader.name == "parquet":
                import pyarrow.parquet as pq

                return list(pq.read_schema(p).names)
            if reader.name == "csv":
                from align.io.formats import content_lines

                lines = content_lines(p, self.format, 1)
                return [c.strip().strip('"').strip() for c in lines[0][1].split(self.format.separator)] if lines else None
        except Exception:  # noqa: BLE001 - a header that cannot be read is the reader's to report
            return None
        return None

    def inputs(self) -> dict[str, Any]:
        """How the source was given, for a result's ``inputs``."""
        return {"log": str(self.path), "columns": None if self.columns is None else ",".join(self.columns),
                "time_column": self.time_column, "rate_hz": self.rate_hz, "units": self.units,
                **self.format.to_dict(),
                **({"temperature_column": self.temperature_column, "temperature_units": self.temperature_units}
                   if self.temperature_column is not None else {})}


def check_distinct(first: tuple[Sensor, Sequence[str], str], second: tuple[Sensor, Sequence[str], str]) -> None:
    """Refuse one column named for two sensors of one file (``(sensor, names, field)`` each).

    Raises
    ------
    InputError
        Naming the column, both sensors and the second sensor's option (``{field}``).

    Examples
    --------
    >>> check_distinct((Sensor.GYROSCOPE, ["gx", "gy", "gz"], "gyro_columns"),
    ...                (Sensor.ACCELEROMETER, ["ax", "ay", "az"], "accel_columns"))
    """
    (s1, n1, _), (s2, n2, field2) = first, second
    for name in n2:
        if name in n1:
            raise InputError(f"'{literal(name)}' is both a {s1.value} and an {s2.value} column; name each column "
                             "once", "{" + field2 + "}")
