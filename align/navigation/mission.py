"""Missions: the true motion the residual errors are propagated along.

A mission is the true gyro rates (inertial, body frame) and specific force of a body sampled at
``fs`` over its duration, its initial attitude and the navigation settings (latitude, Earth rate,
gravity). Three kinds:

* **static**: level at a heading, at rest (the gyros read the Earth rate when it is included);
* **manoeuvre**: a sensitivity manoeuvre file's rotations about a fixed point, each over
  ``|angle| / turn_rate`` with a smooth rate profile ``w(t) = 2 (angle / d) sin^2(pi t / d)``
  (zero rate and acceleration at both ends), spread with equal rests between them over the mission;
  or its ``[series]`` of rates (read at ``fs`` by linear interpolation, at rest after its end);
* **recorded**: a log's own gyro and accelerometer readings taken as the truth (what the residual
  errors would add along that trajectory).

For rotations about a fixed point the specific force is ``f = C^T (0, 0, -g)`` and the gyros read
``w_nb + C^T omega_ie``.

Public names
------------
Mission, static_mission, rotation_mission, rate_mission, recorded_mission, manoeuvre_mission
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.attitude import integrate
from align.errors import InputError
from align.navigation.strapdown import earth_rate_ned, euler_from_quat, normal_gravity, quat_from_euler, rotate
from align.units import DEG
from align.values import Value

#: the kinds of mission
KINDS = ("static", "manoeuvre", "recorded")


@dataclass(frozen=True, eq=False)
class Mission(Value):
    """The true motion of a mission (module docstring).

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    fs : float
        Sample rate, Hz.
    w, f : ndarray, shape (n, 3)
        True gyro rates (rad/s) and specific force (m/s^2).
    q0 : ndarray, shape (4,)
        Initial attitude, body to NED.
    latitude : float
        rad.
    earth_rate : bool
    gravity : float
        m/s^2.
    description : str
    """

    kind: str
    fs: float
    w: np.ndarray
    f: np.ndarray
    q0: np.ndarray
    latitude: float = 0.0
    earth_rate: bool = False
    gravity: float = 9.80665
    description: str = ""

    @property
    def duration(self) -> float:
        """s."""
        return (len(self.w) - 1) / self.fs

    @property
    def heading(self) -> float:
        """Initial heading, rad."""
        return float(euler_from_quat(self.q0)[2])

    @property
    def earth_body(self) -> np.ndarray:
        """The Earth rate in the initial body frame, rad/s (zero when left out)."""
        if not self.earth_rate:
            return np.zeros(3)
        return rotate(self.q0 * np.array([1, -1, -1, -1]), earth_rate_ned(self.latitude))

    def to_dict(self) -> dict:
        """The mission's settings (not its samples), display units."""
        return {"kind": self.kind, "description": self.description, "duration_s": self.duration, "rate_hz": self.fs,
                "initial_attitude_deg": dict(zip(("roll", "pitch", "heading"), (euler_from_quat(self.q0) / DEG).tolist())),
                "latitude_deg": self.latitude / DEG, "earth_rate": self.earth_rate, "gravity_m_s2": self.gravity}


def _samples(duration: float, fs: float) -> int:
    if not (np.isfinite(duration) and duration > 0):
        raise InputError("the mission needs a duration > 0", "{duration}")
    if not (np.isfinite(fs) and fs > 0):
        raise InputError("the sample rate must be > 0", "{rate_hz}")
    n = int(round(duration * fs)) + 1
    if n < 3:
        raise InputError(f"{duration:g} s at {fs:g} Hz is fewer than 3 samples", "{duration}")
    if n > 50_000_001:
        raise InputError(f"{duration:g} s at {fs:g} Hz is {n:,} samples per run; lower {{rate_hz}}", "{duration}")
    return n


def _settings(latitude: float, gravity: float | None) -> float:
    return normal_gravity(latitude) if gravity is None else float(gravity)


def _moving(w_nb: np.ndarray, fs: float, q0: np.ndarray, latitude: float, earth_rate: bool,
            g: float) -> tuple[np.ndarray, np.ndarray]:
    """Gyro rates and specific force of rotations ``w_nb`` (n, 3) about a fixed point."""
    q = integrate(w_nb, 1.0 / fs, q0)
    conj = q * np.array([1.0, -1.0, -1.0, -1.0])
    f = rotate(conj, np.array([0.0, 0.0, -g]))
    w = w_nb + (rotate(conj, earth_rate_ned(latitude)) if earth_rate else 0.0)
    return w, f


def static_mission(duration: float, fs: float, heading: float = 0.0, latitude: float = 0.0, earth_rate: bool = False,
                   gravity: float | None = None) -> Mission:
    """A level body at rest for ``duration`` s at heading ``heading`` (rad)."""
    n = _samples(duration, fs)
    g = _settings(latitude, gravity)
    q0 = quat_from_euler(0.0, 0.0, heading)
    conj = q0 * np.array([1.0, -1.0, -1.0, -1.0])
    f = np.tile(rotate(conj, np.array([0.0, 0.0, -g])), (n, 1))  # at rest: constant readings
    w = np.tile(rotate(conj, earth_rate_ned(latitude)) if earth_rate else np.zeros(3), (n, 1))
    return Mission("static", fs, w, f, q0, latitude, earth_rate, g, f"level, at rest, heading {heading / DEG:g} deg")


def rotation_mission(segments, duration: float, fs: float, turn_rate: float, heading: float = 0.0,
                     latitude: float = 0.0, earth_rate: bool = False, gravity: float | None = None,
                     description: str = "") -> Mission:
    """Rotations ``segments`` ((axis "x"/"y"/"z", signed angle rad), ...) spread over the mission (module docstring).

    Raises
    ------
    InputError
        The rotations at ``turn_rate`` take longer than the mission.
    """
    n = _samples(duration, fs)
    if not (np.isfinite(turn_rate) and turn_rate > 0):
        raise InputError("the turn rate must be > 0", "{turn_rate}")
    spans = [abs(a) / turn_rate for _, a in segments]
    rest = (duration - sum(spans)) / (len(spans) + 1)
    if rest < 0:
        raise InputError(f"the rotations take {sum(spans):.4g} s at this turn rate, more than the mission's "
                         f"{duration:.4g} s; raise {{turn_rate}} or {{duration}}", "{manoeuvre}")
    t = np.arange(n) / fs
    w = np.zeros((n, 3))
    start = rest
    for (axis, angle), d in zip(segments, spans):
        inside = (t >= start) & (t <= start + d)
        w[inside, "xyz".index(axis)] = 2 * angle / d * np.sin(np.pi * (t[inside] - start) / d) ** 2
        start += d + rest
    g = _settings(latitude, gravity)
    q0 = quat_from_euler(0.0, 0.0, heading)
    wi, f = _moving(w, fs, q0, latitude, earth_rate, g)
    text = description or "; ".join(f"{a} {v / DEG:+g} deg" for a, v in segments)
    return Mission("manoeuvre", fs, wi, f, q0, latitude, earth_rate, g,
                   f"{text} at {turn_rate / DEG:g} deg/s (mean), rests of {rest:.4g} s")


def rate_mission(t_series: np.ndarray, w_series: np.ndarray, duration: float, fs: float, heading: float = 0.0,
                 latitude: float = 0.0, earth_rate: bool = False, gravity: float | None = None,
                 description: str = "") -> Mission:
    """Body rates (rad/s) given at times ``t_series`` (s), read at ``fs`` from the series' start; at rest after its end."""
    n = _samples(duration, fs)
    t = np.arange(n) / fs
    ts = np.asarray(t_series, float) - float(t_series[0])
    ws = np.asarray(w_series, float)
    w = np.stack([np.interp(t, ts, ws[:, j], right=0.0) for j in range(3)], axis=1)
    g = _settings(latitude, gravity)
    q0 = quat_from_euler(0.0, 0.0, heading)
    wi, f = _moving(w, fs, q0, latitude, earth_rate, g)
    return Mission("manoeuvre", fs, wi, f, q0, latitude, earth_rate, g, description or "rate series")


def recorded_mission(gyro: np.ndarray, accel: np.ndarray, fs: float, q0: np.ndarray, latitude: float = 0.0,
                     earth_rate: bool = False, gravity: float | None = None, description: str = "") -> Mission:
    """A log's own readings (rad/s, m/s^2, shape (n, 3)) as the true motion, from the attitude ``q0``."""
    gyro, accel = np.asarray(gyro, float), np.asarray(accel, float)
    if gyro.shape != accel.shape or gyro.ndim != 2 or gyro.shape[1] != 3 or len(gyro) < 3:
        raise InputError("a recorded trajectory needs gyro and accelerometer columns of equal length (>= 3 rows)",
                         "{log}")
    return Mission("recorded", fs, gyro, accel, np.asarray(q0, float), latitude, earth_rate,
                   _settings(latitude, gravity), description or f"recorded, {len(gyro)} samples")


def manoeuvre_mission(data: dict, where: str, base_dir, duration: float, fs: float, turn_rate: float,
                      heading: float = 0.0, latitude: float = 0.0, earth_rate: bool = False,
                      gravity: float | None = None) -> Mission:
    """The mission of a sensitivity manoeuvre file (parsed TOML ``data``; checked by
    :func:`align.sensitivity.manoeuvre_from_dict`): its ``[[rotation]]`` steps at ``turn_rate``
    (:func:`rotation_mission`), or its ``[series]`` of rates (:func:`rate_mission`)."""
    from align.io import read_log
    from align.io.formats import LogFormat
    from align.io.keys import file_name
    from align.sensitivity import manoeuvre_from_dict

    man = manoeuvre_from_dict(data, where, base_dir)
    if man.segments:
        return rotation_mission(man.segments, duration, fs, turn_rate, heading=heading, latitude=latitude,
                                earth_rate=earth_rate, gravity=gravity, description=man.description)
    series = data["series"]  # read as the manoeuvre reader read it (its checks passed)
    cols = series.get("columns", "time,wx,wy,wz")
    cols = [c.strip() for c in cols.split(",")] if isinstance(cols, str) else [c.strip() for c in cols]
    path = file_name(series, "file", f"{where}: series.file", "rates.csv", base_dir)
    t, w = read_log(path, cols[1:], series.get("units", "deg/s"), cols[0],
                    log_format=LogFormat(time_units=series.get("time_units", "s")))
    return rate_mission(t, w, duration, fs, heading=heading, latitude=latitude, earth_rate=earth_rate, gravity=gravity,
                        description=man.description)
