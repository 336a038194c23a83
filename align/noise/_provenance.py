"""The provenance of a long record without a second wait: its SHA-256 is computed in a thread while the job runs.

A static record can be gigabytes; :func:`align.provenance.file_record` reads it once more after the Allan
deviation is done. :func:`start_hashing` (called when the record is read) starts that hash in a background
thread (``hashlib`` releases the GIL), and :class:`PrehashedJob` stamps the result with it, or hashes the file
then when it changed since, or was never started.
"""

from __future__ import annotations

import threading
from concurrent.futures import Future
from pathlib import Path
from typing import Any

from align.job import Job
from align.provenance import InputFile, Provenance, file_record, plain

_LOCK = threading.Lock()
#: (path, size, mtime_ns) -> the file's record being computed
_PENDING: dict[tuple[str, int, int], Future] = {}


def _key(path: str | Path) -> tuple[str, int, int] | None:
    try:
        st = Path(path).stat()
    except OSError:
        return None
    return str(Path(path).resolve()), st.st_size, st.st_mtime_ns


def start_hashing(paths: list[str | Path]) -> None:
    """Start the SHA-256 of each file in a background thread (a file already started is not started again)."""
    todo = []
    with _LOCK:
        for p in paths:
            key = _key(p)
            if key is not None and key not in _PENDING:
                todo.append((key, p))
    if not todo:
        return
    jobs = []
    with _LOCK:
        for key, p in todo:
            future: Future = Future()
            _PENDING[key] = future
            jobs.append((future, p))

    def work() -> None:
        for future, p in jobs:
            try:
                future.set_result(file_record("", p))
            except BaseException as exc:  # noqa: BLE001 - handed to the caller, who hashes again
                future.set_exception(exc)

    # a daemon thread: a run refused after this does not wait for the hash at exit
    threading.Thread(target=work, name="imu-align-sha256", daemon=True).start()


def _record(role: str, path: str | Path) -> InputFile:
    """The file's record: the one computed in the background when the file is unchanged, else computed now."""
    key = _key(path)
    with _LOCK:
        future = _PENDING.pop(key, None) if key is not None else None
    if future is not None and future.exception() is None:
        done = future.result()
        if done.size >= 0 and _key(path) == key:
            return InputFile(role, str(path), done.size, done.sha256)
    return file_record(role, path)


class PrehashedJob(Job):
    """A :class:`~align.job.Job` whose provenance takes the hashes started by :func:`start_hashing`."""

    def stamp(self, result: Any, options: Any) -> Any:
        files = tuple(_record(role, p) for role, p in self.files(options).items() if p is not None)
        return result.replace(provenance=Provenance(self.name, files, plain(options)))
