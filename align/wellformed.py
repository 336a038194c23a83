"""Well-formed result files: arrays of the right shape, finite, and one line for a malformed file.

Public names
------------
require_finite, array_field, malformed, check_inverse, INVERSE_TOLERANCE
"""

from __future__ import annotations

import math

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


#: the largest |A M - I| of a result's A and M: about ten steps of a float (2^-23) at 1, below what a C header's float
#: literals resolve; a larger one is a hand-edited file
INVERSE_TOLERANCE = 1e-6


def check_inverse(m, a, where: str, field: str) -> None:
    """Refuse an ``A`` that is not ``M^-1`` beyond :data:`INVERSE_TOLERANCE` (an ``M`` that is singular, left-handed
    or not finite is left to the checks that name ``M``: :func:`align.plausible.check_usable_model`)."""
    m, a = np.asarray(m, dtype=float), np.asarray(a, dtype=float)
    if m.shape != (3, 3) or a.shape != (3, 3) or not (np.all(np.isfinite(m)) and np.linalg.det(m) > 1e-12):
        return
    err = float(np.max(np.abs(a @ m - np.eye(3)))) if np.all(np.isfinite(a)) else math.inf
    if not err <= INVERSE_TOLERANCE:
        raise InputError(f"is not the inverse of {field}M (largest |A M - I| = {err:.2g}, more than "
                         f"{INVERSE_TOLERANCE:g}): the file was edited; restore A = M^-1 or regenerate the result",
                         f"{where}: {field}A")
