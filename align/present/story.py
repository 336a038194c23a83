"""The whole story in one call: budget, allowance, noise plan and alignment, and the report.

:func:`build_report` runs every job whose inputs are given and returns the HTML
page, a short text summary and the JSON-ready results; :func:`demo_inputs`
stages the bundled inputs (the reference's Examples 1 and 2, a simulated static
record and a simulated rate-table session) in the run's
:class:`~align.io.outputs.Outputs`, so that the demo is a report of real files
like any other, and a demo that fails leaves none of them behind.

Public names
------------
build_report, demo_inputs, run_demo, DEMO_TITLE, DEMO
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from align.io import LogFormat, read_sensor_log, read_static, read_toml
from align.io.outputs import Outputs
from align.units import DEG, DEG_H, parse_unit
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


def build_report(mount: Path, manoeuvre: Path, log: Path | None = None, plan: Path | None = None,
                 allan: Path | None = None, allan_columns: str = "gyro_x,gyro_y,gyro_z", allan_rate_hz: float | None = None,
                 allan_units: str = "deg/s", gyro_units: str = "deg/s", table_rate: str = "100 deg/s",
                 accuracy: str = "0.1 deg", noise_ratio: float = 10.0, monte_carlo: int = 100_000, seed: int = 0,
                 basis: str = "rss", progress=None, title: str = "IMU alignment report",
                 source: Callable[[Path], Path] | None = None,
                 log_format: LogFormat | None = None) -> tuple[str, str, dict]:
    """Run every job whose inputs are given; return (HTML, summary text, results).

    The inputs are named by their paths; ``source`` maps such a path to the file to read, when
    that differs (the demo reads its staged inputs: :meth:`align.io.outputs.Outputs.staged`).
    ``log_format`` (a logger file's preamble, comments, delimiter, time unit) applies to the
    rate-table log and the static record alike.
    """
    import align.present.html as report
    from align.sensitivity import allowable, check_margins, manoeuvre_from_dict
    from mechanics.budget import budget
    from mechanics.montecarlo import monte_carlo as run_mc
    from mechanics.mount import mount_from_dict
    from mechanics.render import assembly_png, histogram_png

    src = source or Path
    m = mount_from_dict(read_toml(src(mount)), str(mount), Path(mount).parent)
    b = budget(m)
    if monte_carlo:
        b = b.replace(monte_carlo=run_mc(m, monte_carlo, seed, progress=progress))
    man = manoeuvre_from_dict(read_toml(src(manoeuvre)), str(manoeuvre), Path(manoeuvre).parent)
    inputs = {"mount": (str(mount), _text(src(mount))), "manoeuvre": (str(manoeuvre), _text(src(manoeuvre)))}
    allow = allowable(man)
    table = check_margins(b.elements(basis), allow, basis)
    sections = [report.budget_section(b, histogram_png(b) if monte_carlo else None, assembly_png(m)),
                report.allowance_section(allow, table, basis)]
    results = {"budget": b, "allowable": allow, "check": table}
    lines = [f"budget: source total {b.total / DEG:.4f} deg, worst case {b.worst_case / DEG:.4f} deg"
             + (f", Monte Carlo p99.73 any axis {b.monte_carlo.percentiles['99.73'][3] / DEG:.4f} deg" if monte_carlo else ""),
             f"allowance: binding {allow.binding} = {allow.binding_value / DEG:.4f} deg; budget ({basis}) "
             f"{'PASSES' if table.passed else 'FAILS'} the check"]
    job = pl = plot = None
    if allan is not None:
        from align.noise import plan_from_allan, run_allan
        from align.present.plots import allan_plot_png

        names = [c.strip() for c in allan_columns.split(",")]
        parse_unit(allan_units, "angular_rate", "{allan_units}")  # the plan needs a gyro's record
        data, fs = read_static(src(allan), names, allan_rate_hz, log_format)
        job = run_allan([data], fs, names, allan_units, where=str(allan))
        pl = plan_from_allan(job, q(table_rate, "angular_rate", "{rate}"), q(accuracy, "angle", "{accuracy}"), noise_ratio,
                             "measured curve (worst channel)")
        job = job.replace(inputs=(str(allan),), plan=pl)
        plot = allan_plot_png(job, pl.noise_target, pl.averaging.tau)
        inputs["static record"] = (str(allan), "")
        results["allan"], results["plan"] = job, pl
        avg = "infeasible" if pl.averaging.tau is None else f"{pl.averaging.tau:.4g} s per step"
        lines.append(f"plan: noise target {pl.noise_target / DEG_H:.2f} deg/h at {table_rate}, {accuracy}: averaging {avg}")
    sections.append(report.allan_section(job, plot, pl) if allan is not None else
                    report.Section("Noise and test planning", "<p>No static record given.</p>"))
    if log is not None and plan is not None:
        from align.alignment.job import align
        from align.alignment.plan import Plan
        from align.present.plots import segmentation_plot_png

        the_plan = Plan.from_dict(read_toml(src(plan)), str(plan))
        got = read_sensor_log(src(log), ["gyro_x", "gyro_y", "gyro_z"], gyro_units, log_format=log_format)
        t, g = got.t, got.data
        r = align(t, g, the_plan, units=got.shown, where=str(log))
        r = r.replace(notes=r.notes + tuple(filter(None, [got.time_note()])))
        sections.append(report.alignment_section(r, segmentation_plot_png(t, g, r, r.units)))
        inputs["rate-table log"] = (str(log), "")
        inputs["plan"] = (str(plan), _text(src(plan)))
        results["alignment"] = r
        ang = r.angles
        lines.append(f"alignment: psi = {', '.join(f'{v / DEG:.3f}' for v in ang.psi)} deg, "
                     f"sigma(M) <= {np.nanmax(r.sigma_M):.1e}, "
                     f"checks: {_check_counts(r.checks)}"
                     + (f"; {len(r.motions)} motion(s) no step claimed, ignored" if r.motions else ""))
    sections.insert(0, report.inputs_section(inputs))
    return report.html_report(title, sections), "\n".join(lines), results


def _text(path: Path) -> str:
    """The text of an input already read by its checked reader, for the report (undecodable bytes shown as such)."""
    return Path(path).read_bytes().decode("utf-8", "replace")


def _check_counts(checks) -> str:
    """``"5 pass, 1 not checked"``: how many checks ended in each status."""
    counts: dict[str, int] = {}
    for c in checks:
        counts[c.status] = counts.get(c.status, 0) + 1
    return ", ".join(f"{n} {status}" for status, n in counts.items())


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
