"""Logger files as they come: a preamble, comment lines, a delimiter, the unit of the time column.

A data logger rarely writes a plain CSV in seconds: the MPU-6050 logs of ``../shared/data`` start
with four metadata lines (``Fs,100``) before their header, others write ``#`` comments, ``;`` or
tab separated fields, or time in milliseconds, microseconds or nanoseconds. :class:`LogFormat`
says how to read such a file; every log reader (:mod:`align.io.logs`) takes one, and without one
reads a plain CSV by its fastest path, unchanged.

The time column's unit is detected from the median sample interval unless given
(:func:`time_unit`): a MEMS IMU log samples between about 1 Hz and 10 kHz, so the unit is the one of
s, ms, us, ns that puts the median step's rate in :data:`DETECT_BAND_HZ` (seconds also up to
100 kHz). When two units do (a step of 1 is a 1 Hz log in s or a 1 kHz log in ms; 0.1 to 1 and 100
to 1000 and 1e5 to 1e6 likewise), the unit is not guessed: the log is refused with both readings and
the option to choose. A step no unit explains, or a given unit that puts the rate outside
:data:`RATE_BAND_HZ`, is refused naming the time column and the fix. A detected unit other than
seconds is stated with the result.

Public names
------------
LogFormat, TIME_UNITS, STAMPS, DELIMITERS, RATE_BAND_HZ, DETECT_BAND_HZ, delimiter_char, time_unit, csv_source, preamble_hint,
content_lines
"""

from __future__ import annotations

import gzip
import math
import zlib
from dataclasses import asdict, dataclass
from pathlib import Path

from align.errors import InputError, literal

#: time unit -> its size in seconds
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}
#: the kinds of time stamp a multi-stream log may carry (:attr:`LogFormat.stamps`)
STAMPS = ("header", "record")
#: the sample rates an IMU log may have, Hz (outside: not a sample interval, or the wrong time unit)
RATE_BAND_HZ = (1.0, 1e5)
#: the sample rates a unit is detected for, Hz (seconds also up to the top of :data:`RATE_BAND_HZ`)
DETECT_BAND_HZ = (1.0, 1e4)
#: names of delimiters that are awkward to type
DELIMITERS = {"tab": "\t", "\\t": "\t", "space": " ", "comma": ",", "semicolon": ";", "pipe": "|"}
#: characters that can be neither a delimiter nor a comment: they are parts of numbers, quotes or line ends
_NUMERIC = set("0123456789.+-eE\"\r\n")


def delimiter_char(text: str) -> str:
    """A delimiter as typed (``','``, ``';'``, ``'tab'``, ``'\\t'``, ``'space'``, ``'|'``) -> the one character.

    Raises
    ------
    InputError
        Anything else (named as ``{delimiter}``).
    """
    char = DELIMITERS.get(str(text).strip().lower(), text if len(str(text)) == 1 else None)
    if char is None or char in _NUMERIC or char.isalnum():
        raise InputError(f"{literal(repr(text))} is not a delimiter; give one character such as ',' or ';', or tab or "
                         "space", "{delimiter}")
    return char


@dataclass(frozen=True)
class LogFormat:
    """How to read a logger's text file; the default is a plain CSV with time in detected units.

    Attributes
    ----------
    skip_rows : int
        Lines at the top of the file to skip before the header (a logger's preamble), >= 0.
    comment : str or None
        One character: from it to the end of the line is ignored (lines that hold nothing else are
        dropped), e.g. ``'#'``.
    delimiter : str or None
        The field separator: one character, or ``'tab'``, ``'space'`` (any run of blanks), ``';'``...
        (:func:`delimiter_char`); None: ``','``.
    time_units : str or None
        Unit of the time column, one of :data:`TIME_UNITS`; None: detected from the median step
        (:func:`time_unit`).
    topic : str or None
        The stream of a log that holds several (:attr:`align.io.readers.LogReader.streams`): a ROS topic
        (``/imu0``), a ULog topic with its instance (``sensor_gyro:1``), a DataFlash message (``IMU:1``);
        None: the reader's choice (the only IMU stream, or the first instance), stated in the result.
    stamps : str or None
        Which time a stream's samples carry, where a format has two: ``"header"`` (the sensor's stamp) or
        ``"record"`` (when the recorder wrote it); None: the format's default (the header stamp).
    """

    skip_rows: int = 0
    comment: str | None = None
    delimiter: str | None = None
    time_units: str | None = None
    topic: str | None = None
    stamps: str | None = None

    def __post_init__(self) -> None:
        if isinstance(self.skip_rows, bool) or not isinstance(self.skip_rows, int) or self.skip_rows < 0:
            raise InputError(f"{literal(repr(self.skip_rows))} is not a number of lines; give a whole number >= 0, "
                             "e.g. {skip_rows=4}", "{skip_rows}")
        if self.delimiter is not None:
            object.__setattr__(self, "delimiter", delimiter_char(self.delimiter))
        c = self.comment
        if c is not None and (not isinstance(c, str) or len(c) != 1 or c in _NUMERIC or c.isalnum() or c.isspace()
                              or c == self.separator):
            raise InputError(f"{literal(repr(c))} is not a comment character; give one character that starts a "
                             "comment and is not the delimiter, e.g. {comment=#}", "{comment}")
        if self.topic is not None and (not isinstance(self.topic, str) or not self.topic.strip()):
            raise InputError(f"{literal(repr(self.topic))} is not a topic; give its name, e.g. {{topic=/imu0}}", "{topic}")
        if self.stamps is not None and self.stamps not in STAMPS:
            raise InputError(f"{literal(repr(self.stamps))} is not a kind of time stamp; give one of "
                             f"{', '.join(STAMPS)}", "{stamps}")
        if self.time_units is not None and self.time_units not in TIME_UNITS:
            raise InputError(f"{literal(repr(self.time_units))} is not a unit of the time column; give one of "
                             f"{', '.join(TIME_UNITS)}", "{time_units}")

    @property
    def separator(self) -> str:
        """The field separator in effect (``','`` by default)."""
        return self.delimiter or ","

    @property
    def plain(self) -> bool:
        """No preamble, comment or delimiter given: the file is read as a plain CSV (the fast path)."""
        return self.skip_rows == 0 and self.comment is None and self.delimiter is None

    def streams_given(self) -> list[str]:
        """The options of a multi-stream log given (their field names), for a format that has one stream."""
        return [k for k in ("topic", "stamps") if getattr(self, k) is not None]

    def given(self) -> list[str]:
        """The text options given (their field names), for a file type they do not apply to."""
        return [k for k in ("skip_rows", "comment", "delimiter") if getattr(self, k) not in (0, None)]

    def to_dict(self) -> dict:
        """The options as a result's ``inputs`` records them (``delimiter`` as typed words for tab and space)."""
        d = asdict(self)
        for key in ("topic", "stamps"):  # recorded when given (a text log's inputs stay as they were)
            if d[key] is None:
                del d[key]
        if self.delimiter is not None:
            d["delimiter"] = {"\t": "tab", " ": "space"}.get(self.delimiter, self.delimiter)
        return d


def _rate(step: float, unit: str) -> float:
    return 1.0 / (step * TIME_UNITS[unit])


def _in_band(step: float, unit: str) -> bool:
    lo, hi = RATE_BAND_HZ
    return lo * (1 - 1e-9) <= _rate(step, unit) <= hi * (1 + 1e-9)


def _detect(step: float) -> list[str]:
    """The units that put the step's rate in :data:`DETECT_BAND_HZ` (seconds: up to 100 kHz)."""
    lo, hi = DETECT_BAND_HZ
    return [u for u in TIME_UNITS if lo * (1 - 1e-9) <= _rate(step, u) <= (RATE_BAND_HZ[1] if u == "s" else hi) * (1 + 1e-9)]


def time_unit(step: float, column: str, where: str, given: str | None = None,
              first: float | None = None, *, stated: bool = False) -> tuple[str, bool]:
    """The unit of a time column from its median step, or the given unit checked against it.

    Parameters
    ----------
    step : float
        Median difference of consecutive time stamps, in the file's numbers. A step that is not a
        finite number > 0 (time that does not increase) is taken in ``given`` or seconds unchecked:
        the time checks that follow name the row.
    column : str
        Name of the time column, for the message.
    where : str
        The file, for the message.
    given : str, optional
        The unit stated by the user (a key of :data:`TIME_UNITS`); None: detect it.
    first : float, optional
        The first time stamp: a Unix epoch (1973 to 2286 in one of the units) settles a step two units
        would explain.

    Returns
    -------
    unit : str
        A key of :data:`TIME_UNITS`.
    detected : bool
        True when the unit was detected, False when given (or unchecked).

    Raises
    ------
    InputError
        No unit puts the rate within :data:`RATE_BAND_HZ`, or the given unit does not; the message
        names the time column and the fix (``{time_units=ms}``, ``{columns}``, ``{rate_hz}``).
    """
    if not (math.isfinite(step) and step > 0):
        return given or "s", False
    units = _detect(step)
    if len(units) > 1 and first is not None:  # an epoch time stamp tells the unit
        units = [u for u in units if 1e8 <= first * TIME_UNITS[u] <= 1e10] or units
    found = units[0] if len(units) == 1 else None
    name = f"time column '{literal(column)}'"
    band = f"{RATE_BAND_HZ[0]:g} Hz to {RATE_BAND_HZ[1] / 1e3:g} kHz"
    if given is None:
        if len(units) > 1:
            readings = " or ".join(f"{_rate(step, u):.4g} Hz in {u}" for u in units)
            choose = " or ".join(f"{{time_units={u}}}" for u in units)
            raise InputError(f"{name}: its median step {step:.4g} reads as {readings}: the unit cannot be told from the "
                             f"file; give {choose}", where)
        if found is None:
            rates = ", ".join(f"as {u}: {_rate(step, u):.3g} Hz" for u in ("s", "ns"))
            raise InputError(f"{name}: its median step {step:.4g} is no IMU sample interval in s, ms, us or ns "
                             f"({rates}; {band} expected); name the time column with {{columns}}, or read the log "
                             "without it with {rate_hz}", where)
        return found, True
    if _in_band(step, given):
        return given, False
    fix = (f"the step suggests {{time_units={found}}}" if found is not None and found != given and not stated
           else "it is the log's own time (its unit stated): read another stream ({topic})" if stated
           else "check the time column ({columns}), or read the log without it ({rate_hz})")
    raise InputError(f"{name} in {given}: its median step {step:.6g} {given} is {_rate(step, given):.6g} Hz, not an "
                     f"IMU sample rate ({band}); {fix}", where)  # 6 digits: 0.99995 Hz is not shown as 1 Hz


# ---- text sources for pyarrow's CSV reader ----


def _raw_bytes(p: Path) -> bytes:
    """The file's bytes (a ``.gz`` file decompressed)."""
    if p.suffix.lower() == ".gz":
        try:
            return gzip.decompress(p.read_bytes())
        except (OSError, EOFError, ValueError, zlib.error) as exc:
            raise InputError(f"cannot read the compressed file ({literal(exc)})", str(p)) from None
    return p.read_bytes()


def _strip_comments(data: bytes, comment: str) -> bytes:
    """``data`` with everything from ``comment`` to the end of each line removed (with the blanks before it);
    the line ends stay, so line numbers hold and lines left empty are skipped by the CSV reader.

    Walks the comments only (``bytes.find``), so a large log with few comments costs about one copy.
    """
    c, pieces, pos = comment.encode(), [], 0
    at = data.find(c)
    while at >= 0:
        end = data.find(b"\n", at)
        end = len(data) if end < 0 else end
        cut = at
        while cut > pos and data[cut - 1] in (32, 9):   # the blanks before the comment
            cut -= 1
        pieces.append(data[pos:cut])
        pos = end - 1 if data[end - 1 : end] == b"\r" else end   # the line end stays
        at = data.find(c, end)
    pieces.append(data[pos:])
    return b"".join(pieces)


def _blanks_to_commas(data: bytes) -> bytes:
    """Fields separated by runs of blanks (``'space'``), leading and trailing blanks dropped, as CSV
    (``bytes.replace`` passes only, at C speed: a run of k blanks takes log2(k) passes)."""
    data = data.replace(b"\t", b" ")
    while b"  " in data:
        data = data.replace(b"  ", b" ")
    data = data.replace(b" ", b",")
    data = data.replace(b"\n,", b"\n").replace(b",\r\n", b"\r\n").replace(b",\n", b"\n")
    data = data[1:] if data.startswith(b",") else data
    return data[:-1] if data.endswith(b",") else data


def csv_source(p: Path, fmt: LogFormat):
    """What pyarrow's CSV reader is given for a text log read with ``fmt``.

    Returns
    -------
    open : callable
        ``open()`` -> a fresh source (the path, or a buffer reader over the prepared bytes).
    read_options, parse_options : dict
        Keyword arguments of ``pyarrow.csv.ReadOptions`` and ``ParseOptions``.

    Notes
    -----
    Without a comment character found in the file and without ``'space'`` the file goes to pyarrow
    as it is (``skip_rows`` and ``delimiter`` are pyarrow's own options): no copy is made. Otherwise
    its bytes are prepared once (bytes.find and bytes.replace, not a Python loop over the lines).
    """
    read = {"skip_rows": fmt.skip_rows} if fmt.skip_rows else {}
    parse = {"delimiter": fmt.delimiter} if fmt.delimiter not in (None, ",", " ") else {}
    if fmt.comment is None and fmt.delimiter != " ":
        return (lambda: p), read, parse
    data = _raw_bytes(p)
    if fmt.comment is not None and fmt.comment.encode() not in data and fmt.delimiter != " ":
        return (lambda: p), read, parse
    import pyarrow as pa

    head, body = _split_lines(data, fmt.skip_rows)
    if fmt.comment is not None:
        body = _strip_comments(body, fmt.comment)
    if fmt.delimiter == " ":
        body = _blanks_to_commas(body)
    buffer = pa.py_buffer(body)
    return (lambda: pa.BufferReader(buffer)), {}, parse


def _split_lines(data: bytes, n: int) -> tuple[bytes, bytes]:
    """The first ``n`` lines of ``data`` and the rest."""
    pos = 0
    for _ in range(n):
        nl = data.find(b"\n", pos)
        if nl < 0:
            return data, b""
        pos = nl + 1
    return data[:pos], data[pos:]


def _head(p: Path, size: int = 1 << 16) -> bytes:
    """The first ``size`` bytes of the file (decompressed for ``.gz``)."""
    try:
        if p.suffix.lower() == ".gz":
            with gzip.open(p, "rb") as fh:
                return fh.read(size)
        with open(p, "rb") as fh:
            return fh.read(size)
    except (OSError, EOFError, zlib.error):
        return b""


def content_lines(p: Path, fmt: LogFormat, limit: int = 200) -> list[tuple[int, str]]:
    """Up to ``limit`` lines of the file's head that hold data (``(line number, text)``; 1-based), after
    ``skip_rows``, without comments and blank lines (a last, cut line is dropped)."""
    text = _head(p).decode("utf-8", "replace").removeprefix("\ufeff")
    lines = text.split("\n")
    if len(lines) > 1:
        lines = lines[:-1]
    out = []
    for number, line in enumerate(lines[fmt.skip_rows:], fmt.skip_rows + 1):
        if fmt.comment is not None:
            line = line.split(fmt.comment, 1)[0]
        if line.strip():
            out.append((number, line.rstrip("\r")))
        if len(out) >= limit:
            break
    return out


def _fields(line: str, sep: str) -> int:
    return len(line.split()) if sep == " " else line.count(sep) + 1


#: the separators a text log may use, tried in this order when none is given, with their option spelling
_SEPARATORS = ((",", ","), (";", ";"), ("\t", "tab"), ("|", "|"), (" ", "space"))


def preamble_hint(p: Path, fmt: LogFormat) -> str | None:
    """Advice for a text log the CSV reader could not read: a preamble to skip, comments, another delimiter.

    Looks at the file's head: lines starting with ``#`` (comments: ``{comment=#}``); the separator that splits
    the last lines into several fields (the given one, else the first of ``, ; tab | blanks`` that does:
    ``{delimiter=...}`` when it is not the comma); first lines with fewer fields than the lines after them (a
    logger's metadata before the header: ``{skip_rows=N}``, N counted from the top of the file).

    Returns
    -------
    str or None
        One clause for the message, None when nothing explains the failure.
    """
    lines = content_lines(p, fmt)
    mark = "#" if fmt.comment is None and any(text.lstrip().startswith("#") for _, text in lines) else None
    body = [(n, text) for n, text in lines if mark is None or not text.lstrip().startswith(mark)]
    if not body:
        return None
    given = fmt.separator if fmt.delimiter is not None else None
    tried = [(given, None)] if given is not None else list(_SEPARATORS)
    sep, word = next(((c, w) for c, w in tried if _fields(body[-1][1], c) > 1), tried[0])
    found, advice = [], []
    if given is None and word != ",":
        found.append(f"its fields are separated by {'blanks' if word == 'space' else 'tabs' if word == 'tab' else repr(word)}")
        advice.append(f"{{delimiter={word}}}")
    counts = [_fields(text, sep) for _, text in body]
    start = len(counts)
    while start > 0 and counts[start - 1] == counts[-1]:
        start -= 1
    if 0 < start < len(counts) - 1 and all(c < counts[-1] for c in counts[:start]):
        first, shown = body[start][0], sorted(set(counts[:start]))
        found.append(f"its first {_lines(first - 1)} {'hold' if first > 2 else 'holds'} {' or '.join(map(str, shown))} "
                     f"field{'s' if shown != [1] else ''} and the lines from line {first} on hold {counts[-1]} (a "
                     "logger's preamble before the header?)")
        advice.append(f"{{skip_rows={first - 1}}}")
        after = [n for n, text in lines if n > first and mark is not None and text.lstrip().startswith(mark)]
    else:
        after = [n for n, text in lines if mark is not None and text.lstrip().startswith(mark)]
    if after:
        found.append(f"line {after[0]} starts with '{mark}' (a comment?)")
        advice.append(f"{{comment={mark}}}")
    return f"{' and '.join(found)}: give {' and '.join(advice)}" if found else None


def _lines(n: int) -> str:
    return "line" if n == 1 else f"{n} lines"
