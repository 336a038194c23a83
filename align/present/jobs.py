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

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from align.errors import AlignError
from align.io import LogFormat, read_sensor_log, read_static, read_toml
from align.present.html import Section
from align.present.presets import preset_lines
from align.present.reread import LOG_FIELDS, Said, in_words, read_capture, statics_picture, template
from align.present.verdicts import FAIL, INFO, PASS, WARN, Verdict, worst
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


def mount_job(rep: Report, mount: Path, monte_carlo: int, seed: int, progress=None, parts: dict | None = None):
    """The mounting budget (Eq 1-4, worst case, Monte Carlo); returns the Budget and the mount.

    ``parts`` is the table of presets the mount's part is looked up in (the built-in one when None).
    """
    from mechanics.budget import budget
    from mechanics.montecarlo import monte_carlo as run_mc
    from mechanics.mount import mount_from_dict

    m = mount_from_dict(read_toml(rep.source(mount)), str(mount), Path(mount).parent, parts=parts)
    b = budget(m)
    if monte_carlo:
        b = b.replace(monte_carlo=run_mc(m, monte_carlo, seed, progress=progress))
    rep.inputs["mount"] = (str(mount), rep.text(mount))
    rep.results["budget"] = b
    rep.lines.append(f"budget: source total {b.total / DEG:.4f} deg, worst case {b.worst_case / DEG:.4f} deg"
                     + (f", Monte Carlo p99.73 any axis {b.monte_carlo.percentiles['99.73'][3] / DEG:.4f} deg"
                        if monte_carlo else ""))
    rep.lines += preset_lines(b)
    return b, m


def manoeuvre_job(rep: Report, manoeuvre: Path, budget=None, mount=None, basis: str = "rss", monte_carlo: int = 0):
    """What the manoeuvre allows and, with a budget, the budget against it; the budget's section too."""
    import align.present.html as report
    from mechanics.render import assembly_png, histogram_png

    allow = table = None
    if manoeuvre is not None:
        from align.sensitivity import allowable, check_margins, manoeuvre_from_dict

        man = manoeuvre_from_dict(read_toml(rep.source(manoeuvre)), str(manoeuvre), Path(manoeuvre).parent)
        rep.inputs["manoeuvre"] = (str(manoeuvre), rep.text(manoeuvre))
        allow = allowable(man)
        rep.results["allowable"] = allow
        if budget is not None:
            table = check_margins(budget.elements(basis), allow, basis)
            rep.results["check"] = table
        rep.lines.append(f"allowance: binding {allow.binding} = {allow.binding_value / DEG:.4f} deg"
                         + ("" if table is None else
                            f"; budget ({basis}) {'PASSES' if table.passed else 'FAILS'} the check"))
    if budget is not None:
        rep.add("mount", report.budget_section(budget, histogram_png(budget) if monte_carlo else None,
                                               assembly_png(mount)))
        if table is not None:
            w = worst(list(table.rows))
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


def _log_columns(columns: str | None, rate_hz: float | None) -> tuple[str | None, list[str]]:
    """The report's rate-table log columns: ``time,x,y,z``, or ``x,y,z`` with a sample rate."""
    from align.errors import InputError

    names = [c.strip() for c in (columns or "time,gyro_x,gyro_y,gyro_z").split(",") if c.strip()]
    if len(names) != (3 if rate_hz is not None else 4):
        raise InputError("give four names time,x,y,z (three, x,y,z, with {log_rate_hz})", "{gyro_columns}")
    return (None, names) if rate_hz is not None else (names[0], names[1:])


def _read_log(rep: Report, log: Path, gyro_units: str, log_format: LogFormat | None, columns: str | None,
              rate_hz: float | None):
    """The rate-table log as the report's options say; its errors name the report's own inputs."""
    time_col, cols = _log_columns(columns, rate_hz)
    try:
        return read_sensor_log(rep.source(log), cols, gyro_units, time_col, rate_hz, log_format=log_format)
    except AlignError as exc:
        raise type(exc)(template(exc, LOG_FIELDS)) from None


def alignment_job(rep: Report, allow, log: Path | None = None, plan: Path | None = None, result: Path | None = None,
                  gyro_units: str = "deg/s", log_format: LogFormat | None = None, columns: str | None = None,
                  rate_hz: float | None = None) -> None:
    """The electronic alignment from a log and its plan, or from a result file; the measured misalignment
    against the allowance (:mod:`align.present.measured`).

    ``log_format``, ``columns`` (``time,x,y,z``; ``x,y,z`` with ``rate_hz``) and ``rate_hz``: how to read the log
    (None: a plain CSV ``time,gyro_x,gyro_y,gyro_z``); for a result file, None keeps what it recorded.
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
        from align.alignment.job import align
        from align.alignment.plan import Plan

        the_plan = Plan.from_dict(read_toml(rep.source(plan)), str(plan))
        got = _read_log(rep, log, gyro_units, log_format, columns, rate_hz)
        r = align(got.t, got.data, the_plan, units=got.shown, where=str(log))
        r = r.replace(notes=r.notes + tuple(filter(None, [got.time_note()])),
                      inputs={"log": str(log), "plan": str(plan), "gyro_units": gyro_units,
                              "columns": columns or "time,gyro_x,gyro_y,gyro_z", "rate_hz": rate_hz, **got.inputs()})
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
    warned = [c.name for c in r.checks if c.status == "warn"]
    rep.verdicts.append(Verdict("alignment self-checks", WARN if warned else PASS,
                                f"{counts.get('pass', 0)} of {len(r.checks)} pass", float(counts.get("pass", 0)),
                                ("warnings: " + ", ".join(warned)) if warned else
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
    from align.present.measured import describe, measured_margins, measured_section, output_margins

    outputs = output_margins(r.M, r.sigma_M, r.mounting, allow.manoeuvre)
    rows = measured_margins(r, allow)
    status, w, detail = describe(outputs, rows)
    rep.add("measured", measured_section(outputs, rows))
    rep.measured = rows
    rep.verdicts.append(Verdict("measured misalignment vs allowance", status,
                                f"output {w.output} margin {w.margin / DEG:+.4f} deg", w.margin / DEG, detail))
    rep.lines.append(f"measured vs allowance: {status} (output {w.output}: error {w.error / DEG:.4f} "
                     f"± {w.sigma / DEG:.4f} deg, limit {w.limit / DEG:.4f} deg; guard band {w.k:g} sigma)")


def allan_job(rep: Report, allan: Path, columns: str, rate_hz: float | None, units: str, table_rate: str,
              accuracy: str, noise_ratio: float, log_format: LogFormat | None) -> None:
    """The Allan deviation of a static record (or an Allan result file), and the test plan from it (gyro data)."""
    from align.noise import plan_from_allan, run_allan
    from align.noise.job import AllanJob
    from align.present.noisesection import allan_section
    from align.present.plots import allan_plot_png

    if Path(allan).suffix.lower() == ".json":
        from align.results import load_result

        job = load_result(rep.source(allan), (AllanJob,))
        rep.inputs["Allan result"] = (str(allan), "")
    else:
        names = [c.strip() for c in columns.split(",")]
        parse_unit(units, "angular_rate", "{allan_units}")  # the plan needs a gyro's record
        data, fs = read_static(rep.source(allan), names, rate_hz, log_format)
        job = run_allan([data], fs, names, units, where=str(allan))
        job = job.replace(inputs=(str(allan),))
        rep.inputs["static record"] = (str(allan), "")
    pl = None
    if job.sensor == "gyroscope":
        pl = plan_from_allan(job, q(table_rate, "angular_rate", "{rate}"), q(accuracy, "angle", "{accuracy}"), noise_ratio,
                             "measured curve (worst channel)")
        job = job.replace(plan=pl)
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
        n = max(known, key=known.get)
        unit = fits[n]["ieee_point_readouts"]["N_unit"]
        rep.verdicts.append(Verdict("noise: N at tau = 1 s", INFO, f"{known[n]:.4g} {unit} ({n})", known[n],
                                    "the worst channel's random walk (IEEE point readout)"))


def calibration_job(rep: Report, path: Path) -> None:
    """A calibration result (accelerometer, Ferraris, gyro, magnetometer): its section, picture and summary number."""
    from align.calibration.magnetometer import MagCalibration
    from align.calibration.results import CalibrationSet
    from align.present.calsection import calibration_section, magnetometer_section
    from align.results import load_result

    res = load_result(rep.source(path), (CalibrationSet, MagCalibration))
    name = Path(path).stem
    rep.inputs[f"calibration {name}"] = (str(path), "")
    rep.results[f"calibration {name}"] = res
    if isinstance(res, MagCalibration):
        from align.present.calplots import magnetometer_png

        _, raw, why = read_capture(Path(path), res.inputs, "mag_x,mag_y,mag_z", "mag_units", "magnetic_field")
        png = None
        if raw is not None:
            png, why = magnetometer_png(raw[:, -3:], res), ""
        rep.add("calibration", magnetometer_section(res, str(path), png, in_words(why)))
        rep.verdicts.append(Verdict(f"magnetometer ({name})", INFO, f"heading error {res.heading_error / DEG:.3f} deg",
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
        pool = dict(cal.checks) or dict(cal.residuals)
        what = "held-out check" if cal.checks else "residual"
        worst_v = max((float(np.abs(v).max()) for v in pool.values()), default=float("nan"))
        from align.present.figures import display_unit

        factor, shown = display_unit(cal.units)
        rep.verdicts.append(Verdict(f"{kind} calibration ({name})", INFO,
                                    f"largest {what} {worst_v / factor:.3g} {shown}", worst_v / factor,
                                    f"{cal.method}; {_count(pool, cal.sensor)}"))
        rep.lines.append(f"{kind} calibration {path}: {cal.method}, largest {what} {worst_v / factor:.3g} {shown}")
        if why and png is None:
            rep.lines.append(Said("  " + why))


def _count(pool: dict, sensor: str) -> str:
    """``10 attitudes``, ``6 rotations``: the residuals' own word (``attitude 1``) or the sensor's usual one."""
    first = next(iter(pool), "")
    word = first.split()[0] if " " in first and first.split()[-1].isdigit() else (
        "rotation" if sensor == "gyroscope" else "position")
    return f"{len(pool)} {word}{'' if len(pool) == 1 else 's'}"


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
