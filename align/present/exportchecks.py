"""Checks of a result before it is exported: the numbers of a C header within a C float. (``A = M^-1`` is checked
where every result file is read: :func:`align.wellformed.check_inverse`.)

Public names
------------
c_values
"""

from __future__ import annotations

import numpy as np

from align.io.consumers import float32_value


def c_values(a: np.ndarray, bias: np.ndarray, where: str) -> None:
    """The numbers of an alignment's C header (``A``, and the bias in the header's unit), each within a C float:
    refused naming the file and the field, never written as ``inf`` or ``0.0``."""
    for fld, values in (("A", a), ("bias", bias)):
        for x in np.asarray(values, dtype=float).ravel():
            float32_value(x, f"{where}: {fld}", "a C header")
