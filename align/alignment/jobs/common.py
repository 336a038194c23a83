"""What the alignment family's jobs share: a log given as a path, a blank unit refused, the columns read.

Public names
------------
source, check_unit_given, names_read
"""

from __future__ import annotations

from pathlib import Path

from align.io.logs import sensor_scale
from align.io.source import LogSource
from align.vocab import Sensor

__all__ = ["source", "check_unit_given", "names_read"]


def source(log: LogSource | str | Path) -> LogSource:
    return log if isinstance(log, LogSource) else LogSource(path=Path(log))


def check_unit_given(unit: str | None, expect: str, field: str) -> None:
    """A unit given as blank text is refused naming its option (:meth:`LogSource.read` would take the default)."""
    if unit is not None and not unit.strip():
        sensor_scale(unit, expect, field)  # raises the reader's own refusal of an empty unit


def names_read(src: LogSource, sensor: Sensor) -> tuple[str | None, list[str]]:
    """The time and data columns ``src.read(sensor)`` reads (the old default names when the file has them)."""
    time, cols = src.names(sensor)
    if src.columns is None:
        cols = src._defaults_present(sensor, cols, time)
    return time, cols
