"""Checks of a result before it is exported: ``A = M^-1`` (a hand-edited file is refused, naming the field), and the
numbers of a C header within a C float.

Public names
------------
check_inverse, check_inverses, c_values, INVERSE_TOLERANCE
"""

from __future__ import annotations

import math

import numpy as np

from align.errors import InputError
from align.io.consumers import float32_value

#: the largest |A M - I| of a result's A and M: about ten steps of a float (2^-23) at 1, below what a C header's float
#: literals resolve; a larger one is a hand-edited file
INVERSE_TOLERANCE = 1e-6


def check_inverse(m, a, where: str, field: str) -> None:
    """Refuse an ``A`` that is not ``M^-1`` beyond :data:`INVERSE_TOLERANCE` (an ``M`` that is singular or not finite
    is left to the checks that name ``M``)."""
    m, a = np.asarray(m, dtype=float), np.asarray(a, dtype=float)
    if m.shape != (3, 3) or a.shape != (3, 3) or not (np.all(np.isfinite(m)) and abs(np.linalg.det(m)) > 1e-12):
        return
    err = float(np.max(np.abs(a @ m - np.eye(3)))) if np.all(np.isfinite(a)) else math.inf
    if not err <= INVERSE_TOLERANCE:
        raise InputError(f"is not the inverse of {field}M (largest |A M - I| = {err:.2g}, more than "
                         f"{INVERSE_TOLERANCE:g}): the file was edited; restore A = M^-1 or regenerate the result",
                         f"{where}: {field}A")


def check_inverses(d: dict, where: str) -> None:
    """Every ``M``/``A`` pair of a result file (the top level, and each sensor's table) holds ``A = M^-1``.

    Raises
    ------
    InputError
        Naming the field (``accelerometer.A``) whose ``A`` is not the inverse of its ``M``.

    Examples
    --------
    >>> check_inverses({"M": [[2, 0, 0], [0, 1, 0], [0, 0, 1]], "A": [[0.5, 0, 0], [0, 1, 0], [0, 0, 1]]}, "a.json")
    >>> check_inverses({"gyroscope": {"M": [[2, 0, 0], [0, 1, 0], [0, 0, 1]], "A": [[1, 0, 0], [0, 1, 0],
    ...                 [0, 0, 1]]}}, "a.json")
    Traceback (most recent call last):
    ...
    align.errors.InputError: a.json: gyroscope.A: is not the inverse of gyroscope.M (largest ...
    """
    tables = [("", d)] + [(f"{k}.", v) for k, v in d.items() if isinstance(v, dict)]
    for field, t in tables:
        if "M" in t and "A" in t:
            try:
                m, a = np.array(t["M"], dtype=float), np.array(t["A"], dtype=float)
            except (TypeError, ValueError):
                continue  # malformed: the result's reader says so
            check_inverse(m, a, where, field)


def c_values(a: np.ndarray, bias: np.ndarray, where: str) -> None:
    """The numbers of an alignment's C header (``A``, and the bias in the header's unit), each within a C float:
    refused naming the file and the field, never written as ``inf`` or ``0.0``."""
    for fld, values in (("A", a), ("bias", bias)):
        for x in np.asarray(values, dtype=float).ravel():
            float32_value(x, f"{where}: {fld}", "a C header")
