"""The ``calibrate positions`` job: gyro and accelerometer from indexed static positions on a table pointed north,
with Earth rate (seed 000's six-, twelve- and twenty-four-position methods; :mod:`align.calibration.multiposition`).

The positions file (TOML)::

    latitude = "45 deg"        # or the option; give it once
    gravity = "9.8062 m/s^2"   # optional, default 9.80665 m/s^2
    scheme = "twelve"          # a standard scheme's positions in its order (six, twelve, twenty-four) ...
    [[position]]               # ... or one table per position, in the order recorded:
    name = "z up"
    up = "+z"                  # the sensor axis pointing up (or a vector [x, y, z])
    north = "+y"               # the sensor axis pointing north; or roll, pitch, yaw ("10 deg"; numbers are
                               # degrees): the sensor frame's attitude to north-east-down, Z-Y-X order
    start = 0                  # samples (end exclusive), for every position or for none (then detected)
    end = 6000

Public names
------------
PositionsOptions, PositionsInputs, PositionsResult, POSITIONS, calibrate_positions, readings, rehearsal, FORMAT
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from align.calibration.jobs.common import accel_source, log_source, read_sensor, same_file, static_detector
from align.calibration.multiposition import AXES, AxisFit, Reading, SensorFit, parse_positions_file
from align.errors import InputError, TestError
from align.io.logs import SensorLog
from align.io.source import LogSource
from align.job import Job, Progress, fields_signature, quantity
from align.merit import Figure
from align.results import Result
from align.units import STANDARD_GRAVITY
from align.vocab import Sensor

__all__ = ["PositionsOptions", "PositionsInputs", "PositionsResult", "POSITIONS", "calibrate_positions", "readings",
           "rehearsal", "FORMAT"]

FORMAT = "imu-align.positions"
CONVENTION = ("gyro = M_g w + K_ga f + b_g, accel = M_a f + b_a; rows of M are sensor axes; w, f in the sensor frame "
              "from each position's orientation in east-north-up; SI")
NOT_OBSERVABLE = "not observable from these positions"
TEST = "calibrate positions"
SENSORS = ("gyroscope", "accelerometer")


@dataclass(frozen=True, kw_only=True)
class PositionsOptions:
    """Options of ``calibrate positions``.

    Attributes
    ----------
    log : LogSource
        The gyro's log (default columns ``gyro_x, gyro_y, gyro_z``; unit: the file's, else deg/s).
    accel : LogSource or None
        The accelerometer (None: ``acc_x, acc_y, acc_z`` in ``log``, m/s^2 unless the file states a unit).
    positions : Path
        The positions file (module docstring).
    latitude : float or None
        Geodetic latitude, rad (None: the positions file's).
    gravity : float or None
        Local gravity, m/s^2 (None: the file's, else 9.80665).
    g_sensitivity : bool
        Model the gyro's g-sensitivity ``K_ga`` (False: assumed zero).
    gyro_scale : bool
        Estimate the gyro's ``M`` from Earth rate where the positions make it observable (True); False takes it
        as the identity (nominal), so that only the bias and ``K_ga`` are estimated (ignored with ``frame``).
    window_s, factor, init_static_s, min_static_s : float
        The static detector (as ``calibrate accel``), used when the positions give no start/end.
    max_rate : float
        Largest mean gyro rate (rad/s, after the session's median) of a static sample: a table turning about
        the vertical at constant rate does not change the accelerometer's variance.
    frame : Path or None
        A rate-table result of the same gyro (alignment or calibration JSON): its ``M`` is taken as known, Earth
        rate removed through it, and only the gyro's bias and ``K_ga`` estimated; None: ``M`` estimated where
        the positions make it observable.
    limits : Path or None
        A limits file (:mod:`align.limits`) the figures of merit are judged against, beside the default limits.
    """

    log: LogSource
    accel: LogSource | None = None
    positions: Path
    latitude: float | None = quantity(None, "angle", ge=-math.pi / 2, le=math.pi / 2)
    gravity: float | None = quantity(None, "acceleration", gt=0)
    g_sensitivity: bool = True
    gyro_scale: bool = True
    window_s: float = quantity(1.0, "time", gt=0)
    factor: float = quantity(6.0, "dimensionless", gt=0)
    init_static_s: float | None = quantity(None, "time", gt=0)
    min_static_s: float = quantity(1.0, "time", gt=0)
    max_rate: float = quantity(math.radians(0.5), "angular_rate", gt=0)
    frame: Path | None = None
    limits: Path | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "positions", Path(self.positions))
        if self.frame is not None:
            object.__setattr__(self, "frame", Path(self.frame))


@dataclass(frozen=True)
class PositionsInputs:
    """The checked inputs: the gyro's and the accelerometer's readings (SI, sampled together), the
    positions file as read, and the rate-table ``M`` of the gyro (``frame``) or None."""

    gyr: SensorLog
    acc: SensorLog
    spec: dict
    gyro_M: np.ndarray | None = None


def _read(o: PositionsOptions) -> PositionsInputs:
    import align.io as fileio

    gyr = read_sensor(o.log, Sensor.GYROSCOPE, field="gyro_units", columns_field="gyro_columns", counts=False,
                      expect=Sensor.GYROSCOPE.dimension)
    src = accel_source(o.log, o.accel)
    if same_file(o.log, src) and src.time_column is None and src.rate_hz is None:
        gtime, _ = o.log.names(Sensor.GYROSCOPE, field="gyro_columns")
        src = replace(src, time_column=gtime, rate_hz=o.log.rate_hz if gtime is None else None)
    acc = read_sensor(src, Sensor.ACCELEROMETER, field="accel_units", columns_field="accel_columns", counts=False)
    if len(acc.t) != len(gyr.t) or np.abs(acc.t - gyr.t).max() > 0.5 * float(np.median(np.diff(gyr.t))):
        raise InputError(f"the accelerometer's {len(acc.t)} time stamps are not the gyro's {len(gyr.t)}: both "
                         "sensors must be sampled together", str(src.path))
    table = None
    if o.frame is not None:
        from align.alignment.result import AlignmentResult
        from align.calibration.results import CalibrationSet
        from align.results import load_result

        got: Any = load_result(o.frame, (AlignmentResult, CalibrationSet)).correction("gyroscope", str(o.frame))
        table = np.asarray(got.M, float)
    return PositionsInputs(gyr, acc, fileio.read_toml(o.positions), table)


def _sigma(x: np.ndarray) -> np.ndarray:
    """1-sigma of the mean of ``x`` (n, 3), white noise; a reading that never changes gets its quantisation."""
    s = np.std(x, axis=0, ddof=1)
    for i in np.flatnonzero(s == 0):
        steps = np.diff(np.unique(x[:, i]))
        s[i] = (steps.min() if steps.size else max(abs(float(x[0, i])), 1e-12) * 1e-7) / math.sqrt(12)
    return s / math.sqrt(len(x))


def _ranges(i: PositionsInputs, o: PositionsOptions, n: int, where: str) -> list[tuple[int, int]]:
    from align.alignment.segment import true_runs
    from align.calibration.statics import common_intervals, static_intervals

    t, g, a = i.gyr.t, i.gyr.data, i.acc.data
    fs = 1.0 / float(np.median(np.diff(t)))
    d = static_detector(o)
    quiet_a = static_intervals(a, fs, d.window_s, d.factor, d.init_static_s, d.min_static_s)
    w = max(3, int(round(d.window_s * fs)))
    kernel = np.ones(w) / w
    rate = np.column_stack([np.convolve(g[:, k] - np.median(g[:, k]), kernel, "same") for k in range(3)])
    quiet_g = true_runs(np.linalg.norm(rate, axis=1) < o.max_rate)
    found = [(s + w // 2, e - w // 2) for s, e in common_intervals(quiet_a, quiet_g, int(d.min_static_s * fs) + w)]
    if len(found) != n:
        shown = "; ".join(f"t={t[s]:.1f}-{t[e - 1]:.1f} s" for s, e in found[:30])
        raise TestError(f"{len(found)} static intervals detected but {n} positions listed ({shown}); adjust the static "
                        "detector ({factor}, {window_s}, {max_rate}) or give start/end per position", where)
    return found


def readings(i: PositionsInputs, o: PositionsOptions) -> tuple[list[Reading], float, float, list[tuple[int, int]]]:
    """The positions' readings (means and their 1-sigma), latitude (rad), gravity (m/s^2) and sample ranges."""
    from align.plausible import check_at_rest, check_gravity

    where = str(o.positions)
    listed, lat, grav = parse_positions_file(i.spec, where)
    if o.latitude is not None and lat is not None and abs(o.latitude - lat) > 1e-9:
        raise InputError(f"the latitude is given twice ({math.degrees(o.latitude):.6g} and {math.degrees(lat):.6g} "
                         "deg): give it once", "{latitude}")
    lat = o.latitude if o.latitude is not None else lat
    if lat is None:
        raise InputError("no latitude: give it (e.g. '45 deg') or write latitude in the positions file", "{latitude}")
    gravity = check_gravity(o.gravity if o.gravity is not None else grav if grav is not None else STANDARD_GRAVITY)
    given = [s for _, _, s in listed if s is not None]
    ranges = given if given else _ranges(i, o, len(listed), str(o.log.path))
    out = []
    for (name, R, _), (s, e) in zip(listed, ranges, strict=True):
        if not 0 <= s < e <= len(i.gyr.t) or e - s < 10:
            raise InputError(f"samples {s}..{e} are not 10 or more of the log's {len(i.gyr.t)}", f"{where}: {name}")
        g, a = i.gyr.data[s:e], i.acc.data[s:e]
        out.append(Reading(name, R, g.mean(axis=0), _sigma(g), a.mean(axis=0), _sigma(a)))
    check_at_rest(np.array([np.linalg.norm(r.accel) for r in out]), gravity, i.acc.shown, "accel_units",
                  str(o.log.path))
    return out, lat, gravity, list(ranges)


def _axis_dict(ax: AxisFit) -> dict[str, Any]:
    return {"names": list(ax.names), "value": [None if not math.isfinite(v) else v for v in ax.value],
            "covariance": [[None if not math.isfinite(v) else v for v in row] for row in ax.cov],
            "status": list(ax.status), "rank": ax.rank, "condition": ax.condition}


def _axis_from(d: dict) -> AxisFit:
    nan = lambda v: math.nan if v is None else float(v)  # noqa: E731
    return AxisFit(tuple(d["names"]), np.array([nan(v) for v in d["value"]]),
                   np.array([[nan(v) for v in row] for row in d["covariance"]]), tuple(d["status"]), int(d["rank"]),
                   float(d["condition"]))


def _sensor_dict(s: SensorFit) -> dict[str, Any]:
    return {"axes": [_axis_dict(a) for a in s.axes], "residuals": {k: list(map(float, v)) for k, v in s.residuals.items()},
            "chi2": list(s.chi2), "dof": list(s.dof), "notes": list(s.notes)}


def _sensor_from(key: str, d: dict) -> SensorFit:
    return SensorFit(key, tuple(_axis_from(a) for a in d["axes"]), {k: np.array(v, float) for k, v in
                                                                   d["residuals"].items()},
                     tuple(float(c) for c in d["chi2"]), tuple(int(v) for v in d["dof"]), tuple(d["notes"]))


def _row_figures(s: SensorFit, unit: str, method: str) -> list[Figure]:
    """bias, scale and cross-axis angles of one sensor (``scale_i = |M_i|``, ``phi_ij = asin(M_ij / |M_i|)``)."""
    out = []
    for i, a in enumerate(AXES):
        v, sg, st = s.param("b", i)
        out.append(_figure(f"bias_{a}", s.sensor, v, sg, unit, method, st))
    for i, a in enumerate(AXES):
        if f"M_{a}x" not in s.axes[i].names:  # M given (a rate-table result), not measured here
            continue
        got = [s.param("M", i, j) for j in range(3)]
        m = np.array([g[0] for g in got])
        k = [s.axes[i].names.index(f"M_{a}{b}") for b in AXES]
        cov = s.axes[i].cov[np.ix_(k, k)]
        worst = max((g[2] for g in got), key=("observable", "weakly observable", "not observable").index)
        norm = float(np.linalg.norm(m)) if np.all(np.isfinite(m)) else math.nan
        jac = m / norm
        out.append(_figure(f"scale_{a}", s.sensor, norm, float(np.sqrt(jac @ cov @ jac)), "1", method, worst))
        for j, b in enumerate(AXES):
            if j != i:
                u = m[j] / norm
                jac = (np.eye(3)[j] / norm - m[j] * m / norm**3) / math.sqrt(max(1 - u * u, 1e-12))
                out.append(_figure(f"phi_{a}{b}", s.sensor, math.asin(u) if math.isfinite(u) else math.nan,
                                   float(np.sqrt(jac @ cov @ jac)), "rad", method, worst))
    return out


def _figure(name: str, sensor: str, value: float, sigma: float, unit: str, method: str, status: str) -> Figure:
    """One figure; a parameter the positions do not determine gets no value, and says so."""
    from align.keyfigures import title

    if status == "not observable" or not math.isfinite(value):
        return Figure(name, sensor, math.nan, math.nan, unit, title(name), method, TEST, detail=NOT_OBSERVABLE)
    detail = "weakly observable: the positions determine it only to the stated sigma" if status != "observable" else ""
    return Figure(name, sensor, value, sigma, unit, title(name), method, TEST, detail=detail)


class PositionsResult(Result, format=FORMAT, convention=CONVENTION):
    """A multi-position session's gyro and accelerometer parameters with their observability.

    Attributes
    ----------
    gyroscope, accelerometer : SensorFit
        Per axis the parameters ``b``, ``M`` (and the gyro's ``K``), 1-sigma, observability, rank, condition.
    latitude : float
        rad.
    gravity : float
        m/s^2.
    positions : tuple of dict
        ``name``, ``R`` (ENU -> sensor, 3 x 3 rows) and ``samples`` ([start, end] or None) per position.
    inputs : dict
    """

    gyroscope: SensorFit
    accelerometer: SensorFit
    latitude: float
    gravity: float
    positions: tuple = ()
    inputs: dict = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """The versioned JSON form (SI: rad, rad/s, m/s^2, rad/s per m/s^2)."""
        units = {"gyroscope": "rad/s", "accelerometer": "m/s^2", "M": "1", "K": "rad/s/(m/s^2)", "latitude": "rad"}
        return {**self.envelope(units), "inputs": dict(self.inputs), "latitude": self.latitude, "gravity": self.gravity,
                "positions": [dict(p) for p in self.positions],
                **{k: _sensor_dict(getattr(self, k)) for k in SENSORS}}

    @classmethod
    def from_dict(cls, d: dict, where: str = "positions result") -> PositionsResult:
        """Read the form written by :meth:`to_dict`."""
        cls.check_envelope(d, where, keys=["inputs", "latitude", "gravity", "positions", *SENSORS])
        try:
            return cls(_sensor_from("gyroscope", d["gyroscope"]), _sensor_from("accelerometer", d["accelerometer"]),
                       float(d["latitude"]), float(d["gravity"]), tuple(dict(p) for p in d["positions"]),
                       dict(d.get("inputs") or {}))
        except (KeyError, TypeError, ValueError, IndexError) as exc:
            raise InputError(f"malformed positions result ({exc}); regenerate it", where) from None

    def figures_of_merit(self) -> tuple[Figure, ...]:
        """bias, scale and cross-axis angles per sensor, and the gyro's g-sensitivity ``gsens_ij`` (rad/s per
        m/s^2); a parameter the positions do not determine has value NaN and says so."""
        n = len(self.positions)
        how = f"weighted least squares over {n} static positions"
        out = _row_figures(self.gyroscope, "rad/s", f"{how} with Earth rate at {math.degrees(self.latitude):.4g} deg "
                                                   "latitude (seed 000)")
        out += _row_figures(self.accelerometer, "m/s^2", f"{how} in gravity (IEEE Std 836, seed 000)")
        g = self.gyroscope
        for i, a in enumerate(AXES):
            for j, b in enumerate(AXES):
                if f"K_{a}{b}" in g.axes[i].names:
                    v, s, st = g.param("K", i, j)
                else:
                    v, s, st = math.nan, math.nan, "not observable"
                out.append(_figure(f"gsens_{a}{b}", "gyroscope", v, s, "rad/s/(m/s^2)",
                                   f"{how} (gyro {a} per specific force along {b})", st))
        return tuple(out)


def _compute(i: PositionsInputs, o: PositionsOptions, progress: Progress | None) -> PositionsResult:
    from align.calibration.multiposition import fit_positions

    reads, lat, gravity, ranges = readings(i, o)
    nominal = None if o.gyro_scale else np.eye(3)
    fit = fit_positions(reads, lat, gravity, o.g_sensitivity, i.gyro_M if i.gyro_M is not None else nominal)
    if progress is not None:
        progress(len(i.gyr.t))
    rows = tuple({"name": r.name, "R": np.asarray(r.R).tolist(), "samples": list(s)} for r, s in zip(reads, ranges))
    inputs = {"log": str(o.log.path), "positions": str(o.positions), "gyro_units": i.gyr.units,
              "accel_units": i.acc.units, "g_sensitivity": o.g_sensitivity, "gyro_scale": o.gyro_scale,
              "frame": None if o.frame is None else str(o.frame)}
    return PositionsResult(fit.gyroscope, fit.accelerometer, lat, gravity, rows, inputs)


def _files(o: PositionsOptions) -> dict[str, Path | None]:
    acc = accel_source(o.log, o.accel)
    return {"log": o.log.path, "accel_log": None if same_file(o.log, acc) else acc.path, "positions": o.positions,
            "frame": o.frame}


POSITIONS: Job[PositionsOptions, PositionsInputs, PositionsResult] = Job(
    TEST, PositionsOptions, _read, _compute, _files,
    "gyro bias (and where observable scale and g-sensitivity) with Earth rate, accelerometer from gravity, over "
    "indexed static positions on a table pointed north")


def rehearsal(scheme_name: str, latitude: float, seed: int, rate_hz: float = 100.0, dwell_s: float = 60.0,
              move_s: float = 10.0, gyro_noise: float = 1.5e-5, accel_noise: float = 1e-3,
              gyro_units: str = "deg/s") -> tuple[list[str], np.ndarray, str, dict[str, Any]]:
    """A rehearsal of the test for ``imu-align simulate positions``: a session of a standard scheme's positions on a
    table at ``latitude`` (rad), a random truth (gyro ``M`` about 1e-3, bias about 0.05 deg/s, ``K_ga`` about
    0.01 deg/s per g; accelerometer ``M`` about 1e-3, bias about 0.03 m/s^2) drawn from ``seed``, white noise
    ``gyro_noise`` (rad/sqrt(s)) and ``accel_noise`` (m/s^2/sqrt(Hz)).

    Returns
    -------
    columns, table (n, 7) (time s, gyro in ``gyro_units``, accelerometer m/s^2), the positions file's text (the
    scheme and latitude; the positions detected), and the truth (SI, JSON values).
    """
    from align.calibration.multiposition import SCHEMES, scheme, simulate_session
    from align.units import to_unit

    positions = scheme(scheme_name)
    rng = np.random.default_rng(seed)
    truth = {"M_g": np.eye(3) + rng.normal(0, 1e-3, (3, 3)), "b_g": rng.normal(0, 1e-3, 3),
             "K_ga": rng.normal(0, 1.8e-5, (3, 3)), "M_a": np.eye(3) + rng.normal(0, 1e-3, (3, 3)),
             "b_a": rng.normal(0, 0.03, 3)}
    t, g, a, ranges = simulate_session(positions, latitude, truth, rate_hz, dwell_s, move_s, gyro_noise, accel_noise,
                                       rng)
    name = next(k for k in SCHEMES if len(SCHEMES[k]) == len(positions))
    text = f'# {len(positions)}-position rehearsal, seed {seed}\nlatitude = "{math.degrees(latitude):.10g} deg"\n' \
           f'scheme = "{name}"\n'
    said = {"seed": seed, "scheme": name, "latitude_deg": math.degrees(latitude), "rate_hz": rate_hz,
            "convention": CONVENTION, "units": {"gyroscope": "rad/s", "accelerometer": "m/s^2", "K": "rad/s/(m/s^2)"},
            "gyroscope": {"M": truth["M_g"].tolist(), "bias": truth["b_g"].tolist(), "K_ga": truth["K_ga"].tolist()},
            "accelerometer": {"M": truth["M_a"].tolist(), "bias": truth["b_a"].tolist()},
            "positions": [{"name": n, "samples": list(r)} for (n, _), r in zip(positions, ranges)]}
    columns = ["time", "gyro_x", "gyro_y", "gyro_z", "acc_x", "acc_y", "acc_z"]
    return columns, np.column_stack([t, to_unit(g, gyro_units), a]), text, said


@fields_signature(PositionsOptions)
def calibrate_positions(*, log: LogSource | str | Path, progress: Progress | None = None,
                        **fields: Any) -> PositionsResult:
    """Calibrate from indexed static positions with Earth rate (``imu-align calibrate positions``).

    Parameters
    ----------
    log : LogSource or str or Path
        The session log; a path takes ``columns`` (the gyro's), ``time_column``, ``rate_hz``, ``units`` and
        ``format`` beside it.
    progress : callable, optional
    **fields
        The other fields of :class:`PositionsOptions` (``positions``, ``latitude`` rad or ``"45 deg"``, ...).

    Returns
    -------
    PositionsResult

    Examples
    --------
    >>> import tempfile
    >>> cols, table, text, truth = rehearsal("six", math.radians(45), seed=1, dwell_s=20.0, move_s=5.0)
    >>> d = Path(tempfile.mkdtemp())
    >>> np.savetxt(d / "s.csv", table, delimiter=",", header=",".join(cols), comments="")
    >>> _ = (d / "positions.toml").write_text(text)
    >>> r = calibrate_positions(log=d / "s.csv", positions=d / "positions.toml")
    >>> bool(abs(r.gyroscope.bias()[0] - truth["gyroscope"]["bias"][0]) < 3 * r.gyroscope.param("b", 0)[1])
    True
    >>> r.gyroscope.param("K", 0, 0)[2]                  # six positions cannot tell K_ga from M
    'not observable'
    """
    src = log_source(log, fields)
    return POSITIONS.run(PositionsOptions(log=src, **fields), progress=progress)
