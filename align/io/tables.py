"""Named numeric columns of a file: CSV (pyarrow), blank-separated text, .parquet, .npy.

The lowest layer of the log readers (:mod:`align.io.logs`): it reads columns by name, as float64,
and knows nothing of units or time. A text file may have a preamble, comments or another
delimiter (:class:`~align.io.formats.LogFormat`); without them a CSV goes to pyarrow as it is.
Every problem becomes one :class:`~align.errors.InputError` naming the file (and, for a file the
CSV reader cannot read, the likely preamble or delimiter with the option to give).

Public names
------------
read_columns, read_table, shown
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from align.errors import InputError
from align.io.files import existing_log
from align.io.formats import LogFormat, content_lines, csv_source, preamble_hint


def read_columns(path: str | Path, names: list[str] | None = None, time_column: str | None = None,
                 log_format: LogFormat | None = None) -> tuple[list[str], np.ndarray]:
    """Read named numeric columns of a log, by the reader its format registers (:mod:`align.io.readers`).

    Parameters
    ----------
    path : str or Path
    names : list of str, optional
        Columns to read (all when None). For .npy files (no names) the columns
        are taken in order and named ``col0, col1, ...`` unless ``names``
        matches the array's width.
    time_column : str, optional
        The name among ``names`` that is the time (a missing one then points to the sample rate).
    log_format : LogFormat, optional
        Preamble, comments and delimiter of a text file (its ``time_units`` are not used here); the topic
        of a log with several streams.

    Returns
    -------
    names : list of str
    data : ndarray, shape (n, k), float64
    """
    got = read_table(path, names, time_column, log_format)
    return got.names, got.data


def read_table(path: str | Path, names: list[str] | None = None, time_column: str | None = None,
               log_format: LogFormat | None = None):
    """:func:`read_columns` with what the format states besides: the columns' units, the stream read and
    remarks (:class:`align.io.readers.Columns`).

    Raises
    ------
    InputError
        A text option given for a binary file, a topic for a file of one stream, or the reader's refusal.
    """
    from align.io.readers import Columns, reader_for

    p = Path(path)
    p = existing_log(path)
    fmt = log_format or LogFormat()
    reader = reader_for(p, fmt)
    if not reader.text and fmt.given():
        given = ", ".join("{" + k + "}" for k in fmt.given())
        raise InputError(f"{given} apply to text logs, not to a {reader.name} file; leave them out", str(path))
    if not reader.streams and fmt.streams_given():
        given = ", ".join("{" + k + "}" for k in fmt.streams_given())
        raise InputError(f"{given} apply to logs of several streams (ROS bags, ULog, DataFlash), and a "
                         f"{reader.name} file has one; leave them out", str(path))
    stated = _stated(p) if reader.text and not fmt.skip_rows and fmt.comment is None else None
    if stated is not None:  # a CSV imu-align wrote: its first line states the units
        import dataclasses

        got = Columns.of(reader.read(p, names, time_column, dataclasses.replace(fmt, skip_rows=1)))
        return dataclasses.replace(got, units={**{n: stated[n] for n in got.names if n in stated}, **got.units})
    return Columns.of(reader.read(p, names, time_column, fmt))


def _stated(p: Path) -> dict[str, str] | None:
    """The units the first line of a text log states (:func:`align.io.files.stated_units`), if it does."""
    from align.io.files import STATED, stated_units

    with open(p, "rb") as fh:
        head = fh.read(len(STATED))
        if head != STATED.encode():
            return None
        line = (head + fh.readline(4096)).decode("utf-8", "replace").rstrip("\r\n")
    return stated_units(line)


def parquet_columns(p: Path, names: list[str] | None, time_column: str | None, fmt: LogFormat
                    ) -> tuple[list[str], np.ndarray]:
    """Named columns of a Parquet file (pyarrow)."""
    import pyarrow.parquet as pq

    try:
        _require(names, pq.read_schema(p).names, p, time_column)
        table = _as_float(pq.read_table(p, columns=names), p)
    except InputError:
        raise
    except Exception as exc:  # pyarrow raises several types for a bad or damaged file
        raise InputError(f"cannot read parquet ({_first_line(exc)})", str(p)) from None
    return _arrow_columns(table, names, p)


def csv_columns(p: Path, names: list[str] | None, time_column: str | None, fmt: LogFormat
                ) -> tuple[list[str], np.ndarray]:
    """Named columns of a delimited text file with a header (pyarrow's CSV reader); a header-less
    blank-separated table of numbers as ``col0, col1, ...``."""
    if is_whitespace_table(p, fmt):
        return whitespace_columns(p, names, fmt)
    return _arrow_columns(_csv_table(p, names, time_column, fmt), names, p)


def npy_columns(p: Path, names: list[str] | None, time_column: str | None, fmt: LogFormat
                ) -> tuple[list[str], np.ndarray]:
    """The columns of a 2-D .npy array, in order (``col0, col1, ...`` unless ``names`` matches its width)."""
    return _npy_columns(p, names)


def _arrow_columns(table, names: list[str] | None, p: Path) -> tuple[list[str], np.ndarray]:
    cols = names or table.column_names
    if table.num_rows == 0:
        raise InputError("has no data rows (a header alone); record data into it", str(p))
    data = np.empty((len(cols), table.num_rows))  # filled row by row, returned transposed
    for j, name in enumerate(cols):
        pos = 0
        for chunk in table.column(name).chunks:
            data[j, pos : pos + len(chunk)] = _float_chunk(chunk)
            pos += len(chunk)
    return list(cols), data.T


def _npy_columns(p: Path, names: list[str] | None) -> tuple[list[str], np.ndarray]:
    try:
        arr = np.load(p, mmap_mode="r")
    except (ValueError, OSError, EOFError) as exc:
        raise InputError(f"cannot read .npy ({_first_line(exc)})", str(p)) from None
    if not isinstance(arr, np.ndarray) or arr.dtype.kind not in "fiu":
        kind = getattr(arr, "dtype", type(arr).__name__)
        raise InputError(f"holds {kind} values; expected numbers (an integer or float array)", str(p))
    arr = np.asarray(arr, dtype=float)
    if arr.ndim == 1:
        arr = arr[:, None]
    if arr.ndim != 2 or arr.shape[0] == 0:
        raise InputError(f"expected an n x k array of at least one row, got shape {tuple(arr.shape)}", str(p))
    if names is not None and len(names) != arr.shape[1]:
        raise InputError(f"has {arr.shape[1]} columns, expected {len(names)} ({', '.join(map(shown, names))})", str(p))
    return (list(names) if names is not None else [f"col{i}" for i in range(arr.shape[1])]), arr


def _csv_table(p: Path, names: list[str] | None, time_column: str | None, fmt: LogFormat):
    """The wanted columns of a CSV as an Arrow table of float64 (pyarrow, multithreaded)."""
    import pyarrow as pa
    import pyarrow.csv as pcsv

    with open(p, "rb") as fh:
        if fh.read(2) in (b"\xff\xfe", b"\xfe\xff"):
            raise InputError("is UTF-16 text; save it as UTF-8", str(p))
    source, read, parse = csv_source(p, fmt)
    read_opts, parse_opts = pcsv.ReadOptions(**read), pcsv.ParseOptions(**parse)
    try:
        with pcsv.open_csv(source(), read_options=read_opts, parse_options=parse_opts) as reader:
            header = reader.schema.names
    except UnicodeDecodeError:
        raise InputError("its header is not UTF-8 text; save the file as UTF-8", str(p)) from None
    except (pa.ArrowException, OSError, ValueError) as exc:
        hint = preamble_hint(p, fmt)
        raise InputError(hint or f"cannot read CSV ({_first_line(exc)})", str(p)) from None
    _require(names, header, p, time_column, fmt)
    wanted = names or header
    opts = pcsv.ConvertOptions(include_columns=wanted, column_types={n: pa.float64() for n in wanted})
    try:
        return pcsv.read_csv(source(), read_options=read_opts, parse_options=parse_opts, convert_options=opts)
    except (pa.ArrowException, OSError, ValueError) as exc:
        hint = preamble_hint(p, fmt)
        raise InputError(hint or f"a value is not a number ({_first_line(exc)}); clean the file", str(p)) from None


def _float_chunk(chunk) -> np.ndarray:
    """A float64 Arrow array as numpy, empty cells as NaN.

    Reads the buffers directly: ``Array.to_numpy`` imports pandas on first use,
    which alone costs more than reading a million-row CSV.
    """
    validity, values = chunk.buffers()[:2]
    arr = np.frombuffer(values, dtype=np.float64, count=len(chunk) + chunk.offset)[chunk.offset :]
    if chunk.null_count:
        bits = np.unpackbits(np.frombuffer(validity, dtype=np.uint8), bitorder="little")
        arr = np.where(bits[chunk.offset : chunk.offset + len(chunk)].astype(bool), arr, np.nan)
    return arr


def is_whitespace_table(p: Path, fmt: LogFormat) -> bool:
    """A header-less text table of numbers separated by blanks (imu_tk's .mat text, ``x y z`` files)."""
    if p.suffix.lower() in (".npy", ".parquet", ".gz") or fmt.delimiter not in (None, " ", "\t"):
        return False
    if fmt.plain:
        with open(p, "rb") as fh:
            first = fh.readline(4096).decode("ascii", "replace").strip()
    else:
        lines = content_lines(p, fmt, 1)
        first = lines[0][1].strip() if lines else ""
    if not first or "," in first or ";" in first:
        return False
    try:
        [float(v) for v in first.split()]
    except ValueError:
        return False
    return True


def whitespace_columns(p: Path, names: list[str] | None, fmt: LogFormat) -> tuple[list[str], np.ndarray]:
    """Columns ``col0, col1, ...`` of a blank-separated numeric table (parsed in C by numpy)."""
    raw = p.read_bytes()
    try:
        text = raw.decode("ascii")
    except UnicodeDecodeError as exc:
        lineno = raw[: exc.start].count(b"\n") + 1
        raise InputError(f"line {lineno}: byte 0x{exc.object[exc.start]:02x} is not part of a number; a blank-separated "
                         "table holds only numbers: clean the file", str(p)) from None
    lines = text.split("\n")
    skipped = min(fmt.skip_rows, len(lines))
    lines = lines[skipped:]
    if fmt.comment is not None:
        lines = [line.split(fmt.comment, 1)[0] for line in lines]
    first = next((line for line in lines if line.strip()), "")
    width = max(len(first.split()), 1)
    body = "\n".join(lines)
    try:
        values = np.array(body.split(), dtype=float)
    except ValueError:
        for row, line in enumerate(lines, skipped + 1):
            try:
                [float(w) for w in line.split()]
            except ValueError as exc:  # "could not convert string to float: 'five'"
                word = str(exc).split(": ", 1)[-1]
                raise InputError(f"line {row}: {shown(word)} is not a number; clean the file", str(p)) from None
        raise
    if values.size % width:
        raise InputError(f"rows of unequal length (first row has {width} numbers)", str(p))
    data = values.reshape(-1, width)
    available = [f"col{i}" for i in range(width)]
    _require(names, available, p)
    idx = [available.index(n) for n in (names or available)]
    return [available[i] for i in idx], data[:, idx]


def shown(text: str, limit: int = 40) -> str:
    """User text for a message: shortened, its braces made harmless (never read as a placeholder)."""
    text = text if len(text) <= limit else text[: limit - 3] + "..."
    return text.replace("{", "(").replace("}", ")")


def _first_line(exc: Exception) -> str:
    lines = str(exc).strip().splitlines()
    return shown(lines[0] if lines else type(exc).__name__, 200)


def _as_float(table, path):
    """Every column of an Arrow table as float64; a column that is not numeric is named."""
    import pyarrow as pa

    for name, column in zip(table.column_names, table.columns):
        kind = column.type
        if not (pa.types.is_floating(kind) or pa.types.is_integer(kind) or pa.types.is_decimal(kind)
                or pa.types.is_null(kind)):
            raise InputError(f"column '{shown(name)}' holds {kind} values, not numbers; give numeric columns "
                             "(name them with {columns})", str(path))
    try:
        return table.cast(pa.schema([(n, pa.float64()) for n in table.column_names]))
    except (pa.ArrowInvalid, pa.ArrowNotImplementedError) as exc:
        raise InputError(f"a value is not a number ({_first_line(exc)}); clean the file", str(path)) from None


def _require(names: list[str] | None, available: list[str], path, time_column: str | None = None,
             fmt: LogFormat | None = None) -> None:
    """Every name in ``names`` must be a column; a missing time column points to the sample rate, a header
    that looks like a preamble or another delimiter to the option that reads it."""
    if names is None:
        return
    missing = [n for n in names if n not in available]
    if missing:
        advice = "name the columns with {columns}"
        if missing == [time_column]:
            advice = "name its time column with {time_column}, give {rate_hz} for a log without time, or " + advice
        hint = preamble_hint(Path(path), fmt) if fmt is not None else None
        listed = ", ".join(shown(a) for a in available) or "none"
        raise MissingColumns(f"no column {', '.join(repr(shown(m)) for m in missing)} (columns: {listed}); "
                         + (hint or advice), str(path), missing, listed)


class MissingColumns(InputError):
    """A column asked for is not in the file: ``missing`` the names, ``listed`` the columns there are, shown."""

    def __init__(self, message: str, where: str | None = None, missing: list[str] | None = None,
                 listed: str = "") -> None:  # made again from its message alone by a caller that rewords it
        self.missing, self.listed = list(missing or []), listed
        super().__init__(message, where)
