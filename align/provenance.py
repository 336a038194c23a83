"""Where a result came from: its input files (size and SHA-256), the options it ran with, the tool version.

Every job (:class:`align.job.Job`) stamps its result with a :class:`Provenance`, so that a
result file says which bytes it was computed from and how; the batch's content hash and a
reviewer's "was this the file?" read the same record.

A long log is hashed while the job computes: :func:`start_hashing` (called by :meth:`align.job.Job.run` once
the inputs are read) starts the SHA-256 in a background thread (``hashlib`` releases the GIL), and
:meth:`Provenance.of` takes it, or hashes the file then when it changed since or was never started.

A log may be a folder (a ROS 2 bag, an EuRoC dataset: :func:`align.io.files.existing_log`); its record is
the SHA-256 of its files in sorted order (:func:`folder_digest`) and their total size.

Public names
------------
InputFile, Provenance, file_record, folder_digest, start_hashing, prehashed_record, plain
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

__all__ = ["InputFile", "Provenance", "file_record", "folder_digest", "start_hashing", "prehashed_record", "plain"]

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
        Bytes (of a folder: of its files).
    sha256 : str
        Hex digest of the bytes (of a folder: :func:`folder_digest`).
    """

    role: str
    path: str
    size: int
    sha256: str

    def to_dict(self) -> dict[str, Any]:
        return {"role": self.role, "path": self.path, "size": self.size, "sha256": self.sha256}


def _sha256(p: Path) -> bytes:
    """SHA-256 of a file's bytes (read in 1 MiB chunks into one buffer: bounded memory for a long log, and no
    allocation per chunk, which glibc's per-thread heaps of the hashing threads would keep)."""
    digest = hashlib.sha256()
    buffer = bytearray(_CHUNK)
    view = memoryview(buffer)
    with open(p, "rb", buffering=0) as fh:
        while n := fh.readinto(buffer):
            digest.update(view[:n])
    return digest.digest()


def _folder_files(folder: Path) -> list[tuple[str, Path]]:
    """The files under ``folder`` (in its sub-folders too) by their relative POSIX name, sorted."""
    return sorted((p.relative_to(folder).as_posix(), p) for p in folder.rglob("*") if p.is_file())


def folder_digest(folder: str | Path) -> tuple[int, str]:
    """The total size and the SHA-256 of a folder's files: hex digest of, for each file in the sorted order of its
    relative name (POSIX, UTF-8), the name, a NUL byte and the SHA-256 (32 bytes) of the file's bytes. A file
    renamed, added, removed or changed changes it; the folder's own name and the files' times do not.

    Examples
    --------
    >>> import tempfile, hashlib
    >>> d = Path(tempfile.mkdtemp())
    >>> _ = (d / "a.txt").write_bytes(b"abc")
    >>> size, hexed = folder_digest(d)
    >>> size, hexed == hashlib.sha256(b"a.txt\\0" + hashlib.sha256(b"abc").digest()).hexdigest()
    (3, True)
    """
    outer, size = hashlib.sha256(), 0
    for name, p in _folder_files(Path(folder)):
        outer.update(name.encode() + b"\0" + _sha256(p))
        size += p.stat().st_size
    return size, outer.hexdigest()


def file_record(role: str, path: str | Path) -> InputFile:
    """Size and SHA-256 of a file (read in 1 MiB chunks: bounded memory for a long log), or of a log folder
    (:func:`folder_digest`).

    A file that cannot be read (removed since the job read it) has size -1 and an empty digest.
    """
    p = Path(path)
    try:
        if p.is_dir():
            size, hexed = folder_digest(p)
            return InputFile(role, str(path), size, hexed)
        digest = _sha256(p).hex()
        size = p.stat().st_size
    except OSError:
        return InputFile(role, str(path), -1, "")
    return InputFile(role, str(path), size, digest)


_LOCK = threading.Lock()
#: (path, size, mtime_ns) -> the file's record being computed
_PENDING: dict[tuple[str, int, int], Future] = {}


def _key(path: str | Path) -> tuple[str, int, int] | None:
    """What tells whether a file changed since it was hashed: its size and time (of a folder: its files' total
    size and latest time)."""
    p = Path(path)
    try:
        if p.is_dir():
            stats = [f.stat() for _, f in _folder_files(p)]
            return str(p.resolve()), sum(s.st_size for s in stats), max((s.st_mtime_ns for s in stats), default=0)
        st = p.stat()
    except OSError:
        return None
    return str(p.resolve()), st.st_size, st.st_mtime_ns


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


def prehashed_record(role: str, path: str | Path, keep: bool = False) -> InputFile:
    """The file's record: the one computed in the background when the file is unchanged, else computed now.

    ``keep``: the background's record stays for the result's provenance to take (a job that checks a digest while
    it reads, :func:`align.alignment.jobs.verify_job.read_verify`, waits for the same hash instead of computing it
    a second time).
    """
    key = _key(path)
    with _LOCK:
        future = (_PENDING.get(key) if keep else _PENDING.pop(key, None)) if key is not None else None
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
    unit : dict
        The unit the result is of, as a batch's manifest states it (``serial``, and where given ``station``,
        ``fixture``, ``operator``, ``device_id``, ``test_time``; the last two from the log where the manifest
        gives none, :mod:`align.production.identity`); empty for a single command's run.
    """

    job: str
    files: tuple[InputFile, ...] = ()
    options: dict[str, Any] = field(default_factory=dict)
    version: str = f"imu-align {__version__}"
    unit: dict[str, str] = field(default_factory=dict)

    @classmethod
    def of(cls, job: str, files: Mapping[str, str | Path | None], options: Any) -> Provenance:
        """The provenance of a run of ``job`` on ``files`` (role -> path; None: not given) with ``options``."""
        return cls(job, tuple(prehashed_record(role, p) for role, p in files.items() if p is not None), plain(options))

    def to_dict(self) -> dict[str, Any]:
        return {"job": self.job, "files": [f.to_dict() for f in self.files], "options": self.options,
                "version": self.version, **({"unit": dict(self.unit)} if self.unit else {})}

    @classmethod
    def from_dict(cls, d: Any, where: str = "provenance") -> Provenance:
        """Read back what :meth:`to_dict` wrote (a malformed one is refused naming ``where``)."""
        from align.errors import InputError

        try:
            files = tuple(InputFile(str(f["role"]), str(f["path"]), int(f["size"]), str(f["sha256"]))
                          for f in d.get("files", []))
            return cls(str(d["job"]), files, dict(d.get("options") or {}), str(d.get("version", "")),
                       {str(k): str(v) for k, v in dict(d.get("unit") or {}).items()})
        except (KeyError, TypeError, ValueError, AttributeError):
            raise InputError("malformed provenance (job, files with role/path/size/sha256, options, version)",
                             where) from None
