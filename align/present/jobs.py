"""The report's jobs: each turns one kind of input into its results, its sections, its terminal lines and
its verdicts, added to one :class:`Report`.

:func:`align.present.story.build_report` calls them in order for the inputs that are given; a job
reads its files only through the checked readers (or :func:`align.results.load_result` for a result
file). Pictures of a result file's raw data (the alignment log, a calibration capture) are drawn when
the file the result names can be read again, and their absence is said otherwise.

Public names
------------
Report, mount_job, manoeuvre_job, alignment_job, allan_job, calibration_job, drift_job
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import cast

import numpy as np

from align.io import LogFormat
from align.present.html import Section
from align.present.presets import preset_lines
from align.present.reread import LOG_FIELDS, Said, in_words, read_capture, statics_picture, template
from align.present.verdicts import FAIL, INFO, PASS, WARN, Verdict, checks_verdict, worst
from align.units import DEG, DEG_H, parse_unit
from align.units import parse_quantity as q


@dataclass
class Report:
    """What the jobs have produced so far (mutable while the report is built).

    Attributes
    ----------
    source : callable
        Maps an input's path (as shown) to the file to read.
    sections : dict of str -> list of Section
        By part of the page (``"measured"``, ``"mount"``, ``"alignment"``, ``"noise"``, ``"calibration"``,
        ``"navigation"``), put in order by :func:`align.present.story.build_report`.
    results : dict of str -> Result
        Every result, saved as ``<name>.json`` by the demo.
    lines : list of str
        The terminal summary.
    verdicts : list of Verdict
        The summary's checks.
    inputs : dict of str -> (str, str)
        Label -> (path, text shown verbatim or "").
    measured : list of MeasuredMargin
        The measured misalignment against the allowance (empty without both).
    """

    source: Callable[[Path], Path] = Path
    sections: dict = field(default_factory=dict)
    results: dict = field(default_factory=dict)
    lines: list = field(default_factory=list)
    verdicts: list = field(default_factory=list)
    inputs: dict = field(default_factory=dict)
    measured: list = field(default_factory=list)

    def add(self, part: str, section: Section) -> None:
        self.sections.setdefault(part, []).append(section)

    def text(self, path: Path) -> str:
        """The text of an input already read by its checked reader (undecodable bytes shown as such)."""
        return Path(self.source(path)).read_bytes().decode("utf-8", "replace")


def _deg(x: float) -> str:
    return f"{x / DEG:.4f} deg"


def _stamp_shown(rep: Report, job, result, options):
    """``job.stamp(result, options)`` (options naming the files as shown), each input file hashed where it is read
    (``rep.source``: the demo's staged copies)."""
    import dataclasses

    from align.provenance import file_record

    r = job.stamp(result, options)
    if rep.source is Path or r.provenance is None:
        return r
    files = tuple(dataclasses.replace(file_record(f.role, rep.source(Path(f.path))), path=f.path)
                  for f in r.provenance.files)
    return r.replace(provenance=dataclasses.replace(r.provenance, files=files))


def mount_job(rep: Report, mount: Path, monte_carlo: int, seed: int, progress=None, parts: Mapping | None = None):
    """The mounting budget (Eq 1-4, worst case, Monte Carlo): the ``budget`` job (:data:`mechanics.jobs.BUDGET`)
    run with the options the command builds; returns the Budget and the mount.

    ``parts`` is the table of presets the mount's part is looked up in (the built-in one when None).
    """
    from mechanics.jobs import BUDGET, BudgetOptions
    from mechanics.jobs import read as read_budget

    opts = BudgetOptions(mount=Path(mount), monte_carlo=monte_carlo, seed=seed, parts_table=parts)
    b = _stamp_shown(rep, BUDGET, BUDGET.compute(read_budget(opts, rep.source), opts, progress), opts)
    m = b.mount
    rep.inputs["mount"] = (str(mount), rep.text(mount))
    rep.results["budget"] = b
    rep.lines.append(f"budget: source total {b.total / DEG:.4f} deg, worst case {b.worst_case / DEG:.4f} deg"
                     + (f", Monte Carlo p99.73 any axis {b.monte_carlo.percentiles['99.73'][3] / DEG:.4f} deg"
                        if monte_carlo else ""))
    rep.lines += preset_lines(b)
    return b, m


def manoeuvre_job(rep: Report, manoeuvre: Path | None, budget=None, mount=None, basis: str = "rss", monte_carlo: int = 0,
                  mount_path: Path | None = None):
    """What the manoeuvre allows and, with a budget, the budget against it; the budget's section too.

    The ``allowable`` and ``check`` jobs (:mod:`align.sensitivity.jobs`) with the options the commands build; the
    check's table from the budget already computed (``mount_path``: its file, named in the table).
    """
    import align.present.html as report
    from align.sensitivity.margins import Margin
    from mechanics.render import assembly_png, histogram_png

    allow = table = None
    if manoeuvre is not None:
        from align.sensitivity.jobs import ALLOWABLE, CHECK, AllowableOptions, CheckOptions, check_table, read_allowable

        aopts = AllowableOptions(manoeuvre=Path(manoeuvre))
        allow = _stamp_shown(rep, ALLOWABLE, ALLOWABLE.compute(read_allowable(aopts, rep.source), aopts, None), aopts)
        rep.inputs["manoeuvre"] = (str(manoeuvre), rep.text(manoeuvre))
        rep.results["allowable"] = allow
        if budget is not None:
            shown = mount_path if mount_path is not None else rep.inputs.get("mount", ("mount",))[0]
            copts = CheckOptions(mount=Path(shown), manoeuvre=Path(manoeuvre), basis=basis)
            table = _stamp_shown(rep, CHECK, check_table(budget, allow, copts), copts)
            rep.results["check"] = table
        rep.lines.append(f"allowance: binding {allow.binding} = {allow.binding_value / DEG:.4f} deg"
                         + ("" if table is None else
                            f"; budget ({basis}) {'PASSES' if table.passed else 'FAILS'} the check"))
    if budget is not None:
        rep.add("mount", report.budget_section(budget, histogram_png(budget) if monte_carlo else None,
                                               assembly_png(mount)))
        if table is not None:
            w: Margin = worst(list(table.rows))  # type: ignore[assignment]  # the check's binding row
            rep.verdicts.append(Verdict(
                f"mounting budget ({basis}) vs allowance", PASS if table.passed else FAIL,
                f"{w.element} margin {w.margin / DEG:+.4f} deg", w.margin / DEG,
                f"design check: predicted {_deg(w.predicted)} against {_deg(w.allowed)} allowed (smallest margin of 9 "
                "elements)" + ("" if table.passed else f"; over: {', '.join(table.failed)}"), design=True))
        else:
            rep.verdicts.append(Verdict("mounting budget", INFO, f"RSS total {budget.total / DEG:.4f} deg",
                                        budget.total / DEG, "no manoeuvre given: nothing to check it against"))
    if allow is not None:
        rep.add("mount", report.allowance_section(allow, table, basis))
    return allow


def _log_source(rep: Report, log: Path, gyro_units: str | None, log_format: LogFormat | None, columns: str | None,
                 rate_hz: float | None, time_column: str | None = None):
    """The rate-table log as the report's options give it, as ``matrix`` takes it (:class:`~align.io.source.LogSource`:
    ``x,y,z`` with the time column ``time_column`` or ``time``, or ``time,x,y,z``; ``x,y,z`` with a sample rate)."""
    from align.io.source import LogSource

    names = None if columns is None else tuple(c.strip() for c in columns.split(",") if c.strip())
    return LogSource(path=Path(rep.source(log)), columns=names, time_column=time_column, rate_hz=rate_hz,
                     units=gyro_units, format=log_format or LogFormat())


def _as_shown(r, shown: dict):
    """A result run on staged copies (the demo) with its inputs and provenance naming the files as shown."""
    import dataclasses

    if all(str(k) == str(v) for k, v in shown.items()):
        return r
    paths = {str(k): str(v) for k, v in shown.items()}
    inputs = {k: paths.get(v, v) if isinstance(v, str) else v for k, v in r.inputs.items()}
    prov = r.provenance
    if prov is not None:
        prov = dataclasses.replace(prov, files=tuple(dataclasses.replace(f, path=paths.get(f.path, f.path))
                                                     for f in prov.files))
    return r.replace(inputs=inputs, provenance=prov)


def alignment_job(rep: Report, allow, log: Path | None = None, plan: Path | None = None, result: Path | None = None,
                  gyro_units: str | None = None, log_format: LogFormat | None = None, columns: str | None = None,
                  rate_hz: float | None = None, time_column: str | None = None) -> None:
    """The electronic alignment from a log and its plan (the ``matrix`` job, :data:`align.alignment.jobs.MATRIX`),
    or from a result file; the measured misalignment against the allowance (:mod:`align.present.measured`).

    ``log_format``, ``columns`` (``x,y,z`` with ``time_column``, default ``time``; ``time,x,y,z``; ``x,y,z`` with
    ``rate_hz``) and ``rate_hz``: how to read the log, with the meaning ``matrix`` gives them (None: a plain CSV
    ``time,gyro_x,gyro_y,gyro_z``); for a result file, None keeps what it recorded.
    """
    from align.present.alignsection import alignment_section
    from align.present.reread import reread_alignment_log
    from align.present.segplot import segmentation_plot_png

    if result is not None:
        from align.alignment.result import AlignmentResult
        from align.results import load_result

        r = load_result(rep.source(result), (AlignmentResult,))
        got, why = reread_alignment_log(Path(result), r, log_format, columns, rate_hz)
        png = None if got is None else segmentation_plot_png(got.t, got.data, r, r.units)
        rep.inputs["alignment result"] = (str(result), "")
    else:
        from align.alignment.jobs import MATRIX, MatrixOptions
        from align.errors import InputError

        if log is None or plan is None:
            raise InputError("give a rate-table log and its plan, or an alignment result", "{log}")
        try:  # the job's defaults, as `matrix` with no options; its errors name the report's own inputs
            opts = MatrixOptions(log=_log_source(rep, log, gyro_units, log_format, columns, rate_hz, time_column),
                                 plan=Path(rep.source(plan)))
            r, inputs = MATRIX.run_with_inputs(opts)
        except InputError as exc:
            raise type(exc)(template(exc, LOG_FIELDS)) from None
        r = _as_shown(r, {opts.log.path: log, opts.plan: plan})  # the files as shown (the demo reads staged copies)
        got = inputs.log
        png, why = segmentation_plot_png(got.t, got.data, r, r.units), ""
        rep.inputs["rate-table log"] = (str(log), "")
        rep.inputs["plan"] = (str(plan), rep.text(plan))
    rep.add("alignment", alignment_section(r, png, why))
    rep.results["alignment"] = r
    ang = r.angles
    counts: dict[str, int] = {}
    for c in r.checks:
        counts[c.status] = counts.get(c.status, 0) + 1
    n_mo = len(r.motions)
    rep.lines.append(f"alignment: psi = {', '.join(f'{v / DEG:.3f}' for v in ang.psi)} deg, "
                     f"sigma(M) <= {np.nanmax(r.sigma_M):.1e}, "
                     f"checks: {', '.join(f'{n} {s}' for s, n in counts.items())}"
                     + (f"; {n_mo} motion{'s' if n_mo != 1 else ''} that no step claimed, ignored" if n_mo else ""))
    if why:
        rep.lines.append(Said("  " + why))
    rep.verdicts.append(checks_verdict("alignment self-checks", r.checks,
                                       "durations, directions, scale, residuals as the alignment checks them"))
    if allow is None:
        k = int(np.argmax(ang.psi))
        rep.verdicts.append(Verdict("measured misalignment", INFO, f"psi_{'xyz'[k]} {ang.psi[k] / DEG:.4f} deg",
                                    ang.psi[k] / DEG, "the largest axis-to-frame angle; no manoeuvre given to check "
                                    "it against"))
        return
    _measured(rep, r, allow)


def _measured(rep: Report, r, allow) -> None:
    """The measured misalignment propagated through the manoeuvre (the verdict), each element alone (the diagnosis)."""
    from align.present.measured import describe, headline, measured_margins, measured_section, output_margins

    outputs = output_margins(r.M, r.sigma_M, r.mounting, allow.manoeuvre)
    rows = measured_margins(r, allow)
    status, w, detail = describe(outputs, rows)
    rep.add("measured", measured_section(outputs, rows))
    rep.measured = rows
    rep.verdicts.append(Verdict("measured misalignment vs allowance", status,
                                f"output {w.output} margin {w.margin / DEG:+.4f} deg", w.margin / DEG, detail))
    rep.lines.append(f"measured vs allowance: {status} ({headline(w)})")


def allan_job(rep: Report, allan: Path, columns: str | None = None, rate_hz: float | None = None,
              units: str | None = None, table_rate: str = "100 deg/s", accuracy: str = "0.1 deg",
              noise_ratio: float = 10.0, log_format: LogFormat | None = None, *, options=None) -> None:
    """The Allan deviation of a static record (or an Allan result file), and the test plan from it (gyro data).

    The record is read, checked and analysed by the ``allan`` job (:data:`align.noise.jobs.ALLAN`), so every
    option of ``allan REC`` means the same here. ``options`` (an :class:`~align.noise.jobs.AllanOptions`, e.g.
    from the command line's ``align.cli.allan.allan_options``) gives them all; without it they are built from
    ``columns``, ``rate_hz``, ``units`` (any rate or acceleration unit, or the size of one count) and
    ``log_format``. The plan is made for gyro records, at ``table_rate`` and ``accuracy`` unless ``options``
    states its own ``rate`` and ``accuracy``.
    """
    import dataclasses

    from align.noise import plan_from_allan
    from align.noise.analysis import AllanAnalysis
    from align.noise.jobs import ALLAN, AllanOptions, allan_unit
    from align.present.noisesection import allan_section
    from align.present.plots import allan_plot_png

    if Path(allan).suffix.lower() == ".json":
        from align.results import load_result

        job = load_result(rep.source(allan), (AllanAnalysis,))
        job = job.replace(plan=None)  # planned again at the report's rate and accuracy
        rep.inputs["Allan result"] = (str(allan), "")
    else:
        if options is None:
            options = AllanOptions(logs=(Path(allan),), columns=None if columns is None else tuple(columns.split(",")),
                                   rate_hz=rate_hz, units=units,
                                   format=log_format or LogFormat())
        gyro = parse_unit(allan_unit(options.gyro_units, options.units)[0]).dim == parse_unit("rad/s").dim
        plan_at = {} if options.rate is not None else {"rate": q(table_rate, "angular_rate", "{rate}"),
                                                        "accuracy": q(accuracy, "angle", "{accuracy}"),
                                                        "noise_ratio": noise_ratio}
        options = dataclasses.replace(options, logs=tuple(Path(rep.source(p)) for p in options.logs),
                                      **(plan_at if gyro else {"rate": None, "accuracy": None}))
        job = ALLAN.run(options).replace(inputs=(str(allan),))
        rep.inputs["static record"] = (str(allan), "")
    pl = job.plan
    if pl is None and job.sensor == "gyroscope":
        pl = plan_from_allan(job, q(table_rate, "angular_rate", "{rate}"), q(accuracy, "angle", "{accuracy}"), noise_ratio,
                             "measured curve (worst channel)")
        job = job.replace(plan=pl)
    if pl is not None:
        rep.results["plan"] = pl
        avg = "infeasible" if pl.averaging.tau is None else f"{pl.averaging.tau:.4g} s per step"
        rep.lines.append(f"plan: noise target {pl.noise_target / DEG_H:.2f} deg/h at {table_rate}, {accuracy}: averaging {avg}")
        rep.verdicts.append(Verdict(
            "test plan: averaging time", WARN if pl.averaging.tau is None else INFO,
            avg, float("nan") if pl.averaging.tau is None else pl.averaging.tau,
            f"for {accuracy} at {table_rate} with noise {noise_ratio:g}x below the goal (target "
            f"{pl.noise_target / DEG_H:.2f} deg/h)"))
    rep.results["allan"] = job
    plot = allan_plot_png(job, None if pl is None else pl.noise_target, None if pl is None else pl.averaging.tau)
    rep.add("noise", allan_section(job, plot, pl))
    fits = job.to_dict()["fit"]
    arw = {n: f["ieee_point_readouts"].get("N_at_tau_1s") for n, f in fits.items()}
    known = {n: v for n, v in arw.items() if v is not None}
    if known:
        n = max(known, key=lambda k: known[k])
        unit = fits[n]["ieee_point_readouts"]["N_unit"]
        rep.verdicts.append(Verdict("noise: N at tau = 1 s", INFO, f"{known[n]:.4g} {unit} ({n})", known[n],
                                    "the worst channel's random walk (IEEE point readout)"))


def calibration_job(rep: Report, path: Path) -> None:
    """A calibration result (accelerometer, Ferraris, gyro, magnetometer, thermal): its section, picture and summary
    number."""
    from align.calibration.magnetometer import MagCalibration
    from align.calibration.results import CalibrationSet
    from align.calibration.thermal.result import ThermalCalibration
    from align.present.calsection import calibration_section, magnetometer_section
    from align.present.residuals import largest
    from align.results import load_result
    from align.vocab import Status

    res = cast("CalibrationSet | MagCalibration | ThermalCalibration",  # load_result's overloads stop at two types
               load_result(rep.source(path), (CalibrationSet, MagCalibration, ThermalCalibration)))
    name = Path(path).stem
    rep.inputs[f"calibration {name}"] = (str(path), "")
    rep.results[f"calibration {name}"] = res
    if isinstance(res, ThermalCalibration):
        from align.present.thermalsection import thermal_job

        thermal_job(rep, Path(path), res, name)
        return
    if isinstance(res, MagCalibration):
        from align.present.calplots import magnetometer_png

        _, raw, why = read_capture(Path(path), res.inputs, "mag_x,mag_y,mag_z", "mag_units", "magnetic_field")
        png = None
        if raw is not None:
            png, why = magnetometer_png(raw[:, -3:], res), ""
        rep.add("calibration", magnetometer_section(res, str(path), png, in_words(why)))
        rep.verdicts.append(Verdict(f"magnetometer ({name})", Status.INFO, f"heading error {res.heading_error / DEG:.3f} deg",
                                    res.heading_error / DEG, f"predicted, 1 sigma; field spread {100 * res.spread_before:.2f} % "
                                    f"before, {100 * res.spread_after:.2f} % after"))
        rep.lines.append(f"magnetometer {path}: predicted heading error {res.heading_error / DEG:.3f} deg, "
                         f"spread {100 * res.spread_after:.2f} % after")
        if why:
            rep.lines.append(Said("  " + why))
        return
    for kind, cal in res.sensors.items():
        png, why = statics_picture(Path(path), res.inputs, cal)
        rep.add("calibration", calibration_section(cal, str(path), png, in_words(why)))
        big = largest(cal, held_out=True) or largest(cal)  # the terminal's and the section's figure and definition
        if big is not None:
            rep.verdicts.append(Verdict(f"{kind} calibration ({name})", Status.INFO, big.number, big.value,
                                        f"{cal.method}; {big.definition}; {big.count}"))
            rep.lines.append(f"{kind} calibration {path}: {cal.method}, {big.number} ({big.where})")
        if why and png is None:
            rep.lines.append(Said("  " + why))


def drift_job(rep: Report, path: Path) -> None:
    """The error growth of a navigation result, through :mod:`align.present.navigation`."""
    from align.navigation.result import DriftResult
    from align.present.navigation import drift_plot_png, navigation_section
    from align.results import load_result

    res = load_result(rep.source(path), (DriftResult,))
    rep.inputs[f"navigation {Path(path).stem}"] = (str(path), "")
    rep.results[f"drift {Path(path).stem}"] = res
    rep.add("navigation", navigation_section(res, drift_plot_png(res)))
    t_end = float(res.t[-1]) if len(res.t) else 0.0
    _, north = res.component("position_m", "north")
    _, east = res.component("position_m", "east")
    _, heading = res.component("attitude_deg", "heading")
    horizontal = float(np.hypot(north[-1], east[-1]))
    rep.verdicts.append(Verdict(f"navigation error growth ({Path(path).stem})", INFO,
                                f"horizontal position {horizontal:.4g} m (1 sigma)", horizontal,
                                f"after {t_end:g} s; heading {heading[-1]:.4g} deg (1 sigma); Monte Carlo of "
                                f"{res.runs:,} runs"))
    rep.lines.append(f"drift {path}: after {t_end:g} s horizontal position {horizontal:.4g} m, heading "
                     f"{heading[-1]:.4g} deg (1 sigma)")
