"""Where a result came from: its input files (size and SHA-256), the options it ran with, the tool version.

Every job (:class:`align.job.Job`) stamps its result with a :class:`Provenance`, so that a
result file says which bytes it was computed from and how; the batch's content hash and a
reviewer's "was this the file?" read the same record.

Public names
------------
InputFile, Provenance, file_record, plain
"""

from __future__ import annotations

import dataclasses
import enum
import hashlib
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from align import __version__

__all__ = ["InputFile", "Provenance", "file_record", "plain"]

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
        return cls(job, tuple(file_record(role, p) for role, p in files.items() if p is not None), plain(options))

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
