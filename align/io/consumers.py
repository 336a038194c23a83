"""Exports: results in the formats other programs load (firmware C headers, Kalibr's imu.yaml, CSV, imucal's JSON).

The writers here take plain arrays and numbers (SI unless a unit is named) and
return text; :mod:`align.present.exportable` picks what each result writes. Every
file states its convention (correcting ``w = A (g - b)`` or modelling
``g = M w + b``), its frame, its units and the tool version.

* C: ``static const float`` arrays whose literals are the nearest IEEE single
  (``float``) to each value, written with 9 significant digits and an ``f``
  suffix (:func:`c_float`): 9 digits identify a float exactly, so the compiler
  reads back the very float ``numpy.float32`` gives.
* Kalibr (ethz-asl/kalibr, ``ImuParameters``): the flat ``imu.yaml`` keys
  (``rostopic``, ``update_rate``, ``accelerometer_noise_density``,
  ``accelerometer_random_walk``, ``gyroscope_noise_density``,
  ``gyroscope_random_walk``) and, for intrinsics, the ``scale-misalignment``
  model's ``accelerometers: {M}`` and ``gyroscopes: {M, A, C_gyro_i}``. Kalibr
  models (``IccScaledMisalignedImu``): ``a_meas = M_accel a_i + b_a`` and
  ``w_meas = M_gyro C_gyro_i w_i + A_gyro C_gyro_i a_i + b_g`` with lower
  triangular ``M`` (the direction of imu-align's ``M``: modelling).
  A full ``M`` is split as ``M = L Q`` (:func:`lower_rotation`). Floats are
  written so that YAML 1.1 readers (PyYAML) read floats, never strings
  (``1.0e-05``, not ``1e-05``).
* CSV: ``#`` comment lines, then a header row naming each column's unit.

Public names
------------
c_float, float32_value, FLT_MAX, c_array, c_file, c_header, kalibr_yaml, yaml_float, lower_rotation, csv_text,
matrix_unit, imucal_dict
"""

from __future__ import annotations

import json
import math
import re

import numpy as np

from align import __version__
from align.errors import InputError, literal
from align.units import DEG, parse_unit

#: a C identifier (the prefix of the arrays of a header)
C_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
#: the tool, as every export names it
TOOL = f"imu-align {__version__}"


def c_float(x: float, where: str = "value") -> str:
    """``x`` as a C ``float`` literal: the nearest IEEE single, 9 significant digits (``%.9g``), ``f`` suffix.

    ``1.0`` -> ``1.0f``; ``1e-5`` -> ``9.99999975e-06f``. Non-finite values are refused (a C literal cannot hold
    them portably).
    """
    text = f"{float32_value(x, where, 'a C header'):.9g}"
    if not any(c in text for c in ".eE"):
        text += ".0"
    return text + "f"


#: the largest finite IEEE single (FLT_MAX of C's float.h)
FLT_MAX = float(np.finfo(np.float32).max)


def float32_value(x: float, where: str = "value", what: str = "a C float") -> float:
    """``x`` rounded to the nearest IEEE single (a C ``float``), refusing what a float cannot hold.

    Refused: a non-finite value, a value beyond ``FLT_MAX`` (3.40282347e+38: the literal would overflow to
    infinity, or be read as something else), and a value other than zero that rounds to ``0.0`` (below half the
    smallest subnormal, 1.4e-45): never written as a number it is not.

    Examples
    --------
    >>> float32_value(0.1)
    0.10000000149011612
    >>> float32_value(1e300, "bias")
    Traceback (most recent call last):
    ...
    align.errors.InputError: bias: holds 1e+300, beyond the range of a C float (|x| <= 3.40282347e+38): ...
    """
    v = float(x)
    if not math.isfinite(v):
        raise InputError(f"holds a non-finite value ({v}); {what} cannot carry it", where)
    with np.errstate(over="ignore", under="ignore"):
        f = float(np.float32(v))
    if not math.isfinite(f):  # beyond FLT_MAX by more than half a float step: the literal overflows
        raise InputError(f"holds {v:.9g}, beyond the range of a C float (|x| <= {FLT_MAX:.9g}): {what} cannot carry "
                         "it; fix the value in the result (or regenerate the result)", where)
    if f == 0.0 and v != 0.0:
        raise InputError(f"holds {v:.9g}, below the smallest C float (1.4e-45): {what} would write it as 0.0; fix "
                         "the value in the result", where)
    return f


def c_array(name: str, values, comment: str, where: str = "value") -> list[str]:
    """``/* comment */`` and ``static const float name[3][3] = {...};`` (1-D or 2-D, row-major) lines."""
    a = np.asarray(values, dtype=float)
    if a.ndim == 1:
        body = "{" + ", ".join(c_float(v, where) for v in a) + "}"
    else:
        body = "{\n" + ",\n".join("    {" + ", ".join(c_float(v, where) for v in row) + "}" for row in a) + "\n}"
    dims = "".join(f"[{n}]" for n in a.shape)
    return [f"/* {comment} */", f"static const float {name}{dims} = {body};", ""]


def _comment_lines(text: str) -> list[str]:
    return [f"/* {line.replace('*/', '* /')} */" for line in text.splitlines() if line.strip()]


def c_file(name: str, preamble: str, blocks: list[list[str]]) -> str:
    """A header guarded by ``<NAME>_H``: the ``preamble`` as comment lines, then the arrays ``blocks``
    (:func:`c_array`)."""
    if not C_NAME.fullmatch(name):
        raise InputError(f"'{literal(name)}' is not a C identifier (letters, digits and _, not starting with a digit)",
                         "{name}")
    guard = f"{name.upper()}_H"
    lines = _comment_lines(preamble) + [f"#ifndef {guard}", f"#define {guard}", ""]
    for block in blocks:
        lines += block
    return "\n".join(lines + [f"#endif /* {guard} */", ""])


def c_header(name: str, matrix: np.ndarray, bias: np.ndarray, bias_unit: str, comment: str,
             frame: str = "the system frame of the test (the rate table's axes)") -> str:
    """The C header of an alignment: ``<name>_A[3][3]`` (row-major) and ``<name>_BIAS[3]`` for ``w = A (g - b)``.

    Parameters
    ----------
    name : str
        C identifier prefix, e.g. ``"IMU_ALIGN"``.
    matrix : ndarray, shape (3, 3)
        The alignment matrix ``A = M^-1``, dimensionless.
    bias : ndarray, shape (3,)
        Gyro bias in ``bias_unit``.
    bias_unit : str
        The readings' unit.
    comment : str
        First lines of the header (what it is, where it came from); ``written by`` the tool is added to the first
        unless it names the tool already, and a line restating the convention (``g = M w + b; ...``) is dropped:
        the header states it once, in full.
    frame : str
        The frame of the corrected rates.
    """
    lines = [ln for ln in comment.splitlines() if ln.strip() and not ln.startswith("g = M w + b")]
    first = lines[0] if lines else "imu-align alignment"
    if TOOL not in first:
        first += f"; written by {TOOL}"
    preamble = ("\n".join([first, *lines[1:]]) + "\n"  # one statement of the convention: the one below
                "convention: correcting, w = A (g - b) with A = M^-1 of the model g = M w + b (g raw reading, "
                "b bias, w true rate); rows of M are gyro axes\n"
                f"frame: w in {frame}\n"
                f"units: A dimensionless; b in {bias_unit}, the unit of the readings g\n"
                "literals: the nearest float (IEEE single) to each value, 9 significant digits")
    return c_file(name, preamble, [
        c_array(f"{name}_A", matrix, "alignment matrix A = M^-1, dimensionless: w = A (g - b)", "A"),
        c_array(f"{name}_BIAS", bias, f"gyro bias b in {bias_unit}", "bias"),
    ])


def yaml_float(x: float, where: str = "value") -> str:
    """A float as YAML that PyYAML (YAML 1.1) reads back as the same float: ``repr`` with a ``.`` in the mantissa."""
    if not math.isfinite(float(x)):
        raise InputError(f"holds a non-finite value ({x}); it cannot be written to Kalibr's file", where)
    text = repr(float(x))
    mantissa, e, exponent = text.partition("e")
    if "." not in mantissa:
        mantissa += ".0"
    return mantissa + (e + exponent if e else "")


def _yaml_matrix(m, where: str) -> str:
    return "[" + ", ".join("[" + ", ".join(yaml_float(v, where) for v in row) + "]" for row in np.asarray(m)) + "]"


def kalibr_yaml(header: str, scalars: list[tuple[str, str | float, str]], sensors: dict[str, dict]) -> str:
    """Kalibr's ``imu.yaml`` (the flat ``ImuParameters`` keys) as text.

    Parameters
    ----------
    header : str
        Comment lines: convention, frame, units, tool, what is missing.
    scalars : list of (key, value, comment)
        ``rostopic`` (str) and the numbers (``update_rate``, noise densities, random walks), each with an
        end-of-line comment (its unit); written in this order.
    sensors : dict
        The intrinsics: ``{"accelerometers": {"M": (3, 3)}, "gyroscopes": {"M": ..., "A": ..., "C_gyro_i": ...}}``
        (either may be absent); with any, ``model: scale-misalignment`` is written.
    """
    lines = [f"# {line}" for line in header.splitlines()]
    for key, value, note in scalars:
        text = json.dumps(value) if isinstance(value, str) else yaml_float(value, key)
        lines.append(f"{key}: {text}" + (f"  # {note}" if note else ""))
    if sensors:
        lines.append("model: scale-misalignment")
        for sensor, mats in sensors.items():
            lines.append(f"{sensor}:")
            lines += [f"  {k}: {_yaml_matrix(v, f'{sensor}.{k}')}" for k, v in mats.items()]
    return "\n".join(lines) + "\n"


def lower_rotation(m: np.ndarray, where: str = "M") -> tuple[np.ndarray, np.ndarray]:
    """``M = L Q``: ``L`` lower triangular with a positive diagonal, ``Q`` a proper rotation (an LQ decomposition).

    Kalibr's scale-misalignment ``M`` is lower triangular and its ``C_gyro_i`` the rotation; from the QR
    decomposition ``M^T = Q' R``: ``L = R^T``, ``Q = Q'^T`` with signs making ``diag(L) > 0``.

    Raises
    ------
    InputError
        ``det(M) <= 0`` (an axis backwards: no rotation gives it) or a matrix that is not finite.
    """
    m = np.asarray(m, dtype=float)
    if not np.all(np.isfinite(m)) or not np.linalg.det(m) > 0:
        raise InputError("M is not finite or has det <= 0 (an axis backwards); no Kalibr intrinsics come from it", where)
    q, r = np.linalg.qr(m.T)
    s = np.sign(np.diag(r))
    lower, rot = np.tril((r * s[:, None]).T) + 0.0, (q * s[None, :]).T  # + 0.0: no -0.0 above the diagonal
    return lower, rot


def csv_text(header: str, columns: list[str], rows: list[list]) -> str:
    """CSV: ``# `` comment lines, the column names (each with its unit), then the rows (floats in full precision)."""
    def cell(v) -> str:
        if isinstance(v, str):
            return v
        if v is None or (isinstance(v, float) and not math.isfinite(v)):
            return ""
        return repr(float(v))

    note = ("floats in full precision: pandas.read_csv(path, comment='#') reads them exactly "
            "(pandas before 3: add float_precision='round_trip')")
    lines = [f"# {line}" for line in [*header.splitlines(), note]] + [",".join(columns)]
    lines += [",".join(cell(v) for v in row) for row in rows]
    return "\n".join(lines) + "\n"


def matrix_unit(units: str, sensor: str) -> str:
    """The unit of ``M`` in ``raw = M true + bias``: ``1`` (dimensionless) for readings in a physical unit, counts per
    SI unit for readings in raw counts."""
    try:
        counts = parse_unit(units).dim == parse_unit("counts").dim
    except InputError:
        counts = False
    si = {"accelerometer": "m/s^2", "gyroscope": "rad/s", "magnetometer": "T"}.get(sensor, "SI unit")
    return f"counts per {si}" if counts else "1"


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
        imucal's keys, in m/s^2 and deg/s (``_format_version`` 2.0.0); its ``comment`` states the convention,
        the frame, the units and the tool.
    """
    def kr(m):
        k = np.diag(np.linalg.norm(m, axis=1))
        return k, np.linalg.inv(k) @ m

    ka, ra = kr(np.asarray(acc_M, float))
    kg, rg = kr(np.asarray(gyr_M, float))
    kga = np.zeros((3, 3)) if gyr_g_sensitivity is None else np.asarray(gyr_g_sensitivity, float) / DEG
    comment = (f"written by {TOOL}: modelling convention raw = K R true + b (gyro: + K_ga acc), imucal's own; "
               "frame: the axes of the calibration positions; units: acc m/s^2, gyr deg/s, K_ga (deg/s)/(m/s^2)")
    return {"acc_unit": "m/s^2", "gyr_unit": "deg/s", "from_acc_unit": "m/s^2", "from_gyr_unit": "deg/s",
            "comment": comment,
            "K_a": ka.tolist(), "R_a": ra.tolist(), "b_a": np.asarray(acc_bias, float).tolist(),
            "K_g": kg.tolist(), "R_g": rg.tolist(), "K_ga": kga.tolist(),
            "b_g": (np.asarray(gyr_bias, float) / DEG).tolist(),
            "cal_type": "Ferraris", "_format_version": "2.0.0"}
