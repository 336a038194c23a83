"""The ``calibrate mag`` job: a magnetometer's hard and soft iron from a tumbling capture, and its misalignment
from axis-down turns.

The package :mod:`align.calibration.jobs` re-exports its names.

Public names
------------
MagOptions, MagInputs, MAG, calibrate_mag
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np

from align.calibration.jobs.common import log_source
from align.calibration.magnetometer import MagCalibration
from align.errors import InputError, literal
from align.io.source import LogSource, column_names
from align.job import Job, Progress, fields_signature
from align.vocab import Sensor

__all__ = ["MagOptions", "MagInputs", "MAG", "calibrate_mag"]


def _axis_down(value: Any) -> dict[str, Path | tuple[int, int]] | None:
    """``x=FILE,...`` text or a mapping -> ``{"x": Path or (start, stop), ...}``."""
    if value is None:
        return None
    from align.calibration.axisdown import parse_axis_down

    spec = parse_axis_down(value) if isinstance(value, str) else dict(value)
    if sorted(spec) != ["x", "y", "z"]:
        raise InputError("give one capture for each of x, y and z", "{axis_down}")
    return {a: (tuple(int(s) for s in v) if isinstance(v, (tuple, list)) else Path(v))  # type: ignore[misc]
            for a, v in spec.items()}


def _axis_down_text(spec: Mapping[str, Any]) -> str:
    return ",".join(f"{a}={v[0]}:{v[1]}" if isinstance(v, tuple) else f"{a}={v}" for a, v in spec.items())


@dataclass(frozen=True, kw_only=True)
class MagOptions:
    """Options of ``calibrate mag``: a magnetometer capture while tumbling the device.

    Attributes
    ----------
    log : LogSource
        The capture (default columns ``mag_x, mag_y, mag_z`` or the old ``mx, my, mz``; no time column
        is read); unit uT, nT, gauss, mG, ``"counts"`` or the size of one count (``"0.92 mG"``); None: the unit
        the file states, else uT.
    accel_columns : tuple of str or None
        Simultaneous accelerometer columns in ``log`` (dip angle, alignment to gravity; any unit).
    field : float or None
        Known field strength to refine to, T (counts for a log read in counts).
    model : {"sphere", "diagonal", "symmetric"}
        Soft-iron model.
    dip : float or None
        Magnetic dip for the heading-error prediction without an accelerometer, rad.
    axis_down : dict or None
        Axis-down turns for the misalignment: ``{"x": Path or (start, stop), "y": ..., "z": ...}``
        (a file with the log's columns, or samples of the log, stop exclusive); the text
        ``"x=FILE,y=FILE,z=FILE"`` is accepted.
    limits : Path or None
        A limits file (:mod:`align.limits`) to judge the figures of merit against; None: the default limits.
    """

    log: LogSource
    accel_columns: tuple[str, ...] | None = None
    field: float | None = None
    model: Literal["sphere", "diagonal", "symmetric"] = "symmetric"
    dip: float | None = None
    axis_down: dict[str, Path | tuple[int, int]] | None = None
    limits: Path | None = None

    def __post_init__(self) -> None:
        if isinstance(self.accel_columns, str):
            object.__setattr__(self, "accel_columns", tuple(c.strip() for c in self.accel_columns.split(",")
                                                            if c.strip()))
        object.__setattr__(self, "axis_down", _axis_down(self.axis_down))


@dataclass(frozen=True)
class MagInputs:
    """The checked inputs of a magnetometer capture.

    Attributes
    ----------
    m : ndarray, shape (n, 3)
        The readings of the ellipsoid fit (the tumble), T or counts.
    acc : ndarray, shape (n, 3) or None
        Simultaneous accelerometer readings (as in the file).
    shown : str
        The unit the results show.
    captures : dict
        Per axis-down axis ``(readings (m, 3+k) as in the file, source)``.
    scale : float
        Factor from the file's numbers to T.
    columns : tuple of str
        The magnetometer columns read.
    units : str
        The unit the readings were read in (typed, stated by the file, or uT).
    stream : dict
        What the result records of the stream read (``stream``, ``units_stated``: as
        :meth:`align.io.logs.SensorLog.stream_inputs`).
    notes : tuple of str
        The reader's remarks (a truncated last record), after the file's name.
    """

    m: np.ndarray
    acc: np.ndarray | None
    shown: str
    captures: dict
    scale: float
    columns: tuple[str, ...]
    units: str = Sensor.MAGNETOMETER.unit
    stream: dict = field(default_factory=dict)
    notes: tuple[str, ...] = ()


def _mag_columns(o: MagOptions) -> tuple[list[str], list[str]]:
    """The magnetometer's and the accelerometer's column names (each named once)."""
    sensor = Sensor.MAGNETOMETER
    _, mag = column_names(o.log.columns, None, 1.0, sensor.columns, "columns")  # no time column is read
    if o.log.columns is None:
        mag = o.log._defaults_present(sensor, mag, None)
    acc: list[str] = []
    if o.accel_columns is not None:
        _, acc = column_names(o.accel_columns, None, 1.0, Sensor.ACCELEROMETER.columns, "accel_columns")
        for name in acc:
            if name in mag:
                raise InputError(f"'{literal(name)}' is both a magnetometer and an accelerometer column; name each "
                                 "column once", "{accel_columns}")
    return mag, acc


def _mag_read(o: MagOptions) -> MagInputs:
    import align.io as fileio
    from align.calibration.axisdown import axis_down_captures
    from align.io.logs import check_readings
    from align.io.readings import units_of
    from align.io.tables import read_table
    from align.units import parse_scale

    if o.model not in ("sphere", "diagonal", "symmetric"):
        raise InputError(f"'{literal(str(o.model))}' is no soft-iron model; give sphere, diagonal or symmetric",
                         "{model}")
    fmt = o.log.format
    if o.log.units is not None:  # a typed unit is checked before the file is read
        parse_scale(o.log.units, "magnetic_field", "{mag_units}")
    mag, acc = _mag_columns(o)
    wanted = mag + acc
    got = read_table(o.log.path, wanted, None, fmt)
    data = got.data
    unit, stated = units_of(o.log.units, got.unit(mag), Sensor.MAGNETOMETER.unit, "magnetic_field", "mag_units",
                            str(o.log.path))
    scale, shown = parse_scale(unit, "magnetic_field", "{mag_units}")
    check_readings(data, str(o.log.path))
    stream = {**({"stream": dict(got.source)} if got.source else {}), **({"units_stated": unit} if stated else {})}

    def read(path: str) -> np.ndarray:  # an axis-down capture file: the log's columns, checked as the log is
        got = fileio.read_columns(path, wanted, log_format=fmt)[1]
        check_readings(got, str(path))
        return got

    captures: dict = {}
    tumble = data
    if o.axis_down is not None:
        spec = {a: (v if isinstance(v, tuple) else str(v)) for a, v in o.axis_down.items()}
        captures, tumble = axis_down_captures(spec, data, str(o.log.path), read)
    if o.field is not None and not o.field > 0:
        raise InputError("give a field strength > 0, e.g. '48.5 uT'", "{field}")
    return MagInputs(tumble[:, :3] * scale, tumble[:, 3:6] if acc else None, shown, captures, scale, tuple(mag), unit,
                     stream, tuple(f"{o.log.path}: {n}" for n in got.notes))


def _mag_compute(i: MagInputs, o: MagOptions, progress: Progress | None) -> MagCalibration:
    from align.calibration import calibrate_magnetometer, with_gravity_alignment
    from align.calibration.axisdown import with_axis_down

    cal = calibrate_magnetometer(i.m, i.shown, o.field, o.model, i.acc, o.dip, where=str(o.log.path))
    if o.axis_down is not None:
        cal = with_axis_down(cal, {a: c[0][:, :3] * i.scale for a, c in i.captures.items()},
                             {a: c[0][:, 3:6] for a, c in i.captures.items()} if i.acc is not None else None,
                             {a: c[1] for a, c in i.captures.items()})
    elif i.acc is not None:
        cal = with_gravity_alignment(cal, i.m, i.acc)
    if progress is not None:
        progress(len(i.m))
    return cal.replace(inputs={"log": str(o.log.path), "columns": ",".join(i.columns), "mag_units": i.units,
                               **o.log.format.to_dict(),
                               **({"axis_down": _axis_down_text(o.axis_down)} if o.axis_down is not None else {}),
                               **i.stream}, notes=tuple(cal.notes) + i.notes)


def _mag_files(o: MagOptions) -> dict[str, Path | None]:
    files: dict[str, Path | None] = {"log": o.log.path}
    for axis, v in (o.axis_down or {}).items():
        if isinstance(v, Path):
            files[f"axis_down.{axis}"] = v
    return files


MAG: Job[MagOptions, MagInputs, MagCalibration] = Job(
    "calibrate mag", MagOptions, _mag_read, _mag_compute, _mag_files,
    "magnetometer hard and soft iron (ellipsoid fit), and the misalignment from axis-down turns")


@fields_signature(MagOptions)
def calibrate_mag(*, log: LogSource | str | Path, progress: Progress | None = None, **fields: Any) -> MagCalibration:
    """Calibrate a magnetometer from a tumbling capture (``imu-align calibrate mag``).

    Parameters
    ----------
    log : LogSource or str or Path
        The capture; a path takes ``columns``, ``units`` and ``format`` beside it.
    progress : callable, optional
        Called with the samples done.
    **fields
        The other fields of :class:`MagOptions` (``accel_columns``, ``field`` T, ``model``, ``dip`` rad,
        ``axis_down``).

    Returns
    -------
    MagCalibration
        Hard iron (3,) T, soft iron (3, 3), the predicted heading error, with provenance.

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> from pathlib import Path
    >>> v = np.random.default_rng(3).normal(size=(600, 3))
    >>> m = 48.0 * v / np.linalg.norm(v, axis=1)[:, None] + [10.0, -5.0, 3.0]
    >>> d = Path(tempfile.mkdtemp())
    >>> np.savetxt(d / "mag.csv", m, delimiter=",", header="mag_x,mag_y,mag_z", comments="")
    >>> cal = calibrate_mag(log=d / "mag.csv", units="uT")
    >>> np.round(np.asarray(cal.hard_iron) * 1e6, 3).tolist()
    [10.0, -5.0, 3.0]
    """
    src = log_source(log, fields)
    return MAG.run(MagOptions(log=src, **fields), progress=progress)
