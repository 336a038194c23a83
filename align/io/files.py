"""Files: TOML and JSON in, atomic writes out.

Writers are atomic (a temporary file renamed into place), so a failed run never
leaves a half-written output; readers name the file and line of a syntax error.

Public names
------------
existing_file, read_toml, read_json, write_json, write_text, write_bytes, write_csv, to_json_value
"""

from __future__ import annotations

import json
import os
import tempfile
import tomllib
from pathlib import Path

import numpy as np

from align.errors import InputError


def existing_file(path: str | Path) -> Path:
    """``path`` as a Path; an InputError when it is not an existing file."""
    p = Path(path)
    if not p.is_file():
        raise InputError("file not found", str(path))
    return p


def read_toml(path: str | Path) -> dict:
    """Parse a TOML file; a syntax error names the file and line."""
    p = existing_file(path)
    try:
        with open(p, "rb") as fh:
            return tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"not valid TOML ({exc})", str(path)) from None


def read_json(path: str | Path) -> dict:
    """Parse a JSON object; a syntax error names the file."""
    p = existing_file(path)
    try:
        data = json.loads(p.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
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


def write_csv(path: str | Path, names: list[str], data: np.ndarray) -> None:
    """Write numeric columns as CSV atomically (pyarrow's writer, full float precision)."""
    import pyarrow as pa
    import pyarrow.csv as pcsv

    table = pa.table({n: np.ascontiguousarray(data[:, j]) for j, n in enumerate(names)})
    _atomic(path, lambda fh: pcsv.write_csv(table, fh))


