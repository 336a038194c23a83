"""ROS bags, read without a ROS installation: ROS 1 ``.bag``, ROS 2 ``.db3`` and ``.mcap`` files and bag folders.

A bag holds many topics; one is read at a time (:attr:`~align.io.formats.LogFormat.topic`, e.g. ``"/imu0"``;
none given: the bag's only ``sensor_msgs/Imu`` topic). Its messages become the columns of the one convention
(:mod:`align.io.readers`) with their units stated:

* ``sensor_msgs/Imu``: ``gyro_x..z`` (``angular_velocity``, rad/s) and ``accel_x..z`` (``linear_acceleration``,
  m/s^2) [REP 145];
* ``sensor_msgs/MagneticField``: ``mag_x..z`` (``magnetic_field``, tesla);
* ``sensor_msgs/Temperature``: ``temperature`` (degC); beside an IMU or magnetometer topic, the bag's
  Temperature topic (the only one, else the one under the topic or in its namespace) is linearly interpolated
  to the samples' times, held at its first and last value outside its span (stated in the result's notes);
* ``time`` in s from the first sample (its stamp in ns is ``Columns.source["time_origin_ns"]``): the header stamp
  (default), or the time the recorder wrote the message (``stamps="record"``).

The container is read by the ``rosbags`` library (Apache-2.0, pure Python; the optional extra ``logs``). Its
message deserialisers run per message in Python (about 50 000 messages/s); these messages have a fixed layout
after their header (``float64`` fields last: 37 for Imu, 12 for MagneticField, 2 for Temperature; the stamp
at bytes 4 to 12 in ROS 1 and in CDR), so the raw bytes are cut and read by numpy at once, checked against
rosbags' own deserialiser on the first and last message (any difference, a big-endian CDR message or a short
one: every message deserialised by rosbags instead).

Public names
------------
READER, read, describe, sniff, iter_chunks
"""

from __future__ import annotations

import functools
from array import array
from collections.abc import Iterator
from contextlib import contextmanager
from itertools import islice
from pathlib import Path
from typing import Any

import numpy as np

from align.errors import InputError, literal
from align.io.formats import LogFormat
from align.io.readers import Columns, LogReader, Stream

__all__ = ["READER", "read", "describe", "sniff", "iter_chunks"]

IMU, MAGNETIC, TEMPERATURE = "sensor_msgs/msg/Imu", "sensor_msgs/msg/MagneticField", "sensor_msgs/msg/Temperature"
_XYZ = "xyz"
#: message type -> (number of float64 fields at its end, column -> (index among them, field path))
_LAYOUTS: dict[str, tuple[int, dict[str, tuple[int, tuple[str, ...]]]]] = {
    IMU: (37, {**{f"gyro_{a}": (13 + i, ("angular_velocity", a)) for i, a in enumerate(_XYZ)},
               **{f"accel_{a}": (25 + i, ("linear_acceleration", a)) for i, a in enumerate(_XYZ)}}),
    MAGNETIC: (12, {f"mag_{a}": (i, ("magnetic_field", a)) for i, a in enumerate(_XYZ)}),
    TEMPERATURE: (2, {"temperature": (0, ("temperature",))}),
}
#: the unit each column is stated in
UNITS = {"time": "s", **{f"gyro_{a}": "rad/s" for a in _XYZ}, **{f"accel_{a}": "m/s^2" for a in _XYZ},
         **{f"mag_{a}": "T" for a in _XYZ}, "temperature": "degC"}
_MISSING = "reading a ROS bag needs the rosbags library; install it with pip install 'imu-align[logs]'"
_MAGIC = (b"#ROSBAG V2.0", b"\x89MCAP0\r\n", b"SQLite format 3\x00")


def sniff(head: bytes) -> bool:
    """Whether ``head`` is the start of a bag file, or a folder's listing (names one a line) of a ROS 2 bag.

    Examples
    --------
    >>> sniff(b"metadata.yaml\\nrun_0.mcap"), sniff(b"#ROSBAG V2.0\\n"), sniff(b"data.csv")
    (True, True, False)
    """
    if head.startswith(_MAGIC):
        return True
    names = head.decode("utf-8", "replace").splitlines()
    return "metadata.yaml" in names and any(n.endswith((".db3", ".mcap", ".db3.zstd", ".mcap.zstd")) for n in names)


@functools.lru_cache(maxsize=1)
def _typestore():
    """ROS 2 Humble's message types, for a bag that carries no definitions (a ROS 2 sqlite3 file before Iron)."""
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(Stores.ROS2_HUMBLE)


def _damaged(exc: BaseException, where: str) -> InputError:
    text = " ".join(str(exc).split())[:160] or type(exc).__name__
    return InputError(f"cannot read the bag ({literal(text)}): it is damaged or truncated (a recording cut short?); "
                      "repair it (rosbag reindex, mcap recover) or record it again", where)


def _guarded(messages: Iterator[Any], where: str) -> Iterator[Any]:
    try:
        yield from messages
    except Exception as exc:  # noqa: BLE001 - a chunk or page that cannot be read
        raise _damaged(exc, where) from None


@contextmanager
def _opened(path: Path) -> Iterator[Any]:
    """The bag open in rosbags' ``AnyReader``; its failures (a damaged, truncated, empty file) one InputError."""
    try:
        from rosbags.highlevel import AnyReader
    except ImportError:
        raise InputError(_MISSING, str(path)) from None
    try:
        reader = AnyReader([path], default_typestore=_typestore())
        reader.open()
    except Exception as exc:  # noqa: BLE001 - rosbags raises its own and sqlite's, struct's, yaml's errors
        raise _damaged(exc, str(path)) from None
    try:
        yield reader
    finally:
        reader.close()


def _kind(msgtype: str | None, ros1: bool) -> str:
    """A message type as the bag's ROS names it (``sensor_msgs/Imu`` in ROS 1)."""
    return (msgtype or "?").replace("/msg/", "/") if ros1 else msgtype or "?"


def _topics(bag) -> dict[str, tuple[str, int]]:
    return {name: (info.msgtype or "?", int(info.msgcount)) for name, info in bag.topics.items()}


def _listing(topics: dict[str, tuple[str, int]], ros1: bool, limit: int = 12) -> str:
    shown = [f"{t} ({_kind(k, ros1)}, {n})" for t, (k, n) in sorted(topics.items())]
    more = f" and {len(shown) - limit} more" if len(shown) > limit else ""
    return literal(", ".join(shown[:limit]) + more) if shown else "none"


def _choose(topics: dict[str, tuple[str, int]], fmt: LogFormat, names: list[str] | None, ros1: bool,
            where: str) -> str:
    """The topic to read: the one given (of a type read here), else the bag's only Imu topic that holds messages
    (MagneticField when only magnetometer columns are asked for)."""
    if fmt.topic is not None:
        if fmt.topic not in topics:
            raise InputError(f"has no topic '{literal(fmt.topic)}' (its topics: {_listing(topics, ros1)}); give one of "
                             "them with {topic}", where)
        kind = topics[fmt.topic][0]
        if kind not in _LAYOUTS:
            kinds = " or ".join(_kind(k, ros1) for k in _LAYOUTS)
            raise InputError(f"topic '{literal(fmt.topic)}' holds {_kind(kind, ros1)} messages, not {kinds}; give such "
                             f"a topic with {{topic}} (its topics: {_listing(topics, ros1)})", where)
        return fmt.topic
    mag = names is not None and any(n.startswith("mag_") for n in names) and not any(
        n.startswith(("gyro_", "accel_")) for n in names)
    want = MAGNETIC if mag else IMU
    typed = sorted(t for t, (k, _) in topics.items() if k == want)
    found = [t for t in typed if topics[t][1] > 0] or typed  # an empty topic (advertised, never published) left out
    if len(found) == 1:
        return found[0]
    if not found:
        raise InputError(f"holds no {_kind(want, ros1)} topic (its topics: {_listing(topics, ros1)}); give the topic "
                         "to read with {topic}", where)
    raise InputError(f"holds {len(found)} {_kind(want, ros1)} topics ({literal(', '.join(found))}); choose one with "
                     f"{{topic={literal(found[0])}}}", where)


def _temperature_topic(topic: str, topics: dict[str, tuple[str, int]], ros1: bool, where: str,
                       asked: bool) -> tuple[str | None, str | None]:
    """The Temperature topic joined to ``topic``: the only one, else the only one under ``topic``, else the only
    one in its namespace. Returns (topic or None, why none); several: refused when the temperature is asked for."""
    found = sorted(t for t, (k, n) in topics.items() if k == TEMPERATURE and t != topic)
    if not found:
        return None, "the bag holds no sensor_msgs/Temperature topic"
    if len(found) == 1:
        return found[0], None
    space = topic.rsplit("/", 1)[0]
    for level in (topic, space):
        near = [t for t in found if t.rsplit("/", 1)[0] == level]
        if len(near) == 1:
            return near[0], None
        if near:
            break
    why = (f"the bag holds {len(found)} {_kind(TEMPERATURE, ros1)} topics ({literal(', '.join(found))}) and not one "
           f"alone shares the namespace of '{literal(topic)}'")
    if asked:
        raise InputError(f"{why}; leave {{temperature_column}} out", where)
    return None, why


def _decode(bag, topic: str, kind: str, columns: list[str], where: str, batch=None) -> tuple[np.ndarray, ...]:
    """Record time (ns), header stamp (ns) and the columns (n, k) of ``topic``'s messages (or of ``batch``'s).

    The fixed part is cut from each message's bytes (ROS 1 and CDR: the stamp at bytes 4 to 12, the float64
    fields last) and read by numpy at once; checked against rosbags' deserialiser on the first and last message.
    """
    floats, fields = _LAYOUTS[kind]
    index = [fields[c][0] for c in columns]
    lo, hi = min(index), max(index) + 1
    conns = [c for c in bag.connections if c.topic == topic]
    record, raw = array("q"), bytearray()
    first = last = b""
    start, stop, need = 8 * (floats - lo), 8 * (floats - hi), 12 + 8 * floats
    fast, each = True, (lambda: _guarded(bag.messages(connections=conns), where)) if batch is None else (lambda: batch)
    for _, stamp, data in each():
        n = len(data)
        if n < need:
            fast = False
            break
        record.append(stamp)
        raw += data[:12]
        raw += data[n - start:n - stop]
        first = first or data
        last = data
    if fast and len(record):
        ros1 = not bag.is2
        dtype = np.dtype([("head", "u1", (4,)), ("sec", "<u4" if ros1 else "<i4"), ("nsec", "<u4"),
                          ("v", "<f8", (hi - lo,))])
        rows = np.frombuffer(raw, dtype=dtype)
        header = rows["sec"].astype(np.int64) * 1_000_000_000 + rows["nsec"].astype(np.int64)
        values = rows["v"][:, [i - lo for i in index]].astype(np.float64)
        little = ros1 or bool(np.all(rows["head"][:, 1] == 1) and np.all(rows["head"][:, 0] == 0))
        if little and all(_same(bag, d, kind, header[i], values[i], columns) for i, d in ((0, first), (-1, last))):
            return np.frombuffer(record, dtype=np.int64).copy(), header, values
    return _deserialised(bag, each(), kind, columns, fields, where)


def _field(msg, path: tuple[str, ...]) -> float:
    for name in path:
        msg = getattr(msg, name)
    return float(msg)


def _same(bag, data: bytes, kind: str, header: int, values: np.ndarray, columns: list[str]) -> bool:
    """Whether rosbags deserialises the message ``data`` to the stamp and values cut from its bytes."""
    fields = _LAYOUTS[kind][1]
    try:
        msg = bag.deserialize(data, kind)
        stamp = int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)
        return stamp == header and all(np.array_equal(_field(msg, fields[c][1]), v, equal_nan=True)
                                       for c, v in zip(columns, values))
    except Exception:  # noqa: BLE001 - not deserialised, or not these fields: the slow path says why
        return False


def _deserialised(bag, messages, kind: str, columns: list[str], fields, where: str):
    """Every message deserialised by rosbags (a layout the fast path does not know)."""
    record, header, rows = [], [], []
    try:
        for _, stamp, data in messages:
            msg = bag.deserialize(data, kind)
            record.append(stamp)
            header.append(int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec))
            rows.append([_field(msg, fields[c][1]) for c in columns])
    except Exception as exc:  # noqa: BLE001 - a message that does not deserialise: a damaged bag
        raise _damaged(exc, where) from None
    return (np.array(record, dtype=np.int64), np.array(header, dtype=np.int64),
            np.array(rows, dtype=np.float64).reshape(len(rows), len(columns)))


def _stamps(topic: str, record: np.ndarray, header: np.ndarray, stamps: str, where: str) -> np.ndarray:
    """The samples' stamps in ns: header stamps (checked: not going back, not mostly repeated) or record times."""
    if stamps == "record":
        return record
    t = header / 1e9
    step = np.diff(header)
    back = np.flatnonzero(step < 0)
    fix = "; use {stamps=record} (the time the recorder wrote each message) or fix the stamps"
    if back.size:
        k = int(back[0]) + 1
        raise InputError(f"topic '{literal(topic)}': the header stamp of message {k + 1} ({t[k]:.9f} s) is earlier "
                         f"than the one before ({t[k - 1]:.9f} s){fix}", where)
    if step.size and np.sum(step == 0) > 0.1 * step.size:
        zero = " (all zero: the driver does not stamp them)" if not header.any() else ""
        raise InputError(f"topic '{literal(topic)}': its header stamps repeat on {int(np.sum(step == 0))} of "
                         f"{step.size} steps{zero}{fix}", where)
    return header


def _storage(path: Path, ros1: bool) -> str:
    if ros1:
        return "ros1"
    files = [path] if path.is_file() else list(path.iterdir())
    return "mcap" if any(".mcap" in p.name for p in files) else "sqlite3"


def read(path: Path, names: list[str] | None, time_column: str | None, fmt: LogFormat) -> Columns:
    """One topic of a bag as columns (:data:`UNITS`): ``time`` and the message's readings.

    Parameters
    ----------
    path : Path
        A ``.bag``, ``.db3`` or ``.mcap`` file, or a ROS 2 bag folder (``metadata.yaml``).
    names : list of str or None
        Columns asked for (``time``, ``gyro_x`` ..., ``temperature``); None: all the topic gives.
    time_column : str or None
        The name among ``names`` that is the time (``time``), for the message when it is missing.
    fmt : LogFormat
        ``topic`` (None: the only Imu topic) and ``stamps`` (``"header"``, default, or ``"record"``).

    Returns
    -------
    Columns
        ``data`` (n, k) float64; ``units`` as stated; ``source`` the topic, its type, stamps and storage;
        ``notes`` how the temperature was joined.

    Raises
    ------
    InputError
        No rosbags; a damaged bag; an unknown topic, one of another type, an empty one, several to choose from;
        header stamps that go back; a column the topic does not give.
    """
    where = str(path)
    stamps = fmt.stamps or "header"
    with _opened(path) as bag:
        ros1, topics = not bag.is2, _topics(bag)
        topic = _choose(topics, fmt, names, ros1, where)
        kind, count = topics[topic]
        empty = InputError(f"topic '{literal(topic)}' holds no message; choose another with {{topic}} (its topics: "
                           f"{_listing(topics, ros1)})", where)
        if count == 0:
            raise empty
        own = ["time", *_LAYOUTS[kind][1]]
        asked = names is not None and "temperature" in names and kind != TEMPERATURE
        temp, why = (_temperature_topic(topic, topics, ros1, where, asked) if kind != TEMPERATURE and
                     (names is None or asked) else (None, None))
        available = own + (["temperature"] if temp is not None else [])
        _require(names, available, topic, topics, ros1, time_column, why, where)
        wanted = list(names) if names is not None else available
        record, header, values = _decode(bag, topic, kind, list(_LAYOUTS[kind][1]), where)
        if not len(record):  # an index that counts messages the storage does not hold
            raise empty
        ns = _stamps(topic, record, header, stamps, where)
        origin = int(ns[0])
        t = (ns - origin) / 1e9  # from the first sample: float64 keeps 1e-16 of the span, not 0.24 us of an epoch
        columns = {"time": t, **dict(zip(_LAYOUTS[kind][1], values.T))}
        source: dict[str, Any] = {"format": "rosbag", "topic": topic, "type": _kind(kind, ros1), "stamps": stamps,
                                  "time_origin_ns": origin, "storage": _storage(path, ros1)}
        notes: list[str] = []
        if temp is not None and "temperature" in wanted:
            columns["temperature"], note = _joined(bag, temp, t, origin, stamps, ros1, where)
            source["temperature_topic"] = temp
            notes.append(note)
        elif why is not None and names is None:
            notes.append(f"no temperature column: {why}")
    data = np.column_stack([columns[n] for n in wanted]) if wanted else np.empty((len(t), 0))
    return Columns(wanted, data, {n: UNITS[n] for n in wanted}, source, tuple(notes))


def _joined(bag, topic: str, t: np.ndarray, origin: int, stamps: str, ros1: bool, where: str
            ) -> tuple[np.ndarray, str]:
    """The Temperature topic's readings at the times ``t`` (s after ``origin`` ns; linear interpolation, held beyond
    its ends)."""
    record, header, values = _decode(bag, topic, TEMPERATURE, ["temperature"], where)
    if not len(record):
        raise InputError(f"topic '{literal(topic)}' holds no message; leave {{temperature_column}} out", where)
    tt = (_stamps(topic, record, header, stamps, where) - origin) / 1e9
    held = int(np.sum((t < tt[0]) | (t > tt[-1])))
    note = (f"temperature from topic {topic} ({_kind(TEMPERATURE, ros1)}, {len(tt)} messages) linearly interpolated "
            f"to the samples' {stamps} times" + (f"; held at its first or last value for {held} samples outside its "
                                                 "span" if held else ""))
    return np.interp(t, tt, values[:, 0]), note


def _require(names, available, topic, topics, ros1, time_column, why, where) -> None:
    """Every column asked for is one the topic gives; else one line with the columns there are and the way."""
    missing = [n for n in names or [] if n not in available]
    if not missing:
        return
    advice = "name the columns by the convention (time, gyro_x, accel_x, mag_x, temperature)"
    if missing == [time_column]:
        advice = "its time column is named 'time': give {time_column=time}"
    elif any(n.startswith("mag_") for n in missing) and any(k == MAGNETIC for k, _ in topics.values()):
        mags = ", ".join(t for t, (k, _) in sorted(topics.items()) if k == MAGNETIC)
        advice = f"the magnetometer is topic {literal(mags)} (read it with {{topic}})"
    elif missing == ["temperature"] and why is not None:
        advice = f"{why}; leave {{temperature_column}} out"
    listed = ", ".join(literal(n) for n in available)
    raise InputError(f"topic '{literal(topic)}' has no column {', '.join(repr(literal(m)) for m in missing)} "
                     f"(columns: {listed}); {advice}", where)


def describe(path: Path, fmt: LogFormat) -> list[Stream]:
    """The bag's topics: type, message count and, for those read here, columns, units and mean rate (record times).

    Returns
    -------
    list of Stream
        One per topic, sorted by name; ``extra`` holds ``rate_hz`` (from the record times of the first and last
        message) and ``storage`` for Imu, MagneticField and Temperature topics.
    """
    out = []
    with _opened(path) as bag:
        ros1, topics = not bag.is2, _topics(bag)
        for topic, (kind, count) in sorted(topics.items()):
            if kind not in _LAYOUTS:
                out.append(Stream(topic, _kind(kind, ros1), count))
                continue
            conns = [c for c in bag.connections if c.topic == topic]
            times = [stamp for _, stamp, _ in _guarded(bag.messages(connections=conns), str(path))]
            span = (times[-1] - times[0]) / 1e9 if len(times) > 1 else 0.0
            cols = ("time", *_LAYOUTS[kind][1])
            extra = {"storage": _storage(path, ros1), **({"rate_hz": (len(times) - 1) / span} if span > 0 else {})}
            out.append(Stream(topic, _kind(kind, ros1), len(times), cols, {c: UNITS[c] for c in cols}, extra))
    return out


def iter_chunks(path: Path, fmt: LogFormat, names: list[str] | None = None, rows: int = 100_000) -> Iterator[Columns]:
    """The columns :func:`read` gives (no temperature joined) in blocks of ``rows`` messages, in bounded memory."""
    where, stamps, origin = str(path), fmt.stamps or "header", None
    with _opened(path) as bag:
        topic = _choose(topics := _topics(bag), fmt, names, ros1 := not bag.is2, where)
        own = ["time", *_LAYOUTS[kind := topics[topic][0]][1]]
        _require(names, own, topic, topics, ros1, "time", "blocks of a long bag join no temperature topic", where)
        wanted = list(names) if names is not None else own
        source = {"format": "rosbag", "topic": topic, "type": _kind(kind, ros1), "stamps": stamps,
                  "storage": _storage(path, ros1)}
        messages = _guarded(bag.messages(connections=[c for c in bag.connections if c.topic == topic]), where)
        while batch := list(islice(messages, rows)):
            record, header, values = _decode(bag, topic, kind, list(_LAYOUTS[kind][1]), where, batch)
            ns = _stamps(topic, record, header, stamps, where)
            origin = int(ns[0]) if origin is None else origin
            columns = {"time": (ns - origin) / 1e9, **dict(zip(_LAYOUTS[kind][1], values.T))}
            yield Columns(wanted, np.column_stack([columns[n] for n in wanted]), {n: UNITS[n] for n in wanted},
                          {**source, "time_origin_ns": origin})


#: ROS bags: files by suffix, and a ROS 2 bag folder (its ``metadata.yaml``) by its listing
READER = LogReader("rosbag", (".bag", ".db3", ".mcap"), read, sniff, streams=True, describe=describe, folder=True,
                   chunks=iter_chunks)
