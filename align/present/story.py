"""The whole story in one call: budget, allowance, noise plan and alignment, and the report.

:func:`make_report` runs every job whose inputs are given (any subset: the jobs are in
:mod:`align.present.jobs`) and returns the HTML page, a short text summary, the JSON-ready results and
the verdicts of the summary at the top of the page (:func:`build_report`: the first three); :func:`demo_inputs`
stages the bundled inputs (the reference's Examples 1 and 2, a simulated static
record and a simulated rate-table session) in the run's
:class:`~align.io.outputs.Outputs`, so that the demo is a report of real files
like any other, and a demo that fails leaves none of them behind.

Public names
------------
make_report, Outcome, build_report, demo_inputs, run_demo, DEMO_TITLE, DEMO, PARTS
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from align.io import LogFormat
from align.io.outputs import Outputs
from align.units import DEG
from align.units import parse_quantity as q

DEMO = Path(__file__).with_name("demo")
DEMO_TITLE = "imu-align demo: ADIS16485 on a vehicle antenna platform"


def demo_inputs(out: Path, staged: Outputs | None = None, seed: int = 0) -> dict:
    """Stage the demo's inputs (their names in ``out``) in ``staged``; return their paths and reading options.

    The files are read back from their staged copies (``staged.staged(path)``) until the run commits;
    without ``staged`` they are written at once.
    """
    if staged is None:
        with Outputs() as now:
            return demo_inputs(out, now, seed)
    from align.alignment.plan import Plan
    from align.alignment.simulate import SessionSpec, SimulationTruth, simulate_session
    from align.model import SensorModel
    from align.noise.sim import NoiseSpec, simulate_noise
    from align.units import to_unit

    mount, manoeuvre = out / "mount.toml", out / "manoeuvre.toml"
    staged.write_text(mount, (DEMO / "mount.toml").read_text())
    staged.write_text(manoeuvre, (DEMO / "manoeuvre.toml").read_text())
    rng = np.random.default_rng(seed)
    # a static record with the ADIS16485's datasheet noise (0.3 deg/sqrt(h), 6.25 deg/h), 20 min at 100 Hz
    static = simulate_noise(120_000, 100.0, NoiseSpec(white=q("0.3 deg/sqrt(h)", "angle_random_walk"),
                                                       flicker=q("6.25 deg/h", "angular_rate")), 3, rng)
    static_path = out / "static.npy"
    staged.write_bytes(static_path, _npy(to_unit(static, "deg/s")))
    # a +/-100 deg/s six-dwell session of an IMU mounted 0.8 deg off, known truth
    plan = Plan.standard_rate(100 * DEG)
    from scipy.spatial.transform import Rotation

    truth = SensorModel.from_rotation(Rotation.from_rotvec(np.array([0.3, -0.5, 0.55]) * DEG),
                                      scale=[1.002, 0.998, 1.001], delta=np.array([0.03, -0.02, 0.04]) * DEG,
                                      bias=np.array([0.2, -0.1, 0.05]) * DEG)
    t, g, _ = simulate_session(plan, truth, SessionSpec(fs=200.0, dwell_s=8.0, static_s=2.0,
                                                        noise_density=q("0.3 deg/sqrt(h)", "angle_random_walk")), rng)
    log, plan_path = out / "session.csv", out / "plan.toml"
    staged.write_csv(log, ["time", "gyro_x", "gyro_y", "gyro_z"], np.column_stack([t, to_unit(g, "deg/s")]))
    staged.write_text(plan_path, plan.to_toml())
    return {"mount": mount, "manoeuvre": manoeuvre, "log": log, "plan": plan_path, "allan": static_path,
            "allan_rate_hz": 100.0, "allan_columns": "gyro_x,gyro_y,gyro_z", "truth_M": truth.M,
            "truth": SimulationTruth(truth, "deg/s", seed, {"log": str(log), "plan": str(plan_path)})}


def _npy(arr: np.ndarray) -> bytes:
    import io

    buf = io.BytesIO()
    np.save(buf, np.ascontiguousarray(arr))
    return buf.getvalue()


#: the order of the report's parts after the summary (the inputs come last)
PARTS = ("measured", "mount", "alignment", "noise", "calibration", "merit", "navigation")


@dataclass(frozen=True)
class Outcome:
    """A report and what it found.

    Attributes
    ----------
    page : str
        The HTML report.
    text : str
        The terminal summary: one line per job, then the verdict.
    results : dict of str -> Result
        Every job's result (the demo saves each as ``<name>.json``).
    verdicts : tuple of Verdict
        The summary's checks, in the order shown.
    measured : tuple of MeasuredMargin
        The measured misalignment against the allowance, element by element (empty without both).
    """

    page: str
    text: str
    results: dict
    verdicts: tuple
    measured: tuple = ()

    @property
    def failed(self) -> list:
        """The checks that failed (the command exits 4 when there is one)."""
        return [v for v in self.verdicts if v.failed]


def make_report(mount: Path | None = None, manoeuvre: Path | None = None, log: Path | None = None,
                plan: Path | None = None, allan: Path | None = None, allan_columns: str = "gyro_x,gyro_y,gyro_z",
                allan_rate_hz: float | None = None, allan_units: str | None = None, gyro_units: str | None = None,
                table_rate: str = "100 deg/s", accuracy: str = "0.1 deg", noise_ratio: float = 10.0,
                monte_carlo: int = 100_000, seed: int = 0, basis: str = "rss", progress=None,
                title: str | None = None, source: Callable[[Path], Path] | None = None,
                log_format: LogFormat | None = None, alignment: Path | None = None, calibrations: Sequence[Path] = (),
                drift: Sequence[Path] = (), header: dict | None = None, parts: Mapping | None = None,
                log_columns: str | None = None, log_rate_hz: float | None = None,
                spell: Callable[[str, str | None], str] | None = None, allan_options: Any = None,
                log_time_column: str | None = None, limits: Path | None = None) -> Outcome:
    """Run every job whose inputs are given, from any subset of them, and build the report.

    Parameters
    ----------
    mount, manoeuvre : Path, optional
        Mount and manoeuvre TOML: the budget (Eq 1-4, Monte Carlo) and what the manoeuvre allows.
    log, plan : Path, optional
        A rate-table log and its plan, aligned here (both or neither); or ``alignment``, an alignment result file.
    log_columns, log_rate_hz : str, float, optional
        The log's columns (``time,x,y,z``; ``x,y,z`` with ``log_rate_hz``, Hz, for a log without time); None: a
        log's ``time,gyro_x,gyro_y,gyro_z``, and for an alignment result file what it recorded.
    log_time_column : str, optional
        The log's time column (``matrix``'s ``time_column``; default ``time``).
    allan_options : AllanOptions, optional
        Every option of the ``allan`` job for the static record (:class:`align.noise.jobs.AllanOptions`, e.g.
        from ``align.cli.allan.allan_options``); None: built from ``allan_columns``, ``allan_rate_hz``,
        ``allan_units`` and ``log_format``.
    allan : Path, optional
        A static record (``allan_columns``, ``allan_rate_hz``, ``allan_units``) or an Allan result file (``.json``);
        a gyro's gives the test plan for ``table_rate``, ``accuracy``, ``noise_ratio``.
    calibrations : sequence of Path
        Calibration result files (accelerometer, Ferraris, gyro, magnetometer).
    drift : sequence of Path
        Navigation results whose error growth is shown (:mod:`align.present.navigation`).
    parts : dict of str to Part, optional
        The presets the mount's part is looked up in (:func:`align.parts.merge_parts`); the built-in table when None.
    title : str, optional
        The report's title; default by what is reported: ``IMU alignment report`` (a mount, manoeuvre or
        alignment), ``IMU calibration report`` (calibrations), ``IMU noise report`` (an Allan record alone),
        ``IMU report`` otherwise.
    header : dict, optional
        The report's identification (``"serial number"``, ``"operator"``, ``"test"``, ``"date"``), shown under
        the title with the tool's version.
    source : callable, optional
        Maps an input's path (as shown) to the file to read (the demo reads its staged inputs).
    log_format : LogFormat, optional
        A logger file's preamble, comments, delimiter, time unit: for the rate-table log and the static record;
        None: a plain CSV, and for an alignment result file the format it recorded.
    spell : callable, optional
        ``spell(field, value_or_None) -> str``: how the terminal summary names an input in a note (the command
        line's flags); plain words when None.

    Returns
    -------
    Outcome
        The summary (every check, its verdict and its number) comes first on the page, the inputs last.
        The measured misalignment, when checked, governs the outcome: the mounting budget against the
        allowance is then a design check, shown with its verdict but failing nothing.

    Raises
    ------
    InputError
        No input at all, ``log`` without ``plan`` (or the reverse), ``log`` with ``alignment``, or a bad file.
    """
    import align.present.html as report
    from align.errors import InputError
    from align.present import jobs
    from align.present.verdicts import INFO, Verdict, summary_section

    if (log is None) != (plan is None):
        raise InputError("give {log} and {plan} together", "{log}" if log is None else "{plan}")
    if log is not None and alignment is not None:
        raise InputError("give a rate-table log and its plan, or an alignment result, not both", "{alignment}")
    if all(x is None for x in (mount, manoeuvre, log, allan, alignment)) and not calibrations and not drift:
        raise InputError("nothing to report: give at least one of {mount}, {manoeuvre}, {log} with {plan}, {alignment}, "
                         "{allan}, {calibration}, {drift}")
    from align.limits import read_limits

    read = None if limits is None else read_limits(limits)  # before any job: a bad limits file costs no work
    rep = jobs.Report(source or Path)
    b = m = None
    if mount is not None:
        b, m = jobs.mount_job(rep, mount, monte_carlo, seed, progress, parts)
    allow = jobs.manoeuvre_job(rep, manoeuvre, b, m, basis, monte_carlo, mount_path=mount)
    if log is not None or alignment is not None:
        jobs.alignment_job(rep, allow, log, plan, alignment, gyro_units, log_format, log_columns, log_rate_hz,
                           time_column=log_time_column)
    elif allow is not None and b is None:
        rep.verdicts.append(Verdict("allowance", INFO, f"binding {allow.binding} = {allow.binding_value / DEG:.4f} deg",
                                    allow.binding_value / DEG, "no budget or alignment given to check against it"))
    if allan is not None:
        jobs.allan_job(rep, allan, allan_columns, allan_rate_hz, allan_units, table_rate, accuracy, noise_ratio, log_format,
                       options=allan_options)
    for path in calibrations:
        jobs.calibration_job(rep, path)
    for path in drift:  # the error growth of a navigation result
        jobs.drift_job(rep, path)
    from align.present.merit import merit_parts

    for label, result in rep.results.items():  # every result's figures of merit, judged (issue 27)
        judged = merit_parts(label, result, read)
        if judged is not None:
            rep.verdicts.append(judged[0])
            rep.add("merit", judged[1])
    if rep.measured:  # the unit is measured: the budget is a design check and governs nothing
        rep.verdicts = [dataclasses.replace(v, governs=False) if v.design else v for v in rep.verdicts]
    sections = [summary_section(rep.verdicts)]
    sections += [s for part in PARTS for s in rep.sections.get(part, [])]
    sections.append(report.inputs_section(rep.inputs))
    text = "\n".join([_say(x, spell) for x in rep.lines] + [f"summary: {_verdict(rep.verdicts)}"])
    if title is None:
        title = ("IMU alignment report" if any(x is not None for x in (mount, manoeuvre, log, alignment)) else
                 "IMU calibration report" if calibrations else "IMU noise report" if allan is not None and not drift
                 else "IMU report")
    return Outcome(report.html_report(title, sections, header, _conventions(rep.results)), text, rep.results,
                   tuple(rep.verdicts), tuple(rep.measured))


def _conventions(results: dict) -> list[str]:
    """The matrix conventions of the results shown (a gyro alignment's, a calibration's, a magnetometer's), once each."""
    from align import CONVENTION

    out: list[str] = []
    for r in results.values():
        c = getattr(type(r), "CONVENTION", "")
        c = CONVENTION if c.startswith(CONVENTION) else c
        if c.startswith(("g = M", "raw = M", "m_cal =")) and c not in out:
            out.append(c)
    return out


def _say(line, spell) -> str:
    """A terminal line; a note's placeholders in the caller's spelling (plain words by default)."""
    from align.errors import AlignError
    from align.present.reread import Said, in_words

    if not isinstance(line, Said):
        return line
    return in_words(line.template) if spell is None else AlignError(line.template).render(spell)


def _verdict(verdicts) -> str:
    """The terminal's last line (:func:`align.present.verdicts.summary_line`: what the page's banner says)."""
    from align.present.verdicts import summary_line

    return summary_line(verdicts)


def build_report(mount: Path | None = None, manoeuvre: Path | None = None, **kwargs) -> tuple[str, str, dict]:
    """:func:`make_report` as ``(HTML, summary text, results)``."""
    out = make_report(mount, manoeuvre, **kwargs)
    return out.page, out.text, out.results


def run_demo(out: Path, staged: Outputs, progress=None) -> tuple[str, str, dict]:
    """The demo: bundled inputs staged for ``out``, every job run, the alignment compared with the truth.

    Nothing is written until the caller commits ``staged`` (with the results and the report added).

    Returns
    -------
    page : str
        The HTML report.
    summary : str
        What the demo found, ending with the alignment's largest error against the simulation's truth.
    results : dict of str to Result
        The jobs' results and the simulation's truth (``"truth"``), each to be saved as ``<name>.json``.
    """
    inp = demo_inputs(out, staged)
    page, summary, results = build_report(inp["mount"], inp["manoeuvre"], log=inp["log"], plan=inp["plan"],
                                          allan=inp["allan"], allan_columns=inp["allan_columns"],
                                          allan_rate_hz=inp["allan_rate_hz"], progress=progress, title=DEMO_TITLE,
                                          source=staged.staged)
    truth = inp["truth"]
    error = float(np.abs(results["alignment"].M - truth.model.M).max())
    summary += f"\nalignment error against the simulation's truth: {error:.1e} (largest element of M)"
    return page, summary, {**results, "truth": truth}
