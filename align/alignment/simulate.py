"""Rate-table session simulator: known truth for rehearsals, tests and examples.

The table runs a :class:`~align.plan.Plan`: a static head, then for each step a
ramp up at a constant angular acceleration, the dwell (rate steps) or cruise
(angle steps), a ramp down, and a static gap. The gyros read::

    g = M (w_table + w_move + w_earth) + b(t) + noise

with ``b(t)`` a turn-on bias plus a random walk and flicker, white noise from a noise
density, an optional table rate/angle error and saturation at a stated range; each gyro's reading is bent
by its stated scale-factor asymmetry and nonlinearity (``scale_errors``,
:class:`~align.alignment.linearity.ScaleErrors`; several rates per axis: its ``linearity_plan``).

The physics is the simulator's own (:mod:`align.alignment.kinematics`, not the estimator's):
the orientation ``C`` (system axes in ENU) at the start of each step is the step's ``rest``
when stated, else the current one when the step's axis already points along its table axis,
else the smallest rotation that brings it there (the first step without ``rest``: a heading
about the table axis drawn from the seed when Earth's rate or moves depend on it, else 0).
With ``reorient`` the change of orientation is a move in the log (static, a turn at
``move_rate`` with ramps at ``accel``, static); without it the orientation just switches at the
start of the gap. Earth's rate ``C(t)^T Omega_e (0, cos L, sin L)`` is added when a latitude
is known (the plan's, or the spec's; they must agree).

Public names
------------
SessionSpec, Move, SimulatedSession, simulate_run, simulate_session, random_model, mount_model,
mounting_from_rotation, SimulationTruth
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial

import numpy as np

from align import CONVENTION
from align.alignment import kinematics as kin
from align.alignment.linearity import ScaleErrors
from align.alignment.plan import Plan
from align.alignment.timeline import Move, build_timeline
from align.errors import InputError
from align.flicker import flicker_fft, flicker_gm
from align.model import SensorModel
from align.results import Result, file_unit
from align.units import DEG, DEG_S, format_quantity, to_unit
from align.values import Value
from align.wellformed import malformed


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
        Static gap between steps and after the last (and on each side of a move), s.
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
        rad; adds Earth rate when set (the plan's latitude is used when this is None).
    gyro_range : float or None
        Saturation, rad/s.
    head_s : float or None
        Static time before the first step, s (0: the log starts moving); None: ``static_s``.
    reorient : bool
        Put each change of orientation between steps in the log as a move.
    move_rate : float
        Cruise rate of the moves, rad/s.
    flicker : float
        Bias instability coefficient ``B`` of each gyro (flicker, Allan floor ``0.664 B``), rad/s.
    scale_errors : ScaleErrors or None
        Each gyro's departure from a straight line (asymmetry, quadratic and cubic terms in its linear reading
        ``M w``, :class:`~align.alignment.linearity.ScaleErrors`); None: linear.
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
    head_s: float | None = None
    reorient: bool = False
    move_rate: float = 20.0 * DEG_S
    flicker: float = 0.0
    scale_errors: ScaleErrors | None = None

    def __post_init__(self) -> None:
        """Refuse values outside their domain, each named as its input (``{dwell_s}``, ``{fs}``)."""
        rules = {"fs": (self.fs, 0.0, True), "dwell_s": (self.dwell_s, 0.0, True), "static_s": (self.static_s, 0.0, False),
                 "accel": (self.accel, 0.0, True), "turn_rate": (self.turn_rate, 0.0, True),
                 "noise_density": (self.noise_density, 0.0, False), "bias_walk": (self.bias_walk, 0.0, False),
                 "table_rate_error": (self.table_rate_error, -1.0, True),
                 "table_angle_error": (self.table_angle_error, -1.0, True),
                 "move_rate": (self.move_rate, 0.0, True), "flicker": (self.flicker, 0.0, False)}
        if self.gyro_range is not None:
            rules["gyro_range"] = (self.gyro_range, 0.0, True)
        if self.head_s is not None:
            rules["head_s"] = (self.head_s, 0.0, False)
        for name, (x, low, strict) in rules.items():
            if not (np.isfinite(x) and (x > low if strict else x >= low)):
                raise InputError(f"must be finite and {'>' if strict else '>='} {low:g} (got {float(x):g})", "{" + name + "}")
        if self.latitude is not None and not (np.isfinite(self.latitude) and abs(self.latitude) <= np.pi / 2):
            raise InputError(f"must lie within -90 and 90 deg (got {float(self.latitude) / DEG:g} deg)", "{latitude}")

    @property
    def head(self) -> float:
        """Static time before the first step, s."""
        return self.static_s if self.head_s is None else self.head_s


#: the most samples a simulated session may hold (about 5 GB of arrays)
MAX_SAMPLES = 200_000_000


def _check_size(plan: Plan, spec: SessionSpec) -> None:
    """Refuse a session too long to hold in memory, before any array is made (a bound from above:
    each step's ramps, its dwell or its turn at the slowest cruise, the gaps and the moves)."""
    seconds = spec.head + len(plan.steps) * spec.static_s
    for step in plan.steps:
        if step.rate is not None:
            seconds += spec.dwell_s + 2 * abs(step.rate) * (1 + abs(spec.table_rate_error)) / spec.accel
        else:
            total = abs(step.turn) * (1 + abs(spec.table_angle_error))
            seconds += total / min(spec.turn_rate, np.sqrt(total * spec.accel)) + 2 * spec.turn_rate / spec.accel
    if spec.reorient:  # a move of at most half a turn, and a gap after it, before each step but the first
        move = np.pi / min(spec.move_rate, np.sqrt(np.pi * spec.accel)) + 2 * spec.move_rate / spec.accel
        seconds += (len(plan.steps) - 1) * (move + spec.static_s)
    n = seconds * spec.fs
    if not n <= MAX_SAMPLES:
        raise InputError(f"the session would hold about {n:.3g} samples, more than {MAX_SAMPLES:.0e}: shorten "
                         "{dwell_s} or {static_s}, or lower {fs}", "simulation")


@dataclass(frozen=True, eq=False)
class SimulatedSession(Value):
    """A simulated session with its truth.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Time, s, from 0 at ``fs``.
    g : ndarray, shape (n, 3)
        Gyro readings, rad/s.
    w : ndarray, shape (n, 3)
        True angular rate of the system frame, rad/s (table, moves and Earth).
    bias : ndarray, shape (n, 3)
        True bias path (turn-on, random walk, flicker), rad/s.
    rate : ndarray, shape (n,)
        Signed rate of the table or move about its axis, rad/s (0 when static).
    pieces : tuple of :class:`~align.alignment.kinematics.Piece`
        Static stretches, steps and moves in order, with the orientation at each one's start.
    moves : tuple of Move
        The re-orientation moves (empty without ``reorient``).
    latitude : float or None
        rad, the one simulated.
    heading : float
        Heading of the first step about its table axis, rad (when it had no stated rest).
    fs : float
        Hz.
    """

    t: np.ndarray
    g: np.ndarray
    w: np.ndarray
    bias: np.ndarray
    rate: np.ndarray
    pieces: tuple
    moves: tuple[Move, ...]
    latitude: float | None
    heading: float
    fs: float

    @property
    def steps(self) -> tuple[tuple[int, int], ...]:
        """(start, end) samples of each plan step, in plan order (end exclusive)."""
        return tuple((p.start, p.end) for p in self.pieces if p.kind == "step")

    @property
    def rests(self) -> tuple[np.ndarray, ...]:
        """Orientation ``C`` (3, 3) at the start of each plan step (system axes in ENU, columns)."""
        return tuple(p.c for p in self.pieces if p.kind == "step")

    def orientation(self, samples=None) -> np.ndarray:
        """Orientation ``C`` (k, 3, 3) at ``samples`` (all when None), K1 of :mod:`align.alignment.kinematics`."""
        idx = np.arange(len(self.t)) if samples is None else np.atleast_1d(samples)
        return kin.orientations(self.pieces, self.rate, 1.0 / self.fs, idx)


def _latitude(plan: Plan, spec: SessionSpec) -> float | None:
    """The latitude simulated: the spec's or the plan's; both given, they must agree."""
    if spec.latitude is not None and plan.latitude is not None and abs(spec.latitude - plan.latitude) > 1e-9:
        raise InputError(f"the plan states latitude {format_quantity(plan.latitude, 'deg', 6)} but "
                         f"{{latitude={format_quantity(spec.latitude, 'deg', 6)}}}: give one, or the same", "simulation")
    return spec.latitude if spec.latitude is not None else plan.latitude


def _simulate(plan: Plan, model: SensorModel, spec: SessionSpec, seed) -> dict:
    """The session's arrays and truth, writable (see :func:`simulate_run`)."""
    rng = np.random.default_rng(seed)
    _check_size(plan, spec)
    latitude = _latitude(plan, spec)
    # the first heading matters only to Earth's rate and to moves; drawn only then (other sessions keep their noise)
    heading = float(rng.uniform(0.0, 2 * np.pi)) if latitude is not None or spec.reorient else 0.0
    line = build_timeline(plan, spec, heading)
    rate = np.concatenate(line.rates)
    pieces = tuple(line.pieces)
    n, dt = len(rate), 1.0 / spec.fs
    w = kin.body_rates(pieces, rate, dt, latitude)
    bias = np.broadcast_to(model.bias, (n, 3))
    if spec.bias_walk > 0:
        bias = bias + np.cumsum(rng.standard_normal((n, 3)) * spec.bias_walk * np.sqrt(dt), axis=0)
    white = rng.standard_normal((n, 3)) * spec.noise_density * np.sqrt(spec.fs)
    if spec.flicker > 0:
        flicker = flicker_fft if n <= FFT_FLICKER_SAMPLES else partial(flicker_gm, bank=12)
        bias = bias + flicker(n, spec.fs, spec.flicker, rng, 3)
    g = (w @ model.M.T if spec.scale_errors is None else spec.scale_errors.apply(w @ model.M.T)) + bias + white
    if spec.gyro_range is not None:
        g = np.clip(g, -spec.gyro_range, spec.gyro_range)
    if not np.isfinite(g).all():
        raise InputError("the simulated readings overflow (not finite): lower {noise_density} or {bias_walk}",
                         "simulation")
    return {"t": np.arange(n) * dt, "g": g, "w": w, "bias": bias, "rate": rate, "pieces": pieces,
            "moves": tuple(line.moves), "latitude": latitude, "heading": heading, "fs": float(spec.fs)}


#: longer sessions get their flicker from a bank of Gauss-Markov processes instead of one FFT
FFT_FLICKER_SAMPLES = 1 << 24


def simulate_run(plan: Plan, model: SensorModel, spec: SessionSpec = SessionSpec(),
                 seed: int | np.random.Generator = 0) -> SimulatedSession:
    """Simulate a rate-table session and keep its truth.

    Parameters
    ----------
    plan : Plan
        The steps to run, in order, with their table axes and rests; its latitude adds Earth's rate.
    model : SensorModel
        True ``M`` (mounting included, see :func:`mount_model`) and turn-on bias (rad/s).
    spec : SessionSpec
    seed : int or numpy.random.Generator

    Returns
    -------
    SimulatedSession
        ``g = M (w_table + w_move + w_earth) + b(t) + noise`` (rad/s) with ``w``, ``b(t)``, the pieces and the moves.

    Raises
    ------
    InputError
        The spec's and the plan's latitudes disagree; a session too long to hold; readings not finite.
    """
    return SimulatedSession(**_simulate(plan, model, spec, seed))


def simulate_session(plan: Plan, model: SensorModel, spec: SessionSpec = SessionSpec(), seed: int | np.random.Generator = 0):
    """Simulate the gyro log of a rate-table session (:func:`simulate_run` without the truth).

    Parameters
    ----------
    plan : Plan
        The table steps: axes, rates (rad/s) and durations (s).
    model : SensorModel
        The truth: ``M`` (3, 3), dimensionless, and ``bias`` (3,), rad/s (``g = M w + b``, Eq 14-15).
    spec : SessionSpec
        Sample rate (Hz), dwell and static times (s), noise density (rad/s/sqrt(Hz)), table errors.
    seed : int or numpy.random.Generator
        As :func:`simulate_run`.

    Returns
    -------
    t : ndarray, shape (n,)
        Time, s, from 0 at ``spec.fs``.
    g : ndarray, shape (n, 3)
        Gyro readings, rad/s.
    w : ndarray, shape (n, 3)
        True angular rate of the system frame, rad/s (table, moves and Earth).

    Examples
    --------
    Noise-free readings follow ``g = M w + b`` exactly (Eq 14-15):

    >>> import numpy as np
    >>> from align.alignment.plan import Plan
    >>> from align.model import SensorModel
    >>> from align.units import DEG
    >>> M = np.array([[1.002, 0.003, -0.002], [-0.004, 0.998, 0.001], [0.002, -0.001, 1.001]])
    >>> b = np.array([0.01, -0.02, 0.005]) * DEG
    >>> t, g, w = simulate_session(Plan.standard_rate(100 * DEG), SensorModel(M, b), SessionSpec(noise_density=0.0))
    >>> g.shape == w.shape == (len(t), 3), bool(np.allclose(g, w @ M.T + b, atol=1e-12))
    (True, True)
    """
    run = _simulate(plan, model, spec, seed)
    return run["t"], run["g"], run["w"]


def random_model(rng: np.random.Generator, misalignment: float, scale_sd: float = 2e-3, delta_sd: float = 0.05 * DEG,
                 bias_sd: float = 0.2 * DEG, mounting: np.ndarray | None = None) -> SensorModel:
    """A realistic random gyro model: a mounting rotation of size ``misalignment`` (rad) about a
    random axis, scale errors, non-orthogonality and a turn-on bias, on a nominal ``mounting``.

    ``M = M_small N`` with ``M_small = diag(scale) D R^T`` (see :meth:`SensorModel.from_rotation`) and ``N`` the
    nominal mounting (rows: each gyro's nominal axis in the system frame; identity when None);
    ``scale ~ 1 + N(0, scale_sd)``, ``delta ~ N(0, delta_sd)`` rad, ``bias ~ N(0, bias_sd)`` rad/s.
    """
    from scipy.spatial.transform import Rotation

    rotvec = rng.normal(size=3)
    rotvec *= misalignment / np.linalg.norm(rotvec)
    small = SensorModel.from_rotation(Rotation.from_rotvec(rotvec), scale=1 + rng.normal(0, scale_sd, 3),
                                      delta=rng.normal(0, delta_sd, 3), bias=rng.normal(0, bias_sd, 3))
    return small if mounting is None else mount_model(small, mounting)


def _rotation(n: np.ndarray, where: str) -> np.ndarray:
    n = np.asarray(n, float)
    if n.shape != (3, 3) or not np.isfinite(n).all() or np.abs(n @ n.T - np.eye(3)).max() > 1e-6 \
            or np.linalg.det(n) < 0:
        raise InputError("a nominal mounting is a rotation (3 x 3, orthonormal rows, det +1)", where)
    return n


def mount_model(model: SensorModel, mounting: np.ndarray) -> SensorModel:
    """The model of an IMU mounted nominally by ``mounting`` ``N``: ``M = M_small N``, the same bias."""
    return SensorModel(model.M @ _rotation(mounting, "{mounting}"), model.bias)


def mounting_from_rotation(angle: float, axis) -> np.ndarray:
    """The nominal mounting ``N`` (3, 3) of an IMU turned by ``angle`` (rad) about ``axis`` (system frame):
    gyro ``i`` points along ``Rot(axis, angle) e_i``, so ``N = Rot(axis, angle)^T`` (rows: the gyro axes)."""
    axis = np.asarray(axis, float)
    norm = np.linalg.norm(axis)
    if axis.shape != (3,) or not np.isfinite(norm) or norm == 0 or not np.isfinite(angle):
        raise InputError("give a finite angle about a non-zero axis", "{mounting}")
    return kin.axis_rotation(axis / norm, angle).T


class SimulationTruth(Result, format="imu-align.truth", convention=CONVENTION):
    """The true model of a simulated session (``truth.json``), to compare an alignment with.

    Attributes
    ----------
    model : SensorModel
        ``g = M w + b``, bias in rad/s; ``M`` includes the nominal mounting.
    units : str
        File unit of the bias.
    seed : int or None
        The simulation's random seed.
    inputs : dict
    mounting : ndarray, shape (3, 3), or None
        The nominal mounting ``N`` simulated (``M N^T`` is the small part), None when not recorded.
    moves : tuple of Move
        The re-orientation moves in the log.
    bias_mean : ndarray, shape (3,), or None
        Mean of the true bias path over the session, rad/s: what an alignment's bias estimates when the bias
        drifts (``bias`` is the turn-on value).
    """

    model: SensorModel
    units: str = "deg/s"
    seed: int | None = None
    inputs: dict = field(default_factory=dict)
    mounting: np.ndarray | None = None
    moves: tuple[Move, ...] = ()
    bias_mean: np.ndarray | None = None

    def to_dict(self) -> dict:
        units = {"M": "1", "bias": self.units, "move_angle": "deg", "move_rate": "deg/s"}
        return {**self.envelope(units), "M": self.model.M.tolist(),
                "A": self.model.alignment().tolist(), "bias": to_unit(self.model.bias, self.units).tolist(),
                "mounting": None if self.mounting is None else self.mounting.tolist(),
                "moves": [m.to_dict() for m in self.moves], "seed": self.seed, "inputs": self.inputs,
                "bias_mean": None if self.bias_mean is None else to_unit(self.bias_mean, self.units).tolist()}

    @classmethod
    def from_dict(cls, d: dict, where: str = "truth") -> SimulationTruth:
        cls.check_envelope(d, where, keys=["M", "A", "bias", "mounting", "moves", "seed", "inputs", "bias_mean"])
        try:
            u, f = file_unit(d, "bias", "angular_rate", where)
            mounting = d.get("mounting")
            moves = d.get("moves") or []
            if moves:
                fa, fr = file_unit(d, "move_angle", "angle", where)[1], file_unit(d, "move_rate", "angular_rate", where)[1]
                moves = [Move.from_dict(m, fa, fr) for m in moves]
            return cls(SensorModel(np.array(d["M"], float), np.array(d["bias"], float) * f), u, d.get("seed"),
                       dict(d.get("inputs", {})), None if mounting is None else _rotation(mounting, where),
                       tuple(moves), None if d.get("bias_mean") is None else np.array(d["bias_mean"], float) * f)
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"malformed simulation truth ({malformed(exc)}); regenerate it", where) from None
