"""What a log holds, before any job: its streams, and for each IMU stream its samples, rate, gaps and clipping.

``imu-align inspect LOG`` is :func:`inspect_log`. A log of several streams (a ROS bag, a ULog, a DataFlash log:
:attr:`align.io.readers.LogReader.streams`) lists what its reader's ``describe`` says (topics or messages,
instances, counts), then reads each IMU stream (or the one its :attr:`~align.io.formats.LogFormat.topic` names);
a one-stream file (CSV, NPY, Parquet) is its columns. Each stream read gets the same figures
(:func:`time_figures`, :func:`clipped_samples`), on its time column in seconds:

* samples, the nominal rate when the format states one (:func:`_nominal`: ``nominal_rate_hz`` in the stream's
  ``extra`` or ``source``, a sensor description's ``rate_hz``), the measured rate (one over the median positive
  step), the duration (last minus first stamp);
* gaps: steps longer than :data:`GAP` times the median step, the samples they drop (``round(step / median) - 1``
  each), the largest and when;
* time out of order: steps backwards (``< 0``) and repeated stamps (``== 0``), the first of them;
* the temperature range (a ``temperature`` column, degrees Celsius);
* clipped samples per channel: runs of two or more samples at the channel's extreme over the record, entered or
  left by a step of at least 1 % of the extreme's distance from the channel's median, that extreme beyond 10 times
  the channel's noise from the median (a smooth peak neither repeats its exact largest value nor turns a corner
  there; a quantized reading at rest repeats its extremes a few counts out: the flat-top rule of
  :func:`align.calibration.gyrochecks.saturated_samples`, :func:`clipped_samples`);
* the units the file states (a CSV states none: a job's unit options then say them).

A stream that holds no message is one line (``no message``), not an error. The JSON form (:meth:`LogInspection.to_dict`)
is a plain documented file with the envelope of every result (``format`` :data:`FORMAT`, ``version``, ``generator``,
``convention``, ``units``); it describes a log and is read back by no command (no :class:`align.results.Result`).

Public names
------------
TimeFigures, Series, LogInspection, inspect_log, time_figures, clipped_samples, GAP, FORMAT, VERSION, CONVENTION
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from align.errors import InputError
from align.io.formats import TIME_UNITS, LogFormat, time_unit

__all__ = ["TimeFigures", "Series", "LogInspection", "inspect_log", "time_figures", "clipped_samples", "GAP",
           "FORMAT", "VERSION", "CONVENTION"]

#: a step longer than this many median steps is a gap
GAP = 1.5
#: the format and version of the JSON form
FORMAT, VERSION = "imu-align.inspect", 1
CONVENTION = (f"time in s; rate measured: 1 / the median positive step; a gap: a step > {GAP:g} x the median step, "
              "dropping round(step / median) - 1 samples; out of order: a step < 0 (backwards) or = 0 (repeated); "
              "clipped: runs of >= 2 samples at a channel's extreme over the record, entered or left by a step >= 1 % "
              "of the extreme's distance from the channel's median, the extreme > 10 noise sigma (1.4826 median "
              "|diff| / sqrt 2) from it; temperature in degC")
#: the data columns of an IMU stream, by the one convention (:mod:`align.io.readers`)
_IMU = ("gyro_x", "accel_x", "mag_x")


@dataclass(frozen=True)
class TimeFigures:
    """The figures of a time column (seconds).

    Attributes
    ----------
    count : int
        Samples.
    rate_hz : float or None
        Measured rate: one over the median positive step, Hz (None: fewer than two samples).
    nominal_hz : float or None
        The rate the format states, Hz.
    duration_s : float
        Last stamp minus first, s.
    gaps, dropped : int
        Steps longer than :data:`GAP` median steps, and the samples they drop.
    largest_gap_s, largest_gap_at_s : float or None
        The longest such step, s, and the stamp before it, s.
    backwards, repeated : int
        Steps below zero, and steps of zero.
    out_of_order_at_s : float or None
        The stamp before the first step backwards or repeated, s.
    """

    count: int
    rate_hz: float | None
    nominal_hz: float | None = None
    duration_s: float = 0.0
    gaps: int = 0
    dropped: int = 0
    largest_gap_s: float | None = None
    largest_gap_at_s: float | None = None
    backwards: int = 0
    repeated: int = 0
    out_of_order_at_s: float | None = None


def time_figures(t: np.ndarray, nominal_hz: float | None = None) -> TimeFigures:
    """Samples, rate, duration, gaps and steps out of order of time stamps ``t`` (n,), s.

    Examples
    --------
    >>> t = np.r_[np.arange(10) * 0.01, 0.13, 0.14, 0.14, 0.135, 0.145]
    >>> f = time_figures(t, 100.0)
    >>> f.count, round(f.rate_hz, 6), f.gaps, f.dropped, round(f.largest_gap_s, 6), f.backwards, f.repeated
    (15, 100.0, 1, 3, 0.04, 1, 1)
    """
    t = np.asarray(t, dtype=float)
    n = len(t)
    if n < 2:
        return TimeFigures(n, None, nominal_hz)
    dt = np.diff(t)
    forward = dt[dt > 0]
    med = float(np.median(forward)) if len(forward) else float("nan")
    gap = dt > GAP * med if np.isfinite(med) else np.zeros(len(dt), bool)
    k = int(np.argmax(np.where(gap, dt, -np.inf))) if gap.any() else None
    odd = dt <= 0
    first = int(np.argmax(odd)) if odd.any() else None
    return TimeFigures(n, 1.0 / med if np.isfinite(med) else None, nominal_hz, float(t[-1] - t[0]), int(gap.sum()),
                       int(np.sum(np.round(dt[gap] / med) - 1)) if gap.any() else 0,
                       None if k is None else float(dt[k]), None if k is None else float(t[k]),
                       int(np.sum(dt < 0)), int(np.sum(dt == 0)), None if first is None else float(t[first]))


def clipped_samples(x: np.ndarray) -> int:
    """Samples of one channel ``x`` (n,) held at its extreme: runs of two or more at its largest (or smallest) value,
    entered or left by a step of at least 1 % of that value's distance from the median, that value farther from the
    median than 10 times the channel's noise (``1.4826 median |diff| / sqrt 2``: a quantized reading at rest repeats
    its extremes a few counts out); 0 for a constant channel.

    Examples
    --------
    >>> clipped_samples(np.r_[0.0, 1.0, 250.0, 250.0, 250.0, 3.0, -1.0])
    3
    >>> clipped_samples(np.r_[0.0, 1.0, 1.999, 2.0, 2.0, 1.999, 1.0, 0.0])  # a smooth peak turns no corner
    0
    """
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    if len(x) < 2 or x.max() == x.min():
        return 0
    mid, count = float(np.median(x)), 0
    noise = 1.4826 * float(np.median(np.abs(np.diff(x)))) / np.sqrt(2)
    for extreme in {float(x.max()), float(x.min())} - {mid}:
        if abs(extreme - mid) <= 10 * noise:
            continue
        at = np.diff(np.r_[0, (x == extreme).astype(np.int8), 0])
        for a, b in zip(np.flatnonzero(at == 1), np.flatnonzero(at == -1)):
            steps = [abs(extreme - x[k]) for k in (a - 1, b) if 0 <= k < len(x)]
            if b - a >= 2 and max(steps, default=0.0) >= 0.01 * abs(extreme - mid):
                count += int(b - a)
    return count


@dataclass(frozen=True)
class Series:
    """One stream read (an IMU topic, or a one-stream file's columns) and its figures.

    Attributes
    ----------
    name : str
        The topic (what a job's topic option selects it by), or the file's name.
    kind : str
        Its message type, or the reader's name.
    columns : tuple of str
    units : mapping of str to str
        The units the file states (empty for a CSV).
    source : mapping of str to object
        The stream read, as a result's provenance records it (topic, instance, device id).
    time_column : str or None
        The time column the figures are of (None: the stream has none).
    time_units : str or None
        Its unit (stated, given or detected); None: not told (the figures are then in the file's numbers).
    time : TimeFigures or None
    temperature_c : tuple of float or None
        The temperature column's range, degrees Celsius.
    clipped : mapping of str to int
        Per data column, its samples held at its extreme (:func:`clipped_samples`); columns with none left out.
    notes : tuple of str
        The reader's remarks (a truncated last record) and this inspection's (a time unit not told).
    empty : bool
        The stream holds no message (nothing else is said of it).
    """

    name: str
    kind: str
    columns: tuple[str, ...] = ()
    units: Mapping[str, str] = field(default_factory=dict)
    source: Mapping[str, Any] = field(default_factory=dict)
    time_column: str | None = None
    time_units: str | None = None
    time: TimeFigures | None = None
    temperature_c: tuple[float, float] | None = None
    clipped: Mapping[str, int] = field(default_factory=dict)
    notes: tuple[str, ...] = ()
    empty: bool = False


@dataclass(frozen=True)
class LogInspection:
    """What :func:`inspect_log` found in a log.

    Attributes
    ----------
    log : str
        The log, as given.
    reader : str
        Its format (the reader's name).
    streams : tuple of Stream
        What the reader's ``describe`` lists (a log of several streams; empty otherwise).
    series : tuple of Series
        The streams read, with their figures.
    """

    log: str
    reader: str
    streams: tuple = ()
    series: tuple[Series, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: the envelope of every result, then ``log``, ``reader``, ``streams``, ``series``."""
        from align.results import envelope

        units = {"time": "s", "rate": "Hz", "duration": "s", "gap": "s", "temperature": "degC"}
        return {**envelope(FORMAT, VERSION, CONVENTION, units), "log": self.log, "reader": self.reader,
                "streams": [{"topic": s.topic, "kind": s.kind, "count": s.count, "columns": list(s.columns),
                             "units": dict(s.units), "extra": dict(s.extra)} for s in self.streams],
                "series": [_series_dict(s) for s in self.series]}

    def lines(self) -> list[str]:
        """The inspection as text, one fact a line."""
        out = [f"{self.log}: {self.reader}" + (f", {len(self.streams)} streams" if self.streams else "")]
        for s in self.streams:
            extra = ", ".join(f"{k} {_shown(v)}" for k, v in s.extra.items() if v is not None)
            out.append(f"  {s.topic}  {s.kind}  " + (_n(s.count, "message") if s.count else "no message")
                       + (f"  ({extra})" if extra else ""))
        for s in self.series:
            out += _series_lines(s, titled=bool(self.streams) or len(self.series) > 1)
        return out


def _series_dict(s: Series) -> dict[str, Any]:
    d = {k: v for k, v in asdict(s).items() if k not in ("time", "temperature_c")}
    d.update(columns=list(s.columns), units=dict(s.units), source=dict(s.source), clipped=dict(s.clipped),
             notes=list(s.notes), time=None if s.time is None else asdict(s.time),
             temperature_c=None if s.temperature_c is None else {"min": s.temperature_c[0], "max": s.temperature_c[1]})
    return d


def _series_lines(s: Series, titled: bool) -> list[str]:
    head = [f"{s.name} ({s.kind}):"] if titled else []
    if s.empty:
        return [f"{s.name} ({s.kind}): no message"]
    by_unit: dict[str, list[str]] = {}
    for c, u in s.units.items():
        by_unit.setdefault(u, []).append(c)
    stated = ", ".join(f"{'/'.join(cs)} {u}" for u, cs in by_unit.items())
    out = head + [f"  columns: {', '.join(s.columns)}" + (f" (units stated: {stated})" if stated else
                                                          " (no units stated)")]
    f = s.time
    if f is None:
        out.append("  no time column" + (f" ('{s.time_column}' absent)" if s.time_column else ""))
    else:
        u, sec = (s.time_units, " s") if s.time_units else ("the file's numbers", "")
        rate = f"{f.rate_hz:.6g} Hz measured" if f.rate_hz else "no rate"
        rate += f", {f.nominal_hz:.6g} Hz nominal" if f.nominal_hz else ""
        out.append(f"  {f.count:,} samples; {rate}; duration {f.duration_s:.6g}{sec} (time column '{s.time_column}' "
                   f"in {u})")
        if f.gaps:
            out.append(f"  {_n(f.gaps, 'gap')} (steps > {GAP:g}x the median), about {_n(f.dropped, 'sample')} dropped; largest "
                       f"{f.largest_gap_s:.4g}{sec} at t={f.largest_gap_at_s:.6g}{sec}")
        if f.backwards or f.repeated:
            out.append(f"  time out of order: {_n(f.backwards, 'step')} back, {_n(f.repeated, 'repeated stamp')} (first "
                       f"at t={f.out_of_order_at_s:.6g}{sec})")
    if s.temperature_c is not None:
        out.append(f"  temperature {s.temperature_c[0]:.4g} to {s.temperature_c[1]:.4g} C")
    if s.clipped:
        out.append("  clipped: " + ", ".join(f"{c} {k:,} samples" for c, k in s.clipped.items()))
    return out + [f"  note: {n}" for n in s.notes]


def _n(k: int, what: str) -> str:
    return f"{k:,} {what}" + ("" if k == 1 else "s")


def _nominal(*said: Mapping[str, Any]) -> float | None:
    """The rate a format states (not one its reader measured): ``nominal_rate_hz`` of a stream's ``extra`` or
    ``source``, or ``rate_hz`` of the sensor description a reader gives as ``sensor_yaml`` (EuRoC)."""
    for d in said:
        for value in (d.get("nominal_rate_hz"), (d.get("sensor_yaml") or {}).get("rate_hz")):
            if isinstance(value, (int, float)) and not isinstance(value, bool) and value > 0:
                return float(value)
    return None


def _shown(value: Any) -> str:
    text = f"{value:.6g}" if isinstance(value, float) else str(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _series(got: Any, name: str, kind: str, time_column: str | None, fmt: LogFormat, where: str,
            nominal: float | None) -> Series:
    """The figures of the columns a reader read (:class:`align.io.readers.Columns`)."""
    from align.units import temperature_offset

    names, data = list(got.names), np.asarray(got.data, dtype=float)
    units, notes = dict(got.units), list(got.notes)
    col = {n: data[:, j] for j, n in enumerate(names)}
    figures, unit = None, None
    if time_column is not None and time_column in col:
        raw = col[time_column]
        unit = units.get(time_column) if units.get(time_column) in TIME_UNITS else fmt.time_units
        if unit is None:
            steps = np.diff(raw)
            steps = steps[steps > 0]
            try:
                unit = time_unit(float(np.median(steps)) if len(steps) else float("nan"), time_column, where,
                                 first=float(raw[0]) if len(raw) else None)[0]
            except InputError as exc:
                notes.append(f"the time unit cannot be told ({exc.message}); figures in the file's numbers")
        figures = time_figures(raw * (TIME_UNITS[unit] if unit else 1.0), nominal)
    temp = None
    if "temperature" in col and np.isfinite(col["temperature"]).any():
        scale, offset = temperature_offset(units.get("temperature") or "degC")
        c = col["temperature"] * scale + offset
        temp = (float(np.nanmin(c)), float(np.nanmax(c)))
    clipped = {n: k for n in names if n not in (time_column, "temperature") and (k := clipped_samples(col[n]))}
    return Series(name, kind, tuple(names), units, dict(got.source), time_column if time_column in col else None,
                  unit, figures, temp, clipped, tuple(notes))


def inspect_log(path: str | Path, log_format: LogFormat | None = None, time_column: str | None = None
                ) -> LogInspection:
    """What a log holds: its streams, and the figures of each IMU stream (or of its columns).

    Parameters
    ----------
    path : str or Path
        A log file of any registered format, or a log folder (a ROS 2 bag, an EuRoC dataset).
    log_format : LogFormat, optional
        A text log's preamble, comments, delimiter, time unit; the one stream to read of a log of several
        (``topic``; None: every IMU stream its reader lists) and its time stamps.
    time_column : str, optional
        The time column of a one-stream file (default ``time``); a stream's is ``time``.

    Returns
    -------
    LogInspection

    Raises
    ------
    InputError
        A file that cannot be read, a topic it does not hold, a topic or text option it takes none of.

    Examples
    --------
    >>> import tempfile
    >>> d = Path(tempfile.mkdtemp())
    >>> t = np.r_[np.arange(100), np.arange(103, 200)] / 100.0
    >>> np.savetxt(d / "log.csv", np.column_stack([t, np.sin(t), np.cos(t), t]), delimiter=",",
    ...            header="time,gyro_x,gyro_y,gyro_z", comments="")
    >>> f = inspect_log(d / "log.csv").series[0].time
    >>> f.count, round(f.rate_hz), f.gaps, f.dropped
    (197, 100, 1, 3)
    """
    from align.io.files import existing_log
    from align.io.readers import reader_for
    from align.io.tables import read_table

    p = existing_log(path)
    fmt = log_format or LogFormat()
    where = str(path)
    reader = reader_for(p, fmt)
    if not reader.streams:
        got = read_table(p, None, None, fmt)
        name = p.name
        return LogInspection(where, reader.name, (), (_series(got, name, reader.name, time_column or "time", fmt, where,
                                                              _nominal(got.source)),))
    streams = tuple(reader.describe(p, fmt)) if reader.describe is not None else ()
    if fmt.topic is not None:
        chosen: Sequence[str | None] = [fmt.topic]
    elif streams:
        chosen = [s.topic for s in streams if any(c in s.columns for c in _IMU)]
    else:
        chosen = [None]  # the reader's own choice
    series = []
    for topic in chosen:
        listed = next((s for s in streams if s.topic == topic), None)
        if listed is not None and listed.count == 0:
            series.append(Series(str(topic), listed.kind, empty=True))
            continue
        got = read_table(p, None, "time", replace(fmt, topic=topic))
        name = str(got.source.get("topic", topic) if topic is None else topic)
        series.append(_series(got, name, listed.kind if listed is not None else reader.name, "time", fmt, where,
                              _nominal(listed.extra if listed is not None else {}, got.source)))
    return LogInspection(where, reader.name, streams, tuple(series))
