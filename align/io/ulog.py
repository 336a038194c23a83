"""PX4 ULog logs (``.ulg``): the IMU topics, read by our own reader (:mod:`align.io.ulog_format`).

A stream is chosen by :attr:`~align.io.formats.LogFormat.topic`, ``name:instance`` (the instance is the
ULog ``multi_id``; ``:0`` when left out), and read as the one convention's columns
(:class:`align.vocab.Sensor`), ``time`` in s from the microseconds of the log:

* ``sensor_combined``: ``gyro_x..z`` from ``gyro_rad[3]`` (rad/s), ``accel_x..z`` from
  ``accelerometer_m_s2[3]`` (m/s^2); no temperature. Time is ``timestamp``, the gyro's; the
  accelerometer's own (``timestamp + accelerometer_timestamp_relative``) when only accelerometer
  columns are read.
* ``sensor_gyro:N``, ``sensor_accel:N``, ``sensor_mag:N``: ``x, y, z`` (rad/s, m/s^2, gauss) as
  ``gyro_*``, ``accel_*``, ``mag_*``, and ``temperature`` (degC); time is ``timestamp_sample``, when the
  sensor sampled, else ``timestamp`` (``stamps="record"``: always ``timestamp``, when it was published).
* ``vehicle_imu:N``: ``delta_angle[3] / delta_angle_dt`` and ``delta_velocity[3] / delta_velocity_dt``, the
  mean rate and specific force over each interval (the intervals are in microseconds as integers; as a
  float, in seconds unless above 1), stamped at the interval's end (``timestamp_sample``).
* ``imu:N``, the joined view (several jobs read both sensors of one file): the gyro and the accelerometer of
  one IMU in one row, from ``sensor_gyro:N`` and ``sensor_accel:N``, a pair being two samples each the other's
  nearest in time and at most half the smaller median step apart (:func:`~align.io.ulog_format.match`; PX4
  stamps both of one FIFO read alike). A row has the gyro's time and temperature; samples without a partner
  are left out (stated). Read for one sensor's columns alone, it is that sensor's topic in full.

No topic given: ``sensor_combined`` if the log has it, else ``imu:0`` (stated in the result's source and
notes). The units stated are those the PX4 message definitions give (:data:`UNITS`). A topic, instance or
column the log lacks, a topic with no sample, time stamps that go back and a file that is no ULog are
refused naming the file and the topic, with what there is.

Public names
------------
read, describe, iter_chunks, sniff, READER, KINDS, UNITS
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from align.errors import InputError, literal
from align.io.formats import LogFormat
from align.io.readers import Columns, LogReader, Stream
from align.io.ulog_format import Join, Layout, Scan, decode, match, sniff, tolerance
from align.io.ulog_time import GPS, Dating, dated, utc_at_boot

__all__ = ["read", "describe", "iter_chunks", "sniff", "READER", "KINDS", "UNITS"]

_XYZ = "xyz"
#: ULog message -> (column of the one convention -> its field)
KINDS: dict[str, dict[str, str]] = {
    "sensor_combined": {**{f"gyro_{a}": f"gyro_rad[{i}]" for i, a in enumerate(_XYZ)},
                        **{f"accel_{a}": f"accelerometer_m_s2[{i}]" for i, a in enumerate(_XYZ)}},
    "sensor_gyro": {**{f"gyro_{a}": a for a in _XYZ}, "temperature": "temperature"},
    "sensor_accel": {**{f"accel_{a}": a for a in _XYZ}, "temperature": "temperature"},
    "sensor_mag": {**{f"mag_{a}": a for a in _XYZ}, "temperature": "temperature"},
    "vehicle_imu": {**{f"gyro_{a}": f"delta_angle[{i}]" for i, a in enumerate(_XYZ)},
                    **{f"accel_{a}": f"delta_velocity[{i}]" for i, a in enumerate(_XYZ)}},
}
#: the unit of each column, as the PX4 message definitions state it
UNITS = {"time": "s", "temperature": "degC", **{f"{s}_{a}": u for s, u in (("gyro", "rad/s"), ("accel", "m/s^2"),
                                                                            ("mag", "gauss")) for a in _XYZ}}
JOINED = "imu"
_ORDER = ("sensor_combined", "sensor_gyro", "sensor_accel", "vehicle_imu", JOINED, "sensor_mag")
_TOPIC = re.compile(r"\s*([A-Za-z0-9_]+)\s*(?::\s*(\d+))?\s*")
_INVALID_RELATIVE = 2**31 - 1  # sensor_combined: no accelerometer sample in this message


@dataclass(frozen=True)
class _Choice:
    """The stream read: its kind (a key of :data:`KINDS`, or ``imu``), instance and scan keys."""

    kind: str
    instance: int
    keys: tuple[int, ...]  # one key; for imu: (sensor_gyro:N, sensor_accel:N), -1 where absent
    default: bool = False

    @property
    def topic(self) -> str:
        return self.kind if self.kind == "sensor_combined" else f"{self.kind}:{self.instance}"


def _key(scan: Scan, name: str, instance: int) -> int:
    return scan.keys.index((name, instance)) if (name, instance) in scan.keys else -1


def _count(scan: Scan, k: int) -> int:
    return int(scan.counts[k]) if k >= 0 else 0


def _instances(scan: Scan, kind: str, column: str | None = None) -> dict[int, int]:
    """Instances of a kind in the log (those whose format has ``column``) -> samples (``imu``: those of its gyro,
    or accelerometer)."""
    if kind == JOINED:
        g, a = _instances(scan, "sensor_gyro", column), _instances(scan, "sensor_accel", column)
        return {i: max(g.get(i, 0), a.get(i, 0)) for i in sorted(set(g) | set(a))}
    return {m: int(scan.counts[k]) for k, (n, m) in enumerate(scan.keys) if n == kind and (
        column in (None, "time") or KINDS[kind].get(str(column), "") in getattr(scan.layouts[k], "fields", ()))}


def _listing(scan: Scan, column: str | None = None) -> str:
    """The IMU topics of the log with instances and samples (``sensor_gyro:0/1/2 (6/6/6)``), those having
    ``column`` when given."""
    parts = []
    for kind in _ORDER:
        if not (inst := _instances(scan, kind, column)):
            continue
        name = kind if kind == "sensor_combined" else f"{kind}:{'/'.join(map(str, inst))}"
        parts.append(f"{name} ({'/'.join(map(str, inst.values()))})")
    return ", ".join(parts) or "none"


def _choose(scan: Scan, topic: str | None, where: str) -> _Choice:
    """The stream ``topic`` names, or the default; refused naming the topics there are."""
    if topic is None:
        if _count(scan, k := _key(scan, "sensor_combined", 0)):
            return _Choice("sensor_combined", 0, (k,))
        topic = "imu:0"
        if not _instances(scan, JOINED):
            raise InputError(f"has no IMU topic with samples (sensor_combined, sensor_gyro, sensor_accel; IMU topics: "
                             f"{_listing(scan)}); give a log recorded with them", where)
    m = _TOPIC.fullmatch(topic)
    kind, inst = (m.group(1).lower(), int(m.group(2) or 0)) if m else (topic, 0)
    shown = literal(topic.strip())
    if kind not in KINDS and kind != JOINED:
        logged = m is not None and any(n == m.group(1) for n, _ in scan.keys)
        what = "is logged but is not an IMU topic this reader reads" if logged else "is not in the log"
        raise InputError(f"topic '{shown}' {what}; give one of its IMU topics with {{topic}}: {_listing(scan)}",
                         where)
    inst_all = _instances(scan, kind)
    if inst not in inst_all:
        have = ", ".join(map(str, inst_all)) or "none"
        raise InputError(f"topic '{shown}': the log has no instance {inst} of {kind} (instances: {have}); IMU "
                         f"topics: {_listing(scan)}", where)
    keys = ((_key(scan, "sensor_gyro", inst), _key(scan, "sensor_accel", inst)) if kind == JOINED
            else (_key(scan, kind, inst),))
    if not any(_count(scan, k) for k in keys):
        raise InputError(f"topic '{shown}' is in the log but holds no sample; IMU topics (samples): "
                         f"{_listing(scan)}", where)
    for k in keys:
        if k >= 0 and scan.layouts[k] is None:
            raise InputError(f"topic '{shown}': the log does not define the format of {scan.keys[k][0]}; the log is "
                             "damaged, give another topic", where)
    return _Choice(kind, inst, keys)


def _available(scan: Scan, choice: _Choice) -> list[str]:
    """The columns the stream gives: time, then those of its fields the log has."""
    if choice.kind == JOINED:
        g = _available(scan, _Choice("sensor_gyro", choice.instance, choice.keys[:1])) if choice.keys[0] >= 0 else []
        a = _available(scan, _Choice("sensor_accel", choice.instance, choice.keys[1:])) if choice.keys[1] >= 0 else []
        return ["time"] + [c for c in g + a if c[:4] in ("gyro", "acce")] + (["temperature"] if "temperature" in g + a
                                                                           else [])
    lay = scan.layouts[choice.keys[0]]
    assert lay is not None
    return ["time"] + [c for c, f in KINDS[choice.kind].items() if f in lay.fields]


def _require(scan: Scan, choice: _Choice, names: list[str] | None, time_column: str | None, where: str) -> list[str]:
    have = _available(scan, choice)
    if choice.kind == JOINED:  # a sensor whose topic has no sample is not on offer
        have = [c for c in have if not ((c.startswith("gyro") and not _count(scan, choice.keys[0]))
                                        or (c.startswith("accel") and not _count(scan, choice.keys[1])))]
    wanted = list(names) if names is not None else have
    missing = [n for n in wanted if n not in have]
    if missing:
        col = missing[0]
        others = _listing(scan, col) if col in UNITS else ""
        advice = (f"{others} have it: give one with {{topic}}" if others and others != "none" else
                  "its time column is 'time': give {time_column=time}" if col == time_column else
                  "name columns of the one convention with {columns}")
        raise InputError(f"topic {choice.topic} has no column {', '.join(repr(literal(c)) for c in missing)} "
                         f"(columns: {', '.join(have)}); {advice}", where)
    return wanted


def _stamps(rec: np.ndarray, lay: Layout, stamps: str | None) -> np.ndarray:
    """Time of each record, integer microseconds: when sampled (``timestamp_sample``) or published."""
    if stamps != "record" and "timestamp_sample" in lay.fields:
        return rec["timestamp_sample"].astype(np.int64)
    t = rec["timestamp"].astype(np.int64)
    return t * 1000 if lay.fields["timestamp"][0] == "u1" else t  # a uint8 timestamp is in ms (the spec)


def _single(scan: Scan, kind: str, k: int, starts: np.ndarray, cols: list[str], stamps: str | None
            ) -> tuple[np.ndarray, dict[str, np.ndarray], dict[str, float], list[int]]:
    """Records of one topic as time (us), columns, samples left out (by why; ``relative``: the accelerometer's
    median stamp after the gyro's, us), device ids seen."""
    lay = scan.layouts[k]
    assert lay is not None
    spec = KINDS[kind]
    fields: set[str] = {f for f in ("timestamp", "timestamp_sample", "device_id", "gyro_device_id", "accel_device_id",
                          "accelerometer_timestamp_relative", "delta_angle_dt", "delta_velocity_dt") if f in lay.fields}
    fields |= {spec[c] for c in cols if c in spec and spec[c] in lay.fields}
    rec = decode(scan.u8, starts, lay, sorted(fields))
    t, stats, keep = _stamps(rec, lay, stamps), dict[str, float](), np.ones(len(rec), bool)
    out = {c: rec[spec[c]].astype(np.float64) if spec[c] in lay.fields else np.full(len(rec), np.nan) for c in cols}
    gyro, accel = any(c.startswith("gyro") for c in out), any(c.startswith("accel") for c in out)
    if kind == "sensor_combined" and "accelerometer_timestamp_relative" in fields and accel:
        rel = rec["accelerometer_timestamp_relative"].astype(np.int64)
        keep &= (ok := rel != _INVALID_RELATIVE)
        stats["messages without an accelerometer sample"] = int((~ok).sum())
        if not gyro:  # the accelerometer alone: its own time
            t = t + np.where(ok, rel, 0)
        elif ok.any():
            stats["relative"] = float(np.median(rel[ok]))
    if kind == "vehicle_imu":
        for sensor, dt_name in (("gyro", "delta_angle_dt"), ("accel", "delta_velocity_dt")):
            if dt_name in fields and any(c.startswith(sensor) for c in out):
                dt = rec[dt_name].astype(np.float64)  # integers: us; a float: s, unless above 1 (then us)
                dt = dt * (1.0 if lay.fields[dt_name][0][-2] == "f" and not (len(dt) and np.median(dt) > 1) else 1e-6)
                keep &= dt > 0
                for c in [c for c in out if c.startswith(sensor)]:
                    out[c] = out[c] / np.where(dt > 0, dt, 1.0)
        stats["samples of a zero interval"] = int((~keep).sum())
    ids = [f for f in ("device_id", "gyro_device_id" if gyro or not accel else "accel_device_id") if f in fields]
    seen = [int(v) for v in np.unique(rec[ids[0]])] if ids else []
    if not keep.all():
        t, out = t[keep], {c: v[keep] for c, v in out.items()}
    return t, out, stats, seen


def _monotonic(t: np.ndarray, before: int, n0: int, label: str, where: str) -> None:
    """Refuse stamps that go back (``before``: the last stamp of the pieces before, ``n0`` samples)."""
    tt = np.concatenate([[before], t])
    if len(back := np.flatnonzero(np.diff(tt) < 0)):
        i = int(back[0])
        raise InputError(f"time stamps of {label} go back at sample {n0 + i + 1} ({tt[i + 1] / 1e6:.6f} s after "
                         f"{tt[i] / 1e6:.6f} s); the log is damaged: give another topic with {{topic}}", where)


class _Reader:
    """One stream of a scanned log read in pieces: each call to :meth:`piece` turns records into rows."""

    def __init__(self, scan: Scan, choice: _Choice, names: list[str], fmt: LogFormat, where: str) -> None:
        self.scan, self.choice, self.names, self.fmt, self.where = scan, choice, names, fmt, where
        data = [n for n in names if n != "time"]
        if choice.kind == JOINED:  # both sensors paired, or the one asked for in full
            (gk, ak), temp = choice.keys, [c for c in data if c == "temperature"]
            g, a = [c for c in data if c.startswith("gyro")], [c for c in data if c.startswith("accel")]
            self.parts = ([("sensor_gyro", gk, g + temp), ("sensor_accel", ak, a)] if g and a else
                          [("sensor_accel", ak, a + temp)] if a or not _count(scan, gk) else [("sensor_gyro", gk, g + temp)])
        else:
            self.parts = [(choice.kind, choice.keys[0], data)]
        self.join = Join(self.parts[0][2], self.parts[1][2]) if len(self.parts) == 2 else None
        self.last, self.n = [-(1 << 62)] * len(self.parts), [0] * len(self.parts)
        self.labels = [kind if kind == "sensor_combined" else f"{kind}:{choice.instance}" for kind, _, _ in self.parts]
        self.stats: dict[tuple[str, str], float] = {}
        self.devices: list[list[int]] = [[] for _ in self.parts]

    def piece(self, starts: dict[int, np.ndarray], final: bool) -> np.ndarray:
        """Rows (n, len(names)) float64 of the records at ``starts`` (by key)."""
        got = []
        for p, (kind, k, cols) in enumerate(self.parts):
            t, out, stats, seen = _single(self.scan, kind, k, starts.get(k, np.zeros(0, np.int64)), cols, self.fmt.stamps)
            _monotonic(t, self.last[p], self.n[p], self.labels[p], self.where)
            self.last[p], self.n[p] = int(t[-1]) if len(t) else self.last[p], self.n[p] + len(t)
            for why, v in stats.items():  # counts add up; the stamps' median is the first piece's
                self.stats[self.labels[p], why] = (self.stats.get((self.labels[p], why), 0) + v if why != "relative"
                                                   else self.stats.get((self.labels[p], why), v))
            self.devices[p] += [d for d in seen if d not in self.devices[p]]
            got.append((t, out))
        if self.join is not None:
            joined = self.join.feed(got[0], got[1], final)
            if joined is None:
                return np.zeros((0, len(self.names)))
            t, out = joined
        else:
            t, out = got[0]
        return np.column_stack([t * 1e-6 if n == "time" else out[n] for n in self.names]) if len(t) else np.zeros(
            (0, len(self.names)))

    def columns(self, data: np.ndarray, last: bool = True) -> Columns:
        """Rows as :class:`Columns`, with the stream's source, units and (with ``last``) every note."""
        c, dev = self.choice, [next(iter(d), None) for d in self.devices]
        source = {"format": "ulog", "topic": c.kind, "instance": c.instance, "device_id": dev[0],
                  **({"messages": [kind for kind, _, _ in self.parts]} if c.kind == JOINED else {}),
                  **({"accel_device_id": dev[1]} if len(dev) == 2 else {})}
        notes: list[str] = []
        if last:
            notes = [*self.scan.notes(), *(f"{label}: {int(v)} {why} left out" if why != "relative" else
                                           f"{label}: accelerometer samples are stamped {v / 1e3:.3g} ms (median) after "
                                           "the gyro's; each row carries the gyro's time"
                                           for (label, why), v in self.stats.items() if v)]
            notes += [f"{label}: its device id changes ({', '.join(map(str, d))})" for label, d in
                      zip(self.labels, self.devices) if len(d) > 1]
            notes += [f"{self.scan.keys[k][0]}:{self.scan.keys[k][1]}: {int(self.scan.wrong[k])} records of a wrong "
                      "size left out" for _, k, _ in self.parts if self.scan.wrong[k]]
            notes += self.join.notes(c.topic) if self.join is not None else []
            if c.default:
                notes.append(f"no topic given: {c.topic} read (the default; the log's IMU topics: "
                             f"{_listing(self.scan)})")
        return Columns(list(self.names), data, {n: UNITS[n] for n in self.names}, source, tuple(notes))


def _open(path: Path, fmt: LogFormat, names: list[str] | None, time_column: str | None, keep: bool
          ) -> tuple[Scan, _Reader, dict[int, list[np.ndarray]]]:
    """Scan a log (the offsets of the candidate topics kept when ``keep``, the GPS fixes' always); choose the stream."""
    scan, where, starts = Scan(path), str(path), dict[int, list[np.ndarray]]()
    wanted = _candidates(fmt.topic) | {GPS} if keep else {GPS}
    for st, key in scan.windows():
        for k in np.unique(key).tolist():
            if scan.keys[k] in wanted:
                starts.setdefault(k, []).append(st[key == k])
    chosen = _choose(scan, fmt.topic, where)
    choice = _Choice(chosen.kind, chosen.instance, chosen.keys, fmt.topic is None)
    return scan, _Reader(scan, choice, _require(scan, choice, names, time_column, where), fmt, where), starts


def _candidates(topic: str | None) -> set[tuple[str, int]]:
    """The (message, multi_id) pairs a topic may read (several: the default's candidates, imu's two)."""
    kind, inst = (m.group(1).lower(), int(m.group(2) or 0)) if (m := _TOPIC.fullmatch(topic or "")) else ("", 0)
    return {(kind, inst)} if topic is not None and kind != JOINED else {("sensor_combined", 0), ("sensor_gyro", inst),
                                                                        ("sensor_accel", inst)}


def read(path: Path, names: list[str] | None, time_column: str | None, log_format: LogFormat) -> Columns:
    """Columns of one IMU stream of a ULog (see the module docstring), float64, time in s.

    Parameters
    ----------
    path : Path
    names : list of str or None
        Columns of the one convention (``time``, ``gyro_x`` ..., ``temperature``); None: all the stream has.
    time_column : str or None
        The name among ``names`` that is the time (``time``), for messages.
    log_format : LogFormat
        ``topic`` (``sensor_gyro:1``, ``imu:0``; None: the default) and ``stamps``.

    Returns
    -------
    Columns
        ``data`` (n, len(names)); units, the stream read (``format``, ``topic``, ``instance``, ``device_id``, and
        ``time_origin_utc_ns``, the first sample's UTC, when the log has a GPS fix's time) and remarks.
    """
    scan, reader, starts = _open(path, log_format, names, time_column, keep=True)
    try:
        rows = reader.piece({k: np.concatenate(v) for k, v in starts.items()}, final=True)
        return dated(reader.columns(rows), utc_at_boot(scan, starts))
    finally:
        scan.close()


def iter_chunks(path: Path, log_format: LogFormat, names: list[str] | None = None, rows: int = 1 << 20
                ) -> Iterator[Columns]:
    """The columns :func:`read` gives, in blocks of at most ``rows`` rows, in bounded memory: the log is scanned
    once to choose the stream (nothing kept), then again window by window, each window's records decoded
    and handed on. The last block carries the notes.

    Yields
    ------
    Columns
        ``data`` (k, len(names)) float64, k <= rows.
    """
    scan, reader, gps = _open(path, log_format, names, "time", keep=False)
    boot = utc_at_boot(scan, gps)
    scan.close()
    scan = reader.scan = Scan(path)
    keys, block, date = {k for _, k, _ in reader.parts}, np.zeros((0, len(reader.names))), Dating(boot)
    try:
        for st, key in scan.windows():
            block = np.concatenate([block, reader.piece({k: st[key == k] for k in keys}, final=False)])
            n = len(block) // rows * rows
            for s in range(0, n, rows):
                yield date(reader.columns(block[s : s + rows], last=False))
            block = block[n:]
        block = np.concatenate([block, reader.piece({}, final=True)])
        for s in range(0, max(len(block), 1), rows):
            yield date(reader.columns(block[s : s + rows], last=s + rows >= len(block)))
    finally:
        scan.close()


def describe(path: Path, log_format: LogFormat) -> list[Stream]:
    """Every logged topic and instance with its samples; for the IMU topics their columns, units, device id and
    median rate (``extra``), and the joined ``imu:N`` views.

    Returns
    -------
    list of Stream
    """
    scan, t, ids = Scan(path), dict[int, np.ndarray](), dict[int, "int | None"]()
    try:
        for st, key in scan.windows():
            for k in np.unique(key).tolist():
                lay = scan.layouts[k]
                assert lay is not None
                idf = [f for f in ("device_id", "gyro_device_id") if f in lay.fields][:1]
                rec = decode(scan.u8, st[key == k], lay, [f for f in ("timestamp", "timestamp_sample") if f in
                                                          lay.fields] + idf)
                t[k] = np.concatenate([t.get(k, np.zeros(0, np.int64)), _stamps(rec, lay, log_format.stamps)])
                ids.setdefault(k, int(rec[idf[0]][0]) if idf else None)
    finally:
        scan.close()
    out = []
    for k, (name, inst) in sorted(enumerate(scan.keys), key=lambda e: e[1]):
        cols = tuple(_available(scan, _Choice(name, inst, (k,)))) if name in KINDS and scan.layouts[k] else ()
        several = name in KINDS and name != "sensor_combined" or inst > 0 or sum(n == name for n, _ in scan.keys) > 1
        out.append(Stream(f"{name}:{inst}" if several else name, name, int(scan.counts[k]), cols,
                          {c: UNITS[c] for c in cols}, {"instance": inst, "median_rate_hz": _rate(t.get(k)),
                                                        "device_id": ids.get(k)}))
    for inst in _instances(scan, JOINED):
        g, a = _key(scan, "sensor_gyro", inst), _key(scan, "sensor_accel", inst)
        if _count(scan, g) and _count(scan, a):
            i, _ = match(t[g], t[a], tolerance(t[g], t[a]))
            cols = tuple(_available(scan, _Choice(JOINED, inst, (g, a))))
            out.append(Stream(f"{JOINED}:{inst}", "sensor_gyro+sensor_accel", len(i), cols, {c: UNITS[c] for c in cols},
                              {"instance": inst, "median_rate_hz": _rate(t[g][i]), "device_id": ids.get(g),
                               "accel_device_id": ids.get(a)}))
    return out


def _rate(t: np.ndarray | None) -> float | None:
    """The median rate of stamps in us, Hz (None: fewer than two, or no step)."""
    step = float(np.median(np.diff(t))) if t is not None and len(t) > 1 else 0.0
    return 1e6 / step if step > 0 else None


READER = LogReader("ulog", (".ulg",), read, sniff=sniff, streams=True, describe=describe, chunks=iter_chunks)
