"""The PX4 ULog file (``.ulg``): its messages, found with one lean loop and decoded with numpy.

The format describes itself (https://docs.px4.io/main/en/dev_log/ulog_file_format.html): a 16-byte header
(the magic ``ULog 01 12 35``, a version byte, the start time, uint64 microseconds), then messages, each a
3-byte header (``uint16 msg_size`` of what follows, ``uint8 msg_type``) and its bytes, little-endian:

* definitions: ``B`` flag bits (8 compat, 8 incompat flag bytes, 3 uint64 offsets of appended data), ``F`` a
  format (``name:type field;type[n] field;...``, a type a base type or a format), ``I``/``M``, ``P``/``Q``;
* data: ``A`` a subscription (``uint8 multi_id``, ``uint16 msg_id``, the format's name), ``R`` its end,
  ``D`` a sample (``uint16 msg_id``, then the fields packed with no padding but the ``_padding`` fields
  the format names; a trailing one is not logged), ``L`` / ``C`` log text, ``S`` a sync marker (8 bytes,
  :data:`SYNC`), ``O`` a dropout (``uint16`` ms lost), ``I`` / ``M`` / ``P`` again.

:class:`Scan` walks the messages by their sizes (one step per message, nothing else; compiled for a large file)
window by window of the file's bytes (the pages of windows read released); each window's ``D`` records are told
apart by their ``msg_id`` with numpy; :func:`decode` reads one topic's records with one structured dtype. A
message cut short ends the scan, bytes that are no message are skipped to the next sync marker (both stated);
data appended after a crash (``DATA_APPENDED``) is read from its offsets on. :func:`match` and :class:`Join`
pair two sensors' samples by their stamps (the joined ``imu:N`` view).

Public names
------------
MAGIC, SYNC, TYPES, Layout, layout, parse_format, sniff, Scan, decode, match, tolerance, Join
"""

from __future__ import annotations

import contextlib
import mmap
import re
import struct
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from align.errors import InputError, literal

__all__ = ["MAGIC", "SYNC", "TYPES", "Layout", "layout", "parse_format", "sniff", "Scan", "decode", "match", "tolerance", "Join"]

#: the first 7 bytes of every ULog file
MAGIC = b"ULog\x01\x12\x35"
#: the payload of a sync message
SYNC = b"\x2f\x73\x13\x20\x25\x0c\xbb\x12"
#: ULog base type -> numpy type (little-endian)
TYPES = {"int8_t": "i1", "uint8_t": "u1", "int16_t": "<i2", "uint16_t": "<u2", "int32_t": "<i4", "uint32_t": "<u4",
         "int64_t": "<i8", "uint64_t": "<u8", "float": "<f4", "double": "<f8", "bool": "?", "char": "S1"}
#: window of bytes scanned at a time (a message is at most 3 + 65535 bytes)
WINDOW = 1 << 24
#: files larger than this (bytes) are walked by the compiled walk: ~0.02 s per 100 MB, after ~1 s to import numba and
#: load it; the Python walk takes ~0.5 s per 100 MB
COMPILED_ABOVE = 200 << 20
_COMPILED: list = []
_FIELD = re.compile(r"\s*([A-Za-z0-9_]+)\s*(?:\[\s*(\d+)\s*\])?\s+([A-Za-z0-9_]+)\s*")
_LETTER = np.isin(np.arange(256), [*range(65, 91), *range(97, 123)])
_D, _A, _R, _F, _O, _B = (ord(c) for c in "DARFOB")


def sniff(head: bytes) -> bool:
    """Whether a file's first bytes are a ULog's: the magic ``ULog 01 12 35``.

    Examples
    --------
    >>> sniff(MAGIC + bytes([1]) + bytes(8)), sniff(b"PAR1")
    (True, False)
    """
    return head[:7] == MAGIC


def parse_format(text: str) -> tuple[str, list[tuple[str, int, str]]]:
    """A format message's text as its name and fields ``(type, count, name)`` (count 1 for a scalar).

    Examples
    --------
    >>> parse_format("sensor_gyro:uint64_t timestamp;float[3] xyz;uint8_t[4] _padding0;")
    ('sensor_gyro', [('uint64_t', 1, 'timestamp'), ('float', 3, 'xyz'), ('uint8_t', 4, '_padding0')])
    """
    name, _, body = text.partition(":")
    fields = []
    for part in filter(str.strip, body.split(";")):
        if (m := _FIELD.fullmatch(part)) is None:
            raise ValueError(f"field {part!r} of format {name!r} is not 'type name' or 'type[n] name'")
        fields.append((m.group(1), int(m.group(2) or 1), m.group(3)))
    return name.strip(), fields


@dataclass(frozen=True)
class Layout:
    """Where each field of a message lies in its ``D`` record (after the msg_id).

    Attributes
    ----------
    fields : dict of str to (str, int)
        Flattened name (``gyro_rad[0]``, ``inner.x``) -> (numpy type, byte offset); padding left out.
    size : int
        Bytes a record holds (a trailing padding field is not logged).
    full : int
        Bytes with the trailing padding (a writer may log it).
    """

    fields: dict[str, tuple[str, int]]
    size: int
    full: int

    def dtype(self, names: list[str]) -> np.dtype:
        """A structured dtype of ``names`` at their offsets, one record of :attr:`size` bytes."""
        return np.dtype({"names": names, "formats": [self.fields[n][0] for n in names],
                         "offsets": [self.fields[n][1] for n in names], "itemsize": self.size})


def _flatten(name: str, formats: dict, prefix: str, offset: int, out: dict, depth: int) -> tuple[int, int]:
    """Fields of format ``name`` into ``out`` from ``offset``; returns (end, start of trailing padding)."""
    if depth > 16 or name not in formats:
        raise ValueError(f"format {name!r} is {'nested too deep' if depth > 16 else 'not defined'}")
    pad_from = None
    for kind, count, field in formats[name]:
        start = offset
        if kind in TYPES:
            size = np.dtype(TYPES[kind]).itemsize
            if not field.startswith("_padding"):
                if kind == "char" and count > 1:
                    out[prefix + field] = (f"S{count}", offset)
                else:
                    for i in range(count):
                        out[prefix + field + (f"[{i}]" if count > 1 else "")] = (TYPES[kind], offset + i * size)
            offset += size * count
        else:
            for i in range(count):
                offset, _ = _flatten(kind, formats, f"{prefix}{field}{f'[{i}]' if count > 1 else ''}.", offset, out,
                                     depth + 1)
        pad_from = (pad_from if pad_from is not None else start) if field.startswith("_padding") else None
    return offset, offset if pad_from is None else pad_from


def layout(name: str, formats: dict[str, list[tuple[str, int, str]]]) -> Layout:
    """The record layout of message ``name`` (nested formats flattened, padding fields left out).

    Examples
    --------
    >>> fmts = {"v": [("float", 3, "xyz")], "m": [("uint64_t", 1, "timestamp"), ("v", 1, "a"),
    ...         ("uint8_t", 1, "flag"), ("uint8_t", 3, "_padding0")]}
    >>> lay = layout("m", fmts)
    >>> lay.fields["a.xyz[2]"], lay.size, lay.full
    (('<f4', 16), 21, 24)
    """
    fields: dict[str, tuple[str, int]] = {}
    full, size = _flatten(name, formats, "", 0, fields, 0)
    return Layout(fields, size, full)


def decode(u8: np.ndarray, starts: np.ndarray, lay: Layout, names: list[str]) -> np.ndarray:
    """The records beginning at byte offsets ``starts`` of ``u8`` as a structured array of ``names``.

    Every record is :attr:`Layout.size` bytes copied as one row (no per-record Python work).
    """
    if len(starts) == 0:
        return np.zeros(0, lay.dtype(names))
    rows = np.lib.stride_tricks.sliding_window_view(u8, lay.size)[starts]
    return np.ascontiguousarray(rows).view(lay.dtype(names)).reshape(-1)


def _chain(buf, pos: int, stop: int, out) -> tuple[int, int]:
    """Offsets of the messages from ``pos`` that end by ``stop`` written to ``out``: where the walk stopped, and how
    many. Plain Python on the mapped bytes; the same source compiled (numba) for a large file (:func:`_walker`)."""
    n = 0
    while pos + 3 <= stop:
        nxt = pos + 3 + buf[pos] + (buf[pos + 1] << 8)
        if nxt > stop:
            break
        out[n] = pos
        n += 1
        pos = nxt
    return pos, n


def _walker(mm: mmap.mmap | bytes, u8: np.ndarray) -> Callable[[int, int, np.ndarray], tuple[int, int]]:
    """The walk of a file's messages: :func:`_chain` in Python, or compiled above :data:`COMPILED_ABOVE` bytes."""
    if len(mm) <= COMPILED_ABOVE:
        return lambda pos, stop, out: _chain(mm, pos, stop, out.data)
    if not _COMPILED:
        from numba import njit

        _COMPILED.append(njit(cache=True, nogil=True)(_chain))
    return lambda pos, stop, out: _COMPILED[0](u8, pos, stop, out)


class Scan:
    """A ULog file mapped and walked message by message.

    After :meth:`windows` has run to its end, ``keys`` (``(message name, multi_id)`` per subscription,
    in order of first appearance), ``counts`` (records of each), :meth:`notes` and ``dropouts`` describe
    the whole file.
    """

    def __init__(self, path: Path) -> None:
        where = str(path)
        try:
            with open(path, "rb") as fh:
                self.mm = mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) if path.stat().st_size else b""
        except OSError as exc:
            raise InputError(f"cannot read the file ({literal(exc.strerror or exc)})", where) from None
        if len(self.mm) < 16 or not sniff(self.mm[:7]):
            raise InputError("is not a PX4 ULog file (it does not start with the ULog magic bytes 55 4C 6F 67 01 12 "
                             "35); give a .ulg log as the flight controller wrote it", where)
        self.u8 = np.frombuffer(self.mm, np.uint8)
        self.version, self.formats = self.mm[7], dict[str, list[tuple[str, int, str]]]()
        self.keys: list[tuple[str, int]] = []
        self.layouts: list[Layout | None] = []
        self.counts, self.wrong = np.zeros(0, np.int64), np.zeros(0, np.int64)  # wrong: records of a wrong size
        self._table = np.full(1 << 16, -1, np.int32)  # msg_id -> key now subscribed under it
        self._limits = np.zeros((2, 0), np.int64)
        self.dropouts, self.dropped_ms, self.orphans, self.skipped, self.gaps = 0, 0, 0, 0, 0
        self.truncated: tuple[int, int, str] | None = None
        self.appended = self._flags(where)

    def _flags(self, where: str) -> list[int]:
        """The flag bits message, if first: refused for an incompatible feature; the appended data's offsets."""
        if len(self.mm) < 19 + 40 or self.mm[18] != _B:
            return []
        incompat, offsets = self.mm[27:35], struct.unpack_from("<3Q", self.mm, 35)
        if incompat[0] & ~1 or any(incompat[1:]):
            raise InputError(f"uses a ULog feature this reader does not know (incompatible flag bits "
                             f"{incompat.hex()}); convert it with a newer PX4 tool or give another log", where)
        return sorted(o for o in offsets if 16 < o < len(self.mm)) if incompat[0] & 1 else []

    def _subscribe(self, pos: int, size: int) -> tuple[int, int]:
        """An ``A`` message: the key it subscribes (a new one, or the earlier of its name and multi_id)."""
        multi, msg_id = self.mm[pos + 3], self.mm[pos + 4] + (self.mm[pos + 5] << 8)
        name = bytes(self.mm[pos + 6 : pos + 3 + size]).decode("utf-8", "replace").rstrip("\x00")
        key = (name, multi)
        if key not in self.keys:
            try:
                lay: Layout | None = layout(name, self.formats)
                lay = lay if lay is not None and "timestamp" in lay.fields else None  # the spec: every topic has one
            except (ValueError, KeyError):
                lay = None
            self.keys, self.layouts = [*self.keys, key], [*self.layouts, lay]
            self.counts, self.wrong = np.append(self.counts, 0), np.append(self.wrong, 0)
            self._limits = np.column_stack([self._limits, (lay.size, lay.full) if lay is not None else (1 << 17, 0)])
        return msg_id, self.keys.index(key)

    def windows(self) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        """Walk the file; per window of bytes (:data:`WINDOW`), the ``D`` records of a known size of a subscribed topic.

        Yields
        ------
        starts : ndarray of int64
            Byte offset of each record's fields (after its 3-byte header and msg_id).
        key : ndarray of int32
            Its subscription (an index of ``keys``), in file order.
        """
        mm, window, bounds = self.mm, max(WINDOW, 3 + 65535), [16, *self.appended, len(self.mm)]
        u8, walk = self.u8, _walker(self.mm, self.u8)
        for first, end in zip(bounds[:-1], bounds[1:]):  # the log, then each piece of appended data
            pos = first
            while pos < end:
                stop = min(pos + window, end)
                nxt, n = walk(pos, stop, out := np.empty((stop - pos) // 3 + 1, np.int64))
                offs = out[:n]
                kind, size = u8[offs + 2], u8[offs].astype(np.int64) | (u8[offs + 1].astype(np.int64) << 8)
                bad = np.flatnonzero((size == 0) | ~_LETTER[kind])
                k = int(bad[0]) if len(bad) else len(offs)
                yield self._window(offs[:k], kind[:k], size[:k])
                if (done := int(offs[0]) // mmap.PAGESIZE * mmap.PAGESIZE if k else 0) and isinstance(mm, mmap.mmap):
                    mm.madvise(mmap.MADV_DONTNEED, 0, done)  # the windows read: their pages go (Linux; bounded memory)
                if len(bad):
                    lost = int(offs[k])
                    found = mm.find(SYNC, lost, end)
                    nxt = end if found < 0 else found + len(SYNC)
                    self.skipped, self.gaps = self.skipped + nxt - lost, self.gaps + 1
                elif stop == end and nxt < end:
                    if end == len(mm):  # the file ends inside a message
                        self.truncated = self._cut(nxt, end)
                    nxt = end
                pos = nxt

    def _cut(self, pos: int, end: int) -> tuple[int, int, str]:
        """The last message, cut short: (bytes there, bytes it should have, what it is)."""
        if end - pos < 3:
            return end - pos, 3, "message header"
        size, kind = self.mm[pos] + (self.mm[pos + 1] << 8), self.mm[pos + 2]
        what = f"'{chr(kind)}' message" if 32 < kind < 127 else "message"
        if kind == _D and end - pos >= 5:
            k = int(self._table[self.mm[pos + 3] + (self.mm[pos + 4] << 8)])
            what = f"data record of {self.keys[k][0]}:{self.keys[k][1]}" if k >= 0 else "data record"
        return end - pos, size + 3, what

    def _window(self, offs: np.ndarray, kind: np.ndarray, size: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One window's messages: the others in order (few), then its ``D`` records sorted to their topics."""
        isd = kind == _D
        events: dict[int, list[tuple[int, int]]] = {}
        for i in np.flatnonzero(~isd).tolist():
            k, pos, n = int(kind[i]), int(offs[i]), int(size[i])
            if k == _F:
                try:
                    name, fields = parse_format(bytes(self.mm[pos + 3 : pos + 3 + n]).decode("utf-8", "replace"))
                    self.formats[name] = fields
                except ValueError:  # a broken format: a topic of it is refused when read
                    pass
            elif k == _A and n >= 3:
                msg_id, key = self._subscribe(pos, n)
                events.setdefault(msg_id, []).append((i, key))
            elif k == _R and n >= 2:
                events.setdefault(self.mm[pos + 3] + (self.mm[pos + 4] << 8), []).append((i, -1))
            elif k == _O and n >= 2:
                self.dropouts, self.dropped_ms = self.dropouts + 1, self.dropped_ms + self.mm[pos + 3] + (
                    self.mm[pos + 4] << 8)
        d = offs[di := np.flatnonzero(isd & (size >= 2))]
        u16 = self.u8[d + 3].astype(np.int32) | (self.u8[d + 4].astype(np.int32) << 8)
        key = self._table[u16]
        for msg_id, evs in events.items():  # subscriptions made or ended within the window
            m = np.flatnonzero(u16 == msg_id)
            values = np.array([self._table[msg_id]] + [k for _, k in evs], np.int32)
            key[m] = values[np.searchsorted([i for i, _ in evs], di[m])]
            self._table[msg_id] = values[-1]
        known, body, (lo, hi) = key >= 0, size[di] - 2, self._limits[:, np.maximum(key, 0)]
        fits = known & (body >= lo) & (body <= np.maximum(hi, lo))
        self.orphans += int(np.count_nonzero(~known))
        self.counts = self.counts + np.bincount(key[fits], minlength=len(self.keys))
        self.wrong = self.wrong + np.bincount(key[known & ~fits], minlength=len(self.keys))
        return d[fits] + 5, key[fits]

    def notes(self) -> list[str]:
        """What a reader states of the file as a whole (a cut last message, skipped bytes, dropouts)."""
        got, want, what = self.truncated or (0, 0, "")
        places, times = "one place" if self.gaps == 1 else f"{self.gaps} places", "s" if self.dropouts > 1 else ""
        return [text for said, text in (
            (self.truncated, f"last message truncated ({got} of {want} bytes, a {what}), left out"),
            (self.skipped, f"{self.skipped} bytes that are no ULog message skipped ({places}), read on from the next "
                           "sync marker"),
            (self.orphans, f"{self.orphans} data records of no subscribed topic left out"),
            (self.dropouts, f"the logger dropped data {self.dropouts} time{times} ({self.dropped_ms} ms in all): "
                            "samples may be missing there"),
            (self.version > 1, f"ULog version {self.version} (this reader knows version 1), read as version 1")) if said]

    def close(self) -> None:
        """Unmap the file (left to the garbage collector while a view of it is held)."""
        self.u8 = np.zeros(0, np.uint8)
        with contextlib.suppress(BufferError, AttributeError):
            self.mm.close()  # type: ignore[union-attr]


def tolerance(tg: np.ndarray, ta: np.ndarray) -> int:
    """Half the smaller median step of the first 1000 samples of each, us (0: fewer than two samples)."""
    steps = [float(np.median(np.diff(t[:1000]))) for t in (tg, ta) if len(t) > 1]
    return int(0.5 * min(steps)) if steps else 0


def match(tg: np.ndarray, ta: np.ndarray, tol: int) -> tuple[np.ndarray, np.ndarray]:
    """Pairs (i, j) of sorted stamps where ``ta[j]`` is the nearest to ``tg[i]``, ``tg[i]`` the nearest to
    ``ta[j]`` (ties: the earlier), and ``|tg[i] - ta[j]| <= tol``.

    Examples
    --------
    >>> match(np.array([0, 10, 20, 30]), np.array([1, 19, 21, 50]), 3)
    (array([0, 2]), array([0, 1]))
    """
    if len(tg) == 0 or len(ta) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)

    def nearest(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        j = np.clip(np.searchsorted(y, x), 1, len(y) - 1) if len(y) > 1 else np.zeros(len(x), np.int64)
        return np.where(np.abs(x - y[j - 1]) <= np.abs(y[j] - x), j - 1, j) if len(y) > 1 else j

    j = nearest(tg, ta)
    i = np.arange(len(tg))
    ok = (nearest(ta, tg)[j] == i) & (np.abs(tg - ta[j]) <= tol)
    return i[ok], j[ok]


class Join:
    """The joined view fed in pieces: pairs are final once both sensors are 2 tolerances past them."""

    def __init__(self, gyro_cols: list[str], accel_cols: list[str]) -> None:
        self.g: tuple = (np.zeros(0, np.int64), {c: np.zeros(0) for c in gyro_cols})
        self.a: tuple = (np.zeros(0, np.int64), {c: np.zeros(0) for c in accel_cols})
        self.tol: int | None = None
        self.done, self.seen, self.paired, self.gaps = -(1 << 62), [0, 0], 0, [np.zeros(0, np.int64)]

    def feed(self, g: tuple, a: tuple, final: bool) -> tuple[np.ndarray, dict[str, np.ndarray]] | None:
        """The pairs made final by a piece ``g``, ``a`` of (stamps us, columns) each (None: too few yet)."""
        self.seen = [self.seen[0] + len(g[0]), self.seen[1] + len(a[0])]
        self.g, self.a = (_cat(self.g, g), _cat(self.a, a))
        (tg, vg), (ta, va) = self.g, self.a
        if not final and (not len(tg) or not len(ta) or self.tol is None and min(len(tg), len(ta)) < 1000):
            return None  # the tolerance needs 1000 samples of each (or all there are), a cut both sensors
        self.tol = tolerance(tg, ta) if self.tol is None else self.tol
        cut = (1 << 62) if final else int(min(tg[-1], ta[-1])) - 2 * self.tol
        i, j = match(tg, ta, self.tol)
        take = (tg[i] >= self.done) & (tg[i] < cut)
        i, j = i[take], j[take]
        self.paired += len(i)
        self.gaps.append(np.abs(tg[i] - ta[j]))
        out = (tg[i], {**{c: v[i] for c, v in vg.items()}, **{c: v[j] for c, v in va.items()}})
        self.done = cut
        self.g, self.a = (_since(self.g, cut - 2 * self.tol), _since(self.a, cut - 2 * self.tol))
        return out

    def notes(self, label: str) -> list[str]:
        """Samples left without a partner; the median gap of the pairs' stamps."""
        lost = (self.seen[0] - self.paired, self.seen[1] - self.paired)
        gaps = np.concatenate(self.gaps)
        out = [f"{label}: {lost[0]} gyro and {lost[1]} accelerometer samples without a partner within "
               f"{(self.tol or 0) / 1e3:.3g} ms left out"] if any(lost) else []
        if len(gaps) and np.median(gaps):
            out.append(f"{label}: gyro and accelerometer stamps differ by {np.median(gaps) / 1e3:.3g} ms (median); "
                       "each row carries the gyro's time")
        return out


def _cat(a: tuple, b: tuple) -> tuple:
    """Two pieces of (stamps, columns) one after the other."""
    return np.concatenate([a[0], b[0]]), {c: np.concatenate([a[1][c], b[1][c]]) for c in a[1]}


def _since(a: tuple, t0: int) -> tuple:
    """The samples of (stamps, columns) from ``t0`` on."""
    return a[0][a[0] >= t0], {c: v[a[0] >= t0] for c, v in a[1].items()}
