"""The Allan job: logs -> Allan deviation, fits, noise figures, plan; its JSON form.

:func:`run_allan` computes the overlapping (and modified) Allan deviation of
the first run (:mod:`align.noise.allan`), fits the five-term IEEE model to each
channel (:mod:`align.noise.fit`), and reads the seed's noise figures (bias,
bias stability; seed 002 Eq 5-8) of every run. :class:`AllanJob` is the
registered result (format ``imu-align.allan``): it writes itself with
``to_dict`` and reads itself back with ``from_dict``. Its plot lives in
:mod:`align.present.plots` (``allan_plot_png``).

Public names
------------
AllanJob, run_allan, read_runs, plan_from_allan, term_units, FORMAT
"""

from __future__ import annotations

from typing import Any

import numpy as np

from align.errors import InputError
from align.noise.allan import NOISE_ALPHA, AllanResult, allan, edf_overlapping
from align.noise.fit import NoiseFit, fit_noise
from align.noise.model import TERMS, avar_design
from align.noise.planner import PlanResult, make_plan
from align.plausible import check_static_rates
from align.results import Result, file_unit
from align.units import DIMENSIONS, parse_unit, to_unit
from align.wellformed import malformed

FORMAT = "imu-align.allan"
CONVENTION = ("overlapping Allan deviation (IEEE Std 1139, NIST SP 1065); noise model "
              "sigma^2(tau) = 3 Q^2/tau^2 + N^2/tau + (2 ln 2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2 (IEEE Std 952)")

#: display units of the five terms for gyros and accelerometers
_GYRO = ("deg", "deg/sqrt(h)", "deg/h", "deg/h/sqrt(h)", "deg/h^2")
_ACCEL = ("m/s", "m/s/sqrt(h)", "ug", "ug/sqrt(h)", "ug/h")
_FIT_METHOD = "weighted non-negative least squares on the Allan variance (IEEE 952 five-term model)"
_FIGURES_METHOD = ("seed 002 Eq 5-8: mean of each run; std (ddof 1) of consecutive P-second means, "
                   "averaged over runs")
#: the IEEE point readouts: key in NoiseFit.readouts -> (JSON key, JSON unit key, term index)
_READOUTS = {"N_tau1": ("N_at_tau_1s", "N_unit", 1), "B_floor": ("B_floor_over_0.664", "B_unit", 2),
             "K_tau3": ("K_at_tau_3s", "K_unit", 3)}


def term_units(units: str) -> tuple[str, ...]:
    """Engineering units of Q, N, B, K, R for data in ``units`` (a rate or an acceleration)."""
    u = parse_unit(units)
    return _GYRO if u.dim == parse_unit("rad/s").dim else _ACCEL


#: the fewest samples a recording may hold: a handful of taus per decade for the five-term fit
MIN_SAMPLES = 100

#: the keys of an Allan file after its envelope (a misspelled key is refused, not ignored)
FILE_KEYS = ("sensor", "fs_hz", "samples", "runs", "tau", "m", "adev", "ci_low", "ci_high", "fit", "figures", "periods_s",
             "adev_run_figures", "inputs", "mdev", "adev_of", "repeatability", "plan")


class AllanJob(Result, format=FORMAT, convention=CONVENTION):
    """Result of :func:`run_allan` (SI inside; ``units`` is the input unit).

    Attributes
    ----------
    result : AllanResult
        Allan deviation of the first run, SI.
    fits : tuple of NoiseFit
        One per channel.
    figures : tuple of dict
        One per channel: ``{"bias": float, "stability": {period_s: float}}``,
        averaged over the runs (SI).
    repeatability : ndarray, shape (C,), or None
        Run-to-run std (ddof 1) of the bias, SI (None for one run).
    units : str
        Unit of the input data (a rate or an acceleration).
    runs : int
    inputs : tuple of str
        The recordings, the first one being the one whose deviation is shown.
    plan : PlanResult or None
        A test plan from the curve, when one was asked for.
    """

    result: AllanResult
    fits: tuple
    figures: tuple
    repeatability: np.ndarray | None
    units: str
    runs: int
    inputs: tuple = ()
    plan: PlanResult | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in ("fits", "figures", "inputs"):
            object.__setattr__(self, name, tuple(getattr(self, name)))

    @property
    def sensor(self) -> str:
        """``"gyroscope"`` for rate data, ``"accelerometer"`` otherwise."""
        return "gyroscope" if term_units(self.units) is _GYRO else "accelerometer"

    def to_dict(self) -> dict[str, Any]:
        """The versioned JSON form: deviations in ``units``, terms in engineering units."""
        r, u = self.result, self.units
        tu = term_units(u)
        periods = list(self.figures[0]["stability"]) if self.figures else []
        d = {
            **self.envelope({"tau": "s", "adev": u, "ci": "68.3 % (1 sigma) chi-square interval",
                             "terms": dict(zip(TERMS, tu)), "bias": u}),
            "sensor": self.sensor, "fs_hz": r.fs, "samples": r.n, "runs": self.runs,
            "tau": r.tau.tolist(),
            "m": r.m.tolist(),
            "adev": {n: to_unit(r.adev[j], u).tolist() for j, n in enumerate(r.names)},
            "ci_low": {n: to_unit(f.ci_low, u).tolist() for n, f in zip(r.names, self.fits)},
            "ci_high": {n: to_unit(f.ci_high, u).tolist() for n, f in zip(r.names, self.fits)},
            "fit": {n: self._fit_dict(f, tu) for n, f in zip(r.names, self.fits)},
            "figures": {n: {**_figures_dict(fig["bias"], fig["stability"], u), "method": _FIGURES_METHOD}
                        for n, fig in zip(r.names, self.figures)},
            "periods_s": periods,
            "adev_run_figures": None if r.bias is None else {
                n: _figures_dict(r.bias[j], {p: v[j] for p, v in (r.stability or {}).items()}, u)
                for j, n in enumerate(r.names)},
            "inputs": list(self.inputs),
        }
        if r.mdev is not None:
            d["mdev"] = {n: [None if not np.isfinite(v) else v for v in to_unit(r.mdev[j], u).tolist()]
                         for j, n in enumerate(r.names)}
        d["adev_of"] = self.inputs[0] if self.inputs else "first run"
        if self.repeatability is not None:
            d["repeatability"] = {n: to_unit(v, u) for n, v in zip(r.names, self.repeatability)}
        if self.plan is not None:
            d["plan"] = self.plan.to_dict()
        return d

    def _fit_dict(self, f: NoiseFit, tu: tuple[str, ...]) -> dict[str, Any]:
        terms = {t: {"value": _term(f.params[k], tu[k]), "sigma": _term(f.sigma[k], tu[k]), "unit": tu[k],
                     "identifiable": bool(f.identifiable[k])} for k, t in enumerate(TERMS)}
        readouts = {}
        for key, (name, unit_key, k) in _READOUTS.items():
            readouts[name], readouts[unit_key] = _term(f.readouts[key], tu[k]), tu[k]
        kind = self.sensor
        return {
            "method": _FIT_METHOD, "terms": terms, "notes": list(f.notes),
            "ieee_point_readouts": readouts,
            "continuous": {  # Kalibr-style densities, SI
                f"{kind}_noise_density": float(f.params[1]),
                f"{kind}_random_walk": float(f.params[3]),
                "units": "rad/s/sqrt(Hz), rad/s^2/sqrt(Hz)" if kind == "gyroscope" else "m/s^2/sqrt(Hz), m/s^3/sqrt(Hz)",
            },
            "dominant": list(f.dominant),
            "edf": f.edf.tolist(),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any], where: str = "result") -> AllanJob:
        """Read the form written by :meth:`to_dict` (files written before ``m``, ``edf``,
        ``dominant`` and ``adev_run_figures`` were added read too: those are rebuilt)."""
        cls.check_envelope(d, where, keys=FILE_KEYS)
        try:
            u, f = file_unit(d, "adev", None, where)
            tu = term_units(u)
            names = tuple(d["adev"])
            fs, n, runs = float(d["fs_hz"]), int(d["samples"]), int(d["runs"])
            tau = np.array(d["tau"], dtype=float)
            m = np.array(d["m"], dtype=np.int64) if "m" in d else np.round(tau * fs).astype(np.int64)
            adev = np.array([d["adev"][k] for k in names], dtype=float) * f
            mdev = np.array([d["mdev"][k] for k in names], dtype=float) * f if "mdev" in d else None
            periods = _periods(d, names)
            figures = tuple(_read_figures(d["figures"][k], periods, f) for k in names)
            run = d.get("adev_run_figures", d["figures"] if runs == 1 else None)
            bias = stability = None
            if run is not None:
                own = [_read_figures(run[k], periods, f) for k in names]
                bias = np.array([g["bias"] for g in own])
                stability = {p: np.array([g["stability"][p] for g in own]) for p in periods}
            result = AllanResult(tau, m, adev, mdev, n, fs, names, bias, stability)
            fits = tuple(_read_fit(d["fit"][k], tu, result, np.array(d["ci_low"][k], dtype=float) * f,
                                   np.array(d["ci_high"][k], dtype=float) * f) for k in names)
            rep = d.get("repeatability")
            return cls(result, fits, figures, None if rep is None else np.array([rep[k] for k in names], dtype=float) * f,
                       u, runs, tuple(d.get("inputs", ())),
                       PlanResult.from_dict(d["plan"], f"{where}: plan") if "plan" in d else None)
        except (KeyError, TypeError, ValueError, IndexError, AttributeError) as exc:
            raise InputError(f"malformed {FORMAT} result ({malformed(exc)}); regenerate it", where) from None


def _term(value: float, unit: str) -> float | None:
    """An SI term value in its engineering unit (None when not finite)."""
    if not np.isfinite(value):
        return None
    return float(to_unit(value, unit))


def _si(value: float | None, factor: float) -> float:
    """A value read from the file, in SI (None is NaN)."""
    return float("nan") if value is None else float(value) * factor


def _figures_dict(bias: float, stability: dict, units: str) -> dict[str, Any]:
    return {"bias": to_unit(bias, units),
            "bias_stability": {f"{p:g} s": to_unit(v, units) for p, v in stability.items()}}


def _periods(d: dict[str, Any], names: tuple[str, ...]) -> list[float]:
    """Averaging periods of the bias stability, s: ``periods_s``, else read off the keys ("10 s")."""
    if "periods_s" in d:
        return [float(p) for p in d["periods_s"]]
    return [float(k.split()[0]) for k in d["figures"][names[0]]["bias_stability"]] if names else []


def _read_figures(fig: dict[str, Any], periods: list[float], factor: float) -> dict[str, Any]:
    values = list(fig["bias_stability"].values())
    if len(values) != len(periods):
        raise ValueError(f"{len(values)} bias stabilities for {len(periods)} periods")
    return {"bias": _si(fig["bias"], factor), "stability": {p: _si(v, factor) for p, v in zip(periods, values)}}


def _read_fit(fd: dict[str, Any], tu: tuple[str, ...], result: AllanResult, ci_low: np.ndarray,
              ci_high: np.ndarray) -> NoiseFit:
    """A :class:`NoiseFit` from its JSON form; ``dominant`` and ``edf`` are rebuilt when absent."""
    factors = [parse_unit(t).factor for t in tu]
    terms = [fd["terms"][t] for t in TERMS]
    params = np.array([_si(t["value"], k) for t, k in zip(terms, factors)])
    sigma = np.array([_si(t["sigma"], k) for t, k in zip(terms, factors)])
    readouts = {key: _si(fd["ieee_point_readouts"][name], factors[k]) for key, (name, _, k) in _READOUTS.items()}
    if "dominant" in fd:
        dominant = tuple(fd["dominant"])
    else:
        dominant = tuple(TERMS[int(k)] for k in np.argmax(avar_design(result.tau) * params**2, axis=1))
    if "edf" in fd:
        edf = np.array(fd["edf"], dtype=float)
    else:
        edf = edf_overlapping(result.n_phase, result.m, np.array([NOISE_ALPHA[t] for t in dominant]))
    return NoiseFit(params, sigma, tuple(bool(t["identifiable"]) for t in terms), tuple(fd.get("notes", ())),
                    dominant, edf, ci_low, ci_high, readouts)


def run_allan(runs: list, fs: float, names: list[str], units: str, grid="dense", per_decade: int = 10,
              modified: bool = False, periods=(1.0, 10.0), progress=None, memory_limit: float = 2e9,
              where: str | list[str] | None = None) -> AllanJob:
    """Allan deviation and fit of the first run, noise figures of every run, the repeatability.

    Parameters
    ----------
    runs : list of array_like, shape (n, C), or chunk sources
        Raw samples in ``units``; everything is computed on the raw numbers and
        scaled afterwards (deviations, means and stabilities are linear in the
        unit), so no SI copy of a large record is made.
    fs : float
        Sample rate, Hz.
    names : list of str
        Channel names, C of them.
    units : str
        Unit of the samples (a rate or an acceleration).
    grid, per_decade, modified, progress, memory_limit : see :func:`align.noise.allan.allan`
    periods : sequence of float
        Averaging periods (s) of the bias stability (seed 002 Eq 7).
    where : str or list of str, optional
        The recordings (their files), for messages.

    Returns
    -------
    AllanJob
        Set its ``inputs`` (and ``plan``) with ``job.replace(...)``.

    Raises
    ------
    InputError
        A sample rate that is not a finite positive number of Hz.
        A recording of fewer than :data:`MIN_SAMPLES` samples.
    TestError
        A channel whose record is constant (a stuck sensor), named with ``where``.
    """
    if not (np.isfinite(fs) and fs > 0):
        raise InputError(f"the sample rate must be a finite number of Hz > 0, not {float(fs)!r}", "{rate_hz}")
    factor = parse_unit(units).factor
    files = list(where) if isinstance(where, (list, tuple)) else [where] * len(runs)
    for run, file in zip(runs, files):
        n = np.shape(run)[0] if not hasattr(run, "chunks") else run.shape[0]
        if n < MIN_SAMPLES:
            raise InputError(f"only {n} samples; an Allan deviation and its fit need at least {MIN_SAMPLES} (several "
                             "taus per decade): record longer", file or "record")
    # the deviations of the first run; of the others only the bias figures (no kernel pass)
    results = [allan(r, fs, names, grid, per_decade, modified, memory_limit, progress=progress if k == 0 else None,
                     periods=periods, deviations=k == 0, where=file) for k, (r, file) in enumerate(zip(runs, files))]
    results = [r.scaled(factor) for r in results]
    res = results[0]
    fits = tuple(fit_noise(res, j, where=f"{files[0]}: {name}" if files[0] else None) for j, name in enumerate(names))
    figures = tuple({"bias": float(np.mean([r.bias[j] for r in results])),
                     "stability": {p: float(np.mean([r.stability[p][j] for r in results])) for p in periods}}
                    for j in range(len(names)))
    if parse_unit(units).dim == DIMENSIONS["angular_rate"][0].dim:  # raw counts read as a rate are refused
        check_static_rates(np.array([f["bias"] for f in figures]), units, list(names), "gyro_units", files[0])
    rep = np.std([r.bias for r in results], axis=0, ddof=1) if len(results) > 1 else None
    return AllanJob(res, fits, figures, rep, units, len(runs))


def read_runs(paths: list, columns: list[str], rate_hz: float | None = None, log_format=None,
              scale: float = 1.0) -> tuple[list, float]:
    """Read static recordings of one sensor for :func:`run_allan`, at one common sample rate.

    Parameters
    ----------
    paths : list of str or Path
        ``.csv``, ``.csv.gz``, ``.npy`` or raw float64 ``.bin`` files (see :func:`align.io.read_static_log`).
    columns : list of str
        Data columns, C of them.
    rate_hz : float, optional
        Sample rate of files without a time column, Hz.
    log_format : align.io.LogFormat, optional
        Preamble, comments, delimiter of text files and the unit of their time column (detected when not given).
    scale : float
        The size of one count in the unit given to :func:`run_allan` (1: the files hold that unit).

    Returns
    -------
    runs : list of array_like, shape (n_k, C), or chunk sources
    fs : float
        The common sample rate, Hz.

    Raises
    ------
    InputError
        A run whose sample rate differs from the first run's (named by its file).
    """
    from align.io import read_static_log

    runs, fs = [], None
    for path in paths:
        got = read_static_log(path, columns, rate_hz, log_format, scale)
        f = got.rate_hz
        if fs is not None and abs(f - fs) > 1e-9 * fs:
            raise InputError(f"sample rate {f:g} Hz differs from the first run's {fs:g} Hz", str(path))
        runs.append(got.data)
        fs = f
    if fs is None:
        raise InputError("no recording given", "{paths}")
    return runs, fs


def plan_from_allan(job: AllanJob, rate: float, accuracy: float, noise_ratio: float = 10.0, source: str | None = None,
                    where: str = "allan result", **common) -> PlanResult:
    """The test plan (Example 3) from a measured Allan deviation: its worst channel at each tau.

    Parameters
    ----------
    job : AllanJob
        Of gyro data.
    rate, accuracy, noise_ratio : see :func:`align.noise.planner.make_plan` (rad/s, rad)
    source : str, optional
        The noise source as the plan states it; by default "measured curve (worst of x, y, z)".
    where : str
        Name of the job (its file) for messages.
    **common
        ``turn_angle``, ``steps``, ``settle`` of :func:`~align.noise.planner.make_plan`.

    Raises
    ------
    InputError
        The job holds accelerometer data.
    """
    if job.sensor != "gyroscope":
        raise InputError(f"holds {job.sensor} data ({job.units}); a test plan needs a gyro's", where)
    r = job.result
    source = source or f"measured curve (worst of {', '.join(r.names)})"
    return make_plan(rate, accuracy, noise_ratio, source, tau=r.tau, adev=r.adev.max(axis=0), **common)
