"""The batch runner with stand-in workers: a worker that dies, and Ctrl-C in the middle of a lot; when workers may be
forks of the batch's process."""

from __future__ import annotations

import os
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from align.production import BatchRun, Task, Unit, run_units, unit_rows
from align.production.pools import ProcessPool


def _tasks(folder: Path, n: int) -> list[Task]:
    units = [Unit(f"U{k}", "allan", folder / f"U{k}.csv", None, (), None, k, f"line {k + 2}") for k in range(n)]
    return [Task(u, folder / "units" / f"{u.serial}.json", (u.log,), "run1") for u in units]


def dying_worker(task: Task) -> list[dict]:
    """Kills its own process for unit U2 (a crash no Python handler sees); a failed job for the others."""
    if task.unit.serial == "U2":
        os._exit(7)
    return unit_rows(task, 3, f"imu-align: error: {task.unit.log.name}: too short", task.digest(), 0.01)


@pytest.mark.parametrize("fork", [True, False], ids=["forked", "fork-server"])
def test_a_worker_that_dies_costs_its_unit_only(tmp_path, monkeypatch, fork):
    import align.production.pools as pools

    monkeypatch.setattr(pools, "_fork_is_safe", lambda: fork)  # both ways a worker starts
    tasks = _tasks(tmp_path, 6)
    with ProcessPool(1) as pool:
        run = run_units(tasks, dying_worker, pool, tmp_path, window=1)
    rows = {r["serial"]: r for r in run.units()}
    assert sorted(rows) == [f"U{k}" for k in range(6)]
    assert rows["U2"]["status"] == "error" and "the worker process died" in rows["U2"]["message"]
    assert all(rows[s]["status"] == "failed" and rows[s]["exit_code"] == 3 for s in rows if s != "U2")
    assert len(pq.read_table(tmp_path / "results.parquet")) == 6


def test_ctrl_c_in_the_middle_keeps_the_units_done(tmp_path):
    """Workers ignore Ctrl-C: a unit running when it comes finishes and writes its result, so its row is kept too
    (a new user found results without rows: the journal had been folded before the running units finished)."""
    tasks = _tasks(tmp_path, 10)
    run = BatchRun(total=10)

    def progress(done):
        if done == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        with ProcessPool(2) as pool:
            run_units(tasks, slow_worker, pool, tmp_path, progress=progress, run=run, window=4)
    table = pq.read_table(tmp_path / "results.parquet").to_pandas()  # the journal was folded on the way out
    written = sorted(p.stem for p in (tmp_path / "units").glob("*.json"))
    assert sorted(table.serial) == sorted(r["serial"] for r in run.units()) == written
    assert 3 < len(written) < 10  # those running finished; those queued were dropped
    assert not (tmp_path / "results.parquet.journal").exists()


def slow_worker(task: Task) -> list[dict]:
    import time

    time.sleep(0.3)
    task.result.write_text("{}")
    return unit_rows(task, 2, "imu-align: error: x: file not found", task.digest(), 0.3)


def failing_worker(task: Task) -> list[dict]:
    return unit_rows(task, 2, "imu-align: error: x: file not found", task.digest(), 0.01)


def test_workers_are_forks_only_when_that_is_safe(monkeypatch):
    """A fork of a process whose numba (GNU OpenMP) threads ran aborts, and one of a process with other threads may
    hold their locks: the fork server then starts the workers."""
    import sys
    import threading
    import types

    import align.production.pools as pools

    monkeypatch.setitem(sys.modules, "numba.np.ufunc.parallel", types.SimpleNamespace(_is_initialized=False))
    if sys.platform != "linux" or threading.active_count() > 1:
        pytest.skip("forks are not used here")
    assert pools._fork_is_safe()
    monkeypatch.setitem(sys.modules, "numba.np.ufunc.parallel", types.SimpleNamespace(_is_initialized=True))
    assert not pools._fork_is_safe()
    monkeypatch.setitem(sys.modules, "numba.np.ufunc.parallel", types.SimpleNamespace(_is_initialized=False))
    stop = threading.Event()
    other = threading.Thread(target=stop.wait)
    other.start()
    try:
        assert not pools._fork_is_safe()
    finally:
        stop.set()
        other.join()


def _content_hash(job: str, options: tuple[str, ...], files: list[Path]) -> str:
    """The content hash as input_hash documents it, written here from its description: imu-align's version, the
    SHA-256 of the job and options joined by NUL, the SHA-256 of each file's bytes."""
    import hashlib

    from align import __version__

    h = hashlib.sha256(b"imu-align batch inputs 1\0" + str(__version__).encode() + b"\0")
    h.update(hashlib.sha256("\0".join([job, *options]).encode()).digest())
    for f in files:
        h.update(hashlib.sha256(f.read_bytes()).digest())
    return h.hexdigest()


def test_a_rerun_skips_the_units_done_with_unchanged_inputs_and_leaves_no_thread(tmp_path):
    # the units' files are hashed in threads: the skip decisions are those of the content hash, and the pool's
    # workers may still be forks of the batch afterwards
    import threading
    from datetime import UTC, datetime

    from align.production import plan_tasks
    from align.production.store import append_rows

    tasks = _tasks(tmp_path, 6)
    for k, t in enumerate(tasks):
        t.unit.log.write_bytes(f"time,x\n0,{k}\n".encode())
        t.result.parent.mkdir(exist_ok=True)
        if k != 4:  # U4's result is gone: it runs again
            t.result.write_text("{}")
    rows = [{"serial": t.unit.serial, "order": k, "run": "run0", "time": datetime(2026, 3, 1, tzinfo=UTC), "job": "allan",
             "status": "failed" if k == 5 else "ok", "exit_code": 0,  # U5 failed before: it runs again
             "input_hash": _content_hash("allan", (), [t.unit.log])} for k, t in enumerate(tasks)]
    append_rows(tmp_path / "results.parquet", rows)
    tasks[3].unit.log.write_bytes(b"time,x\n0,33\n")  # U3's log changed: it runs again
    threads = set(threading.enumerate())  # (a thread of an earlier test may end meanwhile: new ones count)
    by_serial = {t.unit.serial: t for t in tasks}
    made: list[str] = []

    def make(u, result, run):
        made.append(u.serial)
        return by_serial[u.serial]

    def plan(**kw) -> tuple[list, list]:
        skipped: list[dict] = []
        todo = list(plan_tasks([t.unit for t in tasks], tmp_path, make, "run1", skip=skipped.extend, chunk=2, **kw))
        return todo, skipped

    todo, skipped = plan()
    assert [t.unit.serial for t in todo] == ["U3", "U4", "U5"]
    assert [r["serial"] for r in skipped] == ["U0", "U1", "U2"]
    assert all(r["status"] == "ok" and r["order"] == int(r["serial"][1]) for r in skipped)
    assert not set(threading.enumerate()) - threads
    todo, skipped = plan(rerun=True)
    assert len(todo) == 6 and not skipped
    # the tasks are made as they are taken, a chunk at a time: a long lot's options are not all held at once
    made.clear()
    lazy = plan_tasks([t.unit for t in tasks], tmp_path, make, "run1", rerun=True, chunk=2)
    assert next(lazy).unit.serial == "U0" and made == ["U0", "U1"]


def test_a_resume_keeps_the_latest_run_of_the_lot_s_serials_only(tmp_path):
    from datetime import UTC, datetime

    from align.production.store import LatestRuns, append_rows, read_table

    def row(serial, run, day, status="ok"):
        return {"serial": serial, "job": "allan", "run": run, "time": datetime(2026, 3, day, tzinfo=UTC),
                "status": status, "input_hash": f"{serial}{run}", "order": 0}

    store = tmp_path / "results.parquet"
    append_rows(store, [row("A", "r1", 1), row("B", "r1", 1), row("X", "r1", 1)])  # X: another lot's unit
    append_rows(store, [row("A", "r2", 2, "failed"), row("X", "r2", 2)])
    last = LatestRuns(read_table(store), {"A", "B"}, [])
    assert set(last.at) == {("A", "allan"), ("B", "allan")} and last.table.num_rows == 2
    assert (last.status("A", "allan"), last.input_hash("A", "allan")) == ("failed", "Ar2")
    assert last.status("X", "allan") is None and [r["run"] for r in last.rows(last.at[("B", "allan")])] == ["r1"]
