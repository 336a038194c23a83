"""Multi-position static calibration with Earth rate: gyro bias (and, where the positions allow, scale,
misalignment and g-sensitivity), accelerometer bias, scale and misalignment (seed 000's 6/12/24-position methods).

Frames. The local-level frame is **ENU** (east, north, up; :func:`align.earth.earth_rate_enu`). Each position is
an orientation ``R`` (3, 3) taking ENU vectors into the sensor frame (``v_s = R v_enu``); at rest the sensor sees

* specific force ``f = R (0, 0, g)`` (the accelerometer reads ``+g`` on the axis pointing up),
* Earth rate ``w = R Omega (0, cos L, sin L)`` at latitude ``L``.

Models (reference section 1; rows of ``M`` are sensor axes): accelerometer ``a = M_a f + b_a``; gyro
``g = M_g w + K_ga f + b_g`` (``K_ga`` the g-sensitivity of the bias, rad/s per m/s^2). Per sensor axis ``i``
both are linear in the row's parameters: ``y_k = [1, f_k, w_k] . [b_i, K_i, M_i]``, fitted by weighted least
squares over the positions' means with their stated 1-sigma.

Observability. Since ``w = Omega cos L n + (Omega sin L / g) f`` (``n = R e_north``), the gyro's columns are not
independent of the accelerometer's in every design: six positions cannot separate ``M_g`` from ``K_ga``. A
parameter is **observable** when its unit vector lies in the row space of the (column-scaled) design matrix,
i.e. it is an estimable function whatever the other parameters' true values (Searle, *Linear Models*, 5.4); its
estimate is then the same for every generalised inverse, and its 1-sigma follows from ``(X^T W X)^+``. A parameter
outside the row space is **not observable**: it is reported without a value. An observable one whose 1-sigma is
beyond :data:`USEFUL` is **weakly observable** (Earth rate is 15 deg/h: a MEMS gyro's scale from it is
typically useless).

Presets (:data:`SCHEMES`): ``six`` (each axis up then down, turned 180 deg about the horizontal so that both
Earth rate and gravity cancel in the sum: the bias is the plain mean), ``twelve`` (each face up at two opposite
headings), ``twenty-four`` (each face up at four headings).

Public names
------------
SCHEMES, USEFUL, Reading, AxisFit, SensorFit, PositionsFit, from_words, from_angles, scheme, fit_positions,
parse_positions_file, simulate_means, simulate_session, ENU_FROM_NED, FILE_KEYS, POSITION_KEYS
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from align.earth import EARTH_RATE, earth_rate_enu
from align.errors import InputError
from align.io.keys import check_keys, tables
from align.units import STANDARD_GRAVITY, parse_quantity

AXES = "xyz"
#: ENU coordinates of an NED vector: ``v_enu = ENU_FROM_NED v_ned``
ENU_FROM_NED = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
#: the 1-sigma beyond which an observable parameter is only weakly so, per kind (SI): ``M`` 1 % (scale) or
#: 10 mrad (misalignment), ``K_ga`` 1e-4 rad/s per m/s^2 (0.056 deg/s per g), a bias never
USEFUL = {"M": 1e-2, "K": 1e-4, "b": np.inf}
#: the positions of the standard schemes as (axis up, axis north) in the sensor frame
SCHEMES: dict[str, tuple[tuple[str, str], ...]] = {
    "six": (("+x", "+y"), ("-x", "-y"), ("+y", "+z"), ("-y", "-z"), ("+z", "+x"), ("-z", "-x")),
    "twelve": tuple((f"{s}{a}", f"{t}{b}") for a, b in (("x", "y"), ("y", "z"), ("z", "x"))
                    for s in "+-" for t in "+-"),
    "twenty-four": tuple((f"{s}{a}", f"{t}{b}") for a in AXES for s in "+-" for b in AXES if b != a for t in "+-"),
}
#: the observability words a parameter gets
OBSERVABLE, WEAK, NOT_OBSERVABLE = "observable", "weakly observable", "not observable"


def _axis_vector(text: object, where: str) -> np.ndarray:
    from align.alignment.plan import parse_axis

    if isinstance(text, str):
        i, s = parse_axis(text, where)
        return s * np.eye(3)[i]
    v = np.asarray(text, float) if isinstance(text, (list, tuple, np.ndarray)) else np.zeros(0)
    if v.shape != (3,) or not np.all(np.isfinite(v)) or not np.linalg.norm(v) > 0:
        raise InputError("give an axis ('+x') or a non-zero vector [x, y, z] in the sensor frame", where)
    return v / np.linalg.norm(v)


def from_words(up: object, north: object, where: str = "position") -> np.ndarray:
    """The orientation ``R`` (ENU -> sensor, shape (3, 3)) of a position given by the sensor axis pointing up
    and the one pointing north (``"+z"``, ``"-x"`` or unit vectors in the sensor frame, perpendicular).

    Examples
    --------
    >>> R = from_words("+z", "+y")          # level, y north, x east: the identity
    >>> bool(np.allclose(R, np.eye(3)))
    True
    """
    u, n = _axis_vector(up, f"{where}.up"), _axis_vector(north, f"{where}.north")
    if abs(float(u @ n)) > 1e-3:
        raise InputError(f"up and north must be perpendicular (they are {np.degrees(np.arccos(np.clip(u @ n, -1, 1))):.3g} "
                         "deg apart)", where)
    n = n - (u @ n) * u
    n /= np.linalg.norm(n)
    return np.column_stack([np.cross(n, u), n, u])  # the sensor-frame coordinates of east, north, up


def from_angles(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """The orientation ``R`` (ENU -> sensor) of a position given as the sensor frame's attitude relative to
    north-east-down, aerospace Z-Y-X order (yaw about down from north, then pitch, then roll), rad. All zero: the
    sensor's x points north, y east, z down.

    Examples
    --------
    >>> R = from_angles(0.0, 0.0, 0.0)
    >>> R @ np.array([0.0, 0.0, 1.0])       # up is -z of the sensor
    array([ 0.,  0., -1.])
    """
    from scipy.spatial.transform import Rotation

    c_ned_from_sensor = Rotation.from_euler("ZYX", [yaw, pitch, roll]).as_matrix()
    return (ENU_FROM_NED @ c_ned_from_sensor).T


def scheme(name: str) -> tuple[tuple[str, np.ndarray], ...]:
    """The positions of a standard scheme (:data:`SCHEMES`: ``six``, ``twelve``, ``twenty-four``; ``6``, ``12``,
    ``24`` too) as (name ``"+x up, +y north"``, ``R``)."""
    key = {"6": "six", "12": "twelve", "24": "twenty-four"}.get(str(name).strip(), str(name).strip().lower())
    if key not in SCHEMES:
        raise InputError(f"no scheme '{name}'; the schemes are {', '.join(SCHEMES)}", "scheme")
    return tuple((f"{u} up, {n} north", from_words(u, n)) for u, n in SCHEMES[key])


@dataclass(frozen=True)
class Reading:
    """One static position: its name, orientation ``R`` (ENU -> sensor, (3, 3)), and the mean gyro (rad/s) and
    accelerometer (m/s^2) readings (3,) with their 1-sigma (3,) (of the mean, not of one sample)."""

    name: str
    R: np.ndarray
    gyro: np.ndarray
    gyro_sigma: np.ndarray
    accel: np.ndarray
    accel_sigma: np.ndarray


@dataclass(frozen=True)
class AxisFit:
    """The fit of one sensor axis: parameter names (``b_x``, ``K_xy``, ``M_xy``), values (NaN: not observable),
    covariance (NaN rows for the not observable), observability words, the design's rank and condition
    (column-scaled, over its non-zero singular values)."""

    names: tuple[str, ...]
    value: np.ndarray
    cov: np.ndarray
    status: tuple[str, ...]
    rank: int
    condition: float

    def get(self, name: str) -> tuple[float, float, str]:
        """Value, 1-sigma and observability of one parameter."""
        k = self.names.index(name)
        return float(self.value[k]), float(np.sqrt(self.cov[k, k])), self.status[k]


@dataclass(frozen=True)
class SensorFit:
    """One sensor's fit: ``sensor``, one :class:`AxisFit` per axis, the residuals per position ((3,), SI),
    chi-square and its degrees of freedom per axis, and notes (e.g. sigmas widened for a misfit)."""

    sensor: str
    axes: tuple[AxisFit, ...]
    residuals: dict = field(default_factory=dict)
    chi2: tuple[float, ...] = ()
    dof: tuple[int, ...] = ()
    notes: tuple[str, ...] = ()

    def param(self, kind: str, i: int, j: int | None = None) -> tuple[float, float, str]:
        """``kind`` ``"b"``, ``"M"`` or ``"K"`` of axis ``i`` (column ``j``): value, 1-sigma, observability."""
        return self.axes[i].get(f"{kind}_{AXES[i]}" + ("" if j is None else AXES[j]))

    def matrix(self, kind: str) -> np.ndarray:
        """``M`` or ``K`` (3, 3), NaN where not observable."""
        return np.array([[self.param(kind, i, j)[0] for j in range(3)] for i in range(3)])

    def bias(self) -> np.ndarray:
        return np.array([self.param("b", i)[0] for i in range(3)])


@dataclass(frozen=True)
class PositionsFit:
    """Both sensors' fits of a multi-position session, with the latitude (rad) and gravity (m/s^2) used."""

    gyroscope: SensorFit
    accelerometer: SensorFit
    latitude: float
    gravity: float
    positions: tuple[str, ...]


def _wls(X: np.ndarray, y: np.ndarray, s: np.ndarray, names: tuple[str, ...],
         kinds: tuple[str, ...]) -> tuple[AxisFit, np.ndarray, float, int]:
    """Weighted least squares with estimability: fit, residuals, chi-square, degrees of freedom."""
    Xw, yw = X / s[:, None], y / s
    d = np.linalg.norm(Xw, axis=0)
    d[d == 0] = 1.0
    U, S, Vt = np.linalg.svd(Xw / d, full_matrices=False)
    r = int(np.sum(S > S[0] * 1e-9)) if S.size and S[0] > 0 else 0
    V, Sr = Vt[:r].T, S[:r]
    theta = (V @ ((U[:, :r].T @ yw) / Sr)) / d
    cov = (V / Sr**2) @ V.T / np.outer(d, d)
    estimable = np.linalg.norm(V @ V.T - np.eye(len(d)), axis=0) < 1e-6
    res = y - X @ theta
    dof = len(y) - r
    chi2 = float(np.sum((res / s) ** 2))
    value = np.where(estimable, theta, np.nan)
    cov = np.where(np.outer(estimable, estimable), cov, np.nan)
    status = tuple(NOT_OBSERVABLE if not e else WEAK if np.sqrt(cov[k, k]) > USEFUL[kinds[k]] else OBSERVABLE
                   for k, e in enumerate(estimable))
    cond = float(Sr[0] / Sr[-1]) if r else np.inf
    return AxisFit(names, value, cov, status, r, cond), res, chi2, dof


def _sensor(sensor: str, X: np.ndarray, Y: np.ndarray, S: np.ndarray, names: list[str], kinds: tuple[str, ...],
            labels: tuple[str, ...]) -> SensorFit:
    from scipy.stats import chi2 as chi2_dist

    axes, res, chis, dofs, notes = [], np.zeros_like(Y), [], [], []
    for i in range(3):
        fit, r, c, dof = _wls(X, Y[:, i], S[:, i], tuple(n.format(i=AXES[i]) for n in names), kinds)
        if dof > 0 and chi2_dist.sf(c, dof) < 1e-3:  # the residuals exceed what the stated noise explains
            cov = fit.cov * (c / dof)
            status = tuple(st if st == NOT_OBSERVABLE else WEAK if np.sqrt(cov[k, k]) > USEFUL[kinds[k]] else st
                           for k, st in enumerate(fit.status))
            fit = AxisFit(fit.names, fit.value, cov, status, fit.rank, fit.condition)
            notes.append(f"{sensor} {AXES[i]}: residuals {np.sqrt(c / dof):.3g} times the stated noise (chi-square "
                         f"{c:.3g} on {dof}): sigmas widened by that factor; check the orientations and the noise")
        axes.append(fit)
        res[:, i] = r
        chis.append(c)
        dofs.append(dof)
    return SensorFit(sensor, tuple(axes), {k: res[n] for n, k in enumerate(labels)}, tuple(chis), tuple(dofs),
                     tuple(notes))


def fit_positions(readings: list[Reading], latitude: float, gravity: float = STANDARD_GRAVITY,
                  g_sensitivity: bool = True, gyro_M: np.ndarray | None = None) -> PositionsFit:
    """Gyro and accelerometer parameters from static positions (module docstring).

    Parameters
    ----------
    readings : list of Reading
        The positions (orientation ENU -> sensor, means and their 1-sigma, SI).
    latitude : float
        Geodetic latitude, rad.
    gravity : float
        Local gravity, m/s^2.
    g_sensitivity : bool
        Model the gyro's ``K_ga``; False assumes it zero (said in the notes).
    gyro_M : ndarray, shape (3, 3), optional
        The gyro's ``M`` known (a rate-table calibration): Earth rate is removed through it and ``M_g`` is not
        estimated; None: ``M_g`` estimated where observable.

    Returns
    -------
    PositionsFit
        Per sensor and axis the parameters ``b``, ``M`` (and ``K`` for the gyro) with 1-sigma and observability.

    Examples
    --------
    Six positions of a perfect sensor with a gyro bias: the bias comes back, Earth rate cancels, and ``M_g``
    and ``K_ga`` cannot be told apart (not observable).

    >>> b = np.array([1e-4, -2e-4, 3e-4])
    >>> reads = []
    >>> for name, R in scheme("six"):
    ...     w, f = R @ earth_rate_enu(np.radians(45)), R @ [0, 0, STANDARD_GRAVITY]
    ...     reads.append(Reading(name, R, w + b, np.full(3, 1e-6), f, np.full(3, 1e-4)))
    >>> fit = fit_positions(reads, np.radians(45))
    >>> bool(np.allclose(fit.gyroscope.bias(), b)), fit.gyroscope.param("M", 0, 0)[2]
    (True, 'not observable')
    """
    if len(readings) < 4:
        raise InputError(f"only {len(readings)} positions: at least 4 (the six of the 'six' scheme for all "
                         "accelerometer parameters)", "{positions}")
    if not -np.pi / 2 <= latitude <= np.pi / 2:
        raise InputError(f"latitude {np.degrees(latitude):.6g} deg is outside -90..90 deg", "{latitude}")
    labels = tuple(r.name for r in readings)
    R = np.array([np.asarray(r.R, float) for r in readings])
    f = R @ np.array([0.0, 0.0, gravity])
    w = R @ earth_rate_enu(latitude)
    one = np.ones((len(readings), 1))
    sig = [np.array([np.asarray(getattr(r, k), float) for r in readings]) for k in ("gyro_sigma", "accel_sigma")]
    if not all(np.all(np.isfinite(s)) and np.all(s > 0) for s in sig):
        raise InputError("every position needs a finite noise sigma > 0 for both sensors", "{positions}")
    ya = np.array([r.accel for r in readings], float)
    acc = _sensor("accelerometer", np.hstack([one, f]), ya, sig[1], ["b_{i}", "M_{i}x", "M_{i}y", "M_{i}z"],
                  ("b", "M", "M", "M"), labels)
    yg = np.array([r.gyro for r in readings], float)
    cols, names, kinds, notes = [one], ["b_{i}"], ["b"], []
    if g_sensitivity:
        cols.append(f)
        names += ["K_{i}x", "K_{i}y", "K_{i}z"]
        kinds += ["K"] * 3
    else:
        notes.append("g-sensitivity K_ga assumed zero (not modelled)")
    if gyro_M is None:
        cols.append(w)
        names += ["M_{i}x", "M_{i}y", "M_{i}z"]
        kinds += ["M"] * 3
    else:
        yg = yg - w @ np.asarray(gyro_M, float).T
        notes.append("gyro M given (not estimated): Earth rate removed through it")
    gyr = _sensor("gyroscope", np.hstack(cols), yg, sig[0], names, tuple(kinds), labels)
    gyr = SensorFit(gyr.sensor, gyr.axes, gyr.residuals, gyr.chi2, gyr.dof, tuple(notes) + gyr.notes)
    return PositionsFit(gyr, acc, float(latitude), float(gravity), labels)


#: the keys of a positions file and of its ``[[position]]`` tables
FILE_KEYS = ("latitude", "gravity", "scheme", "position")
POSITION_KEYS = ("name", "up", "north", "roll", "pitch", "yaw", "start", "end")


def _angle(value: object, where: str) -> float:
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return math.radians(float(value))
    return parse_quantity(value, "angle", where)  # type: ignore[arg-type]


def parse_positions_file(spec: dict, where: str) -> tuple[list[tuple[str, np.ndarray, tuple[int, int] | None]],
                                                           float | None, float | None]:
    """The positions of a positions file (module docstring): (name, ``R`` ENU -> sensor, samples or None) in
    order, its latitude (rad) and gravity (m/s^2), each None when not given."""
    if not isinstance(spec, dict):
        raise InputError("a positions file holds latitude, gravity, scheme or [[position]] tables", where)
    check_keys(spec, FILE_KEYS, where)
    lat = None if "latitude" not in spec else _angle(spec["latitude"], f"{where}: latitude")
    grav = None if "gravity" not in spec else parse_quantity(spec["gravity"], "acceleration", f"{where}: gravity")
    found = tables(spec, "position", where)
    if ("scheme" in spec) == bool(found):
        raise InputError("give the positions once: a scheme (six, twelve, twenty-four) or [[position]] tables", where)
    if "scheme" in spec:
        try:
            return [(n, R, None) for n, R in scheme(str(spec["scheme"]))], lat, grav
        except InputError as exc:
            raise InputError(exc.message, f"{where}: scheme") from None
    out: list[tuple[str, np.ndarray, tuple[int, int] | None]] = []
    for k, p in enumerate(found, start=1):
        at = f"{where}: position {k}"
        check_keys(p, POSITION_KEYS, at)
        name = str(p.get("name", f"position {k}"))
        if any(n == name for n, _, _ in out):
            raise InputError(f"two positions are named '{name}': give each its own name", at)
        words, angles = {"up", "north"} & set(p), {"roll", "pitch", "yaw"} & set(p)
        if words and angles or (words and len(words) < 2) or not (words or angles):
            raise InputError("give the orientation as up and north, or as roll, pitch and yaw", at)
        R = (from_words(p["up"], p["north"], at) if words else
             from_angles(*(_angle(p.get(a, 0.0), f"{at}.{a}") for a in ("roll", "pitch", "yaw"))))
        if ("start" in p) != ("end" in p):
            raise InputError("give both start and end (samples, end exclusive), or neither", at)
        samples = None
        if "start" in p:
            a, b = p["start"], p["end"]
            if not all(isinstance(v, int) and not isinstance(v, bool) and v >= 0 for v in (a, b)) or b <= a:
                raise InputError(f"start and end must be samples 0 <= start < end, not {a!r}, {b!r}", at)
            samples = (a, b)
        out.append((name, R, samples))
    if len({s is None for _, _, s in out}) > 1:
        raise InputError("give start/end for every position or for none (automatic detection)", where)
    return out, lat, grav


def simulate_means(positions: tuple[tuple[str, np.ndarray], ...], latitude: float, M_g: np.ndarray, b_g: np.ndarray,
                   K_ga: np.ndarray, M_a: np.ndarray, b_a: np.ndarray, gyro_sigma: float, accel_sigma: float,
                   rng: np.random.Generator, gravity: float = STANDARD_GRAVITY) -> list[Reading]:
    """Readings of the positions for a known truth (``simulate`` rehearses the test with it): each position's
    mean with white noise of the stated 1-sigma (of the mean, rad/s and m/s^2) drawn by ``rng``."""
    out = []
    for name, R in positions:
        w, f = R @ earth_rate_enu(latitude), R @ np.array([0.0, 0.0, gravity])
        g = M_g @ w + K_ga @ f + b_g + rng.normal(0.0, gyro_sigma, 3)
        a = M_a @ f + b_a + rng.normal(0.0, accel_sigma, 3)
        out.append(Reading(name, R, g, np.full(3, gyro_sigma), a, np.full(3, accel_sigma)))
    return out


def simulate_session(positions: tuple[tuple[str, np.ndarray], ...], latitude: float, truth: dict, rate_hz: float,
                     dwell_s: float, move_s: float, gyro_noise: float, accel_noise: float, rng: np.random.Generator,
                     gravity: float = STANDARD_GRAVITY) -> tuple[np.ndarray, np.ndarray, np.ndarray, list]:
    """A session log for ``imu-align simulate``'s rehearsal: each position held ``dwell_s``, reached from the last
    by a turn at constant rate about one axis lasting ``move_s``; ``truth`` holds ``M_g``, ``b_g``, ``K_ga``, ``M_a``,
    ``b_a`` (SI); white noise of ``gyro_noise`` (rad/s/sqrt(Hz)) and ``accel_noise`` (m/s^2/sqrt(Hz)).

    Returns
    -------
    t (n,) s, gyro (n, 3) rad/s, accel (n, 3) m/s^2, and each position's samples ``(start, end)``.
    """
    from scipy.spatial.transform import Rotation

    nd, nm = int(round(dwell_s * rate_hz)), int(round(move_s * rate_hz))
    omega, up = earth_rate_enu(latitude), np.array([0.0, 0.0, gravity])
    Rs, ws, ranges = [], [], []
    for k, (_, R) in enumerate(positions):
        if k:
            prev = np.asarray(positions[k - 1][1], float)
            phi = Rotation.from_matrix(prev @ np.asarray(R, float).T).as_rotvec()  # sensor frame, rad
            for j in range(nm):
                Rs.append(Rotation.from_rotvec(-phi * (j + 0.5) / nm).as_matrix() @ prev)
                ws.append(phi / move_s)
        ranges.append((len(Rs), len(Rs) + nd))
        Rs += [np.asarray(R, float)] * nd
        ws += [np.zeros(3)] * nd
    Rt, body = np.array(Rs), np.array(ws)
    f, w = Rt @ up, Rt @ omega + body
    g = w @ truth["M_g"].T + f @ truth["K_ga"].T + truth["b_g"] + rng.normal(0, gyro_noise * np.sqrt(rate_hz), w.shape)
    a = f @ truth["M_a"].T + truth["b_a"] + rng.normal(0, accel_noise * np.sqrt(rate_hz), f.shape)
    return np.arange(len(f)) / rate_hz, g, a, ranges


__all__ = ["SCHEMES", "USEFUL", "Reading", "AxisFit", "SensorFit", "PositionsFit", "from_words", "from_angles",
           "scheme", "fit_positions", "simulate_means", "simulate_session", "parse_positions_file", "ENU_FROM_NED", "EARTH_RATE"]
