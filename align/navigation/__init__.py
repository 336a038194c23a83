"""What residual sensor errors cost in navigation: strapdown integration and error growth.

Modules
-------
strapdown   the strapdown integrator (NED, quaternion attitude through align.attitude, gravity, Earth rate)
residuals   the residual error set of a mission and where each figure comes from
mission     the true motion: static, a manoeuvre file's rotations or rate series, a recorded log
closed      seed 002 Eq 4's closed forms of the static error growth; which error dominates when
montecarlo  the Monte Carlo through the integrator (numba, runs in parallel)
drift       the analysis: Monte Carlo, closed forms, dominance -> DriftResult
result      DriftResult, the registered result ``imu-align.drift``
experiment  seed 002's experiment: simulate static records by methods A, B and statistics restoring,
            navigate them and a real record, its Eq 19-21 table

The pictures and the report section are in :mod:`align.present.navigation`.

Public names
------------
Trajectory, navigate, step_increments, normal_gravity, euler_from_quat, quat_from_euler, level_attitude (strapdown);
SensorErrors, ResidualErrors, residual_errors (residuals); Mission, static_mission, rotation_mission, rate_mission,
recorded_mission, manoeuvre_mission (mission); term_sigmas, static_sigma, dominance (closed); MonteCarlo, monte_carlo
(montecarlo); drift (drift); DriftResult (result)
"""

from align.navigation.closed import dominance, static_sigma, term_sigmas
from align.navigation.drift import drift
from align.navigation.mission import (
    Mission,
    manoeuvre_mission,
    rate_mission,
    recorded_mission,
    rotation_mission,
    static_mission,
)
from align.navigation.montecarlo import MonteCarlo, monte_carlo
from align.navigation.residuals import ResidualErrors, SensorErrors, residual_errors
from align.navigation.result import DriftResult
from align.navigation.strapdown import (
    Trajectory,
    euler_from_quat,
    level_attitude,
    navigate,
    normal_gravity,
    quat_from_euler,
    step_increments,
)

__all__ = ["Trajectory", "navigate", "step_increments", "normal_gravity", "euler_from_quat", "quat_from_euler",
           "level_attitude", "SensorErrors", "ResidualErrors", "residual_errors", "Mission", "static_mission",
           "rotation_mission", "rate_mission", "recorded_mission", "manoeuvre_mission", "term_sigmas", "static_sigma",
           "dominance", "MonteCarlo", "monte_carlo", "drift", "DriftResult"]
