"""When a PX4 ULog was recorded: the UTC of its clock's zero, from a GPS fix.

A ULog's time stamps count microseconds since the flight controller started; a GPS receiver's messages
(``vehicle_gps_position``: ``time_utc_usec``, the fix's UTC, taken at ``timestamp + timestamp_time_relative`` of
the log's clock, per PX4's uORB message definition) tie that clock to UTC. :mod:`align.io.ulog` states the first
sample's UTC in the stream's source (``time_origin_utc_ns``).

Public names
------------
utc_at_boot, dated, Dating, GPS
"""

from __future__ import annotations

import numpy as np

from align.io.readers import Columns
from align.io.ulog_format import Scan, decode

#: the topic whose fix time dates a log (:func:`utc_at_boot`)
GPS = ("vehicle_gps_position", 0)


def utc_at_boot(scan: Scan, starts: dict[int, list[np.ndarray]]) -> int | None:
    """UTC (us since 1970) of the log's time zero, from ``vehicle_gps_position``'s ``time_utc_usec`` (the fix's
    UTC, at ``timestamp + timestamp_time_relative`` of the log's clock; PX4 uORB message definition), the median
    over the messages with a fix time; None when the log has no GPS time."""
    keys = [k for k, key in enumerate(scan.keys) if key == GPS]
    lay = scan.layouts[keys[0]] if keys else None
    if lay is None or "time_utc_usec" not in lay.fields or "timestamp" not in lay.fields:
        return None
    fields = ["timestamp", "time_utc_usec", *(["timestamp_time_relative"] if "timestamp_time_relative" in lay.fields
                                              else [])]
    rec = decode(scan.u8, np.concatenate(starts.get(keys[0]) or [np.zeros(0, np.int64)]), lay, fields)
    utc = rec["time_utc_usec"].astype(np.int64)
    at = rec["timestamp"].astype(np.int64) + (rec["timestamp_time_relative"].astype(np.int64)
                                              if "timestamp_time_relative" in fields else 0)
    ok = utc > 946_684_800_000_000  # after 2000-01-01: a fix's time, not zero
    return int(np.median(utc[ok] - at[ok])) if ok.any() else None


def dated(got: Columns, boot_us: int | None, first_s: float | None = None) -> Columns:
    """``got`` with its stream's first sample's UTC (ns since 1970) as ``source["time_origin_utc_ns"]``, when the
    log's clock is tied to UTC (``boot_us``, :func:`utc_at_boot`) and a time column was read (else ``got`` as it is).

    ``first_s``: the stream's first sample's time (s since power-on) when ``got`` is a later block of it; by default
    ``got``'s own first.
    """
    if first_s is None and "time" in got.names and len(got.data):
        first_s = float(got.data[0, got.names.index("time")])
    if boot_us is None or first_s is None:
        return got
    at = (boot_us + round(first_s * 1e6)) * 1000
    return Columns(got.names, got.data, got.units, {**got.source, "time_origin_utc_ns": int(at)}, got.notes)


class Dating:
    """Blocks of one stream dated alike (:func:`dated`): by the first sample of the first block with one."""

    def __init__(self, boot_us: int | None) -> None:
        self.boot_us = boot_us
        self.first_s: float | None = None

    def __call__(self, got: Columns) -> Columns:
        if self.first_s is None and "time" in got.names and len(got.data):
            self.first_s = float(got.data[0, got.names.index("time")])
        return dated(got, self.boot_us, self.first_s)
