"""Value types: frozen, compared by value, arrays read-only.

Results and models are frozen dataclasses deriving from :class:`Value`. Their
array fields are copied and made read-only when the value is built, so a value
never changes and never shares a buffer a caller can write to; ``==`` compares
every field by value (arrays element-wise, NaN equal to NaN), and
:func:`approx_equal` does the same within a tolerance, as scipy's
``Rotation.approx_equal`` does for rotations.

Public names
------------
Value, frozen_array, approx_equal
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Self

import numpy as np
import numpy.typing as npt


def frozen_array(a: npt.ArrayLike, shape: tuple[int, ...] | None = None, dtype: npt.DTypeLike = float) -> np.ndarray:
    """A read-only copy of ``a`` as an ndarray (reshaped when ``shape`` is given).

    Parameters
    ----------
    a : array_like, any shape
        The values, in whatever unit the caller keeps them.
    shape : tuple of int, optional
        Shape to give the copy, e.g. ``(3, 3)``.
    dtype : data-type
        dtype of the copy (float by default).

    Returns
    -------
    ndarray, shape ``shape`` or that of ``a``
        A new array with ``flags.writeable`` False; ``a`` itself is not changed.
    """
    arr = np.array(a, dtype=dtype)
    if shape is not None:
        arr = arr.reshape(shape)
    arr.flags.writeable = False
    return arr


def _same(a: Any, b: Any, rtol: float, atol: float) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        if a.shape != b.shape:
            return False
        if a.dtype.kind in "fc" or b.dtype.kind in "fc":
            return bool(np.allclose(a, b, rtol=rtol, atol=atol, equal_nan=True)) if (rtol or atol) else \
                bool(np.array_equal(a, b, equal_nan=True))
        return bool(np.array_equal(a, b))
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        if type(a) is not type(b):
            return False
        return all(_same(getattr(a, f.name), getattr(b, f.name), rtol, atol) for f in dataclasses.fields(a) if f.compare)
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(_same(a[k], b[k], rtol, atol) for k in a)
    if isinstance(a, (list, tuple)):
        return isinstance(b, (list, tuple)) and len(a) == len(b) and all(_same(x, y, rtol, atol) for x, y in zip(a, b))
    if isinstance(a, float) or isinstance(b, float):
        if not isinstance(b, (int, float)) or not isinstance(a, (int, float)):
            return False
        if a == b:  # equal, infinities included (inf - inf is NaN)
            return True
        if math.isnan(a) or math.isnan(b):
            return math.isnan(a) and math.isnan(b)
        return abs(a - b) <= atol + rtol * abs(b)
    return a == b


def approx_equal(a: Any, b: Any, rtol: float = 1e-9, atol: float = 0.0) -> bool:
    """True when two values (dataclasses, arrays, dicts, sequences, numbers) agree.

    Floats and arrays agree when ``|a - b| <= atol + rtol |b|`` element-wise
    (NaN agrees with NaN); everything else must be equal.

    Parameters
    ----------
    a, b : Any
        Values to compare: dataclasses field by field (same type), arrays of the
        same shape, dicts with the same keys, lists and tuples of the same length,
        numbers, and anything else with ``==``.
    rtol : float
        Relative tolerance, dimensionless (relative to ``b``).
    atol : float
        Absolute tolerance, in the values' own (SI) units.

    Returns
    -------
    bool
    """
    return _same(a, b, rtol, atol)


class Value:
    """Mixin for frozen dataclasses: read-only array fields and value equality.

    Declare subclasses with ``@dataclass(frozen=True, eq=False)``; a subclass
    with its own ``__post_init__`` calls ``super().__post_init__()``. Array
    fields are copied read-only; ``==`` compares every field by value (arrays
    element-wise, NaN equal to NaN).
    """

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):  # type: ignore[arg-type]  # a mixin: every subclass is a dataclass
            v = getattr(self, f.name)
            if isinstance(v, np.ndarray):
                object.__setattr__(self, f.name, frozen_array(v, dtype=v.dtype))

    def __eq__(self, other: object) -> bool:
        return type(self) is type(other) and _same(self, other, 0.0, 0.0)

    __hash__ = None  # type: ignore[assignment]  # values holding arrays are not hashable

    def replace(self, **changes: Any) -> Self:
        """A copy with some fields changed (``dataclasses.replace``).

        Parameters
        ----------
        **changes : Any
            Field name -> new value, in the field's own unit (SI inside the program).

        Returns
        -------
        Self
            A new value of the same type (``__post_init__`` runs again: new
            arrays are copied read-only); the original is unchanged.
        """
        return dataclasses.replace(self, **changes)  # type: ignore[type-var]  # a mixin: every subclass is a dataclass
