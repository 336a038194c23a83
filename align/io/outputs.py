"""Outputs of a run, all or none: every file staged first, then all committed together.

A command that writes several files (a JSON result and a C header, a folder of
results and a report) stages each one as it is computed: :class:`Outputs`
writes it to a temporary file beside its target (same folder, so the final
rename is atomic and cannot cross file systems). Only when every output is
staged does :meth:`Outputs.commit` rename them all into place. If anything
fails before that (an error, Ctrl-C), every temporary is removed and no output
is left; if a rename itself fails, the renames already done are undone (a file
that was replaced gets its old content back).

Use it as a context manager; leaving the block normally commits, leaving it by
an exception discards::

    with Outputs() as out:
        out.write_json(json_path, result.to_dict())
        out.write_text(header_path, header)      # a failure here leaves neither file

Public names
------------
Outputs
"""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import IO

import numpy as np

from align.errors import InputError
from align.io.files import to_json_value


def _mode() -> int:
    """Permissions of a new file under the current umask (``mkstemp`` makes them 0600)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def _remove(path: str | None) -> None:
    if path is not None:
        try:
            os.unlink(path)
        except OSError:
            pass


def _fail(path: Path, exc: OSError) -> InputError:
    return InputError(f"cannot write ({exc.strerror or exc}); nothing was written", str(path))


class Outputs:
    """The outputs of one run, staged as temporary files and committed together (all or none).

    Attributes
    ----------
    targets : list of Path
        The outputs staged so far, in order.
    """

    def __init__(self) -> None:
        self._staged: dict[Path, str] = {}  # target -> its temporary file
        self._folders: list[Path] = []  # folders this run created, outermost first
        self._done = False

    @property
    def targets(self) -> list[Path]:
        return list(self._staged)

    def staged(self, path: str | Path) -> Path:
        """Where the staged content of ``path`` can be read before the commit: its temporary file, which
        ends in the target's suffix (``.npy``, ``.csv``) so that readers recognise its type."""
        return Path(self._staged[Path(path)])

    def folder(self, path: str | Path) -> Path:
        """Create the output folder ``path`` (and its missing parents); a failed run removes what it created."""
        target = Path(path)
        missing = []
        here = target
        while not here.exists() and here != here.parent:
            missing.append(here)
            here = here.parent
        try:
            target.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise InputError(f"cannot create folder ({exc.strerror or exc})", str(path)) from None
        self._folders += [f for f in reversed(missing) if f not in self._folders]
        return target

    # ---- staging ----

    def _stage(self, path: str | Path, write: Callable[[IO[bytes]], object]) -> Path:
        """Write a temporary file beside ``path`` with ``write(fh)``; a failure removes it and says so."""
        if self._done:
            raise RuntimeError("these outputs are already committed or discarded")
        target = Path(path)
        try:
            fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp" + target.suffix)
        except OSError as exc:
            raise _fail(target, exc) from None
        try:
            with os.fdopen(fd, "wb") as fh:
                write(fh)
            os.chmod(tmp, _mode())
        except BaseException as exc:
            _remove(tmp)
            if isinstance(exc, OSError):
                raise _fail(target, exc) from None
            raise
        _remove(self._staged.get(target))  # staged twice: the last content wins
        self._staged[target] = tmp
        return target

    def write_bytes(self, path: str | Path, data: bytes) -> Path:
        """Stage bytes (a PNG, a GLB, a .npy)."""
        return self._stage(path, lambda fh: fh.write(data))

    def write_text(self, path: str | Path, text: str) -> Path:
        """Stage text (UTF-8)."""
        return self._stage(path, lambda fh: fh.write(text.encode()))

    def write_json(self, path: str | Path, data) -> Path:
        """Stage a JSON object (indented, NaN as null); a result is written as its ``to_dict()``."""
        if hasattr(data, "to_dict"):
            data = data.to_dict()
        return self.write_text(path, json.dumps(to_json_value(data), indent=2) + "\n")

    def write_files(self, files: Iterable[tuple[str | Path, bytes | str]]) -> list[Path]:
        """Stage each ``(path, data)``: bytes as they are, text as UTF-8 (a job's extra output files)."""
        return [self.write_bytes(path, data) if isinstance(data, bytes) else self.write_text(path, data)
                for path, data in files]

    def write_csv(self, path: str | Path, names: list[str], data: np.ndarray) -> Path:
        """Stage numeric columns as CSV (pyarrow's writer, full float precision)."""
        import pyarrow as pa
        import pyarrow.csv as pcsv

        table = pa.table({n: np.ascontiguousarray(data[:, j]) for j, n in enumerate(names)})
        return self._stage(path, lambda fh: pcsv.write_csv(table, fh))

    # ---- the end of the run ----

    def discard(self) -> None:
        """Remove every temporary file (and the folders this run created, when empty); no output is written."""
        for tmp in self._staged.values():
            _remove(tmp)
        self._staged.clear()
        for folder in reversed(self._folders):
            try:
                folder.rmdir()
            except OSError:
                pass
        self._done = True

    def commit(self) -> list[Path]:
        """Rename every staged file into place; on a failure undo the renames done and write nothing.

        Returns
        -------
        list of Path
            The outputs written.

        Raises
        ------
        InputError
            A rename failed (naming the output); no output was changed.
        """
        if self._done:
            raise RuntimeError("these outputs are already committed or discarded")
        done: list[tuple[Path, str | None]] = []  # (target, the old file moved aside, or None)
        current: Path | None = None
        try:
            for target, tmp in self._staged.items():
                current = target
                backup = None
                if os.path.lexists(target) and not target.is_dir():
                    fd, backup = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".old")
                    os.close(fd)
                    os.replace(target, backup)
                done.append((target, backup))
                os.replace(tmp, target)
        except BaseException as exc:
            self._undo(done)
            self.discard()
            if isinstance(exc, OSError) and current is not None:
                raise _fail(current, exc) from None
            raise
        for _, backup in done:
            _remove(backup)
        written = list(self._staged)
        self._staged.clear()
        self._done = True
        return written

    def _undo(self, done: list[tuple[Path, str | None]]) -> None:
        """Put back what the renames in ``done`` replaced (in reverse order)."""
        for target, backup in reversed(done):
            try:
                if backup is not None:
                    os.replace(backup, target)
                elif os.path.lexists(target) and self._staged.get(target) and not os.path.exists(self._staged[target]):
                    os.unlink(target)  # ours: its temporary was renamed onto it
            except OSError:
                pass

    def __enter__(self) -> Outputs:
        return self

    def __exit__(self, kind, exc, tb) -> None:
        if self._done:
            return
        if kind is None:
            self.commit()
        else:
            self.discard()
