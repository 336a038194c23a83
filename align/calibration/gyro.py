"""Gyro calibration without a rate table: rotations between static poses (imu_tk; Tedaldi, Pretto, Menegatti 2014).

A session: an initial static period, then 12 or more static poses (several seconds each) reached by
free rotations about varied axes (by hand or on a simple fixture). The steps:

1. Static poses: the moving-variance detector (:func:`align.calibration.statics.static_intervals`)
   with its threshold ``factor`` times the variance of the initial static period (imu_tk's
   ``T_init``; when not given, the shorter of the accelerometer's and the gyro's rest at the start;
   pose 1 ends with it), or poses given as sample ranges.
2. Accelerometer ``[M | b]`` from ``|a| = g`` over the poses' means
   (:func:`align.calibration.accel.calibrate_accel_free`): ``M_a`` upper triangular, which fixes the
   accelerometer frame ``c`` (z along the accelerometer's z axis, y in its y-z plane: row 3 of ``M_a`` is
   ``(0, 0, u33)``, row 2 ``(0, u22, u23)``).
3. Gyro bias: the mean over the initial static period (pose 1), Earth's rate ignored.
4. Gyro ``M`` (``g = M w + b``, 9 parameters) by least squares on the gravity directions after
   integrating each rotation (:mod:`align.calibration.gyrofit`, equation G1), with 1-sigma,
   residual per rotation (the table :attr:`Calibration.rotations`) and observability; a gyro
   mirrored relative to the accelerometer (``det M < 0``) is refused, a turned one noted.

The gyro's ``M`` is relative to frame ``c``: gravity gives no reference about the vertical, so the
case or system axes are not observed (:mod:`align.calibration.gyroframe` turns both sensors into
the system frame given a rate-table result or a mounting). Poses are numbered from 1 (the initial
period); rotation ``k`` goes from pose ``k`` to pose ``k + 1``.

Public names
------------
RotationReport, GyroSession, calibrate_gyro_session, detect_poses, SINGULAR_CONDITION, METHOD
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.calibration.accel import StaticDetector, calibrate_accel_free
from align.calibration.accelfree import widened_level
from align.calibration.gsens import EARTH_NOTE, g_sensitivity_sigma
from align.calibration.gyrochecks import (
    MIN_POSES,
    RECOMMENDED_POSES,
    check_poses,
    check_saturation,
    check_static,
    parse_intervals,
    rotation_spans,
    saturated_samples,
)
from align.calibration.gyrofit import WEAK_CONDITION, GyroFit, direction_covariance, fit_gyro_matrix
from align.calibration.results import Calibration
from align.calibration.statics import common_intervals, initial_static_period, static_intervals
from align.errors import InputError, TestError
from align.io import check_log
from align.io.consumers import matrix_unit
from align.plausible import check_at_rest, check_gravity, check_usable_model, scale_outside
from align.units import DEG, STANDARD_GRAVITY
from align.values import Value

#: a condition number above this: the rotations do not span 3-D (refused)
SINGULAR_CONDITION = 1000.0
METHOD = "rotations between static poses (imu_tk: gravity directions after integration)"
FRAME_NOTE = ("relative to the accelerometer frame (z along the accelerometer's z axis, y in its y-z plane): gravity "
              "gives no reference about the vertical, so the rotation to the case or system is not observed; combine "
              "with a rate-table result or a mounting to express it in the system frame")


@dataclass(frozen=True, eq=False)
class RotationReport(Value):
    """One rotation between consecutive poses.

    Attributes
    ----------
    number : int
        ``k``: from pose ``k`` to pose ``k + 1``.
    start, end : int
        Integrated samples (the last of pose ``k``, the first of pose ``k + 1``), both included.
    t_start, t_end : float
        Their times, s.
    turn : float
        Angle of the integrated rotation, rad.
    axis : ndarray, shape (3,)
        Its unit axis, accelerometer frame at the start.
    residual : float
        Angle between the predicted and the measured gravity direction at the end, rad.
    used : bool
        False when left out of the fit (then a held-out check).
    """

    number: int
    start: int
    end: int
    t_start: float
    t_end: float
    turn: float
    axis: np.ndarray
    residual: float
    used: bool


@dataclass(frozen=True, eq=False)
class GyroSession(Value):
    """A calibrated session: both sensors, the poses and rotations it used, and what it could observe.

    Attributes
    ----------
    accelerometer, gyroscope : Calibration
    poses : tuple of (int, int)
        Sample ranges (end exclusive); pose 1 is the initial static period.
    rotations : tuple of RotationReport
    condition_number : float
        Of the Jacobian of the gyro fit with respect to ``M``.
    weak_column : int or None
        The column of ``M`` (0, 1, 2) flagged as weakly determined (None when the condition number is below
        :data:`~align.calibration.gyrofit.WEAK_CONDITION`).
    column_turn : ndarray, shape (3,)
        Angle turned about the accelerometer frame's x, y, z over the rotations used, rad.
    init_s : float
        Length of the initial static period behind the detector's threshold, s (NaN with given poses).
    """

    accelerometer: Calibration
    gyroscope: Calibration
    poses: tuple
    rotations: tuple
    condition_number: float
    weak_column: int | None
    column_turn: np.ndarray
    init_s: float

    def sensors(self) -> dict:
        """``{"accelerometer": ..., "gyroscope": ...}`` for a :class:`~align.calibration.results.CalibrationSet`."""
        return {"accelerometer": self.accelerometer, "gyroscope": self.gyroscope}


def detect_poses(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, fs: float, detector: StaticDetector, intervals,
                 where: tuple[str, str] = ("log", "log")) -> tuple[list, float, str]:
    """The poses (sample ranges, end exclusive), the initial static period (s) and how they were found: given
    (``intervals``), or where the accelerometer's moving variance stays below ``factor`` times its variance
    over the initial static period (imu_tk) and the gyro's below ``gyro_factor`` times its own (the gyro sees the
    slow start or end of a turn about a nearly vertical axis, which leaves the accelerometer almost unchanged).

    The initial static period (``T_init``), when not given, is the shorter of the two sensors' (a first turn
    about the vertical leaves the accelerometer still: its ``T_init`` alone runs into the turn); pose 1 ends
    with it, so the gyro bias is its mean over rest only. ``where``: the gyro's and the accelerometer's logs."""
    if intervals is not None:
        return parse_intervals(intervals, len(t)), float("nan"), "given"
    d = detector
    init = d.init_static_s or min(initial_static_period(acc, fs, d.window_s, d.factor, d.min_static_s, where[1]),
                                  initial_static_period(gyr, fs, d.window_s, d.factor, d.min_static_s, where[0]))
    poses = common_intervals(static_intervals(acc, fs, d.window_s, d.factor, init, d.min_static_s),
                             static_intervals(gyr, fs, d.window_s, d.gyro_factor, init, d.min_static_s),
                             int(np.ceil(d.min_static_s * fs)))
    w = max(3, int(round(d.window_s * fs)))
    if not poses or poses[0][0] > w:
        raise TestError(f"the initial static period ({init:g} s) is not at rest: the detector finds motion in its first "
                        "window; record it at rest, or shorten {init_static_s}", where[0])
    poses[0] = (poses[0][0], min(poses[0][1], max(poses[0][0] + 1, int(round(init * fs)))))
    source = "given" if d.init_static_s else "the shorter of the two sensors' rests at the start"
    how = (f"detected automatically (moving variance over {d.window_s:g} s below {d.factor:g} x the accelerometer's "
           f"and {d.gyro_factor:g} x the gyro's variance over the initial {init:.1f} s, {source}; pose 1 ends with it)")
    return poses, float(init), how


def _observability(fit: GyroFit, where: str) -> tuple[int | None, str]:
    turned = "/".join(f"{v / DEG:.0f}" for v in fit.column_turn)
    axis = "xyz"[fit.weak_column]
    if fit.condition_number > SINGULAR_CONDITION:
        raise TestError(f"the rotations do not span 3-D: column {fit.weak_column + 1} ({axis}) of M is not determined "
                        f"(condition number {fit.condition_number:.3g}; turned {turned} deg in total about x/y/z); turn "
                        f"about {axis} too", where)
    if fit.condition_number > WEAK_CONDITION:
        return fit.weak_column, (f"observability: column {fit.weak_column + 1} ({axis}) of M is weakly determined "
                                 f"(condition number {fit.condition_number:.3g}; turned {turned} deg in total about "
                                 f"x/y/z): turn more about {axis}")
    return None, f"observability: condition number {fit.condition_number:.3g}; turned {turned} deg in total about x/y/z"


def calibrate_gyro_session(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, acc_units: str, gyr_units: str,
                           gravity: float = STANDARD_GRAVITY, detector: StaticDetector = StaticDetector(),
                           intervals=None, gyro_range: float | None = None, drop: tuple = (),
                           g_sensitivity: bool = False, where: str = "log", accel_where: str | None = None) -> GyroSession:
    """Calibrate the accelerometer and the gyro of a multi-position session (steps 1-4 of the module).

    Parameters
    ----------
    t : ndarray, shape (n,)
        Time, s (its own steps are integrated over).
    acc, gyr : ndarray, shape (n, 3)
        Readings at the same times: SI (m/s^2, rad/s) or counts (``M`` is then in counts per SI unit).
    acc_units, gyr_units : str
        Their units, for the results and the plausibility checks.
    gravity : float
        Local gravity, m/s^2.
    detector : StaticDetector
        Window, threshold factor, initial static period (detected when None) and shortest pose.
    intervals : str or list of (int, int), optional
        The poses as sample ranges (end exclusive), the first the initial static period, instead of detection.
    gyro_range : float, optional
        The gyro's full scale in the readings' unit: samples at it are saturated (without it: flat tops).
    drop : tuple of int
        Rotations (numbers from 1) left out of the fit, e.g. saturated ones; reported as checks.
    g_sensitivity : bool
        Model the gyro's g-sensitivity ``K_ga`` (``raw = M w + K_ga f + b``): bias and ``K_ga`` from every
        pose's mean reading, ``K_ga f(t)`` removed before integrating. Off: imu_tk's bias from pose 1.
    where : str
        The log, for messages.
    accel_where : str, optional
        The accelerometer's log when it is another file (its problems name it); default ``where``.

    Returns
    -------
    GyroSession
        The ``accelerometer`` and ``gyroscope`` calibrations (``raw = M x + b``, reference section 5), in the
        accelerometer's frame: ``M`` (3, 3), ``bias`` (3,) in the readings' units; the poses, rotation reports
        (angles in rad) and the fit's condition number.

    Raises
    ------
    TestError
        Too few poses, a pose too short or not static, a rotation at the gyro's range, rotations that do
        not span 3-D, readings that are not gravity or rates in the units given, scale factors no
        accelerometer or gyro has, a gyro mirrored relative to the accelerometer (``det M < 0``).

    Examples
    --------
    A simulated noise-free session (:mod:`align.calibration.posesim`) of 10 poses at 25 Hz, with the
    poses given: the truth in the accelerometer's frame comes back.

    >>> import numpy as np
    >>> from align.calibration.posesim import PoseSessionSpec, accel_frame_truth, random_sensors, simulate_poses
    >>> rng = np.random.default_rng(0)
    >>> Ma, ba, Mg, bg = random_sensors(rng)
    >>> spec = PoseSessionSpec(fs=25.0, poses=10, init_s=5.0, gyro_noise=0.0, accel_noise=0.0)
    >>> s = simulate_poses(spec, Ma, ba, Mg, bg, rng)
    >>> r = calibrate_gyro_session(s.t, s.acc, s.gyr, "m/s^2", "rad/s", intervals=list(s.poses))
    >>> T, Mg_c, _ = accel_frame_truth(Ma, Mg)
    >>> bool(np.allclose(r.accelerometer.M, T, atol=1e-9)), bool(np.allclose(r.gyroscope.M, Mg_c, atol=1e-5))
    (True, True)
    >>> bool(np.allclose(r.gyroscope.bias, bg, atol=1e-9))
    True
    """
    t, acc, gyr = (np.asarray(x, float) for x in (t, acc, gyr))
    acc_where = where if accel_where is None else accel_where
    check_log(t, acc, acc_where)
    check_log(t, gyr, where)
    gravity = check_gravity(gravity)
    fs = 1.0 / float(np.median(np.diff(t)))
    poses, init_s, how = detect_poses(t, acc, gyr, fs, detector, intervals, (where, acc_where))
    check_poses(t, poses, detector.min_static_s, where)
    means = check_static(t, acc, poses, acc_where)
    check_at_rest(np.linalg.norm(means, axis=1), gravity, acc_units, "accel_units", acc_where)
    acc_cal = calibrate_accel_free(means, gravity, acc_units, where=acc_where, fields=("accel_units", "accel_columns"))
    var_means = np.array([acc[a:b].var(axis=0) / (b - a) for a, b in poses])
    dirs, dir_cov = direction_covariance(means, var_means, acc_cal.M, acc_cal.bias)
    a0, b0 = poses[0]
    noise = gyr[a0:b0].std(axis=0)
    force = np.linalg.solve(acc_cal.M, (acc - acc_cal.bias).T).T if g_sensitivity else None
    off = _offsets(gyr, poses, force, noise)
    bias = off.bias
    spans = rotation_spans(poses)
    bad = [k for k in drop if not 1 <= k <= len(spans)]
    if bad:
        raise InputError(f"no rotation {bad[0]}: the session has rotations 1 to {len(spans)}", "{drop_rotations}")
    at_range = saturated_samples(gyr, bias, noise, gyro_range, matrix_unit(gyr_units, "gyroscope") != "1")
    check_saturation(t, gyr, spans, at_range, tuple(drop), gyr_units, where)
    used = np.array([k not in drop for k in range(1, len(spans) + 1)])
    if 2 * used.sum() < 10:
        raise TestError(f"only {int(used.sum())} rotations in the fit; the gyro's 9 parameters need at least 5 "
                        "(two equations each)", where)
    fit = fit_gyro_matrix(t, gyr - off.removed, spans, dirs, used, dir_cov=dir_cov, offsets=off.patterns,
                          offset_cov=off.cov)
    weak, seen = _observability(fit, where)
    _check_gyro(fit.M, gyr_units, where)
    rotations = _reports(t, spans, fit, used)
    gyr_cal = _gyro_calibration(fit, off, gyr_units, rotations, poses, t, seen)
    pose_note = f"{len(poses)} static poses {how}"
    if len(poses) < RECOMMENDED_POSES:
        pose_note += (f"; fewer than the {RECOMMENDED_POSES} imu_tk asks for (the least is {MIN_POSES}): the 1-sigma rest "
                      "on few degrees of freedom")
    acc_cal = acc_cal.replace(notes=acc_cal.notes + (pose_note,))
    return GyroSession(acc_cal, gyr_cal, tuple(poses), tuple(rotations), fit.condition_number, weak,
                       fit.column_turn, init_s)


def _check_gyro(m: np.ndarray, units: str, where: str) -> None:
    """The gyro's ``M`` must be a gyro's: not mirrored relative to the accelerometer, usable, scale factors
    within 1 +/- 0.2 (physical units)."""
    det = float(np.linalg.det(m))
    if np.isfinite(det) and det < 0:
        raise TestError("gyro axes mirrored relative to the accelerometer (det M < 0): a column's sign or order is wrong "
                        "in {gyro_columns} or {accel_columns}", where)
    check_usable_model(m, f"{where}: gyroscope")
    if matrix_unit(units, "gyroscope") == "1":
        bad = scale_outside(m, 0.2)
        if bad is not None:
            raise TestError(f"the gyro's {'xyz'[bad[0]]} scale factor is {bad[1]:.3g}, outside 1 +/- 0.2: wrong "
                            "{gyro_units} or {gyro_columns}, or a broken axis", where)


def _reports(t: np.ndarray, spans: list, fit: GyroFit, used: np.ndarray) -> list[RotationReport]:
    out = []
    for k, ((a, b), rv, angle) in enumerate(zip(spans, fit.turns, fit.angles)):
        turn = float(np.linalg.norm(rv))
        out.append(RotationReport(k + 1, a, b, float(t[a]), float(t[b]), turn,
                                  rv / turn if turn > 0 else np.zeros(3), float(angle), bool(used[k])))
    return out


def _gyro_calibration(fit: GyroFit, off: _Offsets, units: str, rotations: list, poses: list, t: np.ndarray,
                      seen: str) -> Calibration:
    """The gyro's Calibration: residuals per rotation as the mean reading error that explains them,
    ``M r_k / T_k`` (readings), the left-out rotations as checks."""
    fitted: dict[str, np.ndarray] = {}
    checks: dict[str, np.ndarray] = {}
    for rep, r in zip(rotations, fit.residuals):
        reading = fit.M @ r / max(rep.t_end - rep.t_start, 1e-9)
        (fitted if rep.used else checks)[f"rotation {rep.number}"] = reading
    used = [r for r in rotations if r.used]
    a0, b0 = poses[0]
    if off.K is None:
        how = (f"bias: mean over the initial static period (pose 1, t={t[a0]:.1f}-{t[b0 - 1]:.1f} s, {b0 - a0} "
               "samples); Earth's rate not removed")
    else:
        how = (f"bias and g-sensitivity K_ga (raw = M w + K_ga f + bias, f the specific force in m/s^2) from the "
               f"{len(poses)} poses' mean readings by least squares; rms pose residual {off.rms:.3g} (readings), "
               "Earth's rate not removed")
    worst = max(used, key=lambda r: r.residual)
    notes = [FRAME_NOTE, how,
             f"M by least squares on the gravity directions after integrating {len(used)} rotations between "
             f"{len(poses)} poses; rms residual {fit.rms / DEG:.3g} deg (largest {worst.residual / DEG:.3g} deg, "
             f"rotation {worst.number}); 1-sigma from the Jacobian and the residual variance ({fit.dof} degrees of "
             f"freedom, widened {fit.widening:.3g}x for the t distribution) plus the accelerometer's and the bias's "
             "noise propagated", seen, *_model_notes(fit, off)]
    left = [r.number for r in rotations if not r.used]
    if left:
        notes.append(f"rotations {', '.join(map(str, left))} left out of the fit (their residuals are checks)")
    notes.append("residual of rotation k: the mean reading error over the rotation that would explain the angle "
                 "between the predicted and the measured gravity direction")
    level = widened_level(fit.widening, fit.dof, " for the residual part of M's covariance; the bias's is plain")
    if off.sigma_K is not None:
        notes.append(EARTH_NOTE)
    return Calibration("gyroscope", fit.M, off.bias, fit.sigma_M, off.sigma_bias, units, METHOD, fitted, checks,
                       tuple(notes), off.K, level, tuple(_table(rotations, poses)), off.sigma_K)



def _table(rotations: list, poses: list) -> list[dict]:
    """The per-rotation table of the file (what the command prints): times, turn, axis, residual angle."""
    return [{"rotation": r.number, "poses": [r.number, r.number + 1], "t_s": [round(r.t_start, 4), round(r.t_end, 4)],
             "turn_deg": round(r.turn / DEG, 4), "axis": [round(float(v), 5) for v in r.axis],
             "residual_deg": round(r.residual / DEG, 5), "used": r.used} for r in rotations]


def _model_notes(fit: GyroFit, off: _Offsets) -> list[str]:
    """What the fit says of the model: a gyro turned relative to the accelerometer, residuals beyond the noise."""
    out = []
    u, _, vt = np.linalg.svd(fit.M)
    turn = float(np.degrees(np.arccos(np.clip((np.trace(u @ vt) - 1) / 2, -1, 1))))
    if turn > 5.0:
        out.append(f"the gyro's axes are turned by {turn:.3g} deg relative to the accelerometer's (two chips, or either "
                   "sensor's columns in another order or sign: a mirrored accelerometer looks like a turned gyro, "
                   "gravity alone cannot tell its handedness): M holds that rotation, in the accelerometer frame")
    ratio = float(np.sqrt(fit.ssr / fit.noise_ssr)) if fit.noise_ssr > 0 else 0.0
    if ratio > 3.0:
        hint = ("" if off.K is not None else "; a g-sensitive gyro (Earth's gravity shifting its bias from pose to pose) "
                "is the usual cause: try the g-sensitivity model (bias and K_ga from every pose)")
        out.append(f"the residuals are {ratio:.3g}x (rms) what the sensors' noise explains: a model error or motion "
                   f"within the poses, which the 1-sigma (from the residuals) includes{hint}")
    return out


@dataclass(frozen=True, eq=False)
class _Offsets:
    """What is removed from the gyro readings before the rotations are integrated: ``removed`` (n, 3) =
    ``bias (+ K f(t))``; ``patterns`` (m, n, 3) and ``cov`` (m, m): its parameters' directions and covariance."""

    bias: np.ndarray
    sigma_bias: np.ndarray
    K: np.ndarray | None
    removed: np.ndarray
    patterns: np.ndarray
    cov: np.ndarray
    rms: float
    sigma_K: np.ndarray | None = None


def _offsets(gyr: np.ndarray, poses: list, force: np.ndarray | None, noise: np.ndarray) -> _Offsets:
    """The bias from the initial static period, or (``force`` given, (n, 3) m/s^2) the bias and g-sensitivity
    from every pose's mean: ``g_k = b + K_ga f_k``, ordinary least squares per axis."""
    n = len(gyr)
    if force is None:
        a0, b0 = poses[0]
        bias = gyr[a0:b0].mean(axis=0)
        var = noise ** 2 / (b0 - a0)
        patterns = np.repeat(np.eye(3)[:, None, :], n, axis=1)
        return _Offsets(bias, np.sqrt(var), None, np.broadcast_to(bias, gyr.shape), patterns, np.diag(var), 0.0)
    gm = np.array([gyr[a:b].mean(axis=0) for a, b in poses])
    x = np.column_stack([np.ones(len(poses)), np.array([force[a:b].mean(axis=0) for a, b in poses])])
    coef = np.linalg.lstsq(x, gm, rcond=None)[0]                                       # (4, 3): b, then K^T
    resid = gm - x @ coef
    s2 = (resid ** 2).sum(axis=0) / max(len(poses) - 4, 1)
    xtxi = np.linalg.inv(x.T @ x)
    cov = np.kron(xtxi, np.diag(s2))                                                    # theta = coef.ravel()
    columns = np.column_stack([np.ones(n), force])
    patterns = np.stack([columns[:, r, None] * np.eye(3)[j] for r in range(4) for j in range(3)])
    return _Offsets(coef[0], np.sqrt(s2 * xtxi[0, 0]), coef[1:].T, columns @ coef, patterns, cov,
                    float(np.sqrt(np.mean(resid ** 2))), g_sensitivity_sigma(s2, xtxi))
