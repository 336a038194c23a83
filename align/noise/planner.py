"""Allan-based test planning: how long to average at each table step (reference Example 3).

The noise target for an alignment goal ``psi_T`` at table rate ``w_TR`` with the
noise ``r`` times below the goal is ``w_TR sin(psi_T) / r`` (100 deg/s, 0.1 deg,
r = 10: 62.83 deg/h). The shortest averaging time is where the Allan deviation
(measured, or the IEEE model of :mod:`align.noise.model`) first falls to the
target, on its falling branch; below the curve's floor no averaging time meets
it. For the angle method the noise on a turn of duration ``T`` is about
``T sigma(T)`` (the angle integrated over ``T``), which must stay below
``Theta sin(psi_T) / r``.

Public names
------------
PlanResult, Averaging, noise_target, model_curve, averaging_time, longest_turn, make_plan, FORMAT
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from align.errors import InputError
from align.noise.model import FLICKER_FACTOR, NoiseModel
from align.parts import Part
from align.results import Result
from align.units import DEG, DEG_H
from align.values import Value
from align.wellformed import malformed

FORMAT = "imu-align.plan"
CONVENTION = ("noise target = rate sin(accuracy) / noise_ratio (Example 3); averaging time: "
              "shortest tau with sigma(tau) <= target on the falling branch of the Allan deviation")


def noise_target(rate: float, accuracy: float, ratio: float = 10.0) -> float:
    """Example 3: ``rate sin(accuracy) / ratio`` (rad/s)."""
    return float(rate * np.sin(accuracy) / ratio)


def model_curve(white: float, flicker: float = 0.0, random_walk: float = 0.0, quantization: float = 0.0) -> NoiseModel:
    """``sigma(tau)`` of the IEEE model (rad/s) as a function of tau (s).

    The terms in SI: ``white`` N (rad/sqrt(s)), ``flicker`` B (rad/s),
    ``random_walk`` K (rad/s/sqrt(s)), ``quantization`` Q (rad). Returns the
    callable :class:`~align.noise.model.NoiseModel` of those terms.
    """
    return NoiseModel(quantization=quantization, white=white, flicker=flicker, random_walk=random_walk)


def preset_model(part: Part, where: str = "{imu}") -> tuple[str, NoiseModel]:
    """The noise model of a datasheet preset: its angle random walk (or noise density) and
    bias instability, with the label a plan states as its noise source. A preset that states no bias
    instability gives a white-noise model: no floor (the label says so)."""
    n = part.si("arw", "angle_random_walk") or part.si("noise_density", "angle_random_walk")
    if n is None:
        raise InputError(f"{part.name} has no angle random walk or noise density in the preset table", where)
    b = part.si("bias_instability", "angular_rate") or 0.0
    label = f"datasheet preset {part.name}" + ("" if b else ", angle random walk only (it states no bias instability)")
    return label, model_curve(n, b)


@dataclass(frozen=True, eq=False)
class Averaging(Value):
    """Shortest averaging time meeting a target on the falling branch, or why none does.

    ``tau`` (s, None when infeasible); the curve's ``floor`` (rad/s; None when the curve has
    none: white noise alone averages down without limit) at ``floor_tau`` (s; None when the
    floor is only approached as tau grows, bias instability without a rising term); ``reason``.
    """

    tau: float | None
    floor: float | None
    floor_tau: float | None
    reason: str


def _model_floor(model: NoiseModel) -> tuple[float | None, float | None] | None:
    """The floor of a model without a rising term (K, R): None (white noise, quantization: no floor) or
    ``(sqrt(2 ln 2 / pi) B, None)`` approached as tau grows (IEEE Std 952); ``None`` result for a model
    with a rising term (its floor is an interior minimum, found numerically)."""
    if model.random_walk > 0 or model.ramp > 0:
        return None
    return (float(np.sqrt(FLICKER_FACTOR) * model.flicker), None) if model.flicker > 0 else (None, None)


def averaging_time(target: float, tau: np.ndarray | None = None, adev: np.ndarray | None = None, sigma=None) -> Averaging:
    """Shortest tau with ``sigma(tau) <= target`` before the curve's minimum.

    Give either a measured curve (``tau``, ``adev``; interpolated log-log, and
    extrapolated along a white-noise slope -1/2 below its first point, which is
    then said) or a model ``sigma`` callable. A :class:`~align.noise.model.NoiseModel`
    without rate random walk or ramp has no interior minimum: with bias
    instability its floor is ``0.664 B`` (IEEE Std 952), approached as tau grows;
    with white noise (and quantization) alone it has no floor.
    """
    from scipy.optimize import brentq, minimize_scalar

    if sigma is not None:
        known = _model_floor(sigma) if isinstance(sigma, NoiseModel) else None
        if known is not None:
            floor, t_floor = known
            if floor is not None and target <= floor:
                return Averaging(None, floor, None, _infeasible(target, floor))
            if float(sigma(1e-9)) <= target:
                return Averaging(1e-9, floor, None, "met at any averaging time")
            hi = 1.0
            while float(sigma(hi)) > target:
                hi *= 10.0
            lt = brentq(lambda x: float(sigma(np.exp(x))) - target, np.log(1e-9), np.log(hi), xtol=1e-12)
            return Averaging(float(np.exp(lt)), floor, None, "model curve")
        res = minimize_scalar(lambda lt: float(sigma(np.exp(lt))), bounds=(np.log(1e-6), np.log(1e7)), method="bounded")
        t_floor, floor = float(np.exp(res.x)), float(sigma(np.exp(res.x)))
        if target < floor:
            return Averaging(None, floor, t_floor, _infeasible(target, floor))
        if float(sigma(1e-9)) <= target:
            return Averaging(1e-9, floor, t_floor, "met at any averaging time")
        lt = brentq(lambda x: float(sigma(np.exp(x))) - target, np.log(1e-9), np.log(t_floor), xtol=1e-12)
        return Averaging(float(np.exp(lt)), floor, t_floor, "model curve")
    tau, adev = np.asarray(tau, float), np.asarray(adev, float)
    k_min = int(np.argmin(adev))
    floor, t_floor = float(adev[k_min]), float(tau[k_min])
    if target < floor:
        return Averaging(None, floor, t_floor, _infeasible(target, floor))
    if adev[0] <= target:
        t = tau[0] * (adev[0] / target) ** 2
        return Averaging(float(t), floor, t_floor, "below the first measured tau: extrapolated along slope -1/2 (white noise)")
    branch = slice(0, k_min + 1)
    lt, la = np.log(tau[branch]), np.log(adev[branch])
    k = int(np.argmax(la <= np.log(target)))
    frac = (np.log(target) - la[k - 1]) / (la[k] - la[k - 1])
    t_met = float(np.exp(lt[k - 1] + frac * (lt[k] - lt[k - 1])))
    return Averaging(t_met, floor, t_floor, "measured curve (log-log interpolation)")


def _infeasible(target: float, floor: float) -> str:
    return (f"infeasible: the target {target / DEG_H:.4g} deg/h is below the curve's floor {floor / DEG_H:.4g} deg/h "
            "(bias instability); no averaging time meets it: lower the noise ratio, raise the table rate or choose a "
            "quieter gyro")


def longest_turn(angle_target: float, sigma, t_max: float = 1e5) -> float | None:
    """Longest turn duration ``T`` with ``T sigma(T) <= angle_target`` (angle method), or None."""
    from scipy.optimize import brentq

    g = lambda lt: float(np.exp(lt) * sigma(np.exp(lt))) - angle_target  # noqa: E731
    if g(np.log(1e-6)) > 0:
        return None
    if g(np.log(t_max)) <= 0:
        return t_max
    return float(np.exp(brentq(g, np.log(1e-6), np.log(t_max), xtol=1e-12)))


#: the keys of a plan file after its envelope
FILE_KEYS = ("rate_deg_s", "accuracy_deg", "noise_ratio", "noise_target_deg_h", "averaging_time_s", "feasible", "reason",
             "floor_deg_h", "floor_tau_s", "noise_source", "angle_method", "test_plan", "inputs")


class PlanResult(Result, format=FORMAT, convention=CONVENTION, version=2):
    """A test plan from the noise (SI units: rad/s, rad, s).

    Attributes
    ----------
    rate : float
        Table rate, rad/s.
    accuracy : float
        Alignment goal, rad.
    noise_ratio : float
    noise_target : float
        ``rate sin(accuracy) / noise_ratio``, rad/s (Example 3).
    averaging : Averaging
    turn_angle : float
        Turn of the angle method, rad.
    longest_turn : float or None
        Longest turn duration meeting the angle target, s.
    steps : int
    settle : float
        Settling time added to each step, s.
    source : str
        Where the noise curve came from.
    inputs : dict
        The inputs, for the record (set with ``replace(inputs=...)``).
    """

    rate: float
    accuracy: float
    noise_ratio: float
    noise_target: float
    averaging: Averaging
    turn_angle: float
    longest_turn: float | None
    steps: int
    settle: float
    source: str
    inputs: dict = field(default_factory=dict)


    @property
    def dwell(self) -> float | None:
        """Averaging time plus settling time per step, s (None when infeasible)."""
        return None if self.averaging.tau is None else self.averaging.tau + self.settle

    def to_dict(self) -> dict[str, Any]:
        """The versioned JSON form (deg, deg/s, deg/h, s); version 2: ``floor_deg_h`` and ``floor_tau_s`` are
        null when the curve has no floor (white noise alone) or reaches it only as tau grows."""
        a, dwell = self.averaging, self.dwell
        return {
            **self.envelope({"noise_target_deg_h": "deg/h", "averaging_time_s": "s", "rate_deg_s": "deg/s",
                             "accuracy_deg": "deg", "floor_deg_h": "deg/h", "floor_tau_s": "s",
                             "turn_angle_deg": "deg", "longest_turn_s": "s", "settle_s": "s", "dwell_s": "s",
                             "total_table_time_s": "s"}),
            "rate_deg_s": self.rate / DEG, "accuracy_deg": self.accuracy / DEG,
            "noise_ratio": self.noise_ratio,
            "noise_target_deg_h": self.noise_target / DEG_H,
            "averaging_time_s": a.tau,
            "feasible": a.tau is not None,
            "reason": a.reason,
            "floor_deg_h": None if a.floor is None else a.floor / DEG_H, "floor_tau_s": a.floor_tau,
            "noise_source": self.source,
            "angle_method": {"turn_angle_deg": self.turn_angle / DEG, "longest_turn_s": self.longest_turn},
            "test_plan": {"steps": self.steps, "settle_s": self.settle, "dwell_s": dwell,
                          "total_table_time_s": None if dwell is None else self.steps * dwell},
            "inputs": self.inputs,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any], where: str = "result") -> PlanResult:
        """Read the form written by :meth:`to_dict`; a key it does not know is refused (a misspelling)."""
        cls.check_envelope(d, where, keys=FILE_KEYS)
        try:
            am, tp = d["angle_method"], d["test_plan"]
            tau = d["averaging_time_s"]
            return cls(
                rate=float(d["rate_deg_s"]) * DEG, accuracy=float(d["accuracy_deg"]) * DEG,
                noise_ratio=float(d["noise_ratio"]), noise_target=float(d["noise_target_deg_h"]) * DEG_H,
                averaging=Averaging(None if tau is None else float(tau),
                                    None if d["floor_deg_h"] is None else float(d["floor_deg_h"]) * DEG_H,
                                    None if d["floor_tau_s"] is None else float(d["floor_tau_s"]), str(d["reason"])),
                turn_angle=float(am["turn_angle_deg"]) * DEG,
                longest_turn=None if am["longest_turn_s"] is None else float(am["longest_turn_s"]),
                steps=int(tp["steps"]), settle=float(tp["settle_s"]), source=str(d["noise_source"]),
                inputs=dict(d.get("inputs", {})),
            )
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise InputError(f"malformed {FORMAT} result ({malformed(exc)}); regenerate it", where) from None


def make_plan(rate: float, accuracy: float, ratio: float, source: str, tau=None, adev=None, sigma=None,
              turn_angle: float = 2 * np.pi, steps: int = 6, settle: float = 2.0) -> PlanResult:
    """The planner: noise target, averaging time, angle-method turn limit and the whole plan.

    The noise target is Example 3's ``rate sin(accuracy) / ratio``; the averaging time the shortest
    ``tau`` where the Allan deviation meets it.

    Parameters
    ----------
    rate : float
        Table rate, rad/s.
    accuracy : float
        Alignment goal, rad.
    ratio : float
        How far below the goal the noise must be (Example 3: 10).
    source : str
        Where the noise curve came from, for the record.
    tau, adev : ndarray, shape (T,), optional
        A measured Allan curve: s and rad/s (when ``sigma`` is not given).
    sigma : callable, optional
        A model ``sigma(tau)``, rad/s (e.g. a :class:`~align.noise.model.NoiseModel`).
    turn_angle : float
        Turn of the angle method, rad.
    steps : int
        Steps of the plan.
    settle : float
        Settling time added to each step, s.

    Returns
    -------
    PlanResult
        ``noise_target`` (rad/s), ``averaging.tau`` (s), ``longest_turn`` (s) and the inputs.

    Raises
    ------
    InputError
        A rate, accuracy or noise ratio that is not finite and positive, a turn angle of 0, fewer
        than one step or a negative settling time (each named as its input), or a measured curve
        with no positive finite point.

    Examples
    --------
    Example 3: 100 deg/s, goal 0.1 deg, noise 10x below it: 62.83 deg/h, met after 0.0821 s with
    white noise alone (ARW 0.3 deg/sqrt(h)).

    >>> from align.noise.model import NoiseModel
    >>> from align.units import DEG
    >>> p = make_plan(100 * DEG, 0.1 * DEG, 10.0, "datasheet", sigma=NoiseModel(white=0.3 * DEG / 60))
    >>> round(p.noise_target * 3600 / DEG, 2), round(p.averaging.tau, 4)
    (62.83, 0.0821)
    """
    for name, x in (("rate", rate), ("accuracy", accuracy), ("ratio", ratio)):
        if not (np.isfinite(x) and x > 0):
            raise InputError(f"must be finite and > 0 (got {float(x):g})", "{" + name + "}")
    if not (np.isfinite(turn_angle) and turn_angle != 0):
        raise InputError(f"must be finite and not 0 (got {float(turn_angle):g})", "{turn_angle}")
    if int(steps) < 1:
        raise InputError(f"must be at least 1 (got {int(steps)})", "{steps}")
    if not (np.isfinite(settle) and settle >= 0):
        raise InputError(f"must be finite and >= 0 (got {float(settle):g})", "{settle}")
    if sigma is None:
        keep = np.isfinite(np.asarray(adev, float)) & (np.asarray(adev, float) > 0)
        if not keep.any():
            raise InputError("the Allan deviation has no positive finite point to plan from; recompute it", "{allan_json}")
        tau, adev = np.asarray(tau, float)[keep], np.asarray(adev, float)[keep]
    target = noise_target(rate, accuracy, ratio)
    avg = averaging_time(target, tau, adev, sigma)
    if sigma is None:
        curve_t, curve_a = np.asarray(tau, float), np.asarray(adev, float)

        def sigma(t):
            return np.exp(np.interp(np.log(t), np.log(curve_t), np.log(curve_a)))
    turn = longest_turn(turn_angle * np.sin(accuracy) / ratio, sigma)
    return PlanResult(rate, accuracy, ratio, target, avg, turn_angle, turn, steps, settle, source)
