"""What each result exports: Kalibr's imu.yaml, the noise keys of OpenVINS, VINS-Fusion, PX4 and ArduPilot, a C
header, CSV tables, imucal's JSON (``imu-align export``).

The writers are :mod:`align.io.consumers`'s and :mod:`align.io.noise_consumers`'s; here each result type is mapped
to what it can export, every file's statement (convention, frame, units, tool, source) is composed, and a result
that has no such export is refused with the list of those that do.

* ``allan``: kalibr, openvins, vins, px4, ardupilot (noise figures in each one's terms:
  :mod:`align.present.noise_figures`), csv (the curve);
* ``alignment``: kalibr (gyroscope intrinsics, with Allan results for the noise keys), c (``A``, bias: the header
  ``matrix`` writes), csv (M, A, angles);
* ``calibration``: kalibr (accelerometer and gyroscope intrinsics, with Allan results), c (``A``, bias, ``K_ga`` per
  sensor), csv, imucal (with both sensors);
* ``magnetometer``: c (``A``, hard iron; soft iron and rotation when found), csv.

A result whose ``A`` is not ``M^-1`` (a hand-edited file) is refused, naming the field
(:mod:`align.present.exportchecks`).

Public names
------------
export, export_text, EXPORTS, NOISE
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from align.alignment.result import AlignmentResult
from align.calibration.magnetometer import MagCalibration
from align.calibration.results import CalibrationSet
from align.errors import InputError, literal
from align.io.consumers import TOOL, c_array, c_file, csv_text, kalibr_yaml, lower_rotation, matrix_unit
from align.io.noise_consumers import CONSUMERS, entries, header_lines
from align.noise.job import AllanJob
from align.parts import Part
from align.present.angles import DEFINITIONS, angle_rows
from align.present.exportchecks import c_values
from align.present.noise_figures import Exported, consumer_rate, gather, noise_export, noise_summary, select
from align.results import Result
from align.units import to_unit

#: the noise consumers other than Kalibr (Allan results and a datasheet in, their noise keys out)
NOISE = ("openvins", "vins", "px4", "ardupilot")
#: the exports, and the result formats each one takes
EXPORTS: dict[str, tuple[str, ...]] = {
    "kalibr": ("imu-align.allan", "imu-align.alignment", "imu-align.calibration"),
    **{n: ("imu-align.allan",) for n in NOISE},
    "c": ("imu-align.alignment", "imu-align.calibration", "imu-align.magnetometer"),
    "csv": ("imu-align.allan", "imu-align.alignment", "imu-align.calibration", "imu-align.magnetometer"),
    "imucal": ("imu-align.calibration",),
}
_SHORT = {"c": "C header", "csv": "CSV table", "imucal": "imucal JSON", **{n: c.title for n, c in CONSUMERS.items()}}
_KEY = {"accelerometer": "ACCEL", "gyroscope": "GYRO"}
_CAL_FRAME = "the axes of the calibration positions (the fixture's frame)"
_ALIGN_FRAME = "the system frame of the test (the rate table's axes)"


def _refuse(result: Result, to: str, where: str) -> InputError:
    takes = ", ".join(f.removeprefix("imu-align.") for f in EXPORTS[to])
    return InputError(f"holds an {result.FORMAT} result, which has no {_SHORT[to]} export ({to} exports: {takes} "
                      "results); give one of those", where)


def _inverse(m: np.ndarray, where: str) -> np.ndarray:
    """``m^-1``; a singular or non-finite matrix is refused (no correcting matrix comes from it)."""
    if not np.all(np.isfinite(m)) or abs(np.linalg.det(m)) < 1e-12 * max(np.abs(m).max(), 1e-300) ** 3:
        raise InputError("the matrix is singular or not finite: it has no inverse to export; regenerate the result",
                         where)
    return np.linalg.inv(m)


def _source(result: Result, where: str) -> str:
    return f"from {Path(where).name} ({result.FORMAT}); written by {TOOL}"


# ---------------------------------------------------------------- C headers

def _calibration_header(cs: CalibrationSet, name: str, where: str) -> str:
    blocks = []
    for sensor, c in cs.sensors.items():
        key, u = f"{name}_{_KEY[sensor]}", c.units
        what = f"{sensor}: A = M^-1 ({_inverse_unit(c)}): true = A (raw - bias" + (
            " - K_ga acc)" if c.g_sensitivity is not None else ")")
        blocks.append(c_array(f"{key}_A", _inverse(c.M, f"{where}: {sensor}.M"), what, f"{where}: {sensor}.M"))
        blocks.append(c_array(f"{key}_BIAS", to_unit(c.bias, u), f"{sensor}: bias in {u}", f"{where}: {sensor}.bias"))
        if c.g_sensitivity is not None:
            blocks.append(c_array(f"{key}_G_SENSITIVITY", c.g_sensitivity * to_unit(1.0, u),
                                  f"{sensor}: K_ga in {u} per m/s^2 (acc: true specific force, m/s^2)",
                                  f"{where}: {sensor}.g_sensitivity"))
    units = "; ".join(f"{s} readings and bias in {c.units}, true values in {_true_unit(c)}" for s, c in cs.sensors.items())
    preamble = (f"imu-align calibration ({', '.join(cs.sensors)}) {_source(cs, where)}\n"
                "convention: correcting, true = A (raw - bias) with A = M^-1 of the model raw = M true + bias "
                "(gyro: + K_ga acc); rows of M are sensor axes\n"
                f"frame: true values in {_CAL_FRAME}\n"
                f"units: {units} (A is dimensionless for readings in a physical unit: true values in the readings' "
                "unit; for readings in counts A maps counts to SI)\n"
                "literals: the nearest float (IEEE single) to each value, 9 significant digits")
    return c_file(name, preamble, blocks)


def _true_unit(c) -> str:
    """The unit of ``A (raw - bias)``: the readings' own, or SI for readings in counts (M in counts per SI unit)."""
    mu = matrix_unit(c.units, c.sensor)
    return c.units if mu == "1" else mu.removeprefix("counts per ")


def _inverse_unit(c) -> str:
    mu = matrix_unit(c.units, c.sensor)
    return "dimensionless" if mu == "1" else f"the inverse of {mu}"


def _mag_header(c: MagCalibration, name: str, where: str) -> str:
    frame = ("the accelerometer's frame (m_body = misalignment m_cal)" if c.misalignment is not None
             else "the magnetometer's own axes (the soft iron is symmetric: no rotation)")
    what = "soft_iron" if c.misalignment is None else "MISALIGNMENT SOFT_IRON"
    blocks = [c_array(f"{name}_A", c.correcting, f"A = {what}, dimensionless: m = A (m_raw - hard_iron)",
                      f"{where}: soft_iron"),
              c_array(f"{name}_HARD_IRON", to_unit(c.hard_iron, c.units), f"hard iron in {c.units}", f"{where}: hard_iron")]
    if c.misalignment is not None:  # A is their product; each for reference
        blocks.append(c_array(f"{name}_SOFT_IRON", c.soft_iron, "soft iron W (symmetric), dimensionless: m_cal = W "
                              "(m_raw - hard_iron); for reference, A holds it", f"{where}: soft_iron"))
        blocks.append(c_array(f"{name}_MISALIGNMENT", c.misalignment, "rotation to the accelerometer frame: m_body = "
                              "MISALIGNMENT m_cal; for reference, A holds it", f"{where}: misalignment"))
    preamble = (f"imu-align magnetometer calibration ({c.model} soft iron) {_source(c, where)}\n"
                "convention: correcting, m = A (m_raw - hard_iron); the model is m_raw = M m + hard_iron with M = A^-1\n"
                f"frame: m in {frame}\n"
                f"units: A dimensionless; hard iron and m in {c.units} (field {to_unit(c.field, c.units):.6g} {c.units})\n"
                "literals: the nearest float (IEEE single) to each value, 9 significant digits")
    return c_file(name, preamble, blocks)


# ---------------------------------------------------------------- CSV

def _angle_rows(sensor: str, m, sigma_m=None, mounting=None, unit: str = "1") -> list[list]:
    """The rows of :func:`align.present.angles.angle_rows` (the layout every output uses): one CSV row per element,
    ``row``/``column`` the element's axes (``phi`` xy: row x, column y), the scale in M's unit, angles in deg."""
    keys = {"rotation": "mounting_rotation"}
    out = []
    for r in angle_rows(m, sigma_m, mounting, unit):
        for k, (n, v) in enumerate(zip(r.names, r.values)):
            sig = None if r.sigmas is None else r.sigmas[k]
            pair = r.key in ("phi", "delta")
            out.append([keys.get(r.key, r.key), sensor, n[0], n[1] if pair else "", v, sig, r.unit])
    return out


def _matrix_rows(q: str, sensor: str, m, sigma, unit: str) -> list[list]:
    sig = np.full((3, 3), np.nan) if sigma is None else np.asarray(sigma, float)
    return [[q, sensor, "xyz"[i], "xyz"[j], float(m[i, j]), float(sig[i, j]), unit] for i in range(3) for j in range(3)]


def _vector_rows(q: str, sensor: str, v, sigma, unit: str) -> list[list]:
    sig = np.full(3, np.nan) if sigma is None else np.asarray(sigma, float)
    return [[q, sensor, a, "", float(v[k]), float(sig[k]), unit] for k, a in enumerate("xyz")]


_CSV_COLUMNS = ["quantity", "sensor", "row", "column", "value", "sigma_1", "unit"]


def _matrix_csv(r: Result, where: str) -> str:
    if isinstance(r, AlignmentResult):
        u = r.units
        rows = (_matrix_rows("M", "gyroscope", r.M, r.sigma_M, "1") + _matrix_rows("A", "gyroscope", r.A, r.sigma_A, "1")
                + _vector_rows("bias", "gyroscope", to_unit(r.bias, u), to_unit(r.sigma_bias, u), u)
                + _angle_rows("gyroscope", r.M, r.sigma_M, r.mounting))
        frame = _ALIGN_FRAME + ("" if np.allclose(r.mounting, np.eye(3)) else "; angles relative to the nominal mounting")
    elif isinstance(r, CalibrationSet):
        rows, frame = [], _CAL_FRAME
        for s, c in r.sensors.items():
            mu = matrix_unit(c.units, s)
            inv = _inverse(c.M, f"{where}: {s}.M")
            rows += (_matrix_rows("M", s, c.M, c.sigma_M, mu) + _matrix_rows("A", s, inv, None, "1" if mu == "1" else f"1/({mu})")
                     + _vector_rows("bias", s, to_unit(c.bias, c.units), to_unit(c.sigma_bias, c.units), c.units)
                     + _angle_rows(s, c.M, c.sigma_M, unit=mu))
    else:
        assert isinstance(r, MagCalibration), r.FORMAT  # EXPORTS["csv"]: the only other matrix result
        a = r.correcting
        m = _inverse(a, f"{where}: soft_iron")
        rows = (_matrix_rows("M", "magnetometer", m, None, "1") + _matrix_rows("A", "magnetometer", a, None, "1")
                + _vector_rows("hard_iron", "magnetometer", to_unit(r.hard_iron, r.units),
                               to_unit(r.sigma_hard_iron, r.units), r.units)
                + _matrix_rows("soft_iron", "magnetometer", r.soft_iron, None, "1")
                + _angle_rows("magnetometer", m))
        frame = "the accelerometer's frame" if r.misalignment is not None else "the magnetometer's own axes"
    header = (f"M, A and the angles {_source(r, where)}\n"
              "convention: M modelling (raw = M true + bias; rows are sensor axes); A = M^-1 correcting "
              "(true = A (raw - bias))\n"
              f"frame: {frame}\n"
              "units: the unit column (angles in deg; scale = |row of M| in M's unit); sigma_1 is the 1-sigma, empty "
              "when unknown\n"
              "angles: " + "; ".join(DEFINITIONS[k] for k in ("scale", "psi", "phi", "delta", "rotation"))
              + " (u_i = row i of M / |row i|)")
    return csv_text(header, _CSV_COLUMNS, rows)


def _allan_csv(job: AllanJob, where: str) -> str:
    r, u = job.result, job.units
    cols = ["tau [s]"]
    data: list[np.ndarray] = [r.tau]
    for j, n in enumerate(r.names):
        f = job.fits[j]
        cols += [f"{n} adev [{u}]", f"{n} ci_low [{u}]", f"{n} ci_high [{u}]"]
        data += [to_unit(r.adev[j], u), to_unit(f.ci_low, u), to_unit(f.ci_high, u)]
    header = (f"Allan deviation curve {_source(job, where)}\n"
              f"overlapping Allan deviation of {job.sensor} data"
              + (f" (pooled curve of {job.runs} runs)" if job.pooled else "") + f" at {r.fs:g} Hz\n"
              f"units: tau in s, deviations in {u}; ci_low/ci_high: 68.3 % chi-square interval\n"
              "frame: the sensor's own axes (no matrix: noise only)")
    return csv_text(header, cols, np.column_stack(data).tolist())


# ---------------------------------------------------------------- Kalibr

def _flat(m: np.ndarray) -> str:
    return "[" + ", ".join("[" + ", ".join(f"{v:.9g}" for v in row) + "]" for row in m) + "]"


def _physical(cs: CalibrationSet, what: str, where: str) -> None:
    """Refuse readings in counts: ``what`` takes a dimensionless ``M`` (readings in a physical unit)."""
    for s, c in cs.sensors.items():
        if matrix_unit(c.units, s) != "1":
            raise InputError(f"the {s} readings are in {c.units}: {what} is dimensionless; calibrate with the "
                             "size of one count as the unit", f"{where}: {s}")


def _kalibr_intrinsics(r: Result, where: str) -> tuple[dict, str]:
    if isinstance(r, AlignmentResult):
        low, rot = lower_rotation(r.M, f"{where}: M")
        return ({"gyroscopes": {"M": low, "A": np.zeros((3, 3)), "C_gyro_i": rot}},
                f"IMU frame i = {_ALIGN_FRAME}; gyroscopes.A (g-sensitivity) not estimated: zero")
    assert isinstance(r, CalibrationSet), r.FORMAT  # EXPORTS["kalibr"]: the only other result with intrinsics
    _physical(r, "Kalibr's M", where)
    out, rot_a, note = {}, np.eye(3), f"IMU frame i = {_CAL_FRAME}"
    if "accelerometer" in r.sensors:
        low, rot_a = lower_rotation(r.sensors["accelerometer"].M, f"{where}: accelerometer.M")
        out["accelerometers"] = {"M": low}
        note = (f"IMU frame i = {_CAL_FRAME} turned by R (x along the accelerometer's x axis, Kalibr's lower "
                f"triangular M): v_i = R v_cal, R = {_flat(rot_a)}")
    if "gyroscope" in r.sensors:
        g = r.sensors["gyroscope"]
        low, rot = lower_rotation(g.M @ rot_a.T, f"{where}: gyroscope.M")
        kga = np.zeros((3, 3)) if g.g_sensitivity is None else g.g_sensitivity @ rot_a.T @ rot.T
        out["gyroscopes"] = {"M": low, "A": kga, "C_gyro_i": rot}
        if g.g_sensitivity is None:
            note += "; gyroscopes.A (g-sensitivity) not estimated: zero"
    return out, note


def _kalibr(results: list[tuple[Result, str]], rostopic: str, inflate: float, rate_hz: float | None,
            part: Part | None, floor_tau: float | None) -> Exported:
    allan: list[tuple[AllanJob, str]] = []
    intrinsics: tuple[Result, str] | None = None
    for r, where in results:
        if isinstance(r, AllanJob):
            allan.append((r, where))
        elif isinstance(r, (AlignmentResult, CalibrationSet)):
            if intrinsics is not None:
                raise InputError(f"a second alignment or calibration (the first: {intrinsics[1]}); give one", where)
            intrinsics = (r, where)
        else:
            raise _refuse(r, "kalibr", where)
    first = results[0][1]
    sensors, frame = ({}, "IMU frame i = the sensor axes of the Allan records") if intrinsics is None else \
        _kalibr_intrinsics(*intrinsics)  # a matrix Kalibr cannot take is named first
    if not allan and part is None:
        raise InputError(f"holds an {results[0][0].FORMAT} result, which has no noise figures: Kalibr's imu.yaml needs "
                         "gyroscope_noise_density, gyroscope_random_walk, accelerometer_noise_density and "
                         "accelerometer_random_walk; give the allan result of each sensor together with it", first)
    consumer = CONSUMERS["kalibr"]
    figs = gather(allan, part, floor_tau)
    got, _ = select(consumer, figs, first)
    f, how = consumer_rate(consumer, figs, rate_hz, first)
    if f is None:
        raise InputError("Kalibr's update_rate is the IMU's rate and no Allan record gives it; give it "
                         "({rate_hz})", first)
    items = entries(consumer, got, inflate, f)
    scalars: list[tuple[str, str | float, str]] = [("rostopic", rostopic, ""), ("update_rate", f, f"Hz, {how}")]
    scalars += [(e.key.name, e.value, f"{e.key.unit}; {e.statement}") for e in items]
    srcs = ", ".join(figs.sources + (() if intrinsics is None else (Path(intrinsics[1]).name,)))
    header = header_lines(consumer, srcs, inflate, f, how)
    header[0] += " (ImuParameters keys; nest it under imu0: for an IMU chain)"
    if sensors:
        header += ["convention: modelling, Kalibr's direction (scale-misalignment model): a_meas = M_accel a_i + b_a, "
                   "w_meas = M_gyro C_gyro_i w_i + A_gyro C_gyro_i a_i + b_g; M lower triangular = imu-align's M "
                   "(raw = M true + bias) split as M = L C; imu-align's A = M^-1 (correcting) is not written; biases "
                   "are estimated by Kalibr, not written", f"frame: {frame}",
                   "intrinsics for reference and comparison only: Kalibr does not read accelerometers/gyroscopes "
                   "from its input imu.yaml (its calibration starts from M = I, C = I, A = 0); it uses the noise keys"]
    else:
        header.append(f"convention: noise only (no intrinsics); frame: {frame}")
    return Exported(kalibr_yaml("\n".join(header), scalars, sensors), noise_summary(items, f, inflate, []))


# ---------------------------------------------------------------- dispatch

def export(results: list[tuple[Result, str]], to: str, name: str | None = None, rostopic: str = "/imu0",
           inflate: float = 1.0, rate_hz: float | None = None, part: Part | None = None,
           floor_tau: float | None = None) -> Exported:
    """The export ``to`` of the results (each with its file name, for messages and the file's statement).

    Parameters
    ----------
    results : list of (Result, str)
        One result for ``c``, ``csv`` and ``imucal``; for ``kalibr`` at most one Allan result per sensor and one
        alignment or calibration; for the other noise consumers (:data:`NOISE`) at most one Allan result per sensor.
    to : {"kalibr", "openvins", "vins", "px4", "ardupilot", "c", "csv", "imucal"}
    name : str, optional
        C identifier prefix of a header's arrays (default ``IMU_ALIGN``, ``IMU_CAL``, ``IMU_MAG``).
    rostopic : str
        Kalibr's and OpenVINS's ``rostopic``.
    inflate : float
        Noise consumers: every noise value multiplied by it, >= 1 (1: as measured).
    rate_hz : float, optional
        Noise consumers: the rate of the conversion: the IMU's (Kalibr, OpenVINS, VINS-Fusion; default the Allan
        record's) or the filter's prediction rate (PX4, ArduPilot; default their documented one).
    part : Part, optional
        A datasheet giving the gyroscope's figures (noise consumers).
    floor_tau : float, optional
        s: the averaging time of the datasheet's Allan floor, bounding ``K`` from ``B``.

    Returns
    -------
    Exported
        The file's text, and the lines the terminal shows (noise consumers: each key, value and conversion).

    Raises
    ------
    InputError
        A result that has no such export (naming its file and the results that have), several results where
        one is taken, a matrix Kalibr cannot take (``det <= 0``, counts), a value a C float cannot hold, an ``A``
        that is not ``M^-1``, a noise term neither identified nor bounded, a noise consumer's figures missing.
    """
    if to not in EXPORTS:
        raise InputError(f"unknown export '{literal(to)}'; choose {', '.join(EXPORTS)}", "{to}")
    if to == "kalibr":
        return _kalibr(results, rostopic, inflate, rate_hz, part, floor_tau)
    if to in NOISE:
        allan: list[tuple[AllanJob, str]] = []
        for r, where in results:
            if not isinstance(r, AllanJob):
                raise InputError(f"holds an {r.FORMAT} result, which has no noise figures: {_SHORT[to]} come from "
                                 "allan results (one per sensor); give those", where)
            allan.append((r, where))
        return noise_export(gather(allan, part, floor_tau), to, results[0][1], rostopic, inflate, rate_hz)
    if len(results) != 1:
        raise InputError(f"a {_SHORT[to]} comes from one result, not {len(results)}; give one (several only with "
                         "{to=kalibr})", results[-1][1])
    r, where = results[0]
    if r.FORMAT not in EXPORTS[to]:
        raise _refuse(r, to, where)
    if to == "c":
        if isinstance(r, AlignmentResult):  # the very header 'matrix' writes
            c_values(r.A, to_unit(r.bias, r.units), where)
            return Exported(r.as_c_header(f"imu-align alignment {_source(r, where)}", name or "IMU_ALIGN"))
        if isinstance(r, CalibrationSet):
            return Exported(_calibration_header(r, name or "IMU_CAL", where))
        assert isinstance(r, MagCalibration), r.FORMAT  # EXPORTS["c"]
        return Exported(_mag_header(r, name or "IMU_MAG", where))
    if to == "csv":
        return Exported(_allan_csv(r, where) if isinstance(r, AllanJob) else _matrix_csv(r, where))
    assert isinstance(r, CalibrationSet), r.FORMAT  # EXPORTS["imucal"]
    missing = [s for s in ("accelerometer", "gyroscope") if s not in r.sensors]
    if missing:
        raise InputError(f"imucal's format needs an accelerometer and a gyroscope; this calibration has no "
                         f"{' or '.join(missing)}", where)
    _physical(r, "imucal's K R", where)
    for s, c in r.sensors.items():
        _inverse(c.M, f"{where}: {s}.M")  # imucal's K R = M: a singular M has no R
    return Exported(json.dumps(r.as_imucal(), indent=2) + "\n")


def export_text(results: list[tuple[Result, str]], to: str, name: str | None = None, rostopic: str = "/imu0",
                **noise) -> str:
    """The text of :func:`export` (the noise consumers' options as keywords: ``inflate``, ``rate_hz``, ``part``,
    ``floor_tau``)."""
    return export(results, to, name, rostopic, **noise).text
