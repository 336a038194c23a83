"""The timeline of a simulated rate-table session: static stretches, plan steps and re-orientation moves.

Each step's table rate is a trapezoid: a ramp at the table's acceleration, the dwell (rate steps) or the
cruise (angle steps, scaled so that the angle is exact), a ramp down. Between steps the orientation
changes as :func:`align.alignment.kinematics.step_orientation` says; with ``reorient`` the change is a move
(static, a turn at ``move_rate`` about the fixed axis of the relative rotation, static), otherwise the
orientation switches at the start of the gap.

Public names
------------
Move, Timeline, build_timeline, trapezoid, step_profile
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from align.alignment import kinematics as kin
from align.alignment.plan import Plan
from align.units import DEG, DEG_S, format_quantity, to_unit

if TYPE_CHECKING:
    from align.alignment.simulate import SessionSpec


def trapezoid(angle: float, peak_max: float, accel: float, dt: float) -> np.ndarray:
    """Rate samples (rad/s) of a turn through the signed ``angle`` (rad): ramps at ``accel``, cruise at most
    ``peak_max``; scaled so that ``sum(rate) dt`` is ``angle`` exactly."""
    total = abs(angle)
    peak = min(peak_max, np.sqrt(total * accel))
    t_ramp = peak / accel
    return _shape(np.sign(angle) * peak, t_ramp, (total - peak * t_ramp) / peak, dt, angle)


def _shape(peak: float, t_ramp: float, cruise: float, dt: float, angle: float | None) -> np.ndarray:
    n_ramp = max(int(np.ceil(t_ramp / dt)), 1)
    ramp = np.linspace(0.0, 1.0, n_ramp, endpoint=False) + 0.5 / n_ramp
    prof = np.concatenate([ramp, np.ones(int(np.floor(cruise / dt))), ramp[::-1]]) * peak
    if angle is not None:  # put the last fraction of a sample back so the angle is exact
        prof *= angle / (prof.sum() * dt)
    return prof


def step_profile(step, spec: SessionSpec) -> np.ndarray:
    """Table rate profile (signed, rad/s) of one step, without gaps."""
    dt = 1.0 / spec.fs
    if step.rate is not None:
        peak = step.rate * (1.0 + spec.table_rate_error)
        return _shape(peak, abs(peak) / spec.accel, spec.dwell_s, dt, None)
    return trapezoid(step.angle * (1.0 + spec.table_angle_error), spec.turn_rate, spec.accel, dt)


@dataclass(frozen=True)
class Move:
    """A re-orientation move the simulator put between two steps (not a plan step).

    Attributes
    ----------
    start, end : int
        Samples of the motion (end exclusive).
    t_start, t_end : float
        s.
    axis : tuple of 3 float
        Unit axis of the turn in the system frame (constant during the move).
    angle : float
        Angle turned about ``axis``, rad, in (0, pi].
    rate : float
        Cruise (peak) rate, rad/s.
    """

    start: int
    end: int
    t_start: float
    t_end: float
    axis: tuple[float, float, float]
    angle: float
    rate: float

    @property
    def label(self) -> str:
        """``"90 deg about (+0.000, +0.000, -1.000) at 20 deg/s"``."""
        axis = ", ".join(f"{v:+.3f}" for v in self.axis)
        return f"{format_quantity(self.angle, 'deg', 4)} about ({axis}) at {format_quantity(self.rate, 'deg/s', 4)}"

    def to_dict(self) -> dict:
        """JSON form: samples, s, the axis, the angle in deg and the rate in deg/s."""
        return {"start": self.start, "end": self.end, "t_start": self.t_start, "t_end": self.t_end,
                "axis": list(self.axis), "angle": float(to_unit(self.angle, "deg")),
                "rate": float(to_unit(self.rate, "deg/s"))}

    @classmethod
    def from_dict(cls, d: dict, angle_factor: float = DEG, rate_factor: float = DEG_S) -> Move:
        axis = tuple(float(v) for v in d["axis"])
        if len(axis) != 3:
            raise ValueError("a move's axis has three components")
        return cls(int(d["start"]), int(d["end"]), float(d["t_start"]), float(d["t_end"]), axis,
                   float(d["angle"]) * angle_factor, float(d["rate"]) * rate_factor)


class Timeline:
    """Builds the pieces of a session and the rate of each sample."""

    def __init__(self, spec: SessionSpec) -> None:
        self.spec, self.dt = spec, 1.0 / spec.fs
        self.pieces: list[kin.Piece] = []
        self.rates: list[np.ndarray] = []
        self.moves: list[Move] = []
        self.n = 0

    def add(self, kind: str, rate: np.ndarray, c: np.ndarray, axis=np.zeros(3), body=np.zeros(3), step=None) -> None:
        if len(rate):
            self.pieces.append(kin.Piece(kind, self.n, self.n + len(rate), tuple(map(tuple, c)), tuple(axis),
                                         tuple(body), step))
            self.rates.append(rate)
            self.n += len(rate)

    def static(self, seconds: float, c: np.ndarray) -> None:
        self.add("static", np.zeros(int(round(seconds * self.spec.fs))), c)

    def move(self, c_from: np.ndarray, c_to: np.ndarray) -> None:
        angle, axis = kin.relative_rotation(c_from, c_to)
        if angle < 1e-9:
            return
        rate = trapezoid(angle, self.spec.move_rate, self.spec.accel, self.dt)
        body = c_from.T @ axis
        start = self.n
        self.add("move", rate, c_from, axis, body)
        self.moves.append(Move(start, self.n, start * self.dt, self.n * self.dt, (float(body[0]), float(body[1]), float(body[2])),
                               angle, float(np.abs(rate).max())))
        self.static(self.spec.static_s, c_to)


def build_timeline(plan: Plan, spec: SessionSpec, heading: float) -> Timeline:
    """The pieces of the session (see the module docstring) and their rates."""
    line = Timeline(spec)
    first = plan.steps[0]
    rest = first.rest_matrix
    c = rest if rest is not None else kin.first_orientation(first.unit_axis, first.table_vector, heading)
    line.static(spec.head, c)
    for k, step in enumerate(plan.steps):
        a, u = step.table_vector, step.unit_axis
        if k > 0:
            new = kin.step_orientation(c, u, a, step.rest_matrix)
            line.static(spec.static_s, c if spec.reorient else new)
            if spec.reorient:
                line.move(c, new)
            c = new
        prof = step_profile(step, spec)
        line.add("step", prof, c, a, u, k)
        c = kin.axis_rotation(a, float(prof.sum()) * line.dt) @ c
    line.static(spec.static_s, c)
    return line
