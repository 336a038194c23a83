"""A batch killed halfway (SIGKILL to its process group, workers and all): the rerun finishes the remaining units only."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import time

import pyarrow.parquet as pq
from support import imu_align_command

from align.alignment.simulate import SessionSpec
from align.production import simulate_lot


def _journaled(path) -> list[dict]:
    if not path.exists():
        return []
    rows = []
    for line in path.read_text().splitlines():
        try:
            rows.append(json.loads(line))
        except ValueError:  # the line being written when the batch was killed
            pass
    return rows


def test_a_rerun_after_killing_the_batch_halfway_finishes_the_remaining_units_only(tmp_path, run_cli):
    n = 60
    lot = simulate_lot(tmp_path / "lot", n, session=SessionSpec(fs=200.0, dwell_s=2.0, static_s=1.0), bad=0, seed=3)
    out = tmp_path / "out"
    journal = out / "results.parquet.journal"
    proc = subprocess.Popen([*imu_align_command(), "batch", str(lot.manifest), "--workers", "2", "--out", str(out)],
                            start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    try:
        while len(_journaled(journal)) < 15:
            assert proc.poll() is None, proc.stderr.read().decode()
            assert time.monotonic() < deadline
            time.sleep(0.02)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)  # the batch and its workers, at once: no clean-up runs
        proc.wait()
    done = {r["serial"] for r in _journaled(journal) if r["status"] == "ok"}
    assert 15 <= len(done) < n and not (out / "results.parquet").exists()  # killed before the end
    assert (out / ".batch.lock").exists()  # left by the killed run: taken over, its process is gone
    res = run_cli("batch", lot.manifest, "--workers", 2, "--out", out)
    assert res.code == 0, res.err
    assert f"{n} units; ran {n - len(done)}, skipped {len(done)}" in res.out, res.out
    table = pq.read_table(out / "results.parquet").to_pandas()
    assert len(table) == n and table.serial.is_unique  # the killed run's rows were kept, none run twice
    assert set(table.serial[table.run == table.run.min()]) == done
    assert not journal.exists() and not (out / ".batch.lock").exists()
    assert sorted(p.name for p in (out / "units").iterdir()) == sorted(f"{s}.matrix.json" for s in table.serial)
    res = run_cli("batch", lot.manifest, "--out", out)
    assert f"ran 0, skipped {n}" in res.out
