"""Sensor logs: the one place that reads recorded data.

CSV (optionally .gz, read with pyarrow), blank-separated text, .parquet, .npy and
raw binary; columns by name; time in seconds; data converted to SI once, here.
Every problem becomes an :class:`~align.errors.InputError` naming the file,
row or column; the checks of a log's rows and time stamps live here too, so
every reader applies the same ones.

Public names
------------
read_columns, read_log, read_static, NpyChunks, check_finite, check_readings, check_time, check_log, MAX_READING
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from align.errors import InputError
from align.io.files import existing_file
from align.units import parse_unit

#: the largest magnitude a reading may have in its file's unit (a 32-bit ADC's counts reach 4.3e9): beyond it a
#: value is a corrupt sample, not a measurement (a single 1e300 would swamp every mean and deviation)
MAX_READING = 1e12


def _rows(n: int) -> str:
    return "1 row" if n == 1 else f"{n} rows"


def check_finite(x: np.ndarray, where: str, t: np.ndarray | None = None, first_row: int = 1) -> None:
    """Reject rows of ``x`` (n, k) (or times ``t``) that are NaN or infinite, naming the first by its data row
    (``first_row``: the number of the first row of ``x``)."""
    bad = ~np.isfinite(x).all(axis=1)
    if t is not None:
        bad |= ~np.isfinite(t)
    if bad.any():
        rows = np.flatnonzero(bad)
        raise InputError(f"{_rows(len(rows))} with NaN or inf (first at data row {rows[0] + first_row}); remove or "
                         "repair them", where)


def check_readings(x: np.ndarray, where: str, t: np.ndarray | None = None, first_row: int = 1) -> None:
    """Reject rows of ``x`` (n, k) that are not readings: NaN or infinite (:func:`check_finite`), or with a
    value beyond :data:`MAX_READING` in magnitude (a corrupt sample); the first is named by its data row."""
    x = np.asarray(x)
    x = x[:, None] if x.ndim == 1 else x
    check_finite(x, where, t, first_row)
    big = (np.abs(x) > MAX_READING).any(axis=1)
    if big.any():
        rows = np.flatnonzero(big)
        value = float(x[rows[0]][np.abs(x[rows[0]]) > MAX_READING][0])
        raise InputError(f"{_rows(len(rows))} with a value beyond +/-{MAX_READING:.0e} (first at data row "
                         f"{rows[0] + first_row}: {value:.3g}): not a sensor reading; remove or repair them", where)


def check_time(t: np.ndarray, where: str, gap: float | None = None, jitter: bool = False) -> None:
    """Time must increase; with ``gap``, no step may exceed ``gap`` times the median step
    (and, with ``jitter``, none may fall below ``2 - gap`` times it: uniform sampling)."""
    dt = np.diff(t)
    if np.any(dt <= 0):
        k = int(np.argmax(dt <= 0))
        raise InputError(f"time does not increase at data row {k + 2} (t={t[k + 1]:.9g} s after {t[k]:.9g} s); "
                         "sort the log or fix the time column", where)
    if gap is None or len(dt) == 0:
        return
    med = float(np.median(dt))
    off = (dt > gap * med) | ((dt < (2 - gap) * med) if jitter else False)
    if off.any():
        k = int(np.argmax(off))
        raise InputError(f"{int(off.sum())} time gaps{' or jitter' if jitter else ''} beyond {100 * (gap - 1):g} % of the "
                         f"{med:.4g} s median step: gap in the time series at t={t[k]:.6g} s (step {dt[k]:.4g} s); "
                         "resample or split the file", where)


def check_log(t: np.ndarray, g: np.ndarray, where: str, min_rows: int = 10) -> None:
    """Reject NaN or infinite rows, non-increasing time and logs that are too short."""
    if len(t) < min_rows:
        raise InputError(f"only {len(t)} rows; at least {min_rows} are needed", where)
    check_readings(g, where, t)
    check_time(t, where)


def read_columns(path: str | Path, names: list[str] | None = None,
                 time_column: str | None = None) -> tuple[list[str], np.ndarray]:
    """Read named numeric columns of a CSV (.csv, .csv.gz), .parquet or .npy file.

    Parameters
    ----------
    path : str or Path
    names : list of str, optional
        Columns to read (all when None). For .npy files (no names) the columns
        are taken in order and named ``col0, col1, ...`` unless ``names``
        matches the array's width.
    time_column : str, optional
        The name among ``names`` that is the time (a missing one then points to the sample rate).

    Returns
    -------
    names : list of str
    data : ndarray, shape (n, k), float64
    """
    p = existing_file(path)
    suffixes = "".join(p.suffixes[-2:]).lower()
    if p.suffix.lower() == ".npy":
        try:
            arr = np.load(p, mmap_mode="r")
        except (ValueError, OSError, EOFError) as exc:
            raise InputError(f"cannot read .npy ({_first_line(exc)})", str(path)) from None
        if not isinstance(arr, np.ndarray) or arr.dtype.kind not in "fiu":
            kind = getattr(arr, "dtype", type(arr).__name__)
            raise InputError(f"holds {kind} values; expected numbers (an integer or float array)", str(path))
        arr = np.asarray(arr, dtype=float)
        if arr.ndim == 1:
            arr = arr[:, None]
        if arr.ndim != 2 or arr.shape[0] == 0:
            raise InputError(f"expected an n x k array of at least one row, got shape {tuple(arr.shape)}", str(path))
        if names is not None and len(names) != arr.shape[1]:
            raise InputError(f"has {arr.shape[1]} columns, expected {len(names)} ({', '.join(map(_shown, names))})",
                             str(path))
        return (list(names) if names is not None else [f"col{i}" for i in range(arr.shape[1])]), arr
    if p.suffix.lower() == ".parquet":
        import pyarrow as pa
        import pyarrow.parquet as pq

        try:
            _require(names, pq.read_schema(p).names, path, time_column)
            table = _as_float(pq.read_table(p, columns=names), path)
        except InputError:
            raise
        except Exception as exc:  # pyarrow raises several types for a bad or damaged file
            raise InputError(f"cannot read parquet ({_first_line(exc)})", str(path)) from None
    elif _is_whitespace_table(p):
        return _whitespace_columns(p, names)
    elif suffixes.endswith((".csv", ".csv.gz", ".txt", ".txt.gz")) or p.suffix.lower() in (".csv", ".gz"):
        import pyarrow as pa
        import pyarrow.csv as pcsv

        with open(p, "rb") as fh:
            if fh.read(2) in (b"\xff\xfe", b"\xfe\xff"):
                raise InputError("is UTF-16 text; save it as UTF-8", str(path))
        try:
            with pcsv.open_csv(p) as reader:
                header = reader.schema.names
        except UnicodeDecodeError:
            raise InputError("its header is not UTF-8 text; save the file as UTF-8", str(path)) from None
        except (pa.ArrowException, OSError, ValueError) as exc:
            raise InputError(f"cannot read CSV ({_first_line(exc)})", str(path)) from None
        _require(names, header, path, time_column)
        wanted = names or header
        opts = pcsv.ConvertOptions(include_columns=wanted, column_types={n: pa.float64() for n in wanted})
        try:
            table = pcsv.read_csv(p, convert_options=opts)
        except (pa.ArrowException, OSError, ValueError) as exc:
            raise InputError(f"a value is not a number ({_first_line(exc)}); clean the file", str(path)) from None
    else:
        raise InputError("unknown file type; use .csv, .csv.gz, .npy or .parquet", str(path))
    cols = names or table.column_names
    if table.num_rows == 0:
        raise InputError("has no data rows (a header alone); record data into it", str(path))
    data = np.empty((len(cols), table.num_rows))  # filled row by row, returned transposed
    for j, name in enumerate(cols):
        pos = 0
        for chunk in table.column(name).chunks:
            data[j, pos : pos + len(chunk)] = _float_chunk(chunk)
            pos += len(chunk)
    return list(cols), data.T


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


def _is_whitespace_table(p: Path) -> bool:
    """A header-less text table of numbers separated by blanks (imu_tk's .mat text, ``x y z`` files)."""
    if p.suffix.lower() in (".npy", ".parquet", ".gz"):
        return False
    with open(p, "rb") as fh:
        first = fh.readline(4096).decode("ascii", "replace").strip()
    if not first or "," in first or ";" in first:
        return False
    try:
        [float(v) for v in first.split()]
    except ValueError:
        return False
    return True


def _whitespace_columns(p: Path, names: list[str] | None) -> tuple[list[str], np.ndarray]:
    """Columns ``col0, col1, ...`` of a blank-separated numeric table (parsed in C by numpy)."""
    try:
        text = p.read_bytes().decode("ascii")
    except UnicodeDecodeError as exc:
        line = p.read_bytes()[: exc.start].count(b"\n") + 1
        raise InputError(f"line {line}: byte 0x{exc.object[exc.start]:02x} is not part of a number; a blank-separated "
                         "table holds only numbers: clean the file", str(p)) from None
    width = len(text.split("\n", 1)[0].split())
    try:
        values = np.array(text.split(), dtype=float)
    except ValueError:
        for row, line in enumerate(text.splitlines(), 1):
            try:
                [float(w) for w in line.split()]
            except ValueError as exc:  # "could not convert string to float: 'five'"
                word = str(exc).split(": ", 1)[-1]
                raise InputError(f"line {row}: {_shown(word)} is not a number; clean the file", str(p)) from None
        raise
    if values.size % width:
        raise InputError(f"rows of unequal length (first row has {width} numbers)", str(p))
    data = values.reshape(-1, width)
    available = [f"col{i}" for i in range(width)]
    _require(names, available, p)
    idx = [available.index(n) for n in (names or available)]
    return [available[i] for i in idx], data[:, idx]


def _shown(text: str, limit: int = 40) -> str:
    """User text for a message: shortened, its braces made harmless (never read as a placeholder)."""
    text = text if len(text) <= limit else text[: limit - 3] + "..."
    return text.replace("{", "(").replace("}", ")")


def _first_line(exc: Exception) -> str:
    lines = str(exc).strip().splitlines()
    return _shown(lines[0] if lines else type(exc).__name__, 200)


def _as_float(table, path):
    """Every column of an Arrow table as float64; a column that is not numeric is named."""
    import pyarrow as pa

    for name, column in zip(table.column_names, table.columns):
        kind = column.type
        if not (pa.types.is_floating(kind) or pa.types.is_integer(kind) or pa.types.is_decimal(kind)
                or pa.types.is_null(kind)):
            raise InputError(f"column '{_shown(name)}' holds {kind} values, not numbers; give numeric columns "
                             "(name them with {columns})", str(path))
    try:
        return table.cast(pa.schema([(n, pa.float64()) for n in table.column_names]))
    except (pa.ArrowInvalid, pa.ArrowNotImplementedError) as exc:
        raise InputError(f"a value is not a number ({_first_line(exc)}); clean the file", str(path)) from None


def _require(names: list[str] | None, available: list[str], path, time_column: str | None = None) -> None:
    """Every name in ``names`` must be a column; a missing time column points to the sample rate."""
    if names is None:
        return
    missing = [n for n in names if n not in available]
    if missing:
        advice = "name the columns with {columns}"
        if missing == [time_column]:
            advice = "give {rate_hz} for a log without time, or " + advice
        listed = ", ".join(_shown(a) for a in available) or "none"
        raise InputError(f"no column {', '.join(repr(_shown(m)) for m in missing)} (columns: {listed}); " + advice,
                         str(path))


def _check_rate(rate_hz: float | None, path, missing: str = "no time column: give {rate_hz}") -> None:
    """A sample rate given for a log without time: present, finite and positive."""
    if rate_hz is None:
        raise InputError(missing, str(path))
    if not (np.isfinite(rate_hz) and rate_hz > 0):
        raise InputError(f"the sample rate must be a finite number of Hz > 0, not {float(rate_hz)!r}; give e.g. "
                         "{rate_hz=100}", str(path))


def read_log(
    path: str | Path,
    columns: list[str],
    units: str,
    time_column: str | None = "time",
    rate_hz: float | None = None,
    expect: str = "angular_rate",
) -> tuple[np.ndarray, np.ndarray]:
    """Read a sensor log: time (s) and data columns converted to SI.

    Parameters
    ----------
    path : str or Path
    columns : list of str
        The data columns, e.g. ``["gyro_x", "gyro_y", "gyro_z"]``.
    units : str
        Unit of the data columns, e.g. ``"deg/s"``; checked against ``expect``.
    time_column : str or None
        Name of the time column (seconds); None when ``rate_hz`` is given.
    rate_hz : float, optional
        Sample rate for logs without a time column.

    Returns
    -------
    t : ndarray, shape (n,)
    data : ndarray, shape (n, len(columns)), SI
    """
    factor = parse_unit(units, expect, "{units}" if expect != "angular_rate" else "{gyro_units}").factor
    use_time = time_column is not None and rate_hz is None
    wanted = ([time_column] if use_time else []) + list(columns)
    p = Path(path)
    if p.suffix.lower() == ".npy":
        _, arr = read_columns(p)
        if arr.shape[1] != len(wanted):
            raise InputError(f"has {arr.shape[1]} columns; expected {len(wanted)} ({', '.join(map(_shown, wanted))})"
                             + ("; give {rate_hz} for a file without time" if use_time else ""), str(path))
        data = arr
    else:
        _, data = read_columns(p, wanted, time_column if use_time else None)
    if use_time:
        t, values = data[:, 0], data[:, 1:]
    else:
        _check_rate(rate_hz, path)
        t, values = np.arange(len(data)) / rate_hz, data
    check_readings(values, str(path), t)
    return np.ascontiguousarray(t), values * factor


class NpyChunks:
    """Row chunks of a 2-D .npy file (or raw binary) read with ``numpy.fromfile``: bounded memory.

    Raw binary files (``.bin``/``.f8``: little-endian float64, ``.f4``: float32)
    hold ``channels`` interleaved columns and no header.

    Attributes
    ----------
    shape : tuple
        ``(n, C)`` of the stored array.
    """

    def __init__(self, path: str | Path, channels: int | None = None) -> None:
        p = existing_file(path)
        if p.suffix.lower() in (".bin", ".f8", ".f4", ".raw"):
            dtype = np.dtype("<f4" if p.suffix.lower() == ".f4" else "<f8")
            if not channels:
                raise InputError("a raw binary file needs its number of columns ({columns})", str(path))
            size = p.stat().st_size
            if size % (dtype.itemsize * channels):
                raise InputError(f"{size} bytes is not a whole number of {channels}-column {dtype} rows", str(path))
            self.path, self.offset, self.fortran, self.dtype = p, 0, False, dtype
            self.shape = (size // (dtype.itemsize * channels), channels)
            return
        try:
            with open(p, "rb") as fh:
                version = np.lib.format.read_magic(fh)
                read = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
                shape, fortran, dtype = read(fh)
                self.offset = fh.tell()
        except (ValueError, OSError) as exc:
            raise InputError(f"cannot read .npy ({exc})", str(path)) from None
        if len(shape) == 1:
            shape = (shape[0], 1)
        if dtype.kind not in "fiu":
            raise InputError(f"holds {dtype} values; expected numbers (an integer or float array)", str(path))
        if len(shape) != 2:
            raise InputError(f"expected an n x k array, got shape {tuple(int(k) for k in shape)}", str(path))
        self.path, self.shape, self.fortran, self.dtype = p, shape, fortran, dtype

    def chunks(self, rows: int = 1 << 20, columns: list[int] | None = None):
        """Yield float64 arrays of up to ``rows`` rows (all columns, or the ones listed)."""
        n, c = self.shape
        cols = list(range(c)) if columns is None else columns
        with open(self.path, "rb") as fh:
            for start in range(0, n, rows):
                k = min(rows, n - start)
                if self.fortran:
                    block = np.empty((k, len(cols)))
                    for j, col in enumerate(cols):
                        fh.seek(self.offset + (col * n + start) * self.dtype.itemsize)
                        block[:, j] = np.fromfile(fh, self.dtype, k)
                else:
                    fh.seek(self.offset + start * c * self.dtype.itemsize)
                    block = np.fromfile(fh, self.dtype, k * c).reshape(k, c)
                    if columns is not None:
                        block = block[:, cols]
                    block = block.astype(np.float64, copy=False)
                yield block


def read_static(log: str | Path, names: list[str], rate_hz: float | None):
    """Raw columns of a static log and its sample rate, for the Allan deviation.

    No unit conversion (the deviations are scaled afterwards, so no SI copy of a
    large record is made). ``.npy`` and raw binary files come back as a
    :class:`NpyChunks` source read in chunks; CSV needs a uniform time column
    (gaps are refused with their position) unless ``rate_hz`` is given.
    """
    log = Path(log)
    if log.suffix.lower() in (".npy", ".bin", ".f8", ".f4", ".raw"):
        _check_rate(rate_hz, log, f"a {log.suffix} file has no time: give {{rate_hz}}")
        source = NpyChunks(log, len(names))
        if source.shape[1] != len(names):
            raise InputError(f"has {source.shape[1]} columns but {len(names)} names were given; name each column with "
                             "{columns}", str(log))
        if source.shape[0] == 0:
            raise InputError("holds no samples", str(log))
        return source, float(rate_hz)  # its samples are checked as they are read (align.noise.allan)
    if rate_hz is not None:
        _check_rate(rate_hz, log)
    wanted = names if rate_hz is not None else ["time"] + names
    _, data = read_columns(log, wanted, None if rate_hz is not None else "time")
    if rate_hz is not None:
        check_readings(data, str(log))
        return data, float(rate_hz)
    t = data[:, 0]
    check_log(t, data[:, 1:], str(log), min_rows=3)
    check_time(t, str(log), gap=1.5, jitter=True)  # an Allan deviation needs uniform samples
    return np.ascontiguousarray(data[:, 1:]), 1.0 / float(np.median(np.diff(t)))


