"""Output paths: checked before a command computes anything, written all together after it succeeded.

Every output a command writes (``--json``, ``--c-header``, ``--plot``,
``--picture``, ``--glb``, ``--out``, ``--imucal-json``, an output folder) is
checked first, the same way everywhere: its folder exists (an output folder
itself is created), it is not a folder where a file is expected, it is none of
the command's inputs, and no two outputs are the same file. A failure is one
:class:`~align.errors.InputError` naming the option (as a placeholder that
:func:`align.cli.options.spell` renders).

A command then stages every output in an :class:`align.io.outputs.Outputs`
as it computes it and commits them together at its end: a failed run leaves
no output at all (:func:`outputs`).

Public names
------------
check_outputs, output_folder, outputs, data_files, named_inputs, resolve_named, write_run, judged_outcome
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


def _check_file(field: str, path: Path, inputs: list[Path], in_new_folder: bool = False) -> None:
    where = "{" + field + "}"
    if path.is_dir():
        raise InputError(f"{path} is a folder; give a file name", where)
    if not in_new_folder:
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
                  results: Iterable[Path | None] = (), **outputs: Path | None) -> None:
    """Refuse, before any work, outputs that cannot be written or would overwrite an input.

    Parameters
    ----------
    inputs : iterable of Path or None
        The files the command reads (None: not given).
    folder : (field, Path, names), optional
        An output folder and the names of the files it will hold; a missing folder is
        created by the run's :class:`~align.io.outputs.Outputs` (and removed again if the run fails).
    **outputs : Path or None
        Output files by field name (``json_out=...``, ``c_header=...``); None: not given.
    results : iterable of Path or None
        Result files the command reads: the data files each names (:func:`named_inputs`) are inputs
        too, and an output that is one is refused naming the result.
    """
    ins = [Path(p) for p in inputs if p is not None]
    for result in results:
        if result is None:
            continue
        for named in named_inputs(result):
            for field, p in outputs.items():
                if p is not None and _same(Path(p), named):
                    raise InputError(f"{p} is a data file {Path(result).name} names (its record of the inputs); "
                                     "write to another file", "{" + field + "}")
            ins.append(named)
    seen: list[tuple[str, Path, bool]] = []
    if folder is not None:
        field, path, names = folder
        new = output_folder(field, path)
        seen += [(field, path / name, new) for name in names]
    seen += [(field, Path(p), False) for field, p in outputs.items() if p is not None]
    for i, (field, path, new) in enumerate(seen):
        _check_file(field, path, ins, new)
        for other, earlier, _ in seen[:i]:
            if _same(path, earlier):
                raise InputError(f"{path} is also the output of {{{other}}}; give each output its own file", "{" + field + "}")


def output_folder(field: str, path: Path) -> bool:
    """Check that the output folder ``path`` can hold the run's files: an existing, writable folder, or a
    missing one that can be created (its nearest existing parent is a writable folder). True when missing."""
    where = "{" + field + "}"
    if path.exists():
        if not path.is_dir():
            raise InputError(f"{path} is a file; give a folder", where)
        _writable(path, where)
        return False
    parent = path.parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    if not parent.is_dir():
        raise InputError(f"cannot create folder {path}: {parent} is a file", where)
    _writable(parent, where)
    return True


def data_files(mount: Path | None = None, manoeuvre: Path | None = None) -> list[Path]:
    """The data files a mount file (its baseplate STL) and a manoeuvre file (its rate series) name: inputs
    too, which no output may overwrite. Lenient: a file that cannot be read names none here (its reader
    refuses it later, in its turn)."""
    import tomllib

    from align.sensitivity.manoeuvre import manoeuvre_inputs
    from mechanics.mount import mount_inputs

    found: list[Path] = []
    for path, listed in ((mount, mount_inputs), (manoeuvre, manoeuvre_inputs)):
        if path is None:
            continue
        try:
            data = tomllib.loads(Path(path).read_text(encoding="utf-8"))
        except (OSError, ValueError):  # missing, a folder, not UTF-8, not TOML
            continue
        found += listed(data, Path(path).parent)
    return found


#: keys of a result's ``inputs`` that name files (other keys' strings count when such a file exists)
_FILE_KEYS = ("log", "plan", "accel_log", "positions", "segments", "mount", "manoeuvre", "parts", "allan",
              "alignment", "frame", "static", "logs", "capture")


def resolve_named(result_path: Path | str, name: str | Path) -> Path:
    """Where a path recorded in a result file is, as the report reads it
    (:func:`align.present.reread.resolve_recorded`): as given when absolute; else relative to the result
    file's folder when that file exists, else relative to the working directory when that one exists,
    else (neither exists) relative to the result file's folder."""
    from align.present.reread import resolve_recorded

    return resolve_recorded(result_path, name)


def named_inputs(result_path: Path | str) -> list[Path]:
    """The data files a result file names in its ``inputs`` (the log, plan, static record, capture,
    positions, segments, mount, manoeuvre, parts file...), resolved as :func:`resolve_named` reads them;
    for a relative name, also its reading against the working directory when that file exists (an
    output may overwrite neither). Lenient: a file that is no JSON, or names nothing, names none here.

    Parameters
    ----------
    result_path : Path or str
        A result file (any ``--json`` output).

    Returns
    -------
    list of Path
    """
    import json

    try:
        d = json.loads(Path(result_path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return []
    inputs = d.get("inputs") if isinstance(d, dict) else None
    if isinstance(inputs, dict):
        pairs = list(inputs.items())
    elif isinstance(inputs, list):
        pairs = [("logs", v) for v in inputs]
    else:
        return []
    names: list[str] = []
    for key, value in pairs:
        for v in value if isinstance(value, list) else [value]:
            if isinstance(v, str) and v.strip():
                if key in _FILE_KEYS or resolve_named(result_path, v).is_file():
                    names.append(v)
    found: list[Path] = []
    for name in names:
        first = resolve_named(result_path, name)
        for p in (first, Path(name)):
            if p not in found and (p == first or p.exists()):
                found.append(p)
    return found


def outputs():
    """The outputs of this run, all or none: ``with outputs() as out: out.write_json(path, result)``."""
    from align.io.outputs import Outputs

    return Outputs()


def write_run(json_out: Path | None, result, files: Iterable[tuple[Path, bytes | str]] = ()) -> None:
    """A job's outputs, all or none: its JSON result (when asked) and the extra files its output options made
    (``<command>_files``: pictures as bytes, headers and CSV as text), every one made before anything is written."""
    files = list(files)
    with outputs() as out:
        if json_out is not None:
            out.write_json(json_out, result)
        out.write_files(files)


def judged_outcome(result) -> None:
    """After a job's files are written: its figures of merit that are not PASS, and the verdict line, on the
    terminal; exit 4 (:class:`~align.errors.CheckFailed`) when a figure FAILs or is NOT USABLE (the files stay,
    for diagnosis)."""
    import typer

    from align.errors import CheckFailed
    from align.judge import failures
    from align.present.merit import verdict_lines

    for line in verdict_lines(result.verdicts):
        typer.echo(line)
    bad = failures(result.verdicts)
    if bad:
        named = ", ".join(f"{f.sensor} {f.name} {f.status}" for f in bad[:3]) + (" ..." if len(bad) > 3 else "")
        raise CheckFailed(f"{len(bad)} figure{'s' if len(bad) > 1 else ''} of merit fail{'' if len(bad) > 1 else 's'}: "
                          f"{named} (listed above; files written)")

