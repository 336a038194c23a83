"""The ``apply`` job: a log corrected with an alignment or a calibration result, checked against it.

``imu-align apply``, the batch and a notebook run :data:`~align.alignment.jobs.APPLY`; the package
:mod:`align.alignment.jobs` re-exports its names.

Public names
------------
MAX_GYRO_RATE, STILL_RATE_MAX, BIAS_CHECKED, ApplyOptions, ApplyInputs, read_apply, compute_apply, apply_input_files, APPLY,
apply, CorrectedLog
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from align.alignment.corrected import CorrectedLog
from align.alignment.jobs.common import check_unit_given, names_read, source
from align.errors import AlignError, InputError, UnitError, literal
from align.io.logs import SensorLog, sensor_scale
from align.io.source import LogSource
from align.job import Job, Progress, fields_signature
from align.units import DEG_S, DIMENSIONS, parse_unit
from align.vocab import Sensor

__all__ = ["MAX_GYRO_RATE", "STILL_RATE_MAX", "BIAS_CHECKED", "ApplyOptions", "ApplyInputs", "read_apply", "compute_apply",
           "apply_input_files", "APPLY", "apply", "CorrectedLog"]

#: the largest rate a MEMS gyro reads, rad/s: beyond the +/-4000 deg/s full scale of the fastest parts
MAX_GYRO_RATE = 5000 * DEG_S
#: the largest rate a gyro reads while still (corrected), rad/s: zero-rate offsets of MEMS gyros stay well within it
STILL_RATE_MAX = 50 * DEG_S
#: the smallest rest reading of a correction (its bias, ``|A b|``) against which a log's unit is judged at rest
BIAS_CHECKED = 0.05 * DEG_S
#: rate units a log is often mistaken for (another's factor is a ratio of theirs)
_RATE_UNITS = ("rad/s", "deg/s", "mdps")


@dataclass(frozen=True, kw_only=True)
class ApplyOptions:
    """What ``apply`` corrects, and with what.

    Attributes
    ----------
    log : LogSource
        The log to correct (a str or Path: the sensor's default columns and time column). Its ``units``, when
        given, is the unit of the readings (field ``units``); None: ``gyro_units`` for a gyro result, else the
        unit the file states (a ULog, a bag), else deg/s for a gyro and the result's own unit otherwise. Its
        ``columns``, None: the sensor's default names.
    alignment : Path
        A result of ``matrix``, ``calibrate ferraris``, ``calibrate accel``, ``calibrate gyro`` or
        ``calibrate mag``.
    sensor : Sensor or None
        The sensor to correct, for a result holding several (a word is parsed: ``"accel"``); None: its only one.
    gyro_units : str or None
        Unit of a gyro log when ``log.units`` is None (a rate unit, or the size of one count); None: the unit the
        file states, else deg/s.
    """

    log: LogSource
    alignment: Path
    sensor: Sensor | str | None = None
    gyro_units: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "log", source(self.log))
        object.__setattr__(self, "alignment", Path(self.alignment))
        if self.sensor is not None:
            try:
                object.__setattr__(self, "sensor", Sensor.parse(getattr(self.sensor, "value", self.sensor)))
            except ValueError:
                raise InputError(f"'{literal(str(self.sensor))}' is not a sensor; choose one of "
                                 f"{', '.join(s.value for s in Sensor)}", "{sensor}") from None


@dataclass(frozen=True)
class ApplyInputs:
    """The checked inputs of ``apply``.

    Attributes
    ----------
    log : SensorLog
        The log as read: ``t`` (n,) s, ``data`` (n, 3) SI (or counts for a result in counts).
    correction : Correction
        What corrects it (the result, or one sensor's calibration of it).
    corrected : ndarray, shape (n, 3)
        The corrected readings, SI (counts for a magnetometer calibrated in counts), checked plausible.
    sensor : Sensor
    units : str
        The unit the log was read in, as given.
    field : str
        The option that gave it (``gyro_units`` or ``units``).
    written : str
        The unit the corrected readings are written in.
    scale : float
        SI per written number.
    time_column : str or None
    columns : tuple of str
        The data columns read.
    notes : tuple of str
        What the correction remarks (samples outside a thermal calibration's range, clamped).
    """

    log: SensorLog
    correction: Any
    corrected: np.ndarray
    sensor: Sensor
    units: str
    field: str
    written: str
    scale: float
    time_column: str | None
    columns: tuple[str, ...]
    notes: tuple[str, ...] = ()


def _dimension_of(unit: str) -> Any:
    return parse_unit(unit).dim


def _typed_unit(options: ApplyOptions, kind: Sensor) -> tuple[str | None, str]:
    """The unit typed for the log (None: the file's, else the default) and the option that gives it."""
    if options.log.units:
        return options.log.units, "units"
    if kind is Sensor.GYROSCOPE:
        return options.gyro_units, "gyro_units"
    return None, "units"


def _log_unit(unit: str, field: str, where: str, correction: Any, kind: Sensor) -> str:
    """The dimension the log is read in (``"counts"`` for a result in counts) for a unit ``unit`` given by
    ``field``; a unit of another dimension than the result's is refused naming the option."""
    expect = kind.dimension
    try:
        own = _dimension_of(correction.units)
    except AlignError:  # the size of one count ('0.92 mG'): the result holds readings of its dimension
        own = DIMENSIONS[expect][0].dim
    counts = DIMENSIONS["counts"][0].dim
    if own == counts:
        expect = "counts"
    try:
        given = _dimension_of(unit)
    except AlignError:  # a count size or a sensitivity ('16384 LSB/g'): read below, against the result's kind
        given = own if own != counts else None
    if given == counts and own != counts:
        return expect  # the log reader asks for the size of one count
    if given != own:
        raise UnitError(f"'{literal(unit)}' is not a unit of the {kind} data of {literal(where)} "
                        f"({literal(correction.units)}); give the log's unit, e.g. {{{field}={correction.units}}}",
                        "{" + field + "}")
    return expect


def _still_blocks(x: np.ndarray, fs: float) -> tuple[np.ndarray, np.ndarray]:
    """Means of the stillest stretches of ``x`` (n, 3): blocks of about 0.5 s whose largest standard deviation is
    within twice the smallest one; and all block means."""
    n = len(x)
    w = int(max(10, min(n // 10 if n >= 100 else n, round(0.5 * fs) if math.isfinite(fs) else 10)))
    nb = max(1, n // w)
    blocks = x[: nb * w].reshape(nb, -1, x.shape[1]) if n >= w else x[None, :, :]
    spread = blocks.std(axis=1).max(axis=1)
    means = blocks.mean(axis=1)
    return means[spread <= 2 * spread.min() + 1e-9], means  # 1e-9 rad/s: rounding of noiseless readings


def _check_gyro(got: SensorLog, correction: Any, unit: str, field: str, where: str) -> None:
    """A gyro log read in physical units must read rates a MEMS gyro reads: none beyond :data:`MAX_GYRO_RATE`, and
    close to zero (corrected) somewhere while it is still (raw counts read as deg/s fail both)."""
    if not len(got.data):
        return
    peak = np.abs(got.data).max(axis=1)
    k = int(np.argmax(peak))
    fix = (f"is the log in another unit than {literal(unit)}? give its unit (deg/s, rad/s, mdps) with {{{field}}}, "
           f"or for raw counts the size of one count, e.g. {{{field}=131 LSB/(deg/s)}} for an MPU-6050 at "
           "+/-250 deg/s")
    if peak[k] > MAX_GYRO_RATE:
        raise UnitError(f"reads {peak[k] / DEG_S:.6g} deg/s at data row {k + 1} as {literal(unit)}, beyond the "
                        f"+/-4000 deg/s full scale of any MEMS gyro: {fix}", where)
    still, _ = _still_blocks(got.data, got.rate_hz)
    rest = np.linalg.norm(correction.correct(still), axis=1)
    if len(rest) and rest.min() > STILL_RATE_MAX:
        raise UnitError(f"corrected, its stillest stretches read at least {rest.min() / DEG_S:.4g} deg/s, beyond the "
                        f"{STILL_RATE_MAX / DEG_S:.0f} deg/s any MEMS gyro reads at rest: {fix} (or the log holds no "
                        "moment at rest)", where)
    _check_bias_at_rest(still, correction, unit, field, where)


def _check_bias_at_rest(still: np.ndarray, correction: Any, unit: str, field: str, where: str) -> None:
    """At rest a log read in its own unit reads about the correction's bias, so that the corrected rest is small
    against the bias removed, ``|A (g_rest - b)| << |A b|``; a log in another unit (rad/s read as deg/s) reads
    ``g_rest = b / k`` and its corrected rest is about ``-A b``. Refused when the corrected rest is over half the
    bias removed while the log read at one of the usual other units (:data:`_RATE_UNITS`) corrects to a fifth of
    it or less; nothing is judged for a bias under :data:`BIAS_CHECKED` (a turn-on's change of bias, Earth's rate)."""
    if not len(still):
        return
    removed = float(np.linalg.norm(np.asarray(correction.correct(np.zeros((1, 3))), float)))
    if removed < BIAS_CHECKED:
        return
    rest = float(np.linalg.norm(correction.correct(still), axis=1).min())
    if rest <= 0.5 * removed:
        return
    factor = parse_unit(unit).factor
    for other in _RATE_UNITS:
        k = parse_unit(other).factor / factor
        if not math.isclose(k, 1.0, rel_tol=1e-6) and \
                float(np.linalg.norm(correction.correct(still * k), axis=1).min()) <= 0.2 * removed:
            raise UnitError(f"read in {literal(unit)}, it reads at rest {rest / DEG_S:.3g} deg/s away from the bias the "
                            f"result removes ({removed / DEG_S:.3g} deg/s), and read in {other} it would match it: is "
                            f"the log in {other}? give it with {{{field}={other}}}", where)


def _check_mag(got: SensorLog, correction: Any, corrected: np.ndarray, unit: str, field: str, where: str) -> None:
    """The corrected field strength must be the calibration's own (within a factor of 2): a log in gauss read as uT
    is refused even when the hard iron puts its corrected strength within Earth's."""
    from align.plausible import FIELD_UNITS, mixup_hint

    known = float(getattr(correction, "field", 0.0) or 0.0)
    if not (math.isfinite(known) and known > 0) or not len(corrected):
        return
    strength = float(np.mean(np.linalg.norm(corrected, axis=1)))
    if 0.5 <= strength / known <= 2.0:
        return
    raw = float(np.mean(np.linalg.norm(got.data, axis=1)))
    hint = mixup_hint(raw, unit, "magnetic_field", FIELD_UNITS, (known / 2, known * 2), field) or \
        f"check {{{field}}} and the columns"
    raise UnitError(f"the corrected field strength is {strength / known:.3g}x the calibration's own "
                    f"({strength * 1e6:.4g} uT against {known * 1e6:.4g} uT): {hint}", where)


def read_apply(options: ApplyOptions) -> ApplyInputs:
    """Read the result and the log, check the log against the result, and correct it.

    Checks: the log's unit is of the dimension of the result's readings (a rate for a gyro alignment, counts
    for a calibration in counts); the log's columns (:meth:`LogSource.read`); the corrected readings are what
    physics allows: an accelerometer's mean ``|a|`` gravity, a magnetometer's mean ``|m|`` Earth's field and
    the calibration's own, a gyro's rates within a MEMS gyro's full scale and near zero while still.

    Raises
    ------
    InputError, UnitError, TestError
        One line naming the file and the option to change (``{gyro_units}``, ``{units}``, ``{columns}``, ...).
    """
    from align.plausible import check_corrected
    from align.results import load_result

    where = str(options.alignment)
    sensor = None if options.sensor is None else Sensor.parse(options.sensor).value
    correction: Any = load_result(options.alignment).correction(sensor, where)
    kind = Sensor.parse(correction.sensor)
    typed, field = _typed_unit(options, kind)
    default = Sensor.GYROSCOPE.unit if kind is Sensor.GYROSCOPE else correction.units
    expect = _log_unit(typed or default, field, where, correction, kind)
    check_unit_given(typed, expect, field)
    src = replace(options.log, units=typed)
    time, cols = names_read(src, kind)
    got = src.read(kind, expect=expect, counts=expect == "counts", field=field, default_units=default)
    unit = got.units
    if got.stated:  # the unit the file states, against the result's
        _log_unit(unit, field, where, correction, kind)
    log = str(src.path)
    notes: tuple[str, ...] = ()
    if getattr(correction, "needs_temperature", False):  # a thermal calibration: raw - bias(T)
        if got.temperature is None:
            raise InputError("a thermal calibration compensates the bias against temperature: give the log's "
                             "temperature column with {temperature_column}", where)
        comp = correction.compensate(got.data, got.temperature, got.t)
        corrected, notes = np.asarray(comp.data), tuple(filter(None, [comp.note]))
    else:
        corrected = np.asarray(correction.correct(got.data))
    if expect == "counts":  # a calibration in counts makes accelerometer and gyro readings physical (SI)
        written = kind.unit if kind is not Sensor.MAGNETOMETER else unit
        scale = parse_unit(written).factor if kind is not Sensor.MAGNETOMETER else 1.0
    else:
        scale, _ = sensor_scale(unit, expect, field)
        written = unit
        check_corrected(kind.value, corrected, got.shown, field, log)  # a log read in the wrong unit is refused
        if kind is Sensor.GYROSCOPE:
            _check_gyro(got, correction, unit, field, log)
        elif kind is Sensor.MAGNETOMETER:
            _check_mag(got, correction, corrected, unit, field, log)
    return ApplyInputs(got, correction, corrected, kind, unit, field, written, float(scale), time, tuple(cols), notes)


def compute_apply(inputs: ApplyInputs, options: ApplyOptions, progress: Progress | None = None) -> CorrectedLog:
    """The corrected log as a value: time, readings in SI, and how they are written back."""
    from align.io.formats import TIME_UNITS

    got = inputs.log
    time = None
    if inputs.time_column is not None:
        time = got.t / TIME_UNITS[got.time_units] if got.time_units else got.t  # the time column as the log had it
    notes = [got.time_note()]
    if inputs.written != inputs.units:
        notes.append(f"readings in {inputs.units} made physical by the calibration: written in {inputs.written}")
    notes += [*inputs.notes, *got.remarks(str(options.log.path))]
    columns = tuple(([inputs.time_column] if inputs.time_column else []) + list(inputs.columns))
    src = options.log
    result = CorrectedLog(
        inputs.sensor.value, got.t, inputs.corrected, inputs.written, inputs.scale, columns, time,
        got.time_units if inputs.time_column else None, tuple(filter(None, notes)),
        {"log": str(src.path), "alignment": str(options.alignment), "sensor": inputs.sensor.value,
         inputs.field: inputs.units, "columns": ",".join(columns), "rate_hz": src.rate_hz,
         "time_column": inputs.time_column, **got.inputs()})
    if progress is not None:
        progress(len(got.t))
    return result


def apply_input_files(options: ApplyOptions) -> dict[str, Path | None]:
    """The input files: the log and the result that corrects it."""
    return {"log": options.log.path, "alignment": options.alignment}


APPLY: Job[ApplyOptions, ApplyInputs, CorrectedLog] = Job(
    "apply", ApplyOptions, read_apply, compute_apply, apply_input_files,
    "correct a log with an alignment or a calibration result")


@fields_signature(ApplyOptions)
def apply(*, progress: Progress | None = None, **fields: Any) -> CorrectedLog:
    """A log corrected with an alignment or calibration result, as ``imu-align apply`` corrects it.

    Gyro ``w = A (g - b)``; accelerometer ``M^-1 (a - b)``; magnetometer ``soft_iron (m - hard_iron)``.

    Parameters
    ----------
    progress : callable, optional
        Called with the samples done.
    **fields
        The fields of :class:`ApplyOptions`: ``log`` (a path, or a :class:`~align.io.source.LogSource` with
        its columns and unit), ``alignment`` (the result file), and optionally ``sensor``, ``gyro_units``.

    Returns
    -------
    CorrectedLog
        ``t`` (n,) s and ``data`` (n, 3) SI, the unit and columns of the CSV, with its provenance.

    Examples
    --------
    An identity alignment leaves a gyro log as it was, less its bias:

    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from align.alignment.result import AlignmentResult
    >>> from align.io import write_csv
    >>> from align.results import save_result
    >>> from align.units import DEG
    >>> folder = Path(tempfile.mkdtemp())
    >>> eye, zero = np.eye(3), np.zeros((3, 3))
    >>> r = AlignmentResult("lsq", eye, eye, np.full(3, 0.5 * DEG), zero, zero, np.zeros(3), 1.0, 10, (), (), ())
    >>> save_result(folder / "r.json", r)
    >>> t = np.arange(200) / 100
    >>> write_csv(folder / "log.csv", ["time", "gyro_x", "gyro_y", "gyro_z"],
    ...           np.column_stack([t, np.full((200, 3), [0.5, 0.5, 10.5])]))
    >>> c = apply(log=folder / "log.csv", alignment=folder / "r.json")
    >>> c.columns, c.units, np.round(c.table()[0], 6).tolist()
    (('time', 'gyro_x', 'gyro_y', 'gyro_z'), 'deg/s', [0.0, 0.0, 0.0, 10.0])
    """
    return APPLY.run(ApplyOptions(**fields), progress=progress)

