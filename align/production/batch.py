"""A batch: every unit of a manifest through its single-unit job, in parallel, resumable.

The batch hands each unit's :class:`Task` (the job's name and its options, built in the parent from the
manifest row by the command's own parser and options builder; its result file; its input files) to a
worker through a pool (:mod:`align.production.pools`). The worker (:func:`run_job`) calls the library
job (``align.api.job(name).run(options)``), writes the JSON result and the extra files the unit's output
options ask for (all or none, :class:`align.io.outputs.Outputs`) and returns the table rows made from the
result in memory (:func:`align.production.keyfigures.result_rows`); a unit with a validation run then replays
its result on the validation session (``verify``: rows of job ``verify JOB``, result ``SERIAL.JOB.verify.json``).
The rows are appended to the lot's table through a journal (:class:`align.production.table.Journal`): per unit as
it finishes, so that a killed batch keeps what was done.

Resuming: a unit is skipped when its result files exist and the table's latest row for it (serial
and job) succeeded with the same content hash of its inputs (:func:`align.production.manifest.input_hash`:
the imu-align version, job, options, the bytes of its log, plan and input files, and its validation run's);
``rerun`` skips none.
Any other unit runs again; its old result file is removed first, so that a unit that fails now leaves no
result of other inputs behind.

Public names
------------
Task, plan_tasks, run_units, run_job, unit_rows, result_unit_rows, error_rows, TABLE, UNITS (and BatchRun, from
:mod:`align.production.batchrun`)
"""

from __future__ import annotations

import os
import socket
import time
from collections.abc import Callable, Collection, Iterable, Iterator, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from align.errors import AlignError
from align.production.batchrun import BatchRun
from align.production.identity import log_identity, unit_identity
from align.production.keyfigures import result_rows
from align.production.manifest import Unit, input_hash
from align.production.pools import release_memory
from align.production.store import Journal, LatestRuns, read_table
from align.production.table import META, now

#: the store's name in the output folder (a folder of Parquet parts, :mod:`align.production.store`)
TABLE = "results.parquet"
#: the folder of the units' result files in the output folder
UNITS = "units"


@dataclass(frozen=True)
class Task:
    """What a worker gets for one unit (picklable).

    Attributes
    ----------
    unit : Unit
    result : Path
        The unit's result file, ``OUT/units/SERIAL.JOB.json``.
    inputs : tuple of Path or None
        The files the content hash covers (log, plan, the job's other input files).
    run : str
        The batch run's id (its start, UTC).
    options : object, optional
        The job's frozen options (``align.api.job(unit.job).options``), built from the manifest row.
    params : mapping, optional
        The command's parameters (plain values) when the unit's output options ask for extra files (a plot,
        a C header): what the job's files builder takes; empty when only the JSON result is written.
    refused : (int, str), optional
        The exit status and one-line message of a unit whose options the job refused before it ran.
    validation : object, optional
        ``verify``'s options for the unit's validation run (:attr:`Unit.validation`): its result replayed on the
        validation session; None when the unit has none, or when they were refused (``validation_refused``).
    validation_refused : (int, str), optional
        The exit status and one-line message of ``verify``'s refusal of the validation run's options.
    """

    unit: Unit
    result: Path
    inputs: tuple[Path | None, ...]
    run: str
    options: Any = None
    params: Mapping[str, Any] = field(default_factory=dict)
    refused: tuple[int, str] | None = None
    validation: Any = None
    validation_refused: tuple[int, str] | None = None

    @property
    def validation_result(self) -> Path:
        """The validation run's result file, ``OUT/units/SERIAL.JOB.verify.json``."""
        return self.result.with_name(self.result.name.removesuffix(".json") + ".verify.json")

    @property
    def outputs(self) -> tuple[Path, ...]:
        """The result files a unit done leaves: its result, and its validation run's."""
        return (self.result, self.validation_result) if self.unit.validation is not None else (self.result,)

    def digest(self, known: Mapping[str, str] | None = None) -> str:
        """The content hash of the unit's inputs now (``known``: path -> SHA-256 of files hashed already, see
        :func:`align.production.manifest.input_hash`); a validation run's options enter after a separator."""
        words = self.unit.options
        if self.unit.validation is not None:
            words = (*words, "\0validation", *self.unit.validation_options)
        return input_hash(self.unit.job, words, self.inputs, known)


def _base(task: Task) -> dict:
    u = task.unit
    return {"serial": u.serial, "slot": u.slot, "order": u.order, "run": task.run, "job": u.job,
            "result": str(task.result), "worker": socket.gethostname() + f":{os.getpid()}", **dict(u.identity)}


def error_rows(task: Task, status: str, exit_code: int, message: str, digest: str | None = None,
               seconds: float = float("nan")) -> list[dict]:
    """The one row of a unit that gave no result: ``status`` ``"failed"`` (the job refused its inputs or its
    test) or ``"error"`` (an internal error, a worker that died), with the job's one-line message."""
    return [{**_base(task), "time": now(), "sensor": None, "status": status, "exit_code": exit_code,
             "message": message, "verdict": status, "checks": "", "input_hash": digest, "seconds": seconds,
             "bias_unit": None}]


def result_unit_rows(task: Task, result, message: str, digest: str, seconds: float) -> list[dict]:
    """The rows of a unit whose job gave ``result`` (in memory): one per sensor with its figures
    (:func:`align.production.keyfigures.result_rows`), status ``"ok"``; the unit's identity completed from its
    log (:func:`align.production.identity.unit_identity`), a device id other than the manifest's said in the
    message and a warning."""
    stamp = now()
    found = result_rows(result) if result is not None else []
    ident, said = unit_identity(dict(task.unit.identity), log_identity(result) if result is not None else {})
    rows = [{**_base(task), **ident, "time": stamp, "status": "ok", "exit_code": 0, "message": message,
             "input_hash": digest, "seconds": seconds, **r}
            for r in (found or [{"sensor": None, "verdict": "pass", "checks": ""}])]
    for r in rows if said else ():  # another device than the manifest's: a warning the batch's summary lists
        r["message"] = "; ".join(filter(None, [r.get("message"), said]))
        r["checks"] = "; ".join(filter(None, [r.get("checks"), "identity: warn"]))  # judged again, still a warning
        r["verdict"] = "warn" if r["verdict"] == "pass" else r["verdict"]
    return rows


def unit_rows(task: Task, exit_code: int, message: str, digest: str, seconds: float, result=None) -> list[dict]:
    """The rows of a unit whose job ran: its figures from ``result`` when it succeeded (exit status 0), else one
    row ``"failed"`` (status 2, 3, 4: the job refused it) or ``"error"`` (any other)."""
    if exit_code != 0:
        return error_rows(task, "failed" if exit_code in (2, 3, 4) else "error", exit_code, message, digest, seconds)
    return result_unit_rows(task, result, message, digest, seconds)


def _say(job: str, exc: BaseException) -> tuple[int, str]:
    """A failure as a bare library caller sees it (the command line gives the batch its own wording)."""
    if isinstance(exc, AlignError):
        return exc.exit_code, f"imu-align: error: {' '.join(str(exc).split())}"
    return 1, f"imu-align: internal error: {' '.join(f'{type(exc).__name__}: {exc}'.split())[:300]}"


def run_job(task: Task, files: Callable | None = None,
            say: Callable[[str, BaseException], tuple[int, str]] | None = None) -> list[dict]:
    """Run one unit's job in this process and return its table rows (the worker of a batch).

    ``align.api.job(task.unit.job).run(task.options)`` (``run_with_inputs`` when the unit asks for extra files);
    the JSON result and the extra files are written all or none; the rows are made from the result in memory.

    Parameters
    ----------
    task : Task
    files : callable, optional
        The job's files builder, ``files(result, inputs, params) -> [(Path, bytes or str)]``: called when
        ``task.params`` is not empty.
    say : callable, optional
        ``say(job, exc) -> (exit status, one line)``: a failure as the job's command says it.

    Returns
    -------
    list of dict
        The unit's rows: one per sensor, or one ``"failed"`` / ``"error"`` row with the one-line message; then, for
        a unit with a validation run (:attr:`Task.validation`), that run's rows (job ``verify JOB``).
    """
    say = say or _say
    started = time.perf_counter()
    if task.refused is not None:
        return unit_rows(task, *task.refused, task.digest(), 0.0)
    try:
        result = _run(task.unit.job, task.options, task.result, task.unit, files if task.params else None, task.params)
    except Exception as exc:  # the job refused the unit (its exit status), or failed inside (status 1)
        code, message = say(task.unit.job, exc)
        return unit_rows(task, code if code != 0 else 1, message, task.digest(), time.perf_counter() - started)
    finally:
        release_memory()  # a worker runs thousands of units: its heap's free pages go back after each
    # the content hash from the bytes the job's provenance hashed (read once), the other inputs read now
    digest = task.digest({f.path: f.sha256 for f in getattr(result.provenance, "files", ())})
    rows = result_unit_rows(task, result, "", digest, time.perf_counter() - started)
    return rows if task.unit.validation is None else rows + _validated(task, say, digest)


def _run(name: str, options: Any, path: Path, unit: Unit, files: Callable | None = None,
         params: Mapping[str, Any] | None = None):
    """Run job ``name`` on ``options`` as the command line does (a warning is no reason to stop: a result that
    cannot be trusted is refused instead), stamp the unit's identity in its provenance, and write its JSON at
    ``path`` with the extra files ``files(result, inputs, params)`` gives, all or none."""
    import warnings

    from align.api import job as find
    from align.io.outputs import Outputs

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        job = find(name)
        if params and files is not None:  # extra files: the job's checked inputs are drawn too
            result, inputs = job.run_with_inputs(options)
            extra = files(result, inputs, params)
        else:
            result, extra = job.run(options), []
        ident, _ = unit_identity(dict(unit.identity), log_identity(result))
        result = result.replace(provenance=replace(result.provenance, unit={"serial": unit.serial, **ident}))
        with Outputs() as out:  # all or none
            out.write_json(path, result)
            out.write_files(extra)
    return result


def _validated(task: Task, say: Callable[[str, BaseException], tuple[int, str]], digest: str) -> list[dict]:
    """The rows of a unit's validation run (job ``verify JOB``): its result replayed on the validation session by
    ``verify`` (:mod:`align.alignment.jobs.verify_job`), the residual's figures and verdict; a refusal's one row."""
    started = time.perf_counter()
    mine = replace(task, unit=replace(task.unit, job=f"verify {task.unit.job}"), result=task.validation_result)
    if task.validation_refused is not None:
        return error_rows(mine, "failed", *task.validation_refused, digest, 0.0)
    try:
        result = _run("verify", task.validation, mine.result, task.unit)
    except Exception as exc:
        code, message = say("verify", exc)
        return unit_rows(mine, code if code != 0 else 1, message, digest, time.perf_counter() - started)
    finally:
        release_memory()
    return result_unit_rows(mine, result, "", digest, time.perf_counter() - started)


def plan_tasks(units: Iterable[Unit], out: Path, make: Callable[[Unit, Path, str], Task],
               run: str, rerun: bool = False, figures: Iterable[str] = (),
               skip: Callable[[list[dict]], None] | None = None, chunk: int = 256) -> Iterator[Task]:
    """The tasks to run, made as they are taken, the journal of a killed run folded first; the table's latest
    rows of each unit skipped (see the module docstring) go to ``skip``.

    Units are taken ``chunk`` at a time: their tasks made, the inputs of those that may be skipped hashed (in
    threads), the others yielded. Only the store's rows of the manifest's serials are kept, and as Arrow columns:
    the batch's memory does not grow with the lot or the store's history.

    Parameters
    ----------
    units : iterable of Unit
        Iterated twice (their serials first): a :class:`~align.production.manifest.Manifest` or a sequence (any
        other iterable is made a list).
    out : Path
        The output folder (holding ``units/`` and the table).
    make : callable
        ``make(unit, result_path, run) -> Task``: the unit's job and options.
    run : str
        This run's id.
    rerun : bool
        Run every unit, skipping none.
    figures : iterable of str
        The figures to read of the skipped units' rows (a spec judges them again); the store's other figure
        columns are not read.
    skip : callable, optional
        ``skip(rows)``: the latest rows of a unit skipped (its result is there, from the same inputs).
    chunk : int
        Units planned at once.

    Yields
    ------
    Task
    """
    units = units if isinstance(units, Collection) else list(units)  # iterated twice: a generator once
    table_path = out / TABLE
    Journal(table_path).recover()
    figures = list(figures)
    last = LatestRuns(read_table(table_path, [n for n, _ in META] + figures), {u.serial for u in units}, figures)
    batch: list[tuple[Unit, Task]] = []
    for unit in units:
        batch.append((unit, make(unit, out / UNITS / unit.result_name, run)))
        if len(batch) >= chunk:
            yield from _sorted(batch, last, rerun, skip)
            batch = []
    yield from _sorted(batch, last, rerun, skip)


def _sorted(batch: list[tuple[Unit, Task]], last: LatestRuns, rerun: bool,
            skip: Callable[[list[dict]], None] | None) -> Iterator[Task]:
    """The tasks of ``batch`` to run; the latest rows of the units skipped to ``skip``."""
    done = [] if rerun else [task for unit, task in batch if all(p.exists() for p in task.outputs)
                             and last.status(unit.serial, unit.job) == "ok"]
    digests = _digests(done)
    skipped: list[tuple[Unit, list[int]]] = []
    for unit, task in batch:
        hashed = digests.get(id(task))
        if hashed is not None and last.input_hash(unit.serial, unit.job) == hashed:
            checked = last.at.get((unit.serial, f"verify {unit.job}"), []) if unit.validation is not None else []
            skipped.append((unit, last.at[(unit.serial, unit.job)] + checked))
            continue
        yield task
    if skip is not None and skipped:  # the skipped units' rows taken from the store at once
        rows = iter(last.rows([i for _, at in skipped for i in at]))
        for unit, at in skipped:
            skip([{**next(rows), "order": unit.order, "slot": unit.slot} for _ in at])


def _digests(tasks: list[Task]) -> dict[int, str]:
    """``id(task) -> task.digest()``, the files read and hashed in threads (``hashlib`` and file reads release the
    GIL: a rerun of a long lot is not one SHA-256 after another); the threads are gone on return, so that the
    pool's workers may still be forks of this process."""
    if len(tasks) < 2:
        return {id(t): t.digest() for t in tasks}
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(min(8, os.cpu_count() or 1, len(tasks))) as ex:
        return dict(zip(map(id, tasks), ex.map(Task.digest, tasks)))


def run_units(tasks: Iterable[Task], worker: Callable[[Task], list[dict]], pool, out: Path,
              judge: Callable[[list[dict]], list[dict]] | None = None, progress=None, run: BatchRun | None = None,
              window: int | None = None) -> BatchRun:
    """Run ``tasks`` through ``worker`` on ``pool`` (entered), journaling each unit's rows as it finishes.

    Parameters
    ----------
    tasks : iterable of Task
        Taken as workers free up (a generator: :func:`plan_tasks`).
    worker : callable
        ``worker(task) -> rows`` (picklable: a module-level function).
    pool : ProcessPool or DaskPool
        Entered (``with pool:``).
    out : Path
        The output folder; its ``units/`` folder is created.
    judge : callable, optional
        ``judge(rows) -> rows``: the rows with their verdict against a spec.
    progress : callable, optional
        ``progress(done)`` after each unit.
    run : BatchRun, optional
        Filled in and returned (so that a caller keeps what was done when interrupted).
    window : int, optional
        Units in flight at once (default: twice the workers, at least 4): memory stays flat however long the lot.

    Returns
    -------
    BatchRun
        The rows of this run (the table holds them too once the journal is folded, at the end of this
        call, even when interrupted).
    """
    run = run if run is not None else BatchRun()
    (out / UNITS).mkdir(parents=True, exist_ok=True)
    journal = Journal(out / TABLE)
    window = window or max(4, 2 * int(getattr(pool, "workers", None) or 2))
    pending = iter(tasks)
    flight: dict = {}
    done, more = 0, True
    try:
        for left in (out / UNITS).glob(".*.json.*"):  # temporaries of a run killed while writing (the lock is ours)
            left.unlink(missing_ok=True)
        while more or flight:
            while more and len(flight) < window:
                task = next(pending, None)
                if task is None:
                    more = False
                    break
                for path in task.outputs:  # a result of other inputs, or of a run killed before its row
                    path.unlink(missing_ok=True)
                flight[pool.submit(worker, task)] = (task, time.perf_counter())
            for fut in pool.wait(flight) if flight else ():
                _keep(fut, flight.pop(fut), pool, judge, journal, run)
                done += 1
                if progress is not None:
                    progress(done)
    except KeyboardInterrupt:  # the units queued are dropped; those running finish (workers ignore Ctrl-C) and are kept
        running = {f for f in flight if not f.cancel() and not _cancelled(f)}
        while running:
            for fut in pool.wait(running):
                running.discard(fut)
                _keep(fut, flight.pop(fut), pool, judge, journal, run)
        raise
    finally:
        journal.fold()
    return run


def _keep(fut, held: tuple[Task, float], pool, judge, journal: Journal, run: BatchRun) -> None:
    """A finished unit's rows judged, journaled and kept in ``run``."""
    rows = _collect(fut, *held, pool)
    rows = judge(rows) if judge is not None else rows
    journal.add(rows)
    run.add(rows)


def _cancelled(fut) -> bool:
    """Whether a future was cancelled (a Dask future's ``cancel`` returns nothing: its state says)."""
    state = getattr(fut, "cancelled", None)
    return bool(state()) if callable(state) else False


def _collect(fut, task: Task, started: float, pool) -> list[dict]:
    """The rows a finished future holds; a worker that raised or died gives the unit one ``"error"`` row."""
    from align.production.pools import BrokenPool

    try:
        return fut.result()
    except BrokenPool as exc:
        pool.restart()
        what = f"the worker process died ({type(exc).__name__}); run the unit alone to see why"
    except Exception as exc:  # the worker's own failure (not the job's: the job's errors are its exit status)
        what = f"the worker failed ({' '.join(f'{type(exc).__name__}: {exc}'.split())[:240]})"
    return error_rows(task, "error", 1, f"imu-align: internal error: {what}", None, time.perf_counter() - started)
