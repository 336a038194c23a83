"""The ArduPilot DataFlash binary log (``.bin``): its records, found and decoded with numpy.

A DataFlash log is a sequence of records, each ``A3 95`` then a message id byte then the message's
fields, packed little-endian with no padding. Message id 128 is ``FMT``, whose fields (``type`` u8,
``length`` u8 of the whole record, ``name`` char[4], ``format`` char[16], ``labels`` char[64]) describe
every other message (ArduPilot's ``libraries/AP_Logger/LogStructure.h``, ``struct log_Format``). One
character of ``format`` per field (:data:`FORMAT_CHARS`, the table of LogStructure.h and AP_Logger's
README.md, ``g`` a half float among them); the legacy characters ``c C e E`` hold hundredths and ``L``
1e-7 degrees (latitude, longitude).

``FMTU`` records give each field a unit and a multiplier by a character, ``UNIT`` and ``MULT`` records say
what the characters mean (:data:`UNITS`, :data:`MULTIPLIERS`: the tables of LogStructure.h); a number in
the log times its multiplier is a value in the unit. For a field of a legacy character LogStructure.h takes
the multiplier and ignores the character's scale, pymavlink's DFReader the scale and ignores the multiplier;
ArduPilot's messages give both the same (a ``c`` field has multiplier ``B``, 1e-2), and this reader does as
DFReader.

:func:`scan` finds the records without a Python loop over them: every ``A3 95`` is a candidate, a
record's length comes from its id, and a run of candidates each ending where the next starts is a run of
records; only a gap (bytes that are no record, skipped and counted) or an ``A3 95`` inside a record's
fields costs a step of the loop. :func:`decode` reads one message's records with one structured dtype.

Public names
------------
FORMAT_CHARS, UNITS, MULTIPLIERS, MessageFormat, Layout, parse_fmt, scan, decode, field_units, sniff
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

__all__ = ["FORMAT_CHARS", "UNITS", "MULTIPLIERS", "MessageFormat", "Layout", "parse_fmt", "scan", "decode",
           "field_units", "sniff"]

#: the two bytes every record starts with
HEAD = b"\xa3\x95"
#: the message id of FMT, and its record's length: 3 + 1 + 1 + 4 + 16 + 64 bytes
FMT_ID, FMT_LENGTH = 128, 89
#: format character -> (numpy type, little-endian; the number stored per unit of the value, or None: the value)
FORMAT_CHARS: dict[str, tuple[str, float | None]] = {
    "a": ("(32,)<i2", None), "b": ("i1", None), "B": ("u1", None), "h": ("<i2", None), "H": ("<u2", None),
    "i": ("<i4", None), "I": ("<u4", None), "f": ("<f4", None), "d": ("<f8", None), "g": ("<f2", None),
    "n": ("S4", None), "N": ("S16", None), "Z": ("S64", None),
    "c": ("<i2", 100.0), "C": ("<u2", 100.0), "e": ("<i4", 100.0), "E": ("<u4", 100.0), "L": ("<i4", 1e7),
    "M": ("u1", None), "q": ("<i8", None), "Q": ("<u8", None),
}
#: unit character -> unit (LogStructure.h ``log_Units``; "" none, "UNKNOWN" not worked out)
UNITS = {
    "-": "", "?": "UNKNOWN", "A": "A", "a": "Ah", "d": "deg", "b": "B", "B": "B/s", "k": "deg/s", "D": "deglatitude",
    "e": "deg/s/s", "E": "rad/s", "G": "Gauss", "h": "degheading", "i": "A.s", "J": "W.s", "l": "l", "L": "rad/s/s",
    "m": "m", "n": "m/s", "o": "m/s/s", "O": "degC", "%": "%", "S": "satellites", "s": "s", "q": "rpm", "r": "rad",
    "U": "deglongitude", "u": "ppm", "v": "V", "P": "Pa", "w": "Ohm", "W": "Watt", "X": "W.h", "y": "l/s", "Y": "us",
    "z": "Hz", "#": "instance",
}
#: multiplier character -> multiplier (LogStructure.h ``log_Multipliers``; 0: none, a string; '?' not worked out)
MULTIPLIERS = {"-": 0.0, "?": 1.0, "2": 1e2, "1": 1e1, "0": 1e0, "A": 1e-1, "B": 1e-2, "C": 1e-3, "D": 1e-4,
               "E": 1e-5, "F": 1e-6, "G": 1e-7, "I": 1e-9, "!": 3.6, "/": 3600.0}
#: ArduPilot's spellings of units -> this program's
_SPELLED = {"m/s/s": "m/s^2", "rad/s/s": "rad/s^2", "deg/s/s": "deg/s^2", "Gauss": "G"}
_NAME = re.compile(rb"[A-Za-z0-9_]{1,4}\x00*")
_LABEL = re.compile(r"[A-Za-z0-9_.\[\]]+")


@dataclass(frozen=True)
class MessageFormat:
    """One message as its FMT record describes it.

    Attributes
    ----------
    type : int
        Its message id (0 to 255).
    name : str
        Its name (``"IMU"``), up to 4 characters.
    length : int
        Bytes of one record, the 3 header bytes included.
    format : str
        One character of :data:`FORMAT_CHARS` per field (``"QBffffffIIfBBHH"``).
    labels : tuple of str
        The fields' names (``"TimeUS", "I", "GyrX"`` ...).
    """

    type: int
    name: str
    length: int
    format: str
    labels: tuple[str, ...]

    @property
    def decodable(self) -> bool:
        """Whether every format character is known and their sizes add up to :attr:`length`."""
        return (all(c in FORMAT_CHARS for c in self.format) and len(self.labels) == len(self.format)
                and 3 + sum(np.dtype(FORMAT_CHARS[c][0]).itemsize for c in self.format) == self.length)

    def dtype(self, labels: list[str]) -> tuple[int, np.dtype]:
        """Where in a record ``labels`` start, and a structured dtype of the bytes from there to the last of
        them (each at its offset)."""
        offsets, at = {}, 3
        for label, char in zip(self.labels, self.format):
            offsets[label] = (at, np.dtype(FORMAT_CHARS[char][0]))
            at += offsets[label][1].itemsize
        lo = min(offsets[k][0] for k in labels)
        hi = max(offsets[k][0] + offsets[k][1].itemsize for k in labels)
        return lo, np.dtype({"names": labels, "formats": [offsets[k][1] for k in labels],
                             "offsets": [offsets[k][0] - lo for k in labels], "itemsize": hi - lo})


def parse_fmt(body: bytes) -> MessageFormat | None:
    """The message a FMT record's 86 bytes after its header describe; None when they are no FMT record
    (a length of at least 3; a name of 1 to 4 letters, digits or ``_``; printable format characters; labels
    of letters, digits or ``_`` separated by commas).

    Examples
    --------
    >>> body = bytes([200, 14]) + b"ABC\\0" + b"Qf".ljust(16, b"\\0") + b"TimeUS,X".ljust(64, b"\\0")
    >>> parse_fmt(body)
    MessageFormat(type=200, name='ABC', length=14, format='Qf', labels=('TimeUS', 'X'))
    >>> parse_fmt(bytes(86)) is None
    True
    """
    if len(body) < FMT_LENGTH - 3 or body[1] < 3 or not _NAME.fullmatch(body[2:6]):
        return None
    fmt, labels = body[6:22].split(b"\0", 1)[0], body[22:86].split(b"\0", 1)[0]
    if not fmt or not all(33 <= c < 127 for c in fmt):
        return None
    try:
        names = tuple(labels.decode("ascii").split(","))
    except UnicodeDecodeError:
        return None
    if not all(_LABEL.fullmatch(n) for n in names):
        return None
    return MessageFormat(body[0], body[2:6].rstrip(b"\0").decode("ascii"), body[1], fmt.decode("ascii"), names)


@dataclass(frozen=True, eq=False)
class Layout:
    """Where a log's records are.

    Attributes
    ----------
    formats : dict of int to MessageFormat
        The messages the log's FMT records describe, by id.
    positions : ndarray, shape (n,), int64
        Byte offset of every record found, in file order.
    ids : ndarray, shape (n,), uint8
        Their message ids.
    skipped : int
        Bytes that were no record (garbage, a record of an undescribed id), skipped to the next ``A3 95``.
    gaps : int
        The number of places such bytes were found.
    truncated : tuple of int or None
        ``(bytes present, bytes of the record)`` of a last record the file cuts short (left out); the second
        is 0 when the cut falls in its header.
    by_name : dict of str to int
        Message ids by name.
    """

    formats: dict[int, MessageFormat]
    positions: np.ndarray
    ids: np.ndarray
    skipped: int = 0
    gaps: int = 0
    truncated: tuple[int, int] | None = None
    by_name: dict[str, int] = field(default_factory=dict)

    def of(self, type_id: int) -> np.ndarray:
        """Byte offsets of the records of one message id, in file order."""
        return self.positions[self.ids == type_id]


def _candidates(buf: np.ndarray) -> np.ndarray:
    """Offsets of every ``A3 95`` followed by an id byte (in chunks: no temporary as large as the file)."""
    found, step, n = [], 1 << 26, len(buf)
    for start in range(0, max(n - 2, 0), step):
        chunk = buf[start:min(start + step, n - 2)]
        at = np.flatnonzero(chunk == 0xA3) + start
        found.append(at[buf[at + 1] == 0x95])
    return np.concatenate(found).astype(np.int64) if found else np.zeros(0, np.int64)


def _formats(buf: np.ndarray, cand: np.ndarray) -> tuple[dict[int, MessageFormat], np.ndarray]:
    """The messages described by the FMT records among the candidates (the first description of an id), and
    which candidates are FMT headers whose bytes are no FMT record (garbage, or a cut last record)."""
    out: dict[int, MessageFormat] = {}
    fmt_at = np.flatnonzero(buf[cand + 2] == FMT_ID)
    false = np.zeros(len(cand), bool)
    for i, p in zip(fmt_at.tolist(), cand[fmt_at].tolist()):
        got = parse_fmt(buf[p + 3:p + FMT_LENGTH].tobytes()) if p + FMT_LENGTH <= len(buf) else None
        if got is not None and got.type not in out:
            out[got.type] = got
        false[i] = got is None and p + FMT_LENGTH <= len(buf)
    out[FMT_ID] = MessageFormat(FMT_ID, "FMT", FMT_LENGTH, "BBnNZ", ("Type", "Length", "Name", "Format", "Columns"))
    return out, false


def scan(buf: np.ndarray) -> Layout:
    """Find every record of a log: the records form a chain from byte 0, each ``length`` bytes long.

    Parameters
    ----------
    buf : ndarray, shape (size,), uint8
        The file's bytes.

    Returns
    -------
    Layout
        Byte gaps that are no record are skipped to the next ``A3 95`` whose record ends where another
        starts (counted in ``skipped``); a last record the file cut short is left out (``truncated``).

    Notes
    -----
    Garbage may begin with a record header: a FMT header whose bytes are no valid FMT record is garbage,
    and so is a header whose record is followed by no record header while a record starts within its bytes.
    A header in garbage whose length happens to end where a record starts cannot be told from a record.
    """
    n = len(buf)
    cand = _candidates(buf)
    formats, false_fmt = _formats(buf, cand)
    lengths = np.zeros(256, np.int64)
    for t, f in formats.items():
        lengths[t] = f.length
    ids = buf[cand + 2] if len(cand) else np.zeros(0, np.uint8)
    ends = cand + lengths[ids]
    known = (lengths[ids] > 0) & ~false_fmt  # a FMT header whose bytes are no FMT record is garbage
    good = known & (ends == np.append(cand[1:], n))  # a record that ends where the next candidate starts
    at = np.minimum(np.searchsorted(cand, ends), max(len(cand) - 1, 0))
    linked = known & ((cand[at] == ends) | (ends >= n))  # ends where a candidate starts (or at or past the end)
    resync_at = np.flatnonzero(linked)  # after a gap: the first of these starts the records again
    bad_at = np.flatnonzero(~good)
    keep = np.zeros(len(cand), bool)
    skipped = gaps = 0
    truncated = None
    m = len(cand)
    i, pos = (0, 0) if m and cand[0] == 0 else (m, 0)
    while i < m:
        j = int(bad_at[np.searchsorted(bad_at, i)]) if len(bad_at) and bad_at[-1] >= i else m
        keep[i:j] = True  # a run of records, each ending where the next starts
        if j == m:
            pos = n
            break
        if known[j] and ends[j] > n:
            truncated, pos = (n - int(cand[j]), int(lengths[ids[j]])), n
            break
        k = int(np.searchsorted(cand, ends[j])) if known[j] else j + 1
        if known[j] and k < m and cand[k] == ends[j]:  # the next record follows (a false header inside this one)
            keep[j], i = True, k
            continue
        inner = int(np.searchsorted(resync_at, j + 1))  # records that start inside this one's bytes
        if known[j] and not (inner < len(resync_at) and resync_at[inner] < k):
            keep[j], pos = True, int(ends[j])  # a record, then no record header: what follows is a gap
        else:  # an id no FMT describes, or a header in garbage (records start within): its bytes are a gap
            pos, k = int(cand[j]), j + 1
        k = int(resync_at[np.searchsorted(resync_at, k)]) if len(resync_at) and resync_at[-1] >= k else m
        nxt = int(cand[k]) if k < m else n
        if k == m and 0 < nxt - pos < 3 and buf[pos:nxt].tobytes() == HEAD[:nxt - pos]:
            truncated = (nxt - pos, 0)  # the header of a last record, cut short
        elif nxt > pos:
            skipped, gaps = skipped + nxt - pos, gaps + 1
        i, pos = k, nxt
    if pos < n and truncated is None:
        skipped, gaps = skipped + n - pos, gaps + 1
    positions, found = cand[keep], ids[keep]
    by_name = {f.name: t for t, f in sorted(formats.items())}
    return Layout(formats, positions, found, skipped, gaps, truncated, by_name)


def decode(buf: np.ndarray, fmt: MessageFormat, positions: np.ndarray, labels: list[str]) -> dict[str, np.ndarray]:
    """Fields of one message's records, read with one structured dtype.

    Parameters
    ----------
    buf : ndarray, shape (size,), uint8
    fmt : MessageFormat
        A :attr:`~MessageFormat.decodable` message.
    positions : ndarray, shape (n,), int64
        Offsets of its records (each whole within ``buf``).
    labels : list of str
        The fields to read.

    Returns
    -------
    dict of str to ndarray
        Numbers as float64 (``c C e E L`` scaled: hundredths, 1e-7 degrees), strings as bytes.
    """
    lo, dtype = fmt.dtype(labels)  # only the bytes of the fields asked for are gathered
    windows = np.lib.stride_tricks.sliding_window_view(buf, dtype.itemsize)
    records = np.ascontiguousarray(windows[positions + lo]).view(dtype)[:, 0]
    out = {}
    for label in labels:
        char = fmt.format[fmt.labels.index(label)]
        values = records[label]
        if values.dtype.kind in "iuf":
            per = FORMAT_CHARS[char][1]  # divided, not multiplied by 0.01: -123456789 / 100 is -1234567.89 exactly
            values = values.astype(np.float64) / per if per is not None else values.astype(np.float64)
        out[label] = values
    return out


def _lookups(buf: np.ndarray, layout: Layout) -> tuple[dict[str, str], dict[str, float], dict[int, tuple[str, str]]]:
    """The unit and multiplier tables (ArduPilot's, then the log's UNIT and MULT records) and the FMTU records."""
    units, mults, fmtu = dict(UNITS), dict(MULTIPLIERS), {}
    for name, keys in (("UNIT", ("Id", "Label")), ("MULT", ("Id", "Mult")), ("FMTU", ("FmtType", "UnitIds", "MultIds"))):
        f = layout.formats.get(layout.by_name.get(name, -1))
        if f is None or not f.decodable or not set(keys) <= set(f.labels):
            continue
        got = decode(buf, f, layout.of(f.type), list(keys))
        rows = zip(*(got[k].tolist() for k in keys))
        for row in rows:
            if name == "UNIT":
                units[chr(int(row[0]) & 0xFF)] = row[1].rstrip(b"\0").decode("ascii", "replace")
            elif name == "MULT":  # a float cast to a double: 7 significant digits, as pymavlink reads it
                mults[chr(int(row[0]) & 0xFF)] = float(f"{row[1]:.7g}")
            else:
                fmtu[int(row[0])] = tuple(v.rstrip(b"\0").decode("ascii", "replace") for v in row[1:])
    return units, mults, fmtu


def field_units(buf: np.ndarray, layout: Layout) -> dict[int, dict[str, tuple[str, float]]]:
    """The unit each field's values are in, and the factor that takes its numbers there, by message id.

    A field is listed only when the log's ``FMTU`` states a unit (not ``-``, ``?`` or ``#``) and a known
    multiplier (not ``?``); a format character's own scale replaces the multiplier (factor 1: :func:`decode`
    applied it). Units are spelled as this program does (``m/s^2`` for ArduPilot's ``m/s/s``).

    Returns
    -------
    dict of int to dict of str to (unit, factor)
    """
    units, mults, fmtu = _lookups(buf, layout)
    out: dict[int, dict[str, tuple[str, float]]] = {}
    for t, (unit_ids, mult_ids) in fmtu.items():
        f = layout.formats.get(t)
        if f is None:
            continue
        mine: dict[str, tuple[str, float]] = {}
        for k, (label, char) in enumerate(zip(f.labels, f.format)):
            unit = units.get(unit_ids[k], "") if k < len(unit_ids) else ""
            mult_id = mult_ids[k] if k < len(mult_ids) else "?"
            if unit in ("", "UNKNOWN", "instance") or mult_id == "?" or mult_id not in mults:
                continue
            scaled = FORMAT_CHARS.get(char, ("", None))[1] is not None
            mult = 1.0 if scaled or mults[mult_id] == 0 else mults[mult_id]
            mine[label] = (_SPELLED.get(unit, unit), mult)
        out[t] = mine
    return out


def sniff(head: bytes) -> bool:
    """Whether bytes are the start of a DataFlash log: a FMT record (``A3 95 80``, then a valid
    description of a message) followed, when there is more, by the next record's ``A3 95``.

    Examples
    --------
    >>> fmt = b"\\xa3\\x95\\x80" + bytes([128, 89]) + b"FMT\\0" + b"BBnNZ".ljust(16, b"\\0")
    >>> sniff(fmt + b"Type,Length,Name,Format,Columns".ljust(64, b"\\0"))
    True
    >>> sniff(bytes(4096)), sniff(b"\\xa3\\x95\\x80" + bytes(200))
    (False, False)
    """
    if len(head) < FMT_LENGTH or not head.startswith(HEAD + bytes([FMT_ID])):
        return False
    if parse_fmt(head[3:FMT_LENGTH]) is None:
        return False
    return len(head) < FMT_LENGTH + 2 or head[FMT_LENGTH:FMT_LENGTH + 2] == HEAD
