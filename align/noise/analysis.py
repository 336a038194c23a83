"""The Allan analysis, the ``allan`` job's result: logs -> Allan deviation of every run, pooled curve, fits,
noise figures, plan; its JSON form.

:func:`run_allan` computes the overlapping (and modified) Allan deviation of
every run on one grid of taus (:mod:`align.noise.allan`) and fits the five-term
IEEE model to each channel of each run (:mod:`align.noise.fit`). With several
runs it pools them (:func:`pool_runs`): the pooled Allan variance at each tau is
the average of the runs' Allan variances weighted by their numbers of second
differences (the plain mean for runs of equal length), and its equivalent
degrees of freedom (EDF) are the sum of theirs. The fit and the
plan then use the pooled curve. The seed's noise figures (bias, bias stability;
seed 002 Eq 5-8) are read from every run and averaged, and the run-to-run
standard deviation of the bias is the repeatability. :class:`AllanAnalysis` is the
registered result (format ``imu-align.allan``, version 2: terms named as in
:data:`align.noise.model.TERM_TABLE`; version 1 files read too). Its plot lives
in :mod:`align.present.plots` (``allan_plot_png``).

Public names
------------
AllanAnalysis, run_allan, pool_runs, read_runs, plan_from_allan, term_units, FORMAT
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from align.errors import InputError
from align.noise import analysisfile as jf
from align.noise.allan import AllanResult, allan, tau_grid
from align.noise.analysisfile import term_units
from align.noise.fit import fit_noise
from align.noise.model import TERM_TABLE
from align.noise.planner import PlanResult, make_plan
from align.plausible import check_static_rates
from align.results import Result, file_unit
from align.units import DIMENSIONS, parse_unit, to_unit
from align.wellformed import malformed

FORMAT = "imu-align.allan"
CONVENTION = ("overlapping Allan deviation (IEEE Std 1139, NIST SP 1065); noise model "
              "sigma^2(tau) = 3 Q^2/tau^2 + N^2/tau + (2 ln 2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2 (IEEE Std 952); "
              "several runs pooled: mean Allan variance weighted by the runs' second differences, EDF summed")
POOLING = ("average Allan variance of the runs at each tau (weighted by their numbers of second differences: "
           "equal runs weigh equally); its EDF is the sum of the runs' EDFs")
_FIGURES_METHOD = ("seed 002 Eq 5-8: mean of each run; std (ddof 1) of consecutive P-second means, "
                   "averaged over runs")

#: the fewest samples a recording may hold: a handful of taus per decade for the five-term fit
MIN_SAMPLES = 100

#: the keys of an Allan file after its envelope (a misspelled key is refused, not ignored)
FILE_KEYS = ("sensor", "fs_hz", "samples", "runs", "tau", "m", "adev", "ci_low", "ci_high", "fit", "figures", "periods_s",
             "adev_run_figures", "inputs", "mdev", "adev_of", "repeatability", "plan", "noise_type_alpha", "edf",
             "edf_mdev", "pooled", "per_run", "streams", "notes")


class AllanAnalysis(Result, format=FORMAT, convention=CONVENTION, version=2):
    """Result of :func:`run_allan` (SI inside; ``units`` is the input unit).

    Attributes
    ----------
    result : AllanResult
        The curve fitted: the Allan deviation of the one run, or the pooled curve of several
        (:func:`pool_runs`; ``n`` the samples of the shortest run, ``runs`` their number; no bias figures), SI.
    fits : tuple of NoiseFit
        One per channel, of ``result``.
    figures : tuple of dict
        One per channel: ``{"bias": float, "stability": {period_s: float}}``,
        averaged over the runs (SI).
    repeatability : ndarray, shape (C,), or None
        Run-to-run std (ddof 1) of the bias, SI (None for one run).
    units : str
        Unit of the input data (a rate or an acceleration).
    runs : int
    inputs : tuple of str
        The recordings.
    plan : PlanResult or None
        A test plan from the curve, when one was asked for.
    run_results : tuple of AllanResult
        Each run's own curve (with its bias figures) when there are several; empty for one run.
    run_fits : tuple of tuple of NoiseFit
        Each run's fits, one per channel, when there are several.
    streams : tuple of dict
        The stream each record was read from, for a log of several (topic, instance, device id); empty otherwise.
    notes : tuple of str
        The readers' remarks (a truncated last record left out).
    """

    result: AllanResult
    fits: tuple
    figures: tuple
    repeatability: np.ndarray | None
    units: str
    runs: int
    inputs: tuple = ()
    plan: PlanResult | None = None
    run_results: tuple = ()
    run_fits: tuple = ()
    streams: tuple = ()
    notes: tuple = ()

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in ("fits", "figures", "inputs", "run_results", "streams", "notes"):
            object.__setattr__(self, name, tuple(getattr(self, name)))
        object.__setattr__(self, "run_fits", tuple(tuple(f) for f in self.run_fits))

    @property
    def sensor(self) -> str:
        """``"gyroscope"`` for rate data, ``"accelerometer"`` otherwise."""
        return "gyroscope" if term_units(self.units) is jf.GYRO else "accelerometer"

    @property
    def pooled(self) -> bool:
        """True when ``result`` is the pooled curve of several runs."""
        return len(self.run_results) > 1

    def figures_of_merit(self) -> tuple:
        """The noise terms ``N``, ``B``, ``K`` of the first three channels as x, y, z with their 1-sigma; NaN where
        the record could not identify a term (never a bound as a value)."""
        from align.keyfigures import AXES, figures_from

        values: dict[str, float] = {}
        for a, fit in zip(AXES, self.fits[:3]):
            for name, index in (("arw", 1), ("bi", 2), ("rrw", 3)):
                ok = bool(fit.identifiable[index])
                values[f"{name}_{a}"] = float(fit.params[index]) if ok else float("nan")
                values[f"{name}_{a}_sigma"] = float(fit.sigma[index]) if ok else float("nan")
        return figures_from(values, self.sensor, method="Allan variance fit (IEEE Std 952 Annex C)")

    def to_dict(self) -> dict[str, Any]:
        """The versioned JSON form: deviations in ``units``, terms in engineering units."""
        r, u, sensor = self.result, self.units, self.sensor
        tu = term_units(u)
        periods = list(self.figures[0]["stability"]) if self.figures else []
        d: dict[str, Any] = {
            **self.envelope({"tau": "s", "adev": u, "ci": "68.3 % (1 sigma) chi-square interval",
                             "terms": {t.json_key(sensor): unit for t, unit in zip(TERM_TABLE, tu)}, "bias": u}),
            "sensor": sensor, "fs_hz": r.fs, "samples": r.n, "runs": self.runs,
            "tau": r.tau.tolist(), "m": r.m.tolist(),
            **jf.curve_dict(r, self.fits, u, tu, sensor),
            "figures": {n: {**jf.figures_dict(fig["bias"], fig["stability"], u), "method": _FIGURES_METHOD}
                        for n, fig in zip(r.names, self.figures)},
            "periods_s": periods,
            "adev_run_figures": None if r.bias is None else jf.run_figures(r, u),
            "inputs": list(self.inputs),
        }
        d["adev_of"] = (f"pooled curve of {self.runs} runs: {POOLING}" if self.pooled
                        else self.inputs[0] if self.inputs else "first run")
        if self.repeatability is not None:
            d["repeatability"] = {n: to_unit(v, u) for n, v in zip(r.names, self.repeatability)}
        if self.pooled:
            d["pooled"] = {"method": POOLING, "runs": len(self.run_results)}
            d["per_run"] = [{"input": self.inputs[k] if k < len(self.inputs) else f"run {k + 1}", "samples": rr.n,
                             **jf.curve_dict(rr, fits, u, tu, sensor), "figures": jf.run_figures(rr, u)}
                            for k, (rr, fits) in enumerate(zip(self.run_results, self.run_fits))]
        if self.plan is not None:
            d["plan"] = self.plan.to_dict()
        if self.streams:
            d["streams"] = [dict(x) for x in self.streams]
        if self.notes:
            d["notes"] = [str(x) for x in self.notes]
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any], where: str = "result") -> AllanAnalysis:
        """Read the form written by :meth:`to_dict`, or version 1 (internal term names; files written before
        ``m``, ``edf``, ``dominant`` and ``adev_run_figures`` were added read too: those are rebuilt)."""
        cls.check_envelope(d, where, keys=FILE_KEYS)
        try:
            u, f = file_unit(d, "adev", None, where)
            tu = term_units(u)
            names = tuple(d["adev"])
            fs, n, runs = float(d["fs_hz"]), int(d["samples"]), int(d["runs"])
            tau = np.array(d["tau"], dtype=float)
            m = np.array(d["m"], dtype=np.int64) if "m" in d else np.round(tau * fs).astype(np.int64)
            periods = jf.periods_of(d, names)
            figures = tuple(jf.read_figures(d["figures"][k], periods, f) for k in names)
            run = d.get("adev_run_figures", d["figures"] if runs == 1 else None)
            result, fits = jf.read_curve(d, tau, m, n, fs, names, f, tu, run, periods)
            if d.get("per_run"):  # the pooled curve: ``samples`` of the shortest run (version 2 files before this
                #                    said all runs' samples: the per-run records tell)
                result = result.replace(n=min(int(p["samples"]) for p in d["per_run"]), runs=len(d["per_run"]))
            per = [jf.read_curve(p, tau, m, int(p["samples"]), fs, names, f, tu, p["figures"], periods)
                   for p in d.get("per_run", ())]
            rep = d.get("repeatability")
            return cls(result, fits, figures, None if rep is None else np.array([rep[k] for k in names], dtype=float) * f,
                       u, runs, tuple(d.get("inputs", ())),
                       PlanResult.from_dict(d["plan"], f"{where}: plan") if "plan" in d else None,
                       tuple(p[0] for p in per), tuple(p[1] for p in per),
                       tuple(dict(x) for x in d.get("streams", ())), tuple(str(x) for x in d.get("notes", ())))
        except (KeyError, TypeError, ValueError, IndexError, AttributeError) as exc:
            raise InputError(f"malformed {FORMAT} result ({malformed(exc)}); regenerate it", where) from None


def pool_runs(results: list[AllanResult], edfs: list[np.ndarray]) -> AllanResult:
    """The pooled curve of several runs on one grid of taus.

    Parameters
    ----------
    results : list of AllanResult
        The runs, K of them, each with deviations of shape (C, T) on the same ``m``.
    edfs : list of ndarray, shape (C, T)
        Each run's equivalent degrees of freedom ``nu_k`` at each tau.

    Returns
    -------
    AllanResult
        ``AVAR = sum_k (N_k - 2m) AVAR_k / sum_k (N_k - 2m)`` at each tau, ``N_k`` the phase points of run
        ``k``: the overlapping Allan variance of all the runs' second differences together (IEEE Std 1139
        / NIST SP 1065 Eq 14 summed over runs, none across a run boundary), the plain mean for runs of equal
        length; its EDF is ``sum_k nu_k`` (independent runs: their chi-square degrees of freedom add, NIST
        SP 1065 section 5.3). The modified deviation is pooled the same way with ``N_k - 3m + 1``.
        ``n`` is the samples of the shortest run and ``runs`` their number (the covariance of its points is that
        of one such run divided by the number of runs: conservative for unequal runs); no bias figures. Its
        ``edf`` (and ``edf_mdev``) is the sum of the runs', its ``alpha`` the first run's noise types.
    """
    first = results[0]
    m = first.m.astype(float)
    nu = np.stack([np.asarray(e, dtype=float) for e in edfs])
    w = np.stack([np.broadcast_to(r.n_phase - 2 * m, r.adev.shape) for r in results])
    pooled = np.sum(w * np.stack([r.adev**2 for r in results]), axis=0) / np.sum(w, axis=0)
    mdev = None
    mdevs = [r.mdev for r in results if r.mdev is not None]
    if len(mdevs) == len(results):
        wm = np.stack([np.broadcast_to(np.maximum(r.n_phase - 3 * m + 1, 0), r.adev.shape) for r in results])
        mdev = np.sqrt(np.sum(wm * np.stack([v**2 for v in mdevs]), axis=0) / np.sum(wm, axis=0))
    res = AllanResult(first.tau, first.m, np.sqrt(pooled), mdev, int(min(r.n for r in results)), first.fs, first.names,
                      runs=len(results))
    fields = {fl.name for fl in dataclasses.fields(AllanResult)}
    extra = {}
    if "edf" in fields:
        extra["edf"] = np.sum(nu, axis=0)
    edf_mdevs = [e for r in results if (e := getattr(r, "edf_mdev", None)) is not None]
    if "edf_mdev" in fields and mdev is not None and len(edf_mdevs) == len(results):
        extra["edf_mdev"] = np.sum(np.stack(edf_mdevs), axis=0)
    if "alpha" in fields and getattr(first, "alpha", None) is not None:
        extra["alpha"] = np.asarray(first.alpha)
    return res.replace(**extra) if extra else res


def _edf_of(res: AllanResult, fits) -> np.ndarray:
    """EDF of each point, shape (C, T): the result's own when it carries them, else the fits'."""
    edf = getattr(res, "edf", None)
    return np.asarray(edf, dtype=float) if edf is not None else np.stack([f.edf for f in fits])


def run_allan(runs: list, fs: float, names: list[str], units: str, grid="dense", per_decade: int = 10,
              modified: bool = False, periods=(1.0, 10.0), progress=None, memory_limit: float = 2e9,
              where: str | list[str] | None = None) -> AllanAnalysis:
    """Allan deviation and fit of every run, the pooled curve of several, noise figures, repeatability.

    Parameters
    ----------
    runs : list of array_like, shape (n_k, C), or chunk sources
        Raw samples in ``units``; everything is computed on the raw numbers and
        scaled afterwards (deviations, means and stabilities are linear in the
        unit), so no SI copy of a large record is made. Several runs share the
        taus of the shortest.
    fs : float
        Sample rate, Hz.
    names : list of str
        Channel names, C of them.
    units : str
        Unit of the samples (a rate or an acceleration).
    grid, per_decade, modified, memory_limit : see :func:`align.noise.allan.allan`
    progress : callable, optional
        Called with the number of samples read so far, over all runs.
    periods : sequence of float
        Averaging periods (s) of the bias stability (seed 002 Eq 7).
    where : str or list of str, optional
        The recordings (their files), for messages.

    Returns
    -------
    AllanAnalysis
        Its ``result`` and ``fits`` are the pooled curve's when there are several runs
        (:func:`pool_runs`). Set its ``inputs`` (and ``plan``) with ``job.replace(...)``.

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
    sizes = [run.shape[0] if hasattr(run, "chunks") else np.shape(run)[0] for run in runs]
    for n, file in zip(sizes, files):
        if n < MIN_SAMPLES:
            raise InputError(f"only {n} samples; an Allan deviation and its fit need at least {MIN_SAMPLES} (several "
                             "taus per decade): record longer", file or "record")
    taus = grid if len(runs) == 1 else list(tau_grid(min(sizes), fs, grid, per_decade) / fs)
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    results = [allan(r, fs, names, taus, per_decade, modified, memory_limit, periods=periods, where=file,
                     progress=None if progress is None else (lambda k, off=int(offsets[i]): progress(off + k))).scaled(factor)
               for i, (r, file) in enumerate(zip(runs, files))]
    run_fits = [tuple(fit_noise(res, j, where=f"{file}: {name}" if file else None) for j, name in enumerate(names))
                for res, file in zip(results, files)]
    biases = [r.bias for r in results if r.bias is not None]
    stabilities = [r.stability for r in results if r.stability is not None]
    assert len(biases) == len(stabilities) == len(results), "allan() gives each run its bias and stability"
    figures = tuple({"bias": float(np.mean([b[j] for b in biases])),
                     "stability": {p: float(np.mean([s[p][j] for s in stabilities])) for p in periods}}
                    for j in range(len(names)))
    if parse_unit(units).dim == DIMENSIONS["angular_rate"][0].dim:  # raw counts read as a rate are refused
        check_static_rates(np.array([f["bias"] for f in figures]), units, list(names), "gyro_units", files[0])
    if len(runs) == 1:
        return AllanAnalysis(results[0], run_fits[0], figures, None, units, 1)
    pooled = pool_runs(results, [_edf_of(r, f) for r, f in zip(results, run_fits)])
    fits = tuple(fit_noise(pooled, j, where=f"pooled runs: {name}") for j, name in enumerate(names))
    rep = np.std(biases, axis=0, ddof=1)
    return AllanAnalysis(pooled, fits, figures, rep, units, len(runs), run_results=tuple(results), run_fits=tuple(run_fits))


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


def plan_from_allan(job: AllanAnalysis, rate: float, accuracy: float, noise_ratio: float = 10.0, source: str | None = None,
                    where: str = "allan result", **common) -> PlanResult:
    """The test plan (Example 3) from a measured Allan deviation: its worst channel at each tau.

    Parameters
    ----------
    job : AllanAnalysis
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
    if job.pooled:
        source += f", pooled over {job.runs} runs"
    return make_plan(rate, accuracy, noise_ratio, source, tau=r.tau, adev=r.adev.max(axis=0), **common)
