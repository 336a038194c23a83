"""Output paths: checked before a command computes anything, written after it succeeded.

Every output a command writes (``--json``, ``--c-header``, ``--plot``,
``--picture``, ``--glb``, ``--out``, ``--imucal-json``, an output folder) is
checked first, the same way everywhere: its folder exists (an output folder
itself is created), it is not a folder where a file is expected, it is none of
the command's inputs, and no two outputs are the same file. A failure is one
:class:`~align.errors.InputError` naming the option (as a placeholder that
:func:`align.cli.options.spell` renders).

Public names
------------
check_outputs, output_folder, save_json
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterable
from pathlib import Path

from align.errors import InputError


def _same(a: Path, b: Path) -> bool:
    try:
        if a.exists() and b.exists():
            return os.path.samefile(a, b)
    except OSError:
        pass
    return a.resolve() == b.resolve()


def _check_file(field: str, path: Path, inputs: list[Path]) -> None:
    where = "{" + field + "}"
    if path.is_dir():
        raise InputError(f"{path} is a folder; give a file name", where)
    parent = path.parent
    if parent.exists() and not parent.is_dir():
        raise InputError(f"{parent} is a file, not a folder; give a path in a folder", where)
    if not parent.is_dir():
        raise InputError(f"folder {parent} does not exist; create it first", where)
    _writable(parent, where)
    for p in inputs:
        if _same(path, p):
            raise InputError(f"{path} is also an input of this command; write to another file", where)


def _writable(folder: Path, where: str) -> None:
    """Refuse a folder in which no file can be created (tried with an unnamed temporary file)."""
    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        raise InputError(f"cannot write in {folder} ({exc.strerror or exc}); choose another folder", where) from None


def check_outputs(inputs: Iterable[Path | None] = (), folder: tuple[str, Path, Iterable[str]] | None = None,
                  **outputs: Path | None) -> None:
    """Refuse, before any work, outputs that cannot be written or would overwrite an input.

    Parameters
    ----------
    inputs : iterable of Path or None
        The files the command reads (None: not given).
    folder : (field, Path, names), optional
        An output folder (created when missing) and the names of the files it will hold.
    **outputs : Path or None
        Output files by field name (``json_out=...``, ``c_header=...``); None: not given.
    """
    ins = [Path(p) for p in inputs if p is not None]
    seen: list[tuple[str, Path]] = []
    if folder is not None:
        field, path, names = folder
        output_folder(field, path)
        seen += [(field, path / name) for name in names]
    seen += [(field, Path(p)) for field, p in outputs.items() if p is not None]
    for i, (field, path) in enumerate(seen):
        _check_file(field, path, ins)
        for other, earlier in seen[:i]:
            if _same(path, earlier):
                raise InputError(f"{path} is also the output of {{{other}}}; give each output its own file", "{" + field + "}")


def output_folder(field: str, path: Path) -> None:
    """Create the output folder ``path`` (and its parents) unless it exists; refuse a file."""
    if path.exists() and not path.is_dir():
        raise InputError(f"{path} is a file; give a folder", "{" + field + "}")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"cannot create folder {path} ({exc.strerror})", "{" + field + "}") from None


def save_json(path: Path, result) -> None:
    """Write a result file (:func:`align.results.save_result`, imported only when a result is written)."""
    from align.results import save_result

    save_result(path, result)
