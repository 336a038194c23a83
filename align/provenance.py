"""Where a result came from: its input files (size and SHA-256), the options it ran with, the tool version.

Every job (:class:`align.job.Job`) stamps its result with a :class:`Provenance`, so that a
result file says which bytes it was computed from and how; the batch's content hash and a
reviewer's "was this the file?" read the same record.

A long log is hashed while the job computes: :func:`start_hashing` (called by :meth:`align.job.Job.run` once
the inputs are read) starts the SHA-256 in a background thread (``hashlib`` releases the GIL), and
:meth:`Provenance.of` takes it, or hashes the file then when it changed since or was never started.

Public names
------------
InputFile, Provenance, file_record, start_hashing, prehashed_record, plain
"""

from __future__ import annotations

import dataclasses
import enum
import hashlib
import math
import threading
from collections.abc import Mapping
from concurrent.futures import Future
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from align import __version__

__all__ = ["InputFile", "Provenance", "file_record", "start_hashing", "prehashed_record", "plain"]

_CHUNK = 1 << 20


@dataclass(frozen=True)
class InputFile:
    """One input file as it was read.

    Attributes
    ----------
    role : str
        What the file is to the job (``"log"``, ``"plan"``, ``"axis_down.x"``).
    path : str
        The path as given.
    size : int
        Bytes.
    sha256 : str
        Hex digest of the bytes.
    """

    role: str
    path: str
    size: int
    sha256: str

    def to_dict(self) -> dict[str, Any]:
        return {"role": self.role, "path": self.path, "size": self.size, "sha256": self.sha256}


def file_record(role: str, path: str | Path) -> InputFile:
    """Size and SHA-256 of a file (read in 1 MiB chunks: bounded memory for a long log).

    A file that cannot be read (removed since the job read it) has size -1 and an empty digest.
    """
    p = Path(path)
    digest = hashlib.sha256()
    try:
        with open(p, "rb") as fh:
            while block := fh.read(_CHUNK):
                digest.update(block)
        size = p.stat().st_size
    except OSError:
        return InputFile(role, str(path), -1, "")
    return InputFile(role, str(path), size, digest.hexdigest())


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


def prehashed_record(role: str, path: str | Path) -> InputFile:
    """The file's record: the one computed in the background when the file is unchanged, else computed now."""
    key = _key(path)
    with _LOCK:
        future = _PENDING.pop(key, None) if key is not None else None
    if future is not None and future.exception() is None:
        done = future.result()
        if done.size >= 0 and _key(path) == key:
            return InputFile(role, str(path), done.size, done.sha256)
    return file_record(role, path)


def plain(x: Any) -> Any:
    """A value as JSON holds it: dataclasses and mappings as dicts, paths as text, enums as their value,
    tuples as lists, non-finite floats as None."""
    if isinstance(x, enum.Enum):
        return x.value
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return {f.name: plain(getattr(x, f.name)) for f in dataclasses.fields(x) if f.repr}
    if isinstance(x, Mapping):
        return {str(k): plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [plain(v) for v in x]
    if isinstance(x, Path):
        return str(x)
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if hasattr(x, "tolist"):  # numpy scalars and arrays
        return plain(x.tolist())
    return x


@dataclass(frozen=True)
class Provenance:
    """The inputs, options and tool version a result was computed from.

    Attributes
    ----------
    job : str
        The job's name (``"matrix"``, ``"calibrate accel"``).
    files : tuple of InputFile
    options : dict
        The job's options as plain JSON values (SI numbers, paths as text).
    version : str
        ``imu-align X.Y.Z``.
    """

    job: str
    files: tuple[InputFile, ...] = ()
    options: dict[str, Any] = field(default_factory=dict)
    version: str = f"imu-align {__version__}"

    @classmethod
    def of(cls, job: str, files: Mapping[str, str | Path | None], options: Any) -> Provenance:
        """The provenance of a run of ``job`` on ``files`` (role -> path; None: not given) with ``options``."""
        return cls(job, tuple(prehashed_record(role, p) for role, p in files.items() if p is not None), plain(options))

    def to_dict(self) -> dict[str, Any]:
        return {"job": self.job, "files": [f.to_dict() for f in self.files], "options": self.options,
                "version": self.version}

    @classmethod
    def from_dict(cls, d: Any, where: str = "provenance") -> Provenance:
        """Read back what :meth:`to_dict` wrote (a malformed one is refused naming ``where``)."""
        from align.errors import InputError

        try:
            files = tuple(InputFile(str(f["role"]), str(f["path"]), int(f["size"]), str(f["sha256"]))
                          for f in d.get("files", []))
            return cls(str(d["job"]), files, dict(d.get("options") or {}), str(d.get("version", "")))
        except (KeyError, TypeError, ValueError, AttributeError):
            raise InputError("malformed provenance (job, files with role/path/size/sha256, options, version)",
                             where) from None
