"""Reading again the raw data a result file names, to draw its picture in the report.

A result records its inputs (``inputs``: the log, its columns, units and format). The report reads that
file again as the result recorded it: the recorded format unless the user gave format options
(:func:`recorded_format`), a relative path found beside the result file first, then in the working
directory (:func:`resolve_recorded`). When the file cannot be read again, the picture is left out and
the reason is kept as a message *template*: placeholders for the report's own inputs (``{delimiter}``,
``{gyro_columns}``), rendered by the caller's spelling (the command line's flags in the terminal, plain
words on the page: :func:`in_words`).

Public names
------------
recorded_format, resolve_recorded, template, in_words, Said, reread_alignment_log, read_capture, statics_picture,
stated_gravity, LOG_FIELDS
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from align.errors import AlignError, literal
from align.io import LogFormat, read_sensor_log, read_toml

#: a rate-table log's reading fields as the report names them (its static record has ``columns`` and ``rate_hz``)
LOG_FIELDS = {"columns": "gyro_columns", "rate_hz": "log_rate_hz", "time_column": "log_time_column"}
_FORMAT = ("skip_rows", "comment", "delimiter", "time_units")


def recorded_format(inputs: dict, given: LogFormat | None = None) -> LogFormat:
    """The format to read a result's log with: ``given`` (the user's format options) when not None, else the
    one the result recorded (``skip_rows``, ``comment``, ``delimiter``, ``time_units``); a result that
    records none is read as a plain CSV with the time unit detected."""
    if given is not None:
        return given
    return LogFormat(**{k: inputs[k] for k in _FORMAT if inputs.get(k) is not None})


def resolve_recorded(result_path: str | Path, name: str | Path) -> Path:
    """Where a file a result names is: an absolute path as it is; a relative one beside the result file
    when it is there, else in the working directory when it is there, else beside the result file."""
    p = Path(name)
    if p.is_absolute():
        return p
    beside = Path(result_path).parent / p
    return beside if beside.exists() or not p.exists() else p


def template(exc: AlignError, rename: dict | None = None, words: bool = False) -> str:
    """An error as a message template: its placeholders kept (renamed by ``rename``: a library field to the
    report's own), or put in plain words when ``words`` (the report has no option for them)."""
    rename = rename or {}

    def keep(name: str, value: str | None) -> str:
        if words:
            return literal(_word(name, value))
        name = rename.get(name, name)
        return "{" + name + ("" if value is None else "=" + value) + "}"

    where = exc.where or ""
    if where and not re.fullmatch(r"\{[a-z][a-z0-9_]*(?:=[^{}]*)?\}", where):  # a file name: taken as it is
        where = literal(where)
    text = exc.message if not where else f"{where}: {exc.message}"
    return AlignError(text).render(keep)


def _word(name: str, value: str | None) -> str:
    words = name.replace("_", " ")
    return words if value is None else f"{words} = {value}"


def in_words(text: str) -> str:
    """A template with its placeholders in plain words (``{delimiter=;}`` -> ``delimiter = ;``)."""
    return AlignError(text).render(_word)


@dataclass(frozen=True)
class Said:
    """A line of the terminal summary that holds placeholders (rendered by the caller's spelling)."""

    template: str


def reread_alignment_log(result_path: Path, r, given: LogFormat | None, columns: str | None = None,
                         rate_hz: float | None = None):
    """The rate-table log an alignment result names, read as it was; ``(log or None, why-not template)``.

    ``given`` (format), ``columns`` and ``rate_hz``: the user's options, which win over the recorded ones.
    """
    inp = r.inputs or {}
    log = inp.get("log")
    if not log:
        return None, "no segmentation picture: the result names no log"
    rate = rate_hz if rate_hz is not None else inp.get("rate_hz")
    cols = [c.strip() for c in str(columns or inp.get("columns") or "time,gyro_x,gyro_y,gyro_z").split(",") if c.strip()]
    if rate is None and len(cols) != 4:
        return None, ("no segmentation picture: the result records the columns " + literal(",".join(cols))
                      + " and no sample rate; give {gyro_columns} (time,x,y,z) or {log_rate_hz}")
    time_col, cols = (cols[0], cols[1:]) if rate is None else (None, cols[-3:])
    path = resolve_recorded(result_path, log)
    try:
        return read_sensor_log(path, cols, inp.get("gyro_units") or r.units, time_col, rate,
                               log_format=recorded_format(inp, given)), ""
    except AlignError as exc:
        return None, "no segmentation picture: the log the result names could not be read again (" + \
            template(exc, LOG_FIELDS) + ")"


def read_capture(result_path: Path, inputs: dict, columns: str, units_key: str, dim: str):
    """The raw capture a calibration names, in SI; ``(header, data, "")`` or ``(None, None, why-not template)``."""
    from align.io import read_columns
    from align.units import parse_scale

    log = inputs.get("log")
    if not log:
        return None, None, "no picture: the calibration names no log"
    path = resolve_recorded(result_path, log)
    try:
        names = [c.strip() for c in str(inputs.get("columns") or columns).split(",")]
        scale, _ = parse_scale(str(inputs.get(units_key) or "counts"), dim, "{units}")
        header, data = read_columns(path, names, log_format=recorded_format(inputs))
        return header, data * np.where(np.array([n.lower().startswith("time") for n in header]), 1.0, scale), ""
    except AlignError as exc:
        return None, None, f"no picture: the capture {literal(log)} could not be read again ({template(exc, words=True)})"


def stated_gravity(spec: dict | None) -> float | None:
    """Local gravity, m/s^2, as a positions file (``spec``, read) states it; None when it states none (or none is
    given) or states it wrongly (the calibration refused that already).

    Examples
    --------
    >>> stated_gravity({"gravity": "9.81 m/s^2"}), stated_gravity(None)
    (9.81, None)
    """
    from align.units import parse_quantity

    if not spec or "gravity" not in spec:
        return None
    try:
        return parse_quantity(spec["gravity"], "acceleration", "gravity")
    except AlignError:
        return None


def statics_picture(result_path: Path, inputs: dict, cal):
    """The static intervals of an accelerometer session, detected again from the log the calibration names;
    ``(png or None, note template)``."""
    if cal.sensor != "accelerometer" or "positions" not in inputs:
        return None, ""
    from align.calibration.accel import StaticDetector, session_intervals
    from align.present.calplots import accel_statics_png

    cols = [c.strip() for c in str(inputs.get("columns") or "time,acc_x,acc_y,acc_z").split(",")]
    time_col, cols = (cols[0], cols[1:]) if len(cols) == 4 else (None, cols)
    try:
        got = read_sensor_log(resolve_recorded(result_path, inputs["log"]), cols,
                              str(inputs.get("accel_units") or cal.units), time_col, inputs.get("rate_hz"),
                              expect="acceleration", log_format=recorded_format(inputs), counts=True)
    except AlignError as exc:
        return None, f"no picture: the log could not be read again ({template(exc, words=True)})"
    except KeyError as exc:
        return None, f"no picture: the calibration does not record its {literal(exc.args[0])}"
    det = inputs.get("detector") or {}
    detector = StaticDetector(**{k: det[k] for k in ("window_s", "factor", "init_static_s", "min_static_s") if k in det})
    positions = inputs.get("positions")
    try:
        spec = None if positions is None else read_toml(resolve_recorded(result_path, positions))
        iv = session_intervals(got.t, got.data, spec, detector, str(positions))
    except AlignError as exc:
        return None, f"no picture: the session's intervals could not be found again ({template(exc, words=True)})"
    note = "" if det else "static intervals detected again with the default detector settings (the file records none)"
    return accel_statics_png(got.t, got.data, iv, cal.units, calibration=cal, gravity=stated_gravity(spec)), note
