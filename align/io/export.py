"""Exports: results in the formats other programs load (firmware C headers).

Public names
------------
c_header
"""

from __future__ import annotations

import numpy as np


def c_header(name: str, matrix: np.ndarray, bias: np.ndarray, bias_unit: str, comment: str) -> str:
    """A C header with the alignment matrix and bias as literals.

    ``<name>_A[3][3]`` (row-major) and ``<name>_BIAS[3]`` for ``w = A (g - b)``.
    """
    guard = f"{name.upper()}_H"
    rows = ",\n".join("    {" + ", ".join(f"{v:.10e}f" for v in row) + "}" for row in matrix)
    lines = [
        f"/* {line} */" for line in comment.splitlines()
    ] + [
        f"#ifndef {guard}",
        f"#define {guard}",
        "",
        "/* alignment matrix A = M^-1, dimensionless: w = A (g - b) */",
        f"static const float {name}_A[3][3] = {{\n{rows}\n}};",
        "",
        f"/* gyro bias b in {bias_unit} */",
        f"static const float {name}_BIAS[3] = {{" + ", ".join(f"{v:.10e}f" for v in bias) + "};",
        "",
        f"#endif /* {guard} */",
        "",
    ]
    return "\n".join(lines)
