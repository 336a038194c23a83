"""GPS time (week and milliseconds of the week) as UTC: what dates a flight controller's log.

GPS time counts from 1980-01-06T00:00:00Z without leap seconds; UTC has had leap seconds inserted since, so
``UTC = GPS epoch + GPS seconds - (GPS - UTC)``, the offset from IERS Bulletin C (:data:`LEAP`: 18 s since
2017-01-01). A log's clock (microseconds since power-on) is tied to UTC by a record holding both.

Public names
------------
gps_utc_us, dated, Dating, LEAP, GPS_EPOCH_US
"""

from __future__ import annotations

from datetime import UTC, datetime

import numpy as np

from align.io.readers import Columns

__all__ = ["gps_utc_us", "dated", "Dating", "LEAP", "GPS_EPOCH_US"]

#: 1980-01-06T00:00:00Z in microseconds since 1970
GPS_EPOCH_US = int(datetime(1980, 1, 6, tzinfo=UTC).timestamp()) * 1_000_000
#: (UTC from which, GPS - UTC in s): the leap seconds of IERS Bulletin C from 1999 on
LEAP = ((datetime(1999, 1, 1, tzinfo=UTC), 13), (datetime(2006, 1, 1, tzinfo=UTC), 14),
        (datetime(2009, 1, 1, tzinfo=UTC), 15), (datetime(2012, 7, 1, tzinfo=UTC), 16),
        (datetime(2015, 7, 1, tzinfo=UTC), 17), (datetime(2017, 1, 1, tzinfo=UTC), 18))


def gps_utc_us(week: np.ndarray, ms: np.ndarray) -> np.ndarray:
    """UTC (us since 1970) of GPS times given as ``week`` (since 1980-01-06) and ``ms`` of the week; -1 before 1999
    (an offset this table does not hold).

    Parameters
    ----------
    week : array_like, shape (n,)
        GPS weeks since 1980-01-06 (not rolled over at 1024).
    ms : array_like, shape (n,)
        Milliseconds since the start of the week (GPS time, no leap seconds).

    Returns
    -------
    ndarray, shape (n,), int64

    Examples
    --------
    GPS week 2300, 216,018 s into it: 2024-02-06T12:00:00Z (18 leap seconds).

    >>> us = int(gps_utc_us(np.array([2300]), np.array([216_018_000]))[0])
    >>> datetime.fromtimestamp(us / 1e6, UTC).isoformat()
    '2024-02-06T12:00:00+00:00'
    """
    gps = GPS_EPOCH_US + np.asarray(week, np.int64) * 604_800_000_000 + np.asarray(ms, np.int64) * 1000
    out = np.full(gps.shape, -1, np.int64)
    for since, offset in LEAP:  # later entries overwrite: the offset in force at each time
        utc = gps - offset * 1_000_000
        out = np.where(utc >= int(since.timestamp()) * 1_000_000, utc, out)
    return out


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
