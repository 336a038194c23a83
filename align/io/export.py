"""Exports: results in the formats other programs load (firmware C headers, imucal's JSON).

Public names
------------
c_header, imucal_dict
"""

from __future__ import annotations

import numpy as np

from align import __version__
from align.units import DEG


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


def imucal_dict(acc_M: np.ndarray, acc_bias: np.ndarray, gyr_M: np.ndarray, gyr_bias: np.ndarray,
                gyr_g_sensitivity: np.ndarray | None = None) -> dict:
    """An accelerometer-gyro pair as imucal's ``FerrarisCalibrationInfo`` JSON (``K``, ``R``, ``b`` per sensor).

    imucal's model is ``raw = K R true + b`` (plus ``K_ga a`` for the gyro), so
    ``K = diag(|rows of M|)`` and ``R = K^-1 M``.

    Parameters
    ----------
    acc_M, gyr_M : ndarray, shape (3, 3)
        Dimensionless ``M`` of ``raw = M true + bias``.
    acc_bias : ndarray, shape (3,)
        m/s^2.
    gyr_bias : ndarray, shape (3,)
        rad/s.
    gyr_g_sensitivity : ndarray, shape (3, 3), optional
        Gyro ``K_ga``, (rad/s) per (m/s^2); zero when not given.

    Returns
    -------
    dict
        imucal's keys, in m/s^2 and deg/s (``_format_version`` 2.0.0).
    """
    def kr(m):
        k = np.diag(np.linalg.norm(m, axis=1))
        return k, np.linalg.inv(k) @ m

    ka, ra = kr(np.asarray(acc_M, float))
    kg, rg = kr(np.asarray(gyr_M, float))
    kga = np.zeros((3, 3)) if gyr_g_sensitivity is None else np.asarray(gyr_g_sensitivity, float) / DEG
    return {"acc_unit": "m/s^2", "gyr_unit": "deg/s", "from_acc_unit": "m/s^2", "from_gyr_unit": "deg/s",
            "comment": f"written by imu-align {__version__}: raw = K R true + b",
            "K_a": ka.tolist(), "R_a": ra.tolist(), "b_a": np.asarray(acc_bias, float).tolist(),
            "K_g": kg.tolist(), "R_g": rg.tolist(), "K_ga": kga.tolist(),
            "b_g": (np.asarray(gyr_bias, float) / DEG).tolist(),
            "cal_type": "Ferraris", "_format_version": "2.0.0"}
