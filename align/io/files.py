"""Files: TOML and JSON in, atomic writes out.

Writers are atomic (a temporary file renamed into place), so a failed run never
leaves a half-written output. Readers refuse in one line naming the file: a
missing file or a folder, text that is not UTF-8 (the byte and its line), a
syntax error (its line), an empty file, a JSON key given twice. The keys of the
tables read are checked by :mod:`align.io.keys`.

Public names
------------
existing_file, existing_log, decode_text, read_text, read_toml, read_json, write_json, write_text, write_bytes, write_csv,
csv_bytes, stated_units, STATED, to_json_value
"""

from __future__ import annotations

import codecs
import json
import math
import os
import tempfile
import tomllib
from pathlib import Path

import numpy as np

from align.errors import InputError


def existing_file(path: str | Path) -> Path:
    """``path`` as a Path; an InputError when it is not an existing file (or is a folder)."""
    p = Path(path)
    if p.is_dir():
        raise InputError("is a folder, not a file", str(path))
    if not p.is_file():
        raise InputError("file not found", str(path))
    return p


def existing_log(path: str | Path) -> Path:
    """``path`` as a Path: an existing file, or a folder a registered log reader claims (a ROS 2 bag, an EuRoC
    dataset: :func:`align.io.readers.reader_for`). A plan, a result or any other input stays a file
    (:func:`existing_file`).

    Raises
    ------
    InputError
        A missing path, or a folder no reader claims (naming the folder kinds there are).
    """
    p = Path(path)
    if p.is_dir():
        from align.io.readers import reader_for

        reader_for(p)  # refuses a folder that is no log, naming the kinds of log folder
        return p
    return existing_file(p)


def decode_text(raw: bytes, where: str) -> str:
    """``raw`` as UTF-8 text (a leading byte-order mark dropped); one line naming ``where`` otherwise.

    Parameters
    ----------
    raw : bytes
        The file's bytes.
    where : str
        The file, for the message.

    Raises
    ------
    InputError
        For UTF-16 text, a binary file (NUL bytes) or bytes that are not UTF-8
        (naming the first bad byte, its offset and line).
    """
    if raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        raise InputError("is UTF-16 text; save it as UTF-8", where)
    skip = len(codecs.BOM_UTF8) if raw.startswith(codecs.BOM_UTF8) else 0
    try:
        text = raw[skip:].decode("utf-8")
    except UnicodeDecodeError as exc:
        at = exc.start + skip
        line = raw[:at].count(b"\n") + 1
        raise InputError(f"not UTF-8 text (byte 0x{raw[at]:02x} at offset {at}, line {line}); save it as UTF-8",
                         where) from None
    if "\x00" in text:
        raise InputError("holds NUL bytes: a binary file, not text", where)
    return text


def read_text(path: str | Path) -> str:
    """The text of an existing UTF-8 file; every problem (missing, a folder, unreadable, not UTF-8) one line."""
    p = existing_file(path)
    try:
        raw = p.read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read ({exc.strerror or exc})", str(path)) from None
    return decode_text(raw, str(path))


def read_toml(path: str | Path) -> dict:
    """Parse a TOML file; a syntax error names the file and line, an empty file is refused."""
    text = read_text(path)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"not valid TOML ({exc})", str(path)) from None
    except RecursionError:
        raise InputError("not valid TOML (nested too deeply)", str(path)) from None
    except ValueError as exc:   # e.g. an integer of thousands of digits
        raise InputError(f"not valid TOML ({exc})", str(path)) from None
    if not data:
        raise InputError("is empty: no tables or keys", str(path))
    return data


class _DuplicateKey(ValueError):
    pass


def _refuse_duplicates(pairs: list) -> dict:
    out = {}
    for key, value in pairs:
        if key in out:
            raise _DuplicateKey(key)
        out[key] = value
    return out


def read_json(path: str | Path) -> dict:
    """Parse a JSON object; a syntax error names the file, a key given twice is refused."""
    text = read_text(path)
    if not text.strip():
        raise InputError("is empty: expected a JSON object", str(path))
    try:
        data = json.loads(text, object_pairs_hook=_refuse_duplicates)
    except _DuplicateKey as exc:
        raise InputError(f"key '{exc}' is given twice in one object; keep one", str(path)) from None
    except RecursionError:
        raise InputError("not valid JSON (nested too deeply)", str(path)) from None
    except ValueError as exc:   # JSONDecodeError, or an integer of thousands of digits
        raise InputError(f"not valid JSON ({exc})", str(path)) from None
    if not isinstance(data, dict):
        raise InputError("expected a JSON object at the top level", str(path))
    return data


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _atomic(path: str | Path, write) -> None:
    p = Path(path)
    if p.parent and not p.parent.exists():
        raise InputError("output folder does not exist", str(path))
    try:
        fd, tmp = tempfile.mkstemp(dir=p.parent or ".", prefix=f".{p.name}.", suffix=".tmp")
    except OSError as exc:
        raise InputError(f"cannot write here ({exc.strerror or exc}); choose another folder", str(path)) from None
    try:
        with os.fdopen(fd, "wb") as fh:
            write(fh)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, p)
    except BaseException as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise InputError(f"cannot write ({exc.strerror or exc}); nothing was written", str(path)) from None
        raise


def write_bytes(path: str | Path, data: bytes) -> None:
    """Write bytes atomically (pictures, GLB)."""
    _atomic(path, lambda fh: fh.write(data))


def write_text(path: str | Path, text: str) -> None:
    """Write text atomically."""
    _atomic(path, lambda fh: fh.write(text.encode()))


def write_json(path: str | Path, data: dict) -> None:
    """Write a JSON object atomically (indented, NaN written as null)."""
    write_text(path, json.dumps(to_json_value(data), indent=2) + "\n")


def to_json_value(x):
    """``x`` with numpy arrays and scalars as plain lists and numbers; NaN and inf as None."""
    t = type(x)  # the plain types first, by identity (most of a result's values; the batch writes one per unit)
    if t is float:
        return x if math.isfinite(x) else None
    if t is dict:
        return {k: to_json_value(v) for k, v in x.items()}
    if t is list or t is tuple:
        return [to_json_value(v) for v in x]
    if t is str or t is int or t is bool or x is None:
        return x
    if isinstance(x, dict):
        return {k: to_json_value(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [to_json_value(v) for v in x]
    if isinstance(x, np.ndarray):
        return to_json_value(x.tolist())
    if isinstance(x, (float, np.floating)):
        return None if not np.isfinite(x) else float(x)
    if isinstance(x, np.integer):
        return int(x)
    return x


#: the first line of a CSV that states its columns' units: ``# imu-align 0.2.0 apply: w = A (g - b); units: time=s,
#: gyro_x=deg/s, ...`` (what wrote it, then ``name=unit`` for each column; read back by the CSV reader)
STATED = "# imu-align "


def csv_bytes(names: list[str], data: np.ndarray, units: dict[str, str] | None = None, wrote: str = "") -> bytes:
    """Numeric columns as CSV bytes (pyarrow's writer, full float precision); with ``units``, a first line that
    states what wrote the file (``wrote``: ``"apply: w = A (g - b) from r.json"``) and each column's unit
    (:data:`STATED`), which :func:`stated_units` reads back.

    Examples
    --------
    >>> text = csv_bytes(["time", "gyro_x"], np.array([[0.0, 1.5]]), {"time": "s", "gyro_x": "deg/s"}, "apply")
    >>> stated_units(text.decode().splitlines()[0])
    {'time': 's', 'gyro_x': 'deg/s'}
    """
    import io

    import pyarrow as pa
    import pyarrow.csv as pcsv

    from align import __version__

    table = pa.table({n: np.ascontiguousarray(data[:, j]) for j, n in enumerate(names)})
    buf = io.BytesIO()
    if units:
        stated = ", ".join(f"{n}={units[n]}" for n in names if n in units)
        buf.write(f"{STATED}{__version__} {wrote}; units: {stated}\n".replace("\n\n", "\n").encode())
    pcsv.write_csv(table, buf)
    return buf.getvalue()


def stated_units(first_line: str) -> dict[str, str] | None:
    """The units a CSV's first line states (:func:`csv_bytes`), or None for a line that states none."""
    if not first_line.startswith(STATED) or "; units: " not in first_line:
        return None
    out = {}
    for item in first_line.rsplit("; units: ", 1)[1].strip().split(", "):
        name, sep, unit = item.partition("=")
        if not sep or not name.strip() or not unit.strip():
            return None
        out[name.strip()] = unit.strip()
    return out


def write_csv(path: str | Path, names: list[str], data: np.ndarray) -> None:
    """Write numeric columns as CSV atomically (pyarrow's writer, full float precision)."""
    import pyarrow as pa
    import pyarrow.csv as pcsv

    table = pa.table({n: np.ascontiguousarray(data[:, j]) for j, n in enumerate(names)})
    _atomic(path, lambda fh: pcsv.write_csv(table, fh))


