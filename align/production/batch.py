"""A batch: every unit of a manifest through its single-unit job, in parallel, resumable.

The batch hands each unit's :class:`Task` (the job's name and its options, built in the parent from the
manifest row by the command's own parser and options builder; its result file; its input files) to a
worker through a pool (:mod:`align.production.pools`). The worker (:func:`run_job`) calls the library
job (``align.api.job(name).run(options)``), writes the JSON result and the extra files the unit's output
options ask for (all or none, :class:`align.io.outputs.Outputs`) and returns the table rows made from the
result in memory (:func:`align.production.keyfigures.result_rows`). The rows are appended to the lot's table
through a journal (:class:`align.production.table.Journal`): per unit as it finishes, so that a killed
batch keeps what was done.

Resuming: a unit is skipped when its result file exists and the table's latest row for it (serial
and job) succeeded with the same content hash of its inputs (:func:`align.production.manifest.input_hash`:
the imu-align version, job, options, the bytes of its log, plan and input files); ``rerun`` skips none.
Any other unit runs again; its old result file is removed first, so that a unit that fails now leaves no
result of other inputs behind.

Public names
------------
Task, BatchRun, plan_tasks, run_units, run_job, unit_rows, result_unit_rows, error_rows, locked, TABLE, UNITS
"""

from __future__ import annotations

import os
import socket
import time
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from align.errors import AlignError, InputError
from align.production.keyfigures import result_rows
from align.production.manifest import Unit, input_hash
from align.production.store import Journal, read_table
from align.production.table import META, latest_rows, now

#: the store's name in the output folder (a folder of Parquet parts, :mod:`align.production.store`)
TABLE = "results.parquet"
#: the folder of the units' result files in the output folder
UNITS = "units"
#: verdicts from best to worst (a serial's summary is its worst row)
_RANK = {"pass": 0, "warn": 1, "fail": 2, "failed": 3, "error": 4}
#: what a :class:`BatchRun` keeps of each row
KEPT = ("serial", "order", "slot", "job", "sensor", "status", "exit_code", "verdict", "message")


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
    """

    unit: Unit
    result: Path
    inputs: tuple[Path | None, ...]
    run: str
    options: Any = None
    params: Mapping[str, Any] = field(default_factory=dict)
    refused: tuple[int, str] | None = None

    def digest(self, known: Mapping[str, str] | None = None) -> str:
        """The content hash of the unit's inputs now (``known``: path -> SHA-256 of files hashed already, see
        :func:`align.production.manifest.input_hash`)."""
        return input_hash(self.unit.job, self.unit.options, self.inputs, known)


@dataclass
class BatchRun:
    """What a batch did: the rows of the units it ran, and those of the units it skipped.

    Rows are kept without their figures (:data:`KEPT`; the table has them all): the batch's memory stays flat
    however long the lot.

    Attributes
    ----------
    rows : list of dict
        One per unit and sensor run now (failed units: one row), in the order they finished.
    skipped : list of dict
        The table's latest rows of the units skipped (their result was there with the same inputs).
    total : int
        Units (serials) in the manifest.
    """

    rows: list = field(default_factory=list)
    skipped: list = field(default_factory=list)
    total: int = 0

    def add(self, rows: list[dict], skipped: bool = False) -> None:
        """Keep ``rows`` (of units run now, or with ``skipped`` of units skipped) without their figures."""
        (self.skipped if skipped else self.rows).extend({k: r.get(k) for k in KEPT} for r in rows)

    @staticmethod
    def _first(rows: list, status: str | None, verdict: str | None) -> list[dict]:
        """One row per serial: its worst over its jobs and sensors (error, failed, fail, warn, pass)."""
        worst: dict[str, dict] = {}
        for r in rows:
            have = worst.get(r["serial"])
            if have is None or _RANK.get(str(r.get("verdict")), 0) > _RANK.get(str(have.get("verdict")), 0):
                worst[r["serial"]] = r
        return [r for r in worst.values()
                if (status is None or r["status"] == status) and (verdict is None or r["verdict"] == verdict)]

    def units(self, status: str | None = None, verdict: str | None = None) -> list[dict]:
        """One row per unit (serial) run now (its worst), optionally only those of a ``status`` or ``verdict``."""
        return self._first(self.rows, status, verdict)

    def lot(self, status: str | None = None, verdict: str | None = None) -> list[dict]:
        """As :meth:`units`, over the units run now and those skipped: the state of the whole lot."""
        return self._first(self.rows + self.skipped, status, verdict)


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
    (:func:`align.production.keyfigures.result_rows`), status ``"ok"``."""
    stamp = now()
    found = result_rows(result) if result is not None else []
    return [{**_base(task), "time": stamp, "status": "ok", "exit_code": 0, "message": message, "input_hash": digest,
             "seconds": seconds, **r} for r in (found or [{"sensor": None, "verdict": "pass", "checks": ""}])]


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
        The unit's rows: one per sensor, or one ``"failed"`` / ``"error"`` row with the one-line message.
    """
    import warnings

    from align.api import job as find
    from align.io.outputs import Outputs

    say = say or _say
    started = time.perf_counter()
    if task.refused is not None:
        return unit_rows(task, *task.refused, task.digest(), 0.0)
    try:
        with warnings.catch_warnings():  # as the command line: a result that cannot be trusted is refused instead
            warnings.simplefilter("ignore")
            job = find(task.unit.job)
            if task.params and files is not None:  # extra files: the job's checked inputs are drawn too
                result, inputs = job.run_with_inputs(task.options)
                extra = files(result, inputs, task.params)
            else:
                result, extra = job.run(task.options), []
            result = result.replace(provenance=replace(result.provenance, unit={"serial": task.unit.serial,
                                                                                 **dict(task.unit.identity)}))
            with Outputs() as out:  # all or none
                out.write_json(task.result, result)
                for path, data in extra:
                    if isinstance(data, bytes):
                        out.write_bytes(path, data)
                    else:
                        out.write_text(path, data)
    except Exception as exc:  # the job refused the unit (its exit status), or failed inside (status 1)
        code, message = say(task.unit.job, exc)
        return unit_rows(task, code if code != 0 else 1, message, task.digest(), time.perf_counter() - started)
    # the content hash from the bytes the job's provenance hashed (read once), the other inputs read now
    read = {f.path: f.sha256 for f in getattr(result.provenance, "files", ())}
    return result_unit_rows(task, result, "", task.digest(read), time.perf_counter() - started)


def plan_tasks(units: Iterable[Unit], out: Path, make: Callable[[Unit, Path, str], Task],
               run: str, rerun: bool = False, figures: Iterable[str] = ()) -> tuple[list[Task], list[dict]]:
    """The tasks to run, and the table's latest rows of the units to skip (see the module docstring), the
    journal of a killed run folded first.

    Parameters
    ----------
    units : iterable of Unit
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
    """
    table_path = out / TABLE
    Journal(table_path).recover()
    last: dict[tuple[str, str], list[dict]] = {}
    figures = list(figures)
    for r in latest_rows(read_table(table_path, [n for n, _ in META] + figures), figures):
        last.setdefault((r["serial"], r["job"]), []).append(r)
    tasks = [(unit, make(unit, out / UNITS / unit.result_name, run)) for unit in units]
    done = [] if rerun else [(unit, task) for unit, task in tasks if task.result.exists()
                             and last.get((unit.serial, unit.job), [{}])[0].get("status") == "ok"]
    digests = _digests([task for _, task in done])
    todo, skipped = [], []
    for unit, task in tasks:
        prev = last.get((unit.serial, unit.job))
        if digests.get(id(task)) is not None and prev is not None and prev[0]["input_hash"] == digests[id(task)]:
            skipped += [{**r, "order": unit.order, "slot": unit.slot} for r in prev]
            continue
        todo.append(task)
    return todo, skipped


def _digests(tasks: list[Task]) -> dict[int, str]:
    """``id(task) -> task.digest()``, the files read and hashed in threads (``hashlib`` and file reads release the
    GIL: a rerun of a long lot is not one SHA-256 after another); the threads are gone on return, so that the
    pool's workers may still be forks of this process."""
    if len(tasks) < 2:
        return {id(t): t.digest() for t in tasks}
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(min(8, os.cpu_count() or 1, len(tasks))) as ex:
        return dict(zip(map(id, tasks), ex.map(Task.digest, tasks)))


def run_units(tasks: list[Task], worker: Callable[[Task], list[dict]], pool, out: Path,
              judge: Callable[[list[dict]], list[dict]] | None = None, progress=None, run: BatchRun | None = None,
              window: int | None = None) -> BatchRun:
    """Run ``tasks`` through ``worker`` on ``pool`` (entered), journaling each unit's rows as it finishes.

    Parameters
    ----------
    tasks : list of Task
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
    pending = list(reversed(tasks))
    flight: dict = {}
    done = 0
    try:
        for t in tasks:
            if t.result.exists():
                t.result.unlink()  # a result of other inputs, or of a run killed before its row
        for left in (out / UNITS).glob(".*.json.*"):  # temporaries of a run killed while writing (the lock is ours)
            left.unlink(missing_ok=True)
        while pending or flight:
            while pending and len(flight) < window:
                task = pending.pop()
                flight[pool.submit(worker, task)] = (task, time.perf_counter())
            for fut in pool.wait(flight):
                task, started = flight.pop(fut)
                rows = _collect(fut, task, started, pool)
                rows = judge(rows) if judge is not None else rows
                journal.add(rows)
                run.add(rows)
                done += 1
                if progress is not None:
                    progress(done)
    finally:
        journal.fold()
    return run


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


@contextmanager
def locked(out: Path) -> Iterator[None]:
    """Hold the output folder for one batch at a time (``OUT/.batch.lock``, naming the host and process);
    a lock whose process is gone (a killed batch on this host) is taken over."""
    path = out / ".batch.lock"
    me = f"{socket.gethostname()} {os.getpid()}"
    for _ in range(2):
        try:
            fd = os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            host, _, pid = (path.read_text(errors="replace").strip() or " ").partition(" ")
            if not host or (host == socket.gethostname() and not _alive(pid)):  # empty: killed while writing it
                path.unlink(missing_ok=True)
                continue
            raise InputError(f"another batch ({host}, process {pid}) is writing to {out}; wait for it, or give "
                             f"another {{out}} (remove {path} if no batch runs)", "{out}") from None
        with os.fdopen(fd, "w") as fh:
            fh.write(me)
        break
    try:
        yield
    finally:
        path.unlink(missing_ok=True)


def _alive(pid: str) -> bool:
    try:
        os.kill(int(pid), 0)
    except (ValueError, ProcessLookupError):
        return False
    except PermissionError:  # a process of another user
        return True
    return True
