"""Accelerometer calibration from static positions (reference section 5; seeds 000 and 004).

The accelerometer shares the alignment convention ``raw = M true + bias``
(:class:`~align.calibration.results.Calibration`).

* Known orientations: ordinary least squares for ``[M | b]`` (12 parameters,
  ``K = Y X^T (X X^T)^-1`` with ``X_k = [g u_k; 1]``), 1-sigma from the
  residuals, positions held out as a check (seed 004's 45-degree positions);
  optionally the Ferraris pairwise bias ``b_i = (a_i(+i up) + a_i(-i up)) / 2``.
* Unknown orientations (imu_tk style): ``|U (a_k - b)| = g`` over many static
  attitudes, ``U`` upper triangular (the sensor-to-case rotation is not
  observable), ``M = U^-1`` (:mod:`align.calibration.accelfree`, re-exported here).
* A session (:func:`accel_session`): the static means of a log's positions,
  then one of the two fits.

Public names
------------
FACES, face_ups, static_means, norms_at_rest, accel_session, calibrate_accel_log, StaticDetector, calibrate_accel,
calibrate_accel_free, session_intervals
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.alignment.estimate import fit_lsq
from align.alignment.observe import Observation
from align.alignment.segment import Segment
from align.calibration.accelfree import calibrate_accel_free
from align.calibration.positions import parse_positions, positions_of
from align.calibration.results import Calibration
from align.calibration.statics import static_intervals
from align.errors import InputError, TestError, literal
from align.io import check_log
from align.plausible import check_at_rest, check_axes, check_gravity, check_scale_factors
from align.units import STANDARD_GRAVITY, parse_quantity, to_unit

#: imucal's section names -> the axis pointing up (the accelerometer reads +g on it)
FACES = {"x_p": (0, 1), "x_a": (0, -1), "y_p": (1, 1), "y_a": (1, -1), "z_p": (2, 1), "z_a": (2, -1)}


def _axis_up(axis: int, sign: int) -> np.ndarray:
    u = np.zeros(3)
    u[axis] = sign
    return u


def face_ups() -> dict:
    """imucal's six faces -> the unit vector (sensor frame) pointing up on each, shape (3,)."""
    return {f: _axis_up(axis, sign) for f, (axis, sign) in FACES.items()}


def _obs(name: str, mean: np.ndarray, var: np.ndarray, phi: np.ndarray) -> Observation:
    return Observation(Segment(name, "static", 0, 1), np.asarray(mean, float), np.asarray(phi, float),
                       np.asarray(var, float), 1.0)


def static_means(x: np.ndarray, ranges: dict, max_spread: float, where: str = "") -> dict:
    """Mean reading of each named sample range ``(start, end)``, refusing ranges that are not static.

    A range is static when every axis varies by at most ``max_spread`` times the
    median magnitude of the readings (1 sigma): unit-free, so raw counts work too.

    Parameters
    ----------
    x : ndarray, shape (n, 3)
        Readings (any unit).
    ranges : dict of str -> (int, int)
        Name -> sample range ``start, end`` (end exclusive).
    max_spread : float
        Largest 1-sigma spread of a static range, as a fraction of the median ``|x|``.
    where : str
        Prefix of the ``where`` of an out-of-range error (a file name and ``": "``).

    Returns
    -------
    dict of str -> ndarray, shape (3,)
        The mean reading of each range.
    """
    limit = max_spread * float(np.median(np.linalg.norm(x, axis=1)))
    out = {}
    for name, (a, b) in ranges.items():
        if not 0 <= a < b <= len(x):
            raise InputError(f"samples {a}..{b} are outside the log's {len(x)} samples", f"{where}{name}")
        if b - a < 10:
            raise TestError(f"only {b - a} samples: too short for a static position", name)
        spread = float(np.std(x[a:b], axis=0).max())
        if spread > limit:
            raise TestError(f"not static: the readings vary by {spread:.3g} (1 sigma) over samples {a}..{b}; "
                            "check the range", name)
        out[name] = x[a:b].mean(axis=0)
    return out


def norms_at_rest(x: np.ndarray, ranges: dict) -> np.ndarray:
    """``|x|`` of every sample in the named ranges ``(start, end)`` (clipped to the log), shape (k,)."""
    parts = [np.linalg.norm(x[max(a, 0):b], axis=1) for a, b in ranges.values()]
    return np.concatenate(parts) if parts else np.zeros(0)


@dataclass(frozen=True)
class StaticDetector:
    """Settings of the static-interval detector (imu_tk's moving variance, see
    :func:`align.calibration.statics.static_intervals`): window (s), threshold factor,
    initial static period (s, or None) and shortest interval (s); for a session with a gyro
    (:mod:`align.calibration.gyro`) the gyro's threshold factor too (a pose held by hand wobbles
    the gyro's variance up to about 100 times its value at rest; the slow start of a turn that the
    accelerometer misses raises it thousands of times)."""

    window_s: float = 1.0
    factor: float = 6.0
    init_static_s: float | None = None
    min_static_s: float = 1.0
    gyro_factor: float = 1000.0


def calibrate_accel_log(t: np.ndarray, a: np.ndarray, spec: dict | None, units: str, gravity: float | None = None,
                        detector: StaticDetector = StaticDetector(), where: str = "log",
                        positions_file: str = "positions") -> Calibration:
    """An accelerometer session from its log: static intervals detected, then :func:`accel_session`.

    Parameters
    ----------
    t, a : ndarray, shapes (n,) and (n, 3)
        Time (s) and readings, SI or counts.
    spec : dict or None
        The positions file (``gravity`` and ``[[position]]`` tables, see
        :mod:`align.calibration.positions`), or None for the ``|a| = g`` fit. A file
        without positions is refused, not read as None.
    units : str
        Unit of the readings.
    gravity : float, optional
        Local gravity (m/s^2); default the positions file's, else 9.80665.
    detector : StaticDetector
    """
    check_log(t, a, where)
    positions = None if spec is None else positions_of(spec, positions_file)
    if gravity is not None:
        gravity = check_gravity(gravity)
    elif spec is not None and "gravity" in spec:
        at = f"{positions_file}: gravity"
        gravity = check_gravity(parse_quantity(spec["gravity"], "acceleration", at), at)
    else:
        gravity = STANDARD_GRAVITY
    fs = 1.0 / float(np.median(np.diff(t)))
    intervals = static_intervals(a, fs, detector.window_s, detector.factor, detector.init_static_s, detector.min_static_s)
    return accel_session(t, a, intervals, positions, gravity, units, where, positions_file)


def session_intervals(t: np.ndarray, a: np.ndarray, spec: dict | None, detector: StaticDetector = StaticDetector(),
                      positions_file: str = "positions") -> list[tuple[int, int]]:
    """The static ranges a session from :func:`calibrate_accel_log` uses (its positions' ``start``/``end``
    when the file gives them, else the detected intervals), as ``(start, end)`` samples, end exclusive:
    what a picture of the session shows."""
    if spec is not None:
        parsed = parse_positions(positions_of(spec, positions_file), positions_file)
        if parsed[0].samples is not None:
            return [p.samples for p in parsed if p.samples is not None]  # the file gives every one or none
    fs = 1.0 / float(np.median(np.diff(t)))
    return static_intervals(a, fs, detector.window_s, detector.factor, detector.init_static_s, detector.min_static_s)


def accel_session(t: np.ndarray, a: np.ndarray, intervals: list, positions: list | None, gravity: float,
                  units: str, where: str = "log", positions_file: str = "positions") -> Calibration:
    """An accelerometer session: known positions (``[[position]]`` tables) or, without them, ``|a| = g``.

    Parameters
    ----------
    t, a : ndarray
        Time (s) and readings (n, 3), SI or counts.
    intervals : list of (start, end)
        Static intervals found by :func:`align.calibration.statics.static_intervals`,
        used when the positions give no ``start``/``end`` (matched in order) and
        for the free fit.
    positions : list of dict or None
        Each with ``up`` (``"+x"`` or ``[x, y, z]``), optional ``name``, ``start``, ``end``, ``holdout``
        (:func:`align.calibration.positions.parse_positions`); None for the ``|a| = g`` fit.
    gravity : float
        Local gravity, m/s^2.
    units : str
        Unit of the readings, for the result's file form.
    where, positions_file : str
        Names of the log and of the positions file, for errors.

    Returns
    -------
    Calibration

    Raises
    ------
    TestError
        Readings at rest that are not gravity in ``units`` (a unit mix-up, named with its fix ``{units=...}``),
        positions that do not match the detected intervals, a handedness error.
    """
    gravity = check_gravity(gravity)
    if positions is None:
        if not intervals:
            raise TestError("no static intervals detected: adjust the static detector ({factor}, {window_s}) "
                            "or list the positions", where)
        detected = {f"interval {k + 1}": r for k, r in enumerate(intervals)}
        check_at_rest(norms_at_rest(a, detected), gravity, units, "units", where)
        means = static_means(a, detected, 0.02, f"{where}: ")
        cal = calibrate_accel_free(np.array(list(means.values())), gravity, units, where=where)
        note = f"{len(intervals)} static intervals detected automatically (moving variance)"
        return cal.replace(notes=cal.notes + (note,))
    parsed = parse_positions(positions, positions_file)
    ranges: list[tuple[int, int]]  # the positions' sample ranges, in order
    if parsed[0].samples is not None:
        ranges = [p.samples for p in parsed if p.samples is not None]  # the file gives every one or none
    else:
        if len(intervals) != len(parsed):
            found = "; ".join(f"t={t[s]:.1f}-{t[e - 1]:.1f} s" for s, e in intervals[:20])
            raise TestError(f"{len(intervals)} static intervals detected but {len(parsed)} positions listed ({found}); "
                            "adjust the static detector ({factor}, {window_s}) or give start/end per position", where)
        ranges = intervals
    named = {p.name: r for p, r in zip(parsed, ranges, strict=True)}
    check_at_rest(norms_at_rest(a, named), gravity, units, "units", where)
    means = static_means(a, named, 0.02, f"{positions_file}: ")
    return calibrate_accel(means, {p.name: p.up for p in parsed}, gravity, units, tuple(p.name for p in parsed if p.holdout),
                           where=positions_file)


def _check_distinct(means: dict, ups: dict, where: str, units: str) -> None:
    """Refuse two positions of different orientation that read the same (one face recorded twice, a copied range)."""
    names = list(means)
    centre = np.mean([means[k] for k in names], axis=0)
    radius = float(np.median([np.linalg.norm(means[k] - centre) for k in names]))  # g times the scale, any unit
    for i, k in enumerate(names):
        for n in names[i + 1:]:
            turn = float(np.linalg.norm(np.asarray(ups[k], float) - np.asarray(ups[n], float)))
            apart = float(np.linalg.norm(means[k] - means[n]))
            if turn > 0.5 and not apart > 0.25 * turn * radius:
                raise TestError(f"positions {literal(k)} and {literal(n)} read the same ({to_unit(apart, units):.3g} {units} "
                                f"apart, about {to_unit(turn * radius, units):.3g} expected for their orientations): one "
                                f"face recorded twice or a range copied; check {literal(k)} and {literal(n)}", where)


def calibrate_accel(means: dict, ups: dict, gravity: float = STANDARD_GRAVITY, units: str = "m/s^2",
                    holdout: tuple = (), pairwise_bias: bool = False, noise: dict | None = None,
                    where: str = "positions") -> Calibration:
    """Accelerometer ``[M | b]`` from static positions of known orientation (reference section 5).

    Parameters
    ----------
    means : dict
        Position name -> mean reading (3,), SI.
    ups : dict
        Position name -> unit vector (sensor frame) of the axis pointing up: the
        true specific force is ``g u``.
    gravity : float
        Local gravity, m/s^2 (default standard gravity).
    units : str
        Unit of the readings, for the result's file form.
    holdout : tuple of str
        Positions left out of the fit and used as a check (their residuals are reported).
    pairwise_bias : bool
        Replace the least-squares bias by the Ferraris pairwise bias (needs the six faces).
    noise : dict, optional
        Position name -> per-sample sigma (3,); accepted but not used yet.
    where : str
        The positions file (or ``"{sections}"``), for errors.

    Returns
    -------
    Calibration
        ``M`` (3, 3), ``bias`` (3,) SI, with residuals per fitted position and
        a check per held-out one.

    Raises
    ------
    TestError, HandednessError
        Readings that are not gravity in ``units`` (a unit mix-up), two orientations reading the
        same, positions not spanning 3-D, an axis reading the wrong way (``det(M) <= 0``: a handedness
        error naming the axis and its positions), a scale factor outside 1 +/- 0.2 (physical units).

    Examples
    --------
    The six faces of a known ``[M | b]`` (``a_meas = M (g u) + b``): the least squares
    ``K_hat = Y X^T (X X^T)^-1`` (reference section 5) returns it.

    >>> import numpy as np
    >>> M = np.array([[1.01, 0.002, -0.003], [0.001, 0.99, 0.004], [-0.002, 0.003, 1.005]])
    >>> b = np.array([0.05, -0.03, 0.02])
    >>> ups = {f"{s}{a}": k * np.eye(3)[i] for i, a in enumerate("xyz") for s, k in (("+", 1), ("-", -1))}
    >>> cal = calibrate_accel({name: M @ (9.80665 * u) + b for name, u in ups.items()}, ups)
    >>> bool(np.allclose(cal.M, M, atol=1e-9)), bool(np.allclose(cal.bias, b, atol=1e-9))
    (True, True)
    """
    gravity = check_gravity(gravity)
    check_at_rest(np.linalg.norm(np.reshape(list(means.values()), (-1, 3)), axis=1), gravity, units)
    fit_names = [k for k in means if k not in holdout]
    if len(fit_names) < 6:
        raise InputError(f"only {len(fit_names)} positions in the fit; the 12-parameter model needs at least 6 "
                         "(the six faces +/-x, +/-y, +/-z up)", where)
    _check_distinct({k: means[k] for k in fit_names}, ups, where, units)
    obs = [_obs(k, means[k], np.ones(3), np.append(gravity * np.asarray(ups[k], float), 1.0)) for k in fit_names]
    spans = "the positions do not span 3-D (every axis must point up and down at least once)"
    try:
        fit = fit_lsq(obs, equal_weights=True, method="ols")
    except TestError:
        raise TestError(spans, where) from None
    m, b = fit.M, fit.bias
    if not np.all(np.isfinite(m)):
        raise TestError(spans, where)
    check_axes(m, {i: [k for k in fit_names if abs(ups[k][i]) > 0.7] for i in range(3)}, where)
    check_scale_factors(m, 0.2, units, "acceleration", "units", where)
    notes = [f"local gravity {gravity:.6g} m/s^2" + (" (standard gravity)" if gravity == STANDARD_GRAVITY else "")]
    if pairwise_bias:
        missing = [f for f in FACES if f not in means]
        if missing:
            raise InputError(f"the pairwise bias needs the six faces; missing {', '.join(missing)}", where)
        b = np.array([(means[f"{a}_p"][i] + means[f"{a}_a"][i]) / 2 for i, a in enumerate("xyz")])
        notes.append("bias: Ferraris pairwise (a_i(+i up) + a_i(-i up)) / 2, robust to a tilted reference surface")
    residuals = {k: means[k] - (m @ (gravity * np.asarray(ups[k])) + b) for k in fit_names}
    checks = {k: means[k] - (m @ (gravity * np.asarray(ups[k])) + b) for k in holdout}
    return Calibration("accelerometer", m, b, fit.sigma_M, fit.sigma_bias, units, "multi-position least squares",
                       residuals, checks, tuple(notes))
