"""Rate-table session simulator: known truth for rehearsals, tests and examples.

The table runs a :class:`~align.plan.Plan`: a static gap, then for each step a
ramp up at a constant angular acceleration, the dwell (rate steps) or cruise
(angle steps), a ramp down, and another static gap. The gyros read
``g = M (w_table + w_earth) + b(t) + noise`` with ``b(t)`` a turn-on bias plus a
random walk, white noise from a noise density, an optional table rate/angle
error and saturation at a stated range.

Public names
------------
SessionSpec, simulate_session, random_model, SimulationTruth
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from align import CONVENTION
from align.alignment.plan import Plan
from align.earth import earth_rate_in_frame
from align.errors import InputError
from align.model import SensorModel
from align.plausible import malformed
from align.results import Result, file_unit
from align.units import DEG, DEG_S, to_unit


@dataclass(frozen=True)
class SessionSpec:
    """How the simulated table and gyros behave (SI units).

    Attributes
    ----------
    fs : float
        Sample rate, Hz.
    dwell_s : float
        Constant-rate part of each rate step, s.
    static_s : float
        Static gap before the first step, between steps and after the last, s.
    accel : float
        Table angular acceleration on the ramps, rad/s^2.
    turn_rate : float
        Cruise rate of angle steps, rad/s.
    noise_density : float
        White rate noise, rad/s/sqrt(Hz) (numerically the ARW in rad/sqrt(s)).
    bias_walk : float
        Rate random walk of the bias, rad/s/sqrt(s).
    table_rate_error : float
        Relative error of the table rate (the table turns at ``rate (1 + e)``).
    table_angle_error : float
        Relative error of the table angle for angle steps.
    latitude : float or None
        Adds Earth rate (rad) when set.
    gyro_range : float or None
        Saturation, rad/s.
    """

    fs: float = 200.0
    dwell_s: float = 10.0
    static_s: float = 3.0
    accel: float = 200.0 * DEG
    turn_rate: float = 30.0 * DEG_S
    noise_density: float = 0.005 * DEG_S
    bias_walk: float = 0.0
    table_rate_error: float = 0.0
    table_angle_error: float = 0.0
    latitude: float | None = None
    gyro_range: float | None = None

    def __post_init__(self) -> None:
        """Refuse values outside their domain, each named as its input (``{dwell_s}``, ``{fs}``)."""
        rules = {"fs": (self.fs, 0.0, True), "dwell_s": (self.dwell_s, 0.0, True), "static_s": (self.static_s, 0.0, False),
                 "accel": (self.accel, 0.0, True), "turn_rate": (self.turn_rate, 0.0, True),
                 "noise_density": (self.noise_density, 0.0, False), "bias_walk": (self.bias_walk, 0.0, False),
                 "table_rate_error": (self.table_rate_error, -1.0, True),
                 "table_angle_error": (self.table_angle_error, -1.0, True)}
        if self.gyro_range is not None:
            rules["gyro_range"] = (self.gyro_range, 0.0, True)
        for name, (x, low, strict) in rules.items():
            if not (np.isfinite(x) and (x > low if strict else x >= low)):
                raise InputError(f"must be finite and {'>' if strict else '>='} {low:g} (got {float(x):g})", "{" + name + "}")
        if self.latitude is not None and not (np.isfinite(self.latitude) and abs(self.latitude) <= np.pi / 2):
            raise InputError(f"must lie within -90 and 90 deg (got {float(self.latitude) / DEG:g} deg)", "{latitude}")


#: the most samples a simulated session may hold (about 5 GB of arrays)
MAX_SAMPLES = 200_000_000


def _profile(step, spec: SessionSpec) -> np.ndarray:
    """Table rate magnitude profile (signed, rad/s) for one step, without gaps."""
    dt = 1.0 / spec.fs
    if step.rate is not None:
        peak = step.rate * (1.0 + spec.table_rate_error)
        t_ramp = abs(peak) / spec.accel
        cruise = spec.dwell_s
    else:
        total = abs(step.angle) * (1.0 + spec.table_angle_error)
        peak_abs = min(spec.turn_rate, np.sqrt(total * spec.accel))
        t_ramp = peak_abs / spec.accel
        cruise = (total - peak_abs * t_ramp) / peak_abs
        peak = np.sign(step.angle) * peak_abs
    n_ramp = max(int(np.ceil(t_ramp / dt)), 1)
    ramp = np.linspace(0.0, 1.0, n_ramp, endpoint=False) + 0.5 / n_ramp
    n_cruise = int(np.floor(cruise / dt))
    prof = np.concatenate([ramp, np.ones(n_cruise), ramp[::-1]]) * peak
    if step.angle is not None:  # put the last fraction of a sample back so the angle is exact
        want = step.angle * (1.0 + spec.table_angle_error)
        prof *= want / (prof.sum() * dt)
    return prof


def _check_size(plan: Plan, spec: SessionSpec) -> None:
    """Refuse a session too long to hold in memory, before any array is made (a bound from above:
    each step's ramps, its dwell or its turn at the slowest cruise, and the gaps)."""
    seconds = (len(plan.steps) + 1) * spec.static_s
    for step in plan.steps:
        if step.rate is not None:
            seconds += spec.dwell_s + 2 * abs(step.rate) * (1 + abs(spec.table_rate_error)) / spec.accel
        else:
            total = abs(step.angle) * (1 + abs(spec.table_angle_error))
            seconds += total / min(spec.turn_rate, np.sqrt(total * spec.accel)) + 2 * spec.turn_rate / spec.accel
    n = seconds * spec.fs
    if not n <= MAX_SAMPLES:
        raise InputError(f"the session would hold about {n:.3g} samples, more than {MAX_SAMPLES:.0e}: shorten "
                         "{dwell_s} or {static_s}, or lower {fs}", "simulation")


def simulate_session(plan: Plan, model: SensorModel, spec: SessionSpec = SessionSpec(), seed: int | np.random.Generator = 0):
    """Simulate the gyro log of a rate-table session.

    Parameters
    ----------
    plan : Plan
        The steps to run, in order.
    model : SensorModel
        True ``M`` and turn-on bias (rad/s).
    spec : SessionSpec
    seed : int or numpy.random.Generator

    Returns
    -------
    t : ndarray, shape (n,)
        Time, s, from 0 at ``spec.fs``.
    g : ndarray, shape (n, 3)
        Gyro readings, rad/s.
    w : ndarray, shape (n, 3)
        True angular rate of the system frame, rad/s (table plus Earth).
    """
    rng = np.random.default_rng(seed)
    _check_size(plan, spec)
    gap = np.zeros(int(round(spec.static_s * spec.fs)))
    pieces, axes = [], []
    for step in plan.steps:
        prof = _profile(step, spec)
        for part in (gap, prof):
            pieces.append(part)
            axes.append(np.repeat(step.unit_axis[None, :], len(part), axis=0))
    pieces.append(gap)
    axes.append(np.repeat(plan.steps[-1].unit_axis[None, :], len(gap), axis=0))
    rate = np.concatenate(pieces)
    up = np.concatenate(axes)
    w = rate[:, None] * up
    n = len(rate)
    dt = 1.0 / spec.fs
    if spec.latitude is not None:
        heading = np.cumsum(rate) * dt
        start = 0
        for piece_axes in axes:  # Earth rate in the frame mounted for each step
            stop = start + len(piece_axes)
            if stop > start:
                w[start:stop] += earth_rate_in_frame(spec.latitude, piece_axes[0], heading[start:stop])
            start = stop
    bias = np.broadcast_to(model.bias, (n, 3))
    if spec.bias_walk > 0:
        bias = bias + np.cumsum(rng.standard_normal((n, 3)) * spec.bias_walk * np.sqrt(dt), axis=0)
    g = w @ model.M.T + bias + rng.standard_normal((n, 3)) * spec.noise_density * np.sqrt(spec.fs)
    if spec.gyro_range is not None:
        g = np.clip(g, -spec.gyro_range, spec.gyro_range)
    if not np.isfinite(g).all():
        raise InputError("the simulated readings overflow (not finite): lower {noise_density} or {bias_walk}",
                         "simulation")
    return np.arange(n) * dt, g, w


def random_model(rng: np.random.Generator, misalignment: float, scale_sd: float = 2e-3, delta_sd: float = 0.05 * DEG,
                 bias_sd: float = 0.2 * DEG) -> SensorModel:
    """A realistic random gyro model: a mounting rotation of size ``misalignment`` (rad) about a
    random axis, scale errors, non-orthogonality and a turn-on bias.

    ``M = diag(scale) N R^T`` (see :meth:`SensorModel.from_rotation`); ``scale ~ 1 + N(0, scale_sd)``,
    ``delta ~ N(0, delta_sd)`` rad, ``bias ~ N(0, bias_sd)`` rad/s.
    """
    from scipy.spatial.transform import Rotation

    rotvec = rng.normal(size=3)
    rotvec *= misalignment / np.linalg.norm(rotvec)
    return SensorModel.from_rotation(Rotation.from_rotvec(rotvec), scale=1 + rng.normal(0, scale_sd, 3),
                                     delta=rng.normal(0, delta_sd, 3), bias=rng.normal(0, bias_sd, 3))


class SimulationTruth(Result, format="imu-align.truth", convention=CONVENTION):
    """The true model of a simulated session (``truth.json``), to compare an alignment with.

    Attributes
    ----------
    model : SensorModel
        ``g = M w + b``, bias in rad/s.
    units : str
        File unit of the bias.
    seed : int or None
        The simulation's random seed.
    inputs : dict
    """

    model: SensorModel
    units: str = "deg/s"
    seed: int | None = None
    inputs: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {**self.envelope({"M": "1", "bias": self.units}), "M": self.model.M.tolist(),
                "A": self.model.alignment().tolist(), "bias": to_unit(self.model.bias, self.units).tolist(),
                "seed": self.seed, "inputs": self.inputs}

    @classmethod
    def from_dict(cls, d: dict, where: str = "truth") -> SimulationTruth:
        cls.check_envelope(d, where, keys=["M", "A", "bias", "seed", "inputs"])
        try:
            u, f = file_unit(d, "bias", "angular_rate", where)
            return cls(SensorModel(np.array(d["M"], float), np.array(d["bias"], float) * f), u, d.get("seed"),
                       dict(d.get("inputs", {})))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"malformed simulation truth ({malformed(exc)}); regenerate it", where) from None
