"""ArduPilot DataFlash logs (``.bin``): the IMU streams, read by our own reader (:mod:`align.io.dataflash_format`).

A DataFlash log holds the ``IMU`` message of every inertial sensor: newer logs one message with an
instance field ``I`` (``IMU:0``, ``IMU:1`` ...), older ones separate messages ``IMU``, ``IMU2``, ``IMU3``
(instances 0, 1, 2; either spelling selects them). A stream is read as the one convention's columns
(:class:`align.vocab.Sensor`): ``time`` in s from ``TimeUS`` (``TimeMS`` in the oldest logs),
``gyro_x, gyro_y, gyro_z`` from ``GyrX, GyrY, GyrZ``, ``accel_x, accel_y, accel_z`` from ``AccX, AccY,
AccZ``, ``temperature`` from ``T`` when the message has it. Their units are the ones the log's ``FMTU``
records state, else those ArduPilot documents for the IMU message (rad/s, m/s^2, degrees Celsius,
microseconds).

A last record the file cuts short is left out and bytes between records that are no record are skipped
to the next record header; the result states both (:attr:`align.io.readers.Columns.notes`). A stream
whose time goes back, a stream or column the log does not have, and a file that is no DataFlash log are
refused, naming the file and the stream.

``.bin`` is also the suffix of raw float64 files: :func:`sniff` tells a DataFlash log by its first record,
a FMT record.

Public names
------------
read, describe, sniff, READER, COLUMNS
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from align.errors import InputError, literal
from align.io.dataflash_format import Layout, decode, field_units, scan
from align.io.dataflash_format import sniff as _sniff
from align.io.formats import LogFormat
from align.io.gpstime import dated
from align.io.readers import Columns, LogReader, Stream

__all__ = ["read", "describe", "sniff", "READER", "COLUMNS"]

#: the one convention's column -> the IMU message's field
COLUMNS = {"gyro_x": "GyrX", "gyro_y": "GyrY", "gyro_z": "GyrZ", "accel_x": "AccX", "accel_y": "AccY",
           "accel_z": "AccZ", "temperature": "T"}
#: the units ArduPilot documents for the IMU message's fields, and the factor from its numbers to them
DOCUMENTED = {"TimeUS": ("s", 1e-6), "TimeMS": ("s", 1e-3), "GyrX": ("rad/s", 1.0), "GyrY": ("rad/s", 1.0),
              "GyrZ": ("rad/s", 1.0), "AccX": ("m/s^2", 1.0), "AccY": ("m/s^2", 1.0), "AccZ": ("m/s^2", 1.0),
              "T": ("degC", 1.0)}
_TOPIC = re.compile(r"\s*([A-Za-z0-9_]+)\s*(?::\s*(\d+))?\s*")
_IMU = re.compile(r"IMU([1-9]?)", re.IGNORECASE)


def sniff(head: bytes) -> bool:
    """Whether a file's first bytes are a DataFlash log's: a FMT record first (``A3 95 80`` and a valid
    description of a message), then the next record's header.

    Examples
    --------
    >>> sniff(b"\\xa3\\x95\\x80" + bytes(4093))
    False
    >>> sniff(np.random.default_rng(0).normal(size=512).tobytes())
    False
    """
    return _sniff(head)


@dataclass(frozen=True)
class _Instance:
    """One IMU stream of a log: its instance, the message holding it and which of its records are its own."""

    instance: int
    type: int
    name: str
    positions: np.ndarray


@dataclass(frozen=True, eq=False)
class _Log:
    """A DataFlash log as scanned: its bytes, its records, its fields' stated units and its IMU streams."""

    path: Path
    buf: np.ndarray
    layout: Layout
    units: dict[int, dict[str, tuple[str, float]]]
    imus: dict[int, _Instance]

    def notes(self) -> tuple[str, ...]:
        """The remarks a result states: a cut last record, bytes skipped."""
        out = []
        if self.layout.truncated is not None:
            got, size = self.layout.truncated
            out.append(f"last record truncated ({got} of {size} bytes), left out" if size else
                       f"last record truncated ({got} bytes of its header), left out")
        if self.layout.skipped:
            places = "one place" if self.layout.gaps == 1 else f"{self.layout.gaps} places"
            out.append(f"{self.layout.skipped} bytes that are no record skipped ({places})")
        return tuple(out)

    def counts(self) -> dict[int, int]:
        """Records of each message id present."""
        n = np.bincount(self.layout.ids, minlength=256)
        return {int(t): int(n[t]) for t in np.flatnonzero(n)}

    def streams(self) -> str:
        """The IMU streams, for messages (``IMU:0, IMU:1``)."""
        return ", ".join(f"IMU:{k}" for k in sorted(self.imus)) or "none"


def _open(path: Path) -> _Log:
    """Scan a DataFlash log (refused when its first record is no FMT record)."""
    try:
        buf = np.fromfile(path, np.uint8)
    except OSError as exc:
        raise InputError(f"cannot read the file ({literal(exc.strerror or exc)})", str(path)) from None
    if not _sniff(buf[:1 << 12].tobytes()):
        raise InputError("is not an ArduPilot DataFlash log (it does not start with a FMT record, bytes A3 95 80); "
                         "give a .bin log as the flight controller wrote it", str(path))
    layout = scan(buf)
    units = field_units(buf, layout)
    imus: dict[int, _Instance] = {}
    present = set(np.flatnonzero(np.bincount(layout.ids, minlength=256)).tolist())
    for t, f in sorted(layout.formats.items(), key=lambda kv: kv[1].name):
        match = _IMU.fullmatch(f.name)
        if match is None or t not in present or not f.decodable:
            continue
        at = layout.of(t)
        if "I" in f.labels:
            which = decode(buf, f, at, ["I"])["I"].astype(np.int64)
            for k in np.unique(which).tolist():
                imus.setdefault(k, _Instance(k, t, f.name, at[which == k]))
        else:
            k = int(match.group(1) or 1) - 1
            imus.setdefault(k, _Instance(k, t, f.name, at))
    return _Log(path, buf, layout, units, imus)


def _instance(log: _Log, topic: str | None) -> _Instance:
    """The IMU stream ``topic`` names (``IMU``, ``IMU:1``, ``IMU2``; None: the first instance)."""
    where = str(log.path)
    if not log.imus:
        names = sorted({log.layout.formats[t].name for t in log.counts()})
        shown = ", ".join(names[:12]) + (f" and {len(names) - 12} more" if len(names) > 12 else "")
        raise InputError(f"holds no IMU message (its messages: {literal(shown) or 'none'}); log the IMU data "
                         "(ArduPilot's LOG_BITMASK, IMU) and give that log", where)
    if topic is None:
        return log.imus[min(log.imus)]
    match = _TOPIC.fullmatch(topic)
    imu = _IMU.fullmatch(match.group(1)) if match else None
    if match is not None and imu is not None and imu.group(1) and match.group(2) is not None:
        raise InputError(f"topic '{literal(topic)}' names an instance twice (an old log's IMU2 is IMU:1); give one of "
                         f"{log.streams()} with {{topic}}", where)
    if match is None or imu is None:
        name = match.group(1) if match else topic
        known = {f.name.upper() for f in log.layout.formats.values()}
        what = ("is a message of this log but no IMU message" if name.upper() in known
                else "is no message of this log")
        raise InputError(f"topic '{literal(topic)}' {what}; give an IMU stream with {{topic}}: {log.streams()}", where)
    k = int(imu.group(1)) - 1 if imu.group(1) else int(match.group(2) or 0)
    if k not in log.imus:
        raise InputError(f"has no IMU stream IMU:{k} (topic '{literal(topic)}'); its IMU streams are {log.streams()}: "
                         "give one with {topic}", where)
    return log.imus[k]


def _columns(log: _Log, imu: _Instance) -> dict[str, tuple[str, str, float]]:
    """The stream's columns: name -> (field, unit, factor from the log's numbers), in the convention's order."""
    f = log.layout.formats[imu.type]
    stated = log.units.get(imu.type, {})
    time = [("time", k) for k in ("TimeUS", "TimeMS") if k in f.labels][:1]
    fields = dict(time) | {c: k for c, k in COLUMNS.items() if k in f.labels}
    return {c: (k, *(stated.get(k) or DOCUMENTED[k])) for c, k in fields.items()}


def _time(log: _Log, imu: _Instance, field: str, raw: np.ndarray) -> None:
    """Refuse time that goes back (two recordings joined, or a damaged log), naming the record."""
    back = np.flatnonzero(np.diff(raw) < 0)
    if len(back):
        k = int(back[0])
        raise InputError(f"IMU:{imu.instance} ({imu.name}): {field} goes back at sample {k + 2} of {len(raw)} (from "
                         f"{raw[k]:.0f} to {raw[k + 1]:.0f}); the log joins two recordings or is damaged: read a log of "
                         "one recording", str(log.path))


def read(path: Path, names: list[str] | None, time_column: str | None, log_format: LogFormat) -> Columns:
    """One IMU stream of a DataFlash log as named columns, in the units the log states.

    Parameters
    ----------
    path : Path
    names : list of str or None
        Columns to read, of ``time, gyro_x, gyro_y, gyro_z, accel_x, accel_y, accel_z, temperature``
        (those the message has); None: all it has.
    time_column : str or None
        The time column among ``names`` (``time``).
    log_format : LogFormat
        Its ``topic`` names the stream (``IMU``, ``IMU:1``, ``IMU2``); None: the first instance.

    Returns
    -------
    Columns
        ``data`` (n, k) float64; ``units`` as the log states them (``time`` s); ``source``
        ``{"format": "dataflash", "topic": "IMU", "instance": k}``, with ``time_origin_utc_ns`` (the first sample's
        UTC) when the log has GPS records with a week; ``notes`` on a cut last record or skipped bytes.

    Raises
    ------
    InputError
        Not a DataFlash log, no IMU message, no such stream, a column the message lacks, time that goes back.
    """
    if log_format.stamps == "record":
        raise InputError("a DataFlash IMU record carries one time stamp, the sample's (TimeUS); leave {stamps} out",
                         str(path))
    log = _open(Path(path))
    imu = _instance(log, log_format.topic)
    columns = _columns(log, imu)
    wanted = list(columns) if names is None else list(names)
    missing = [n for n in wanted if n not in columns]
    if missing:
        fix = ("this IMU logs no temperature: leave {temperature_column} out" if missing == ["temperature"]
               else "name the columns it has")
        raise InputError(f"IMU:{imu.instance} ({imu.name}) has no column {', '.join(repr(literal(m)) for m in missing)} "
                         f"(its columns: {', '.join(columns)}); {fix}", str(path))
    labels = {columns[n][0] for n in wanted + (["time"] if "time" in columns else [])}
    raw = decode(log.buf, log.layout.formats[imu.type], imu.positions, sorted(labels))
    if "time" in columns:  # checked even when read without time: records out of order are a damaged log
        _time(log, imu, columns["time"][0], raw[columns["time"][0]])
    data = np.empty((len(wanted), len(imu.positions)))  # filled column by column, returned transposed
    for j, n in enumerate(wanted):
        label, _, factor = columns[n]
        np.multiply(raw[label], factor, out=data[j])
    got = Columns(wanted, data.T, {n: columns[n][1] for n in wanted},
                  {"format": "dataflash", "topic": "IMU", "instance": imu.instance}, log.notes())
    return dated(got, _utc_at_boot(log)) if "time" in wanted else got  # the first sample's UTC, from the GPS


def _utc_at_boot(log: _Log) -> int | None:
    """UTC (us since 1970) of the log's time zero from its ``GPS`` records: ``GWk`` and ``GMS`` (the fix's GPS
    week and milliseconds, ArduPilot's log message documentation) at ``TimeUS`` (or ``TimeMS``), GPS time made UTC
    (:func:`align.io.gpstime.gps_utc_us`); the median over the records with a week; None without."""
    from align.io.gpstime import gps_utc_us

    t = log.layout.by_name.get("GPS", -1)
    f = log.layout.formats.get(t)
    clock = next((c for c in ("TimeUS", "TimeMS") if f is not None and c in f.labels), None)
    if f is None or clock is None or not f.decodable or not {"GWk", "GMS"} <= set(f.labels):
        return None
    rec = decode(log.buf, f, log.layout.of(t), [clock, "GWk", "GMS"])
    at = rec[clock].astype(np.int64) * (1000 if clock == "TimeMS" else 1)
    utc = gps_utc_us(rec["GWk"], rec["GMS"])
    ok = (rec["GWk"] > 0) & (utc > 0)
    return int(np.median(utc[ok] - at[ok])) if ok.any() else None


def describe(path: Path, log_format: LogFormat) -> list[Stream]:
    """What a DataFlash log holds: its IMU streams (with their rates and temperature ranges), then every
    other message with its number of records.

    Returns
    -------
    list of Stream
        IMU streams as ``IMU:k`` (kind the message, ``IMU`` or ``IMU2`` ...; ``extra``: ``rate_hz``, the median
        one, and ``temperature_degC`` ``(min, max)`` when the message has ``T``), then one per other message
        (``extra``: its ``fields``).
    """
    log = _open(Path(path))
    out, notes = [], log.notes()
    for k, imu in sorted(log.imus.items()):
        columns = _columns(log, imu)
        extra: dict[str, object] = {"message": imu.name, **({"notes": notes} if notes else {})}
        raw = decode(log.buf, log.layout.formats[imu.type], imu.positions,
                     [columns[c][0] for c in ("time", "temperature") if c in columns])
        if "time" in columns and len(imu.positions) > 1:
            step = float(np.median(np.diff(raw[columns["time"][0]]))) * columns["time"][2]
            extra["rate_hz"] = 1.0 / step if step > 0 else float("nan")
        if "temperature" in columns:
            t = raw["T"] * columns["temperature"][2]
            extra["temperature_degC"] = (float(np.min(t)), float(np.max(t)))
        out.append(Stream(f"IMU:{k}", imu.name, len(imu.positions), tuple(columns),
                          {c: u for c, (_, u, _) in columns.items()}, extra))
    imu_types = {imu.type for imu in log.imus.values()}
    for type_id, count in sorted(log.counts().items(), key=lambda kv: log.layout.formats[kv[0]].name):
        f = log.layout.formats[type_id]
        if type_id not in imu_types:
            out.append(Stream(f.name, f.name, count, (), {}, {"fields": f.labels}))
    return out


#: the DataFlash reader, registered for ``.bin`` beside raw binary (told apart by :func:`sniff`)
READER = LogReader("dataflash", (".bin",), read, sniff=sniff, streams=True, describe=describe)
