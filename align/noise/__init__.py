"""The noise family: Allan deviation, the IEEE noise model and its fit, the simulator, test planning.

Modules
-------
model     the IEEE Std 952 five-term Allan-variance model (one place) and TERM_TABLE, the names of its terms
allan     overlapping / modified Allan deviation of many channels, confidence intervals (numba kernels in _kernels)
identify  per-tau noise identification (lag-1 autocorrelation, B1 ratio) and the EDF that follows
covariance covariance of overlapping Allan variances of a noise model (the fit's weights)
fit       whole-model noise fit (generalised least squares), upper bounds, the seed's noise figures
gls       generalised least squares of the Allan variance on the model, with profile intervals (the fit's core)
periodic  a periodic disturbance's Allan signature (IEEE Std 952 Annex C), scanned and tested beside the terms
readouts  IEEE point readouts (N at tau = 1 s, floor, K at tau = 3 s) with their intervals
sim       sensor-error simulator and the seed's three error models
planner   averaging time and test plan (reference Example 3); result ``imu-align.plan``
analysis  the Allan analysis, the ``allan`` job's result (deviation of every run, pooled curve, fits, figures);
          result ``imu-align.allan``
analysisfile the JSON form of the analysis's curves and fits (engineering units, the names of TERM_TABLE)
job       old name of ``analysis`` (its ``AllanJob`` is ``AllanAnalysis``), kept for one release
jobfile   old name of ``analysisfile``, kept for one release
records   static records for the Allan deviation read through the one reader and checked (static, gravity, rate, time unit)
jobs      the family's jobs for the command line, the report, the batch and scripts: AllanOptions, ALLAN, allan
          (static records read and checked -> AllanAnalysis), PlanOptions, PLAN, plan (align.api names them)
warmup    the warm-up time of a static record (the bias settled within a stated band); result ``imu-align.warmup``
repeatability turn-on to turn-on bias repeatability with its chi-square interval; result ``imu-align.repeatability``
bias_jobs the ``warmup`` and ``repeatability`` jobs (align.api names them)

The plot of an Allan job is :func:`align.present.plots.allan_plot_png` (this
family draws nothing). Note that ``align.noise.allan`` as an attribute of this
package is the function :func:`~align.noise.allan.allan`; import the module's
other names with ``from align.noise.allan import ...`` (or from here).

Public names
------------
TERMS, Term, TERM_TABLE, term, NOISE_ALPHA, FLICKER_FACTOR, NoiseModel, avar_design, model_avar, model_adev (model);
tau_grid, AllanResult, allan, ArrayChunks, window_stability, edf_overlapping, confidence_interval (allan);
NoiseFit, fit_noise, point_readouts, noise_figures, nnls_small (fit);
NoiseSpec, FLICKER_MODELS, simulate_noise, simulate_imu, seed_method_a, seed_method_b, seed_restoring (sim);
PlanResult, Averaging, noise_target, model_curve, averaging_time, longest_turn, make_plan (planner);
AllanAnalysis (and its old name AllanJob), run_allan, pool_runs, read_runs, plan_from_allan, term_units (analysis)
"""

from align.noise.allan import AllanResult, ArrayChunks, allan, confidence_interval, edf_overlapping, tau_grid, window_stability
from align.noise.analysis import AllanAnalysis, plan_from_allan, pool_runs, read_runs, run_allan, term_units
from align.noise.fit import NoiseFit, fit_noise, nnls_small, noise_figures, point_readouts
from align.noise.model import (
    FLICKER_FACTOR,
    NOISE_ALPHA,
    TERM_TABLE,
    TERMS,
    NoiseModel,
    Term,
    avar_design,
    model_adev,
    model_avar,
    term,
)
from align.noise.planner import (
    Averaging,
    PlanResult,
    averaging_time,
    longest_turn,
    make_plan,
    model_curve,
    noise_target,
    preset_model,
)
from align.noise.sim import FLICKER_MODELS, NoiseSpec, seed_method_a, seed_method_b, seed_restoring, simulate_imu, simulate_noise

__all__ = [
    "FLICKER_FACTOR", "NOISE_ALPHA", "TERMS", "Term", "TERM_TABLE", "term", "NoiseModel",
    "avar_design", "model_adev", "model_avar",
    "AllanResult", "ArrayChunks", "allan", "confidence_interval", "edf_overlapping", "tau_grid", "window_stability",
    "NoiseFit", "fit_noise", "nnls_small", "noise_figures", "point_readouts",
    "FLICKER_MODELS", "NoiseSpec", "seed_method_a", "seed_method_b", "seed_restoring", "simulate_imu", "simulate_noise",
    "Averaging", "PlanResult", "averaging_time", "longest_turn", "make_plan", "model_curve", "noise_target", "preset_model",
    "AllanAnalysis", "AllanJob", "plan_from_allan", "pool_runs", "read_runs", "run_allan", "term_units",
]

#: the old name of :class:`AllanAnalysis` (the same class), kept for one release
AllanJob = AllanAnalysis
