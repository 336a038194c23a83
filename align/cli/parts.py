"""``imu-align`` parts (the datasheet presets and a user's own parts file), and the ``--parts`` option.

A user's parts file (TOML, one table per part, the fields of the built-in table) extends or overrides
the presets. It is given with ``--parts FILE`` or named by the environment variable
:data:`ENV` (``--parts`` wins); the library never reads either: :func:`parts_table` reads the file here
and the commands pass the merged table on.

Public names
------------
parts, parts_table, parts_file, parts_fields, LazyParts, PartsFile, ENV, COMMANDS
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated

import typer

#: the environment variable naming a user's parts file
ENV = "IMU_ALIGN_PARTS"

PartsFile = Annotated[Path | None, typer.Option("--parts", metavar="PARTS.toml", help=(
    f"Your own parts file (TOML: one [PART] table per part, the figures of 'imu-align parts'); extends or "
    f"overrides the presets. Default: the file named by {ENV}, if set."))]


def parts_file(option: Path | None) -> tuple[Path | None, str | None]:
    """The user's parts file: ``--parts``, else the file :data:`ENV` names (an empty variable is unset), and a
    note of where it came from (None for ``--parts`` or no file)."""
    if option is not None:
        return option, None
    env = os.environ.get(ENV, "").strip()
    return (Path(env), f"named by {ENV}") if env else (None, None)


def parts_table(option: Path | None):
    """The presets with the user's parts laid over them, or None (the built-in table) when there is no parts file.

    Raises
    ------
    InputError
        The file is missing, not TOML, or a part in it is malformed (naming the file, and the
        environment variable when the file came from it).
    """
    from align.errors import AlignError, InputError
    from align.io import read_toml
    from align.parts import merge_parts, parts_from_dict

    path, note = parts_file(option)
    if path is None:
        return None
    try:
        return merge_parts(parts_from_dict(read_toml(path), str(path)))
    except AlignError as exc:
        if note is None:
            raise
        raise InputError(f"{exc.message} (the parts file {note}; fix it or unset {ENV})", exc.where) from None


class LazyParts(Mapping):
    """The parts table (the presets with the user's parts file laid over them), read on first use: a command
    reads the parts file only when its mount (or ``--imu``) looks a part up; its errors name the environment
    variable when the file came from it."""

    def __init__(self, option: Path | None) -> None:
        self.option: Path | None = option
        self._table: Mapping | None = None

    def _load(self) -> Mapping:
        if self._table is None:
            from align.parts import PARTS

            self._table = parts_table(self.option) or PARTS
        return self._table

    def __getitem__(self, key):
        return self._load()[key]

    def __iter__(self):
        return iter(self._load())

    def __len__(self) -> int:
        return len(self._load())


def parts_fields(option: Path | None) -> dict:
    """The jobs' ``parts`` and ``parts_table`` fields from ``--parts`` (or the environment variable): the file, for
    the result's provenance, and its table read on first use (None, None: the presets alone)."""
    path, _ = parts_file(option)
    return {"parts": path, "parts_table": None if path is None else LazyParts(option)}


def parts(
    name: Annotated[str | None, typer.Argument(metavar="[NAME]", show_default=False, help=(
        "One part in full (case-insensitive), e.g. ADIS16485; default: every part."))] = None,
    parts_path: PartsFile = None,
) -> None:
    """Datasheet presets: every figure with its value, unit, source and whether it is confirmed."""
    from align.parts import PARTS, get_part
    from align.present.presets import part_text, parts_listing

    table = parts_table(parts_path)
    path, note = parts_file(parts_path)
    shown = None if path is None else str(path) + (f" ({note})" if note else "")
    if name is None:
        typer.echo(parts_listing(PARTS if table is None else table, shown))
    else:
        typer.echo(part_text(get_part(name, "NAME", table), full=True))


COMMANDS: dict = {"parts": parts}
