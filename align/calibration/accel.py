"""Discrete calibration of accelerometers and gyros (reference section 5; seeds 000 and 004).

Every sensor shares the alignment convention: ``raw = M true + bias``, corrected
by ``true = M^-1 (raw - bias)``. The gyro may also carry a g-sensitivity
``K_ga`` (``raw = M w + K_ga a + bias``).

* Accelerometer, known orientations: ordinary least squares for ``[M | b]``
  (12 parameters, ``K = Y X^T (X X^T)^-1`` with ``X_k = [g u_k; 1]``), 1-sigma
  from the residuals, positions held out as a check (seed 004's 45-degree
  positions); optionally the Ferraris pairwise bias ``b_i = (a_i(+i up) + a_i(-i up)) / 2``.
* Accelerometer, unknown orientations (imu_tk style): ``|U (a_k - b)| = g`` over
  many static attitudes, ``U`` upper triangular (the sensor-to-case rotation is
  not observable), ``M = U^-1``.
* Gyro, turns of known angle: the alignment module's estimators and checks on
  static sections (bias) and integrated turns (Eq 31), after removing the
  g-sensitivity estimated from the static faces (as Ferraris / imucal do).

Public names
------------
Calibration, static_means, accel_session, calibrate_accel, calibrate_accel_free, ferraris, FACES, imucal_dict
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from align import __version__
from align.errors import InputError, TestError
from align.alignment.estimate import Observation, fit_lsq
from align.alignment.segment import Segment
from align.units import STANDARD_GRAVITY, to_unit

FORMAT = "imu-align.calibration"
CONVENTION = "raw = M true + bias; true = M^-1 (raw - bias); rows of M are sensor axes"
#: imucal's section names -> the axis pointing up (the accelerometer reads +g on it)
FACES = {"x_p": (0, 1), "x_a": (0, -1), "y_p": (1, 1), "y_a": (1, -1), "z_p": (2, 1), "z_a": (2, -1)}


@dataclass(frozen=True)
class Calibration:
    """One sensor's calibration (SI inside; ``units`` is the file/display unit of readings)."""

    sensor: str
    M: np.ndarray
    bias: np.ndarray
    sigma_M: np.ndarray
    sigma_bias: np.ndarray
    units: str
    method: str
    residuals: dict = field(default_factory=dict)
    checks: dict = field(default_factory=dict)
    notes: tuple = ()
    g_sensitivity: np.ndarray | None = None

    def to_dict(self) -> dict:
        u = self.units
        d = {
            "sensor": self.sensor, "method": self.method, "convention": CONVENTION,
            "units": {"M": "1", "bias": u, "residuals": u},
            "M": self.M.tolist(), "A": np.linalg.inv(self.M).tolist(),
            "bias": to_unit(self.bias, u).tolist(),
            "uncertainty": {"level": "1 sigma", "M": self.sigma_M.tolist(), "bias": to_unit(self.sigma_bias, u).tolist()},
            "residuals": {k: to_unit(np.asarray(v), u).tolist() for k, v in self.residuals.items()},
            "checks": {k: to_unit(np.asarray(v), u).tolist() for k, v in self.checks.items()},
            "notes": list(self.notes),
        }
        if self.g_sensitivity is not None:
            d["g_sensitivity"] = (self.g_sensitivity * to_unit(1.0, u)).tolist()
            d["units"]["g_sensitivity"] = f"{u} per m/s^2"
        return d

    @classmethod
    def from_dict(cls, d: dict, where: str = "calibration") -> "Calibration":
        from align.units import parse_unit

        try:
            u = d["units"]["bias"]
            f = parse_unit(u, where=f"{where}: units.bias").factor
            unc = d.get("uncertainty", {})
            gs = d.get("g_sensitivity")
            return cls(d["sensor"], np.array(d["M"], float).reshape(3, 3), np.array(d["bias"], float) * f,
                       np.array(unc.get("M", np.full((3, 3), np.nan)), float), np.array(unc.get("bias", [np.nan] * 3), float) * f,
                       u, d.get("method", ""), {k: np.array(v) * f for k, v in d.get("residuals", {}).items()},
                       {k: np.array(v) * f for k, v in d.get("checks", {}).items()}, tuple(d.get("notes", [])),
                       None if gs is None else np.array(gs, float) * f)
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"malformed calibration ({exc!r})", where) from None

    def correct(self, raw: np.ndarray, acc: np.ndarray | None = None) -> np.ndarray:
        """``true = M^-1 (raw - bias - K_ga acc)`` for readings (n, 3), SI."""
        off = self.bias if self.g_sensitivity is None or acc is None else self.bias + acc @ self.g_sensitivity.T
        return np.linalg.solve(self.M, (np.asarray(raw) - off).T).T


def _obs(name: str, mean: np.ndarray, var: np.ndarray, phi: np.ndarray) -> Observation:
    return Observation(Segment(name, "static", 0, 1), np.asarray(mean, float), np.asarray(phi, float),
                       np.asarray(var, float), 1.0)


def static_means(x: np.ndarray, ranges: dict, max_spread: float, where: str = "") -> dict:
    """Mean reading of each named sample range ``(start, end)``, refusing ranges that are not static.

    A range is static when every axis varies by at most ``max_spread`` times the
    median magnitude of the readings (1 sigma): unit-free, so raw counts work too.
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


def accel_session(t: np.ndarray, a: np.ndarray, intervals: list, positions: list | None, gravity: float,
                  units: str, where: str = "log", positions_file: str = "positions") -> Calibration:
    """An accelerometer session: known positions (``[[position]]`` tables) or, without them, ``|a| = g``.

    Parameters
    ----------
    t, a : ndarray
        Time (s) and readings (n, 3), SI or counts.
    intervals : list of (start, end)
        Static intervals found by :func:`align.segment.static_intervals`, used
        when the positions give no ``start``/``end`` (matched in order) and for the free fit.
    positions : list of dict or None
        Each with ``up`` (``"+x"`` or ``[x, y, z]``), optional ``name``, ``start``, ``end``, ``holdout``.
    """
    from align.alignment.plan import parse_axis

    if positions is None:
        means = static_means(a, {f"interval {k + 1}": r for k, r in enumerate(intervals)}, 0.02, f"{where}: ")
        cal = calibrate_accel_free(np.array(list(means.values())), gravity, units)
        note = f"{len(intervals)} static intervals detected automatically (moving variance)"
        return Calibration(**{**cal.__dict__, "notes": cal.notes + (note,)})
    if not isinstance(positions, list) or not positions:
        raise InputError("no [[position]] tables", positions_file)
    if all("start" in p for p in positions):
        ranges = [(int(p["start"]), int(p["end"])) for p in positions]
    elif any("start" in p for p in positions):
        raise InputError("give start/end for every position or for none (automatic detection)", positions_file)
    else:
        if len(intervals) != len(positions):
            found = "; ".join(f"t={t[s]:.1f}-{t[e - 1]:.1f} s" for s, e in intervals[:20])
            raise TestError(f"{len(intervals)} static intervals detected but {len(positions)} positions listed ({found}); "
                            "adjust --factor/--window or give start/end per position", where)
        ranges = intervals
    names, ups, hold = [], {}, []
    for k, p in enumerate(positions, start=1):
        name = str(p.get("name", f"position {k}"))
        up = p.get("up")
        if isinstance(up, str):
            axis, sign = parse_axis(up, f"{positions_file}: {name}.up")
            u = np.zeros(3)
            u[axis] = sign
        elif isinstance(up, list) and len(up) == 3:
            u = np.asarray(up, float) / np.linalg.norm(up)
        else:
            raise InputError("up must be an axis ('+x') or a vector [x, y, z]", f"{positions_file}: {name}.up")
        names.append(name)
        ups[name] = u
        if p.get("holdout"):
            hold.append(name)
    means = static_means(a, dict(zip(names, ranges)), 0.02, f"{positions_file}: ")
    return calibrate_accel(means, ups, gravity, units, tuple(hold))


def calibrate_accel(means: dict, ups: dict, gravity: float = STANDARD_GRAVITY, units: str = "m/s^2",
                    holdout: tuple = (), pairwise_bias: bool = False, noise: dict | None = None) -> Calibration:
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
    holdout : tuple of str
        Positions left out of the fit and used as a check (their residuals are reported).
    pairwise_bias : bool
        Replace the least-squares bias by the Ferraris pairwise bias (needs the six faces).
    noise : dict, optional
        Position name -> per-sample sigma (3,), reported beside the residuals.
    """
    fit_names = [k for k in means if k not in holdout]
    if len(fit_names) < 6:
        raise InputError(f"only {len(fit_names)} positions in the fit; the 12-parameter model needs at least 6 "
                         "(the six faces +/-x, +/-y, +/-z up)", "positions")
    obs = [_obs(k, means[k], np.ones(3), np.append(gravity * np.asarray(ups[k], float), 1.0)) for k in fit_names]
    try:
        fit = fit_lsq(obs, equal_weights=True, method="ols")
    except TestError:
        raise TestError("the positions do not span 3-D (every axis must point up and down at least once)", "positions") from None
    m, b = fit.M, fit.bias
    notes = [f"local gravity {gravity:.6g} m/s^2" + (" (standard gravity)" if gravity == STANDARD_GRAVITY else "")]
    if pairwise_bias:
        missing = [f for f in FACES if f not in means]
        if missing:
            raise InputError(f"the pairwise bias needs the six faces; missing {', '.join(missing)}", "positions")
        b = np.array([(means[f"{a}_p"][i] + means[f"{a}_a"][i]) / 2 for i, a in enumerate("xyz")])
        notes.append("bias: Ferraris pairwise (a_i(+i up) + a_i(-i up)) / 2, robust to a tilted reference surface")
    residuals = {k: means[k] - (m @ (gravity * np.asarray(ups[k])) + b) for k in fit_names}
    checks = {k: means[k] - (m @ (gravity * np.asarray(ups[k])) + b) for k in holdout}
    return Calibration("accelerometer", m, b, fit.sigma_M, fit.sigma_bias, units, "multi-position least squares",
                       residuals, checks, tuple(notes))


def calibrate_accel_free(means: np.ndarray, gravity: float = STANDARD_GRAVITY, units: str = "m/s^2",
                         guess_scale: float | None = None, guess_bias=None) -> Calibration:
    """Accelerometer from static attitudes of unknown orientation: ``|U (a_k - b)| = g`` (imu_tk's idea).

    ``U`` is upper triangular (x along the accelerometer's x axis, y in its x-y
    plane: the rotation to the case is not observable), ``M = U^-1``. Solved by
    Levenberg-Marquardt (scipy) from a sphere guess; the 1-sigma come from the
    Jacobian and the residual variance.
    """
    from scipy.optimize import least_squares

    a = np.asarray(means, float)
    k = len(a)
    if k < 9:
        raise InputError(f"only {k} static attitudes; the 9-parameter fit needs at least 9 (12 or more recommended)",
                         "static intervals")
    centre = a.mean(axis=0) if guess_bias is None else np.asarray(guess_bias, float)
    spread = np.linalg.svd(a - centre, compute_uv=False)
    if spread[-1] < 0.05 * spread[0]:
        raise TestError("the static attitudes lie nearly in a plane: turn the sensor through all directions", "static intervals")
    scale = np.median(np.linalg.norm(a - centre, axis=1)) / gravity if guess_scale is None else guess_scale
    iu = np.triu_indices(3)

    def unpack(p):
        u = np.zeros((3, 3))
        u[iu] = p[:6]
        return u, p[6:]

    x0 = np.zeros(9)
    x0[[0, 3, 5]] = 1.0 / scale  # the diagonal of U in triu order (0,0), (1,1), (2,2)
    x0[6:] = centre

    def resid(p):
        u, b = unpack(p)
        return np.linalg.norm((a - b) @ u.T, axis=1) - gravity

    sol = least_squares(resid, x0, method="lm", x_scale="jac")
    u, b = unpack(sol.x)
    m = np.linalg.inv(u)
    if np.linalg.det(m) <= 0:
        raise TestError("the fit came out reflected (det < 0)", "static intervals")
    dof = max(k - 9, 1)
    s2 = float(np.sum(sol.fun**2)) / dof
    cov = np.linalg.pinv(sol.jac.T @ sol.jac) * s2
    # 1-sigma of M = U^-1 by first-order propagation dM = -M dU M
    sig_u = np.zeros((3, 3))
    sig_u[iu] = np.sqrt(np.diag(cov)[:6])
    sigma_m = np.sqrt((np.abs(m) ** 2) @ (sig_u**2) @ (np.abs(m) ** 2))
    per = float(np.mean(np.diag(m)))  # residuals of |a| (m/s^2) expressed in readings
    resid_norm = {f"attitude {i + 1}": np.array([r * per, 0.0, 0.0]) for i, r in enumerate(sol.fun)}
    note = (f"|a| = g fit over {k} static attitudes (local gravity {gravity:.6g} m/s^2); U upper triangular: "
            f"the accelerometer-to-case rotation is not observable; rms |a| residual {np.sqrt(np.mean(sol.fun**2)):.3g} m/s^2")
    return Calibration("accelerometer", m, b, sigma_m, np.sqrt(np.diag(cov)[6:]), units, "|a| = g fit (unknown attitudes)",
                       resid_norm, {}, (note,))


def ferraris(acc: np.ndarray, gyr: np.ndarray, fs: float, sections: dict, turn_angle: float,
             gravity: float = STANDARD_GRAVITY, acc_units: str = "m/s^2", gyr_units: str = "deg/s",
             pairwise_bias: bool = True, g_sensitivity: bool = True) -> tuple[Calibration, Calibration]:
    """A Ferraris session (six faces, one turn about each axis): accelerometer and gyro.

    Parameters
    ----------
    acc, gyr : ndarray, shape (n, 3)
        Readings, SI (m/s^2, rad/s).
    fs : float
        Hz.
    sections : dict
        imucal's section list: ``x_p``, ``x_a``, ... ``z_a`` (static faces) and
        ``x_rot``, ``y_rot``, ``z_rot`` (turns), each ``(start, end)`` samples, end exclusive.
    turn_angle : float
        Signed angle of each turn about the axis pointing up, rad (imucal: -360 deg).
    """
    from align.alignment.job import AlignOptions, align
    from align.alignment.plan import Plan, Step

    need = list(FACES) + ["x_rot", "y_rot", "z_rot"]
    missing = [k for k in need if k not in sections]
    if missing:
        raise InputError(f"missing sections {', '.join(missing)} (imucal's names: {', '.join(need)})", "sections")
    for name, (a, b) in sections.items():
        if not 0 <= a < b <= len(acc):
            raise InputError(f"{a}..{b} is not inside the log's {len(acc)} samples", f"sections: {name}")
    means = static_means(acc, {f: sections[f] for f in FACES}, 0.05 * gravity / np.median(np.linalg.norm(acc, axis=1)))
    n = len(acc)
    ups = {}
    for f, (axis, sign) in FACES.items():
        u = np.zeros(3)
        u[axis] = sign
        ups[f] = u
    acc_cal = calibrate_accel(means, ups, gravity, acc_units, pairwise_bias=pairwise_bias)
    a_true = acc_cal.correct(acc)
    t = np.arange(n) / fs
    g = np.array(gyr, float)
    kga = None
    notes = []
    if g_sensitivity:
        face_gyr = {f: gyr[a:b].mean(axis=0) for f, (a, b) in sections.items() if f in FACES}
        kga = np.column_stack([(face_gyr[f"{a}_p"] - face_gyr[f"{a}_a"]) / (2 * gravity) for a in "xyz"])
        g = g - a_true @ kga.T
        notes.append("g-sensitivity K_ga from the static faces ((g(+i up) - g(-i up)) / 2g); it also absorbs the "
                     "vertical Earth rate, which changes sign between the faces")
    plan = Plan(tuple(Step(i, 1, angle=turn_angle) for i in range(3)))
    segs = [Segment(f, "static", *sections[f]) for f in FACES]
    segs += [Segment(f"{a}_rot", "angle", *sections[f"{a}_rot"], step=i) for i, a in enumerate("xyz")]
    r = align(t, g, plan, AlignOptions(method="lsq", min_dwell=0.5, scale_tolerance=0.2), segs, gyr_units, "gyroscope")
    notes += ["gyro: Eq 31 on the integrated turns, bias from the static faces (weighted least squares)",
              "Earth rate not modelled: its vertical part differs between opposite faces and lands in K_ga (or, "
              "without it, in the bias); the turns integrate at most 15.04 deg/h times their duration"]
    residuals = {s.name: np.array(s.residual) for s in r.segments if s.kind == "static"}
    gyro_cal = Calibration("gyroscope", r.M, r.bias, r.sigma_M, r.sigma_bias, gyr_units, "Ferraris turns, least squares",
                           residuals, {}, tuple(notes), kga)
    return acc_cal, gyro_cal


def imucal_dict(acc: Calibration, gyr: Calibration) -> dict:
    """The pair as imucal's ``FerrarisCalibrationInfo`` JSON (``K``, ``R``, ``b`` per sensor).

    imucal's model is ``raw = K R true + b`` (plus ``K_ga a`` for the gyro), so
    ``K = diag(|rows of M|)`` and ``R = K^-1 M``. Units: m/s^2 and deg/s.
    """
    def kr(m):
        k = np.diag(np.linalg.norm(m, axis=1))
        return k, np.linalg.inv(k) @ m

    ka, ra = kr(acc.M)
    kg, rg = kr(gyr.M)
    deg = np.pi / 180
    kga = np.zeros((3, 3)) if gyr.g_sensitivity is None else gyr.g_sensitivity / deg
    return {"acc_unit": "m/s^2", "gyr_unit": "deg/s", "from_acc_unit": "m/s^2", "from_gyr_unit": "deg/s",
            "comment": f"written by imu-align {__version__}: raw = K R true + b",
            "K_a": ka.tolist(), "R_a": ra.tolist(), "b_a": acc.bias.tolist(),
            "K_g": kg.tolist(), "R_g": rg.tolist(), "K_ga": kga.tolist(), "b_g": (gyr.bias / deg).tolist(),
            "cal_type": "Ferraris", "_format_version": "2.0.0"}
