"""A unit's identity as its log states it: the sensor's device id and when it was tested.

A manifest may state a unit's ``device_id`` and ``test_time`` (:data:`align.production.manifest.IDENTITY`);
where it does not, a log that states them gives them (the stream a result records, ``inputs["stream"]``, from
the log's reader, :class:`align.io.readers.Columns`; an Allan analysis's ``streams``):

* ``device_id``: the stream's own (a PX4 ULog's ``device_id`` field, ``sensor_gyro:N`` and the like);
* ``test_time``: the UTC of the first sample, from ``time_origin_utc_ns`` (a reader that dates its log from a
  GPS fix: a ULog's ``vehicle_gps_position``, a DataFlash log's ``GPS`` week and milliseconds), else from
  ``time_origin_ns`` when that is a date, between 2000-01-01 and a day from now (a ROS bag's or an EuRoC folder's
  stamps, nanoseconds since 1970 when the recorder's clock is the wall clock; a simulated clock starts near zero
  and dates nothing).

The manifest's value wins; a log that states another device id is said in the unit's message (the wrong log
for a serial, or a label that is wrong).

Public names
------------
log_identity, unit_identity
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from datetime import UTC, datetime, timedelta
from typing import Any

__all__ = ["log_identity", "unit_identity"]

#: 2000-01-01T00:00:00Z in ns since 1970: an earlier origin is a clock since power-on, not a date
_EPOCH_FLOOR_NS = 946_684_800 * 10**9
_EPOCH = datetime(1970, 1, 1, tzinfo=UTC)


def _stream(result: Any) -> Mapping[str, Any]:
    """The first stream a result records: its inputs' ``stream``, or the first of its ``streams`` (an Allan
    analysis's records, as an attribute or in its inputs)."""
    inputs = getattr(result, "inputs", None)
    inputs = inputs if isinstance(inputs, Mapping) else {}
    if isinstance(inputs.get("stream"), Mapping):
        return inputs["stream"]
    for item in (inputs.get("streams") or getattr(result, "streams", None) or ()):
        if isinstance(item, Mapping) and isinstance(item.get("stream"), Mapping):
            return item["stream"]
    return {}


def log_identity(result: Any, now_ns: int | None = None) -> dict[str, str]:
    """``device_id`` and ``test_time`` (ISO 8601, UTC) of the log a result was computed from, where it states them.

    Parameters
    ----------
    result : Result
        Any result whose ``inputs`` record the stream read (module docstring).
    now_ns : int, optional
        The present, ns since 1970 (a time stamp after it is not a date); default: the clock.

    Returns
    -------
    dict of str -> str
        Empty when the log states neither (a CSV file).

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> r = SimpleNamespace(inputs={"stream": {"device_id": 2424842, "time_origin_utc_ns": 1618986658468386000}})
    >>> log_identity(r)
    {'device_id': '2424842', 'test_time': '2021-04-21T06:30:58.468386+00:00'}
    >>> log_identity(SimpleNamespace(inputs={"stream": {"time_origin_ns": 12_000_000_000}}))  # since power-on
    {}
    """
    stream = _stream(result)
    out: dict[str, str] = {}
    if stream.get("device_id") not in (None, "", 0):
        out["device_id"] = str(stream["device_id"])
    limit = (time.time_ns() if now_ns is None else now_ns) + 86_400 * 10**9
    for key in ("time_origin_utc_ns", "time_origin_ns"):
        value = stream.get(key)
        if isinstance(value, int) and _EPOCH_FLOOR_NS <= value <= limit:
            out["test_time"] = (_EPOCH + timedelta(microseconds=value // 1000)).isoformat()
            break
    return out


def unit_identity(stated: Mapping[str, str], logged: Mapping[str, str]) -> tuple[dict[str, str], str]:
    """A unit's identity: the manifest's (``stated``), the log's (``logged``, :func:`log_identity`) where the
    manifest gives none; and a remark (empty when none) where both give a device id and they differ.

    >>> ident, said = unit_identity({"station": "S1", "device_id": "7"}, {"device_id": "9"})
    >>> ident, said.startswith("the log states device id 9")
    ({'device_id': '7', 'station': 'S1'}, True)
    """
    said = ""
    if "device_id" in stated and "device_id" in logged and stated["device_id"] != logged["device_id"]:
        said = (f"the log states device id {logged['device_id']}, the manifest {stated['device_id']}: is it the "
                "unit's log?")
    return {**logged, **stated}, said
