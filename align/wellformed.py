"""Well-formed result files: arrays of the right shape, finite, and one line for a malformed file.

Public names
------------
require_finite, array_field, malformed
"""

from __future__ import annotations

import numpy as np

from align.errors import InputError, literal


def require_finite(where: str, what: str, **arrays: np.ndarray | None) -> None:
    """Refuse a result whose named arrays hold null, NaN or infinite values (a malformed file).

    Parameters
    ----------
    where : str
        The file (and sensor).
    what : str
        The kind of result, e.g. ``"alignment result"``.
    **arrays : ndarray or None
        Name -> array; None is skipped.
    """
    for name, a in arrays.items():
        if a is not None and not np.all(np.isfinite(np.asarray(a, float))):
            raise InputError(f"malformed {what}: {name} holds null or non-finite values; regenerate the result", where)


def array_field(d: dict, key: str, shape: tuple[int, ...], what: str, where: str, factor: float = 1.0) -> np.ndarray:
    """A finite array of ``shape`` read from a result file's ``d[key]`` (times ``factor``), or a one-line refusal.

    Raises
    ------
    InputError
        ``alignment.json: malformed alignment result: M must be a 3x3 array of numbers`` (missing, text, wrong
        shape) or ``...: M holds null or non-finite values; regenerate the result``.
    """
    size = "x".join(map(str, shape)) if len(shape) > 1 else f"{shape[0]}-element"
    if key not in d:
        raise InputError(f"malformed {what}: missing key '{key}'; regenerate the result", where)
    try:
        a = np.array(d[key], dtype=float) * factor
        if a.shape != shape:
            raise ValueError
    except (TypeError, ValueError):
        raise InputError(f"malformed {what}: {key} must be a {size} array of numbers; regenerate the result", where) from None
    require_finite(where, what, **{key: a})
    return a


def malformed(exc: Exception) -> str:
    """What a KeyError, TypeError or ValueError met while reading a result file says, without Python reprs."""
    if isinstance(exc, KeyError):
        return f"missing key {literal(repr(exc.args[0]) if exc.args else '')}"
    return literal(" ".join(str(exc).split()) or type(exc).__name__)
