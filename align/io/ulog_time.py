"""When a PX4 ULog was recorded: the UTC of its clock's zero, from a GPS fix.

A ULog's time stamps count microseconds since the flight controller started; a GPS receiver's messages
(``vehicle_gps_position``: ``time_utc_usec``, the fix's UTC, taken at ``timestamp + timestamp_time_relative`` of
the log's clock, per PX4's uORB message definition) tie that clock to UTC. :mod:`align.io.ulog` states the first
sample's UTC in the stream's source (``time_origin_utc_ns``).

Public names
------------
utc_at_boot, GPS (and :func:`align.io.gpstime.dated`, :class:`align.io.gpstime.Dating`)
"""

from __future__ import annotations

import numpy as np

from align.io.gpstime import Dating, dated  # noqa: F401  (the ULog reader takes them from here)
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
