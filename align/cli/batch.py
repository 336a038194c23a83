"""``imu-align batch``: many units through the single commands (their statistics: :mod:`align.cli.lot`).

``batch`` runs every unit of a manifest (:mod:`align.production.manifest`) through the library job of
the command a user would type for it alone: each row's words are parsed by that command and made into
the job's options by the command's own builder, in this process, when the manifest is read
(:mod:`align.cli.batchjobs`); a worker then runs the job (:func:`align.production.run_job`), writes the
unit's JSON and the extra files its output options ask for, and returns the lot's rows from the result
in memory. A unit's refusal is the single command's one line and exit status
(:func:`align.cli.batchjobs.error_line`), so a unit's result and its refusal are exactly the single
command's.

Public names
------------
batch, run_unit, simulate_lot_command, JOBS, COMMANDS
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from align.cli import options as opt
from align.cli.batchjobs import (  # noqa: F401
    JOBS,
    OUTPUT_OPTIONS,
    RESERVED,
    _jobs,
    check_options,
    parse_rows,
    task_maker,
    validation_unit,
)

# ---- the worker: the unit's library job ----


def _preload(jobs) -> tuple[str, ...]:
    """The modules a worker needs for ``jobs``: its own and each job's (:data:`align.api.JOBS`)."""
    from align.api import JOBS as LIBRARY

    return ("align.cli.batch", "align.production.batch",
            *sorted({LIBRARY[j].partition(":")[0] for j in jobs if j in LIBRARY}))


def run_unit(task) -> list[dict]:
    """Run one unit's job in this process (:func:`align.production.run_job`) and return its table rows; a
    failure is the single command's one line and exit status."""
    from align.cli.batchjobs import error_line
    from align.cli.builders import files_builder
    from align.production import run_job

    return run_job(task, files_builder(task.unit.job) if task.params else None, error_line)


# ---- the commands ----

Workers = Annotated[int | None, typer.Option("--workers", parser=opt.whole(1, 4096, "2"), metavar="N", help=(
    "Worker processes on this machine, or of a local Dask cluster (--scheduler local); default: the CPUs."))]
Scheduler = Annotated[str | None, typer.Option("--scheduler", metavar="ADDRESS", help=(
    "Run on a Dask cluster instead of a process pool: its scheduler (tcp://host:8786), or 'local' for a local "
    "cluster of --workers processes. Needs pip install 'imu-align[cluster]'; the workers must see the files under "
    "the same paths."))]


def batch(
    manifest: opt.Arg("Manifest: CSV with columns serial, job, log, plan, options and optionally slot, station, "
                      "fixture, operator, device_id, test_time (ISO 8601 with its zone), validation, validation_plan, "
                      "validation_options (a rate-table session the unit's result is replayed on by verify), or TOML "
                      "([[unit]] tables, [defaults]); paths relative to it. Jobs: matrix (plan: its --plan), "
                      "calibrate ferraris (--sections), calibrate accel (--positions), calibrate mag, calibrate gyro, "
                      "allan; options as the single command takes them.", "MANIFEST"),
    workers: Workers = None,
    scheduler: Scheduler = None,
    out: opt.OptInput("--out", "Output folder: units/SERIAL.JOB.json and results.parquet (default: the manifest's "
                      "folder).", "DIR") = None,
    spec: opt.OptInput("--spec", "Limits per figure (TOML), to judge each unit as it finishes.", "SPEC.toml") = None,
    rerun: Annotated[bool, typer.Option("--rerun", help=(
        "Run every unit again, even those whose result is there with the same inputs and imu-align version."))]
    = False,
) -> None:
    """Run every unit of a manifest through its single command (matrix, calibrate ..., allan), in parallel.

    Each unit's result goes to OUT/units/SERIAL.JOB.json, its key figures to the results store OUT/results.parquet (a
    folder of Parquet parts, one more per run; read it whole with imu-align lot or pandas.read_parquet). A rerun
    skips units whose result is there and whose inputs are unchanged. Exit status: 0 every unit ran (and passed
    the spec); 3 some units failed or gave an error; 4 some units are outside the spec.
    """
    import itertools
    import os
    import time

    from align.cli.paths import output_folder
    from align.cli.progress import progress
    from align.errors import CheckFailed, InputError, TestError
    from align.present.lot import batch_summary
    from align.production import TABLE, BatchRun, judge_rows, make_pool, plan_tasks, read_manifest, read_spec, run_units
    from align.production.lock import locked
    from align.production.stats import figures_needed, rejudge_rows
    from align.production.table import now

    if scheduler is not None and scheduler != "local" and workers is not None:
        raise InputError("goes with the process pool or a local cluster (--scheduler local); a running cluster has "
                         "its own workers", "{workers}")
    jobs = _jobs()
    lot = read_manifest(manifest, jobs)
    for unit in lot:
        check_options(unit, str(manifest))
        if unit.validation is not None:
            check_options(validation_unit(unit), str(manifest))
    pool = make_pool(workers or os.cpu_count() or 1, scheduler, _preload(lot.jobs))
    pool.prestart()  # a fork server's workers start (and import the jobs) while the rows are parsed here
    try:
        parsed = parse_rows(lot, lot.folder.resolve(), str(manifest))
        limits = read_spec(spec) if spec is not None else None
        folder = out if out is not None else lot.folder
        created = output_folder("out", folder)
        folder.mkdir(parents=True, exist_ok=True)
        started = time.perf_counter()
        run = BatchRun(total=lot.serials)
        try:
            with locked(folder):
                skipped = [0]

                def skip(rows: list[dict]) -> None:  # judged again: the spec may be another
                    run.add(rejudge_rows(rows, limits), skipped=True)
                    skipped[0] += 1

                tasks = plan_tasks(lot, folder, task_maker(lot.folder.resolve(), parsed, str(manifest)),
                                   now().isoformat(), rerun=rerun,
                                   figures=figures_needed(limits) if limits is not None else (), skip=skip)
                first = next(tasks, None)  # every unit skipped: no pool (nor cluster) is started
                if first is not None:
                    with pool, progress(len(lot), "units") as tick:
                        run_units(itertools.chain((first,), tasks), run_unit, pool, folder,
                                  lambda rows: judge_rows(rows, limits), lambda done: tick(done + skipped[0]), run)
        except BaseException:
            if created and not any(folder.iterdir()):  # nothing ran (no cluster, say): leave no folder behind
                folder.rmdir()
            raise
    finally:
        pool.close(cancel=True)  # not used (nothing to run, a refused manifest): stopped, not waited for
    typer.echo(batch_summary(run, str(manifest), pool.where, folder / TABLE, time.perf_counter() - started))
    failed = len(run.lot("failed")) + len(run.lot("error"))
    outside = len(run.lot("ok", "fail"))
    if failed:
        raise TestError(f"{failed} of {run.total} units failed or gave an error"
                        + (f", {outside} outside the spec or their limits" if outside else "") + " (listed above)",
                        "batch")
    if outside:
        raise CheckFailed(f"{outside} of {run.total} units outside the spec or their limits (listed above)", "batch")


def simulate_lot_command(out_dir: Path, n: int, spread: float, scale_spread: float, bias_spread: float, bad: int,
                         seed: int, rate: float, dwell: float, gap: float, rate_hz: float, noise: float) -> None:
    """``imu-align simulate OUT_DIR --lot N ...``: a rehearsal lot (:func:`align.production.simulate_lot`), all or none.

    The lot is written into a temporary folder beside ``out_dir`` and moved into place at the end: a failed
    or interrupted run leaves nothing. Values arrive in SI (the simulate command's options parse them).
    """
    import shutil
    import tempfile

    from align.alignment.simulate import SessionSpec
    from align.cli.paths import output_folder
    from align.errors import InputError
    from align.production import LotSpread, simulate_lot

    names = ("manifest.csv", "plan.toml", "truth.csv", "sessions")
    output_folder("out_dir", out_dir)
    taken = [name for name in names if (out_dir / name).exists()]
    if taken:
        raise InputError(f"{out_dir} already holds {taken[0]}; give an empty or new folder", "{out_dir}")
    spec = SessionSpec(fs=rate_hz, dwell_s=dwell, static_s=gap, noise_density=noise)
    lot_spread = LotSpread(spread, scale_spread, LotSpread().delta, bias_spread)
    base = out_dir.resolve()
    while not base.is_dir():  # the nearest existing folder: staged there, the same file system as the target
        base = base.parent
    staging = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.", dir=base))
    try:
        truth = simulate_lot(staging, n, lot_spread, spec, bad, seed, rate)
        out_dir.mkdir(parents=True, exist_ok=True)
        for name in names:
            (staging / name).rename(out_dir / name)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    listed = ", ".join(f"{u['serial']} ({u['kind']})" for u in truth.units if u["kind"] != "good")
    typer.echo(f"wrote a lot of {n} units to {out_dir}: sessions/SERIAL.csv, plan.toml, manifest.csv (for imu-align "
               f"batch) and truth.csv" + (f"; bad units: {listed}" if listed else ""))


COMMANDS = {"batch": batch}
