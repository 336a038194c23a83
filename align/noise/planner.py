"""Allan-based test planning: how long to average at each table step (reference Example 3).

The noise target for an alignment goal ``psi_T`` at table rate ``w_TR`` with the
noise ``r`` times below the goal is ``w_TR sin(psi_T) / r`` (100 deg/s, 0.1 deg,
r = 10: 62.83 deg/h). The shortest averaging time is where the Allan deviation
(measured, or the model ``N, B, K``) first falls to the target, on its falling
branch; below the curve's floor no averaging time meets it. For the angle
method the noise on a turn of duration ``T`` is about ``T sigma(T)`` (the angle
integrated over ``T``), which must stay below ``Theta sin(psi_T) / r``.

Public names
------------
PlanResult, noise_target, model_curve, averaging_time, longest_turn, make_plan
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.units import DEG_H

_LN = 2 * np.log(2) / np.pi


def noise_target(rate: float, accuracy: float, ratio: float = 10.0) -> float:
    """Example 3: ``rate sin(accuracy) / ratio`` (rad/s)."""
    return float(rate * np.sin(accuracy) / ratio)


def model_curve(white: float, flicker: float = 0.0, random_walk: float = 0.0, quantization: float = 0.0):
    """``sigma(tau)`` of the IEEE model (rad/s) as a function of tau (s)."""
    def sigma(tau):
        tau = np.asarray(tau, dtype=float)
        return np.sqrt(3 * quantization**2 / tau**2 + white**2 / tau + _LN * flicker**2 + random_walk**2 * tau / 3)
    return sigma


@dataclass(frozen=True)
class Averaging:
    """Shortest averaging time meeting a target on the falling branch, or why none does."""

    tau: float | None
    floor: float
    floor_tau: float
    reason: str


def averaging_time(target: float, tau: np.ndarray | None = None, adev: np.ndarray | None = None, sigma=None) -> Averaging:
    """Shortest tau with ``sigma(tau) <= target`` before the curve's minimum.

    Give either a measured curve (``tau``, ``adev``; interpolated log-log, and
    extrapolated along a white-noise slope -1/2 below its first point, which is
    then said) or a model ``sigma`` callable.
    """
    from scipy.optimize import brentq, minimize_scalar

    if sigma is not None:
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
    return Averaging(float(np.exp(lt[k - 1] + frac * (lt[k] - lt[k - 1]))), floor, t_floor, "measured curve (log-log interpolation)")


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


@dataclass(frozen=True)
class PlanResult:
    """A test plan from the noise (SI units)."""

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

    def to_dict(self) -> dict:
        from align import __version__

        a = self.averaging
        dwell = None if a.tau is None else a.tau + self.settle
        return {
            "format": "imu-align.plan", "version": 1, "generator": f"imu-align {__version__}",
            "units": {"noise_target_deg_h": "deg/h", "averaging_time_s": "s"},
            "rate_deg_s": self.rate / np.radians(1), "accuracy_deg": float(np.degrees(self.accuracy)),
            "noise_ratio": self.noise_ratio,
            "noise_target_deg_h": self.noise_target / DEG_H,
            "averaging_time_s": a.tau,
            "feasible": a.tau is not None,
            "reason": a.reason,
            "floor_deg_h": a.floor / DEG_H, "floor_tau_s": a.floor_tau,
            "noise_source": self.source,
            "angle_method": {"turn_angle_deg": float(np.degrees(self.turn_angle)), "longest_turn_s": self.longest_turn},
            "test_plan": {"steps": self.steps, "settle_s": self.settle, "dwell_s": dwell,
                          "total_table_time_s": None if dwell is None else self.steps * dwell},
        }


def make_plan(rate: float, accuracy: float, ratio: float, source: str, tau=None, adev=None, sigma=None,
              turn_angle: float = 2 * np.pi, steps: int = 6, settle: float = 2.0) -> PlanResult:
    """The planner: noise target, averaging time, angle-method turn limit and the whole plan."""
    target = noise_target(rate, accuracy, ratio)
    avg = averaging_time(target, tau, adev, sigma)
    if sigma is None:
        curve_t, curve_a = np.asarray(tau, float), np.asarray(adev, float)

        def sigma(t):
            return np.exp(np.interp(np.log(t), np.log(curve_t), np.log(curve_a)))
    turn = longest_turn(turn_angle * np.sin(accuracy) / ratio, sigma)
    return PlanResult(rate, accuracy, ratio, target, avg, turn_angle, turn, steps, settle, source)
