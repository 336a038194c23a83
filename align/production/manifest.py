"""The manifest of a lot: which units to run, with which job, inputs and options.

A manifest is a CSV file (one row per unit) or a TOML file (``[[unit]]`` tables, with an
optional ``[defaults]`` table whose keys every unit takes unless it states its own)::

    serial,job,log,plan,options,slot
    SN0001,matrix,sessions/SN0001.csv,plan.toml,--gyro-units deg/s,1
    SN0002,calibrate accel,sessions/SN0002.csv,,,2

Columns: ``serial`` (names the unit's result file: letters, digits, ``.``, ``_``, ``-``), ``job``
(a command of the single-unit tool), ``log``, ``plan`` (empty where the job has none), ``options``
(the single command's options as typed, split as a POSIX shell splits them; ``{serial}`` in them
becomes the unit's serial), and optionally ``slot`` (the fixture slot) and the unit's identity: ``station``,
``fixture``, ``operator``, ``device_id`` (the sensor's own id, as its log or label states it) and ``test_time``
(when it was tested, ISO 8601 with its zone: ``2026-11-28T14:05:00+01:00`` or ``...Z``; a trend over test time
needs it, the table's ``time`` being when the row was made; where not given, a log that states them gives
``device_id`` and ``test_time``, :mod:`align.production.identity`). A unit whose job gives a gyro correction
(:data:`VALIDATED`) may name a validation run, a rate-table session its result was not fitted to, replayed on it by
``imu-align verify`` once the job is done: ``validation`` (its log), ``validation_plan`` (its plan; a ``matrix``
unit's own plan when empty) and ``validation_options`` (``verify``'s options). Paths are relative to the
manifest's folder. A bad manifest is one :class:`~align.errors.InputError` naming the file, the
row (CSV line or ``[[unit]]`` number) and the column.

The content hash of a unit's inputs (:func:`input_hash`) decides whether a rerun may skip it.

Public names
------------
Unit, Manifest, read_manifest, input_hash, PLAN_USE, SERIAL, IDENTITY, VALIDATED
"""

from __future__ import annotations

import csv
import difflib
import hashlib
import io
import re
import shlex
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

from align.errors import InputError, literal
from align.io.files import read_text, read_toml

#: what a job does with the manifest's ``plan`` column: needs one, may take one, takes none
PLAN_USE = ("required", "optional", "none")
#: a serial number names a file: letters, digits, '.', '_' and '-', not starting with '.'
SERIAL = re.compile(r"^[A-Za-z0-9_-][A-Za-z0-9._-]{0,127}$")
#: the columns of a manifest: required ones, then optional ones
REQUIRED = ("serial", "job", "log")
OPTIONAL = ("plan", "options", "slot", "station", "fixture", "operator", "device_id", "test_time", "validation",
            "validation_plan", "validation_options")
#: the jobs whose result a validation run replays (``imu-align verify``: a gyro correction on a rate-table session)
VALIDATED = ("matrix", "calibrate ferraris", "calibrate gyro")
#: the optional columns that identify how the unit was tested (carried into its rows of the lot's table)
IDENTITY = ("station", "fixture", "operator", "device_id", "test_time")


@dataclass(frozen=True, slots=True)
class Unit:
    """One unit of a lot, as its manifest row states it (paths resolved against the manifest's folder).

    Attributes
    ----------
    serial : str
        The unit's serial number (its result file is ``SERIAL.JOB.json``, the job's words joined by ``-``;
        one serial may have several jobs, each (serial, job) once).
    job : str
        The single-unit command, e.g. ``"matrix"`` or ``"calibrate accel"``.
    log : Path
        The unit's log, absolute.
    plan : Path or None
        The job's plan-like input (test plan, positions, sections), absolute; None when not given.
    options : tuple of str
        The single command's options, split as typed (``{serial}`` replaced).
    slot : str or None
        The fixture slot.
    order : int
        Position in the manifest, from 0 (the lot's order for trends).
    row : str
        Where the unit is stated, for messages: ``"line 4"`` (CSV) or ``"[[unit]] 3"`` (TOML).
    identity : tuple of (str, str)
        The identity columns given (:data:`IDENTITY`), ``test_time`` as ISO 8601 with its zone.
    validation : Path or None
        A rate-table session the unit's result is replayed on (``imu-align verify``), absolute; None: none.
    validation_plan : Path or None
        That session's plan (a ``matrix`` unit's own plan when not given).
    validation_options : tuple of str
        ``verify``'s options for it, split as typed (``--gyro-units deg/s``, ``--tolerance-angle "0.05 deg"``).
    """

    serial: str
    job: str
    log: Path
    plan: Path | None
    options: tuple[str, ...]
    slot: str | None
    order: int
    row: str
    identity: tuple[tuple[str, str], ...] = ()
    validation: Path | None = None
    validation_plan: Path | None = None
    validation_options: tuple[str, ...] = ()

    @property
    def result_name(self) -> str:
        """The unit's result file name: ``SN0001.calibrate-accel.json``."""
        return f"{self.serial}.{'-'.join(self.job.split())}.json"


@dataclass(frozen=True)
class Manifest:
    """A manifest file and its units, in order, each made when asked for.

    The rows are kept checked but compact (their words, the repeated ones shared): a :class:`Unit` with its
    resolved paths is made as it is iterated, so that a lot of 100,000 units costs the batch a few hundred bytes
    per unit, not a kilobyte and more.
    """

    path: Path
    rows: tuple[tuple, ...]

    @property
    def folder(self) -> Path:
        """The folder the manifest's paths are relative to."""
        return self.path.parent

    def __len__(self) -> int:
        return len(self.rows)

    def __iter__(self) -> Iterator[Unit]:
        """The units in the manifest's order (:func:`_make` of each checked row)."""
        plans: dict[str, Path] = {}
        return (_make(order, row, plans) for order, row in enumerate(self.rows))

    @property
    def units(self) -> tuple[Unit, ...]:
        """Every unit at once (a short manifest; a batch iterates)."""
        return tuple(self)

    @property
    def jobs(self) -> frozenset[str]:
        """The jobs its units name."""
        return frozenset(r[2] for r in self.rows)

    @property
    def serials(self) -> int:
        """How many units (serials) it lists: a serial with several jobs counts once."""
        return len({r[1] for r in self.rows})


def read_manifest(path: str | Path, jobs: Mapping[str, str]) -> Manifest:
    """Read a manifest (CSV, or TOML by its ``.toml`` suffix) and check every row.

    Parameters
    ----------
    path : str or Path
    jobs : mapping of str -> str
        The jobs a unit may name, each with its use of the ``plan`` column (one of :data:`PLAN_USE`).

    Returns
    -------
    Manifest

    Raises
    ------
    InputError
        A missing or unknown column, an unknown job, a serial that cannot name a file or is given twice,
        an empty log, a plan missing where the job needs one (or given where it takes none), options that
        cannot be split: naming the file, the row and the column.
    """
    p = Path(path)
    records = _toml_records(p) if p.suffix.lower() == ".toml" else _csv_records(p)
    if not records:
        raise InputError("lists no units; give one row per unit", str(p))
    rows: list[tuple] = []
    seen: dict[tuple[str, str], str] = {}
    shared: dict = {}
    resolved: dict[str, str] = {}
    folder = p.resolve().parent
    for row, record in records:
        words = list(_checked(record, row, jobs, str(p)))
        for k in (3, 4, 8, 9):  # log, plan and the validation's: resolved once, here (a plan once for the lot)
            if words[k] and words[k] not in resolved:
                resolved[words[k]] = str((folder / words[k]).resolve())
            words[k] = resolved[words[k]] if words[k] else ""
        checked = tuple(shared.setdefault(v, v) for v in words)
        serial, job = checked[1], checked[2]
        key = (serial.lower(), job)  # case-only differences collide on case-insensitive file systems
        if key in seen:
            raise InputError(f"{row}, column serial: {serial} with job {job} is also stated at {seen[key]}; "
                             "give each (serial, job) once (a serial may have several jobs)", str(p))
        seen[key] = row
        rows.append(checked)
    return Manifest(p, tuple(rows))


def _csv_records(path: Path) -> list[tuple[str, dict]]:
    text = read_text(path).lstrip("\ufeff")
    reader = csv.reader(io.StringIO(text))
    header, records = None, []
    for fields in reader:
        if not any(f.strip() for f in fields) or fields[0].lstrip().startswith("#"):
            continue  # blank lines and comments
        if header is None:
            header = [f.strip().lower() for f in fields]
            _check_columns(header, f"line {reader.line_num}", str(path))
            continue
        row = f"line {reader.line_num}"
        if len(fields) > len(header):
            raise InputError(f"{row}: {len(fields)} fields but the header names {len(header)} columns; quote a "
                             "field that holds a comma", str(path))
        records.append((row, {k: v.strip() for k, v in zip(header, fields)}))
    if header is None:
        raise InputError(f"is empty; give a header ({','.join(REQUIRED + OPTIONAL)}) and one row per unit", str(path))
    return records


def _check_columns(header: list[str], row: str, where: str) -> None:
    known = REQUIRED + OPTIONAL
    for name in header:
        if name not in known:
            close = difflib.get_close_matches(name, known, n=1)
            hint = f" (did you mean {close[0]}?)" if close else ""
            raise InputError(f"{row}: unknown column '{literal(name)}'{hint}; the columns are {', '.join(known)}", where)
    for name in REQUIRED:
        if name not in header:
            raise InputError(f"{row}: the header has no column {name}; the columns are {', '.join(known)}", where)
    doubled = {n for n in header if header.count(n) > 1}
    if doubled:
        raise InputError(f"{row}: column {sorted(doubled)[0]} is named twice", where)


def _toml_records(path: Path) -> list[tuple[str, dict]]:
    data = read_toml(path)
    unknown = [k for k in data if k not in ("defaults", "unit")]
    if unknown:
        raise InputError(f"unknown table or key '{literal(unknown[0])}'; a manifest holds [defaults] and [[unit]] tables",
                         str(path))
    defaults = data.get("defaults", {})
    units = data.get("unit", [])
    if not isinstance(defaults, dict) or not isinstance(units, list) or not all(isinstance(u, dict) for u in units):
        raise InputError("give [defaults] as a table and each unit as a [[unit]] table", str(path))
    records = []
    for k, unit in enumerate(units, 1):
        row = f"[[unit]] {k}"
        merged = {**defaults, **unit}
        for key, value in merged.items():
            if key not in REQUIRED + OPTIONAL:
                raise InputError(f"{row}: unknown key '{literal(key)}'; the keys are {', '.join(REQUIRED + OPTIONAL)}",
                                 str(path))
            if key == "options" and isinstance(value, list) and all(isinstance(v, str) for v in value):
                merged[key] = shlex.join(value)
            elif isinstance(value, (int, float)) and not isinstance(value, bool) and key in ("serial", "slot",
                                                                                            "device_id"):
                merged[key] = str(value)
            elif key == "test_time" and isinstance(value, datetime):  # a TOML date-time
                merged[key] = value.isoformat()
            elif not isinstance(value, str):
                raise InputError(f"{row}, column {key}: give a string (got {literal(repr(value))})", str(path))
        records.append((row, {k: v.strip() for k, v in merged.items()}))
    return records


def _checked(record: dict, row: str, jobs: Mapping[str, str], where: str) -> tuple:
    """A row checked, as the words a :class:`Unit` is made of: ``(row, serial, job, log, plan, options, slot,
    identity, validation, validation_plan, validation_options)`` (paths as written, relative to the manifest;
    ``""`` when not given; :func:`read_manifest` resolves them)."""
    def bad(column: str, what: str) -> InputError:
        return InputError(f"{row}, column {column}: {what}", where)

    serial = record.get("serial", "")
    if not SERIAL.match(serial):
        raise bad("serial", f"'{literal(serial)}' cannot name a file; use letters, digits, '.', '_' and '-'"
                  if serial else "empty; give the unit's serial number")
    job = " ".join(record.get("job", "").split())
    if job not in jobs:
        close = difflib.get_close_matches(job, list(jobs), n=1)
        hint = f" (did you mean {close[0]}?)" if close else ""
        raise bad("job", f"unknown job '{literal(job)}'{hint}; the jobs are {', '.join(jobs)}" if job
                  else f"empty; give one of {', '.join(jobs)}")
    log = record.get("log", "")
    if not log:
        raise bad("log", "empty; give the unit's log file")
    plan, use = record.get("plan", ""), jobs[job]
    if use == "required" and not plan:
        raise bad("plan", f"empty; the {job} job needs one")
    if use == "none" and plan:
        raise bad("plan", f"the {job} job takes no plan; leave it empty")
    options, checks = _words(record, "options", serial, bad), _words(record, "validation_options", serial, bad)
    check = record.get("validation", "")
    check_plan = record.get("validation_plan", "") or (plan if check and job == "matrix" else "")
    if not check and (check_plan or checks):
        raise bad("validation", "empty, while validation_plan or validation_options is given; give the validation "
                  "session's log")
    if check and job not in VALIDATED:
        raise bad("validation", f"the {job} job's result is no gyro correction a rate-table session could replay; "
                  f"validation goes with {', '.join(VALIDATED)}")
    if check and not check_plan:
        raise bad("validation_plan", f"empty; give the validation session's test plan (a {job} unit has no plan of "
                  "a rate-table session)")
    return (row, serial, job, log, plan, options, record.get("slot") or None, _identity(record, bad), check,
            check_plan, checks)


def _words(record: dict, column: str, serial: str, bad) -> tuple[str, ...]:
    """A column of options, split as a POSIX shell splits them, ``{serial}`` replaced."""
    try:
        return tuple(t.replace("{serial}", serial) for t in shlex.split(record.get(column, ""), comments=False))
    except ValueError as exc:
        raise bad(column, f"cannot be split ({exc}); check the quotes") from None


def _make(order: int, row: tuple, plans: dict[str, Path]) -> Unit:
    """The :class:`Unit` of a checked row (:func:`_checked`, its paths resolved by :func:`read_manifest`; the
    plans, often one for the whole lot, made paths once: ``plans``)."""
    where, serial, job, log, plan, options, slot, identity, check, check_plan, checks = row
    for p in (plan, check_plan):
        if p and p not in plans:
            plans[p] = Path(p)
    return Unit(serial, job, Path(log), plans[plan] if plan else None, options, slot, order, where, identity,
                Path(check) if check else None, plans[check_plan] if check_plan else None, checks)


def _identity(record: dict, bad) -> tuple[tuple[str, str], ...]:
    """The identity columns given; ``test_time`` checked as ISO 8601 with a zone."""
    out = []
    for key in IDENTITY:
        value = record.get(key) or ""
        if not value:
            continue
        if key == "test_time":
            try:
                stamp = datetime.fromisoformat(value)
            except ValueError:
                raise bad(key, f"'{literal(value)}' is not an ISO 8601 time; give e.g. 2026-11-28T14:05:00+01:00") from None
            if stamp.tzinfo is None:
                raise bad(key, f"'{literal(value)}' states no zone; add it (+01:00, or Z for UTC) so that the lot's "
                          "trend over test time is not shifted")
            value = stamp.isoformat()
        out.append((key, value))
    return tuple(out)


def input_hash(job: str, options: Iterable[str], files: Iterable[Path | None],
               known: Mapping[str, str] | None = None) -> str:
    """The content hash (SHA-256, hex) of a unit's inputs: its job, its options as typed, and the bytes of
    each input file in order (a missing file hashes as missing, so that it counts as changed once it exists).

    Two units hash alike exactly when their job, options and input contents and the imu-align version
    (``align.__version__``: a release that changes an estimator reruns every unit) are the same; the
    files' names and times do not enter.

    Parameters
    ----------
    job : str
    options : iterable of str
    files : iterable of Path or None
    known : mapping of str -> str, optional
        Path -> SHA-256 (hex) of files hashed already (a result's provenance, :class:`align.provenance.InputFile`):
        not read again; an empty digest stands for a file that could not be read. The others are hashed as the
        provenance hashes them, so that both give one digest.
    """
    from align import __version__

    h = hashlib.sha256(b"imu-align batch inputs 1\0" + str(__version__).encode() + b"\0")
    h.update(hashlib.sha256("\0".join([job, *options]).encode()).digest())
    for path in files:
        hexed = None if path is None or not known else known.get(str(path))
        if hexed is None:
            h.update(_file_digest(path))
        else:
            h.update(bytes.fromhex(hexed) if hexed else b"missing")
    return h.hexdigest()


def _file_digest(path: Path | None) -> bytes:
    """SHA-256 of an input's bytes, as its result's provenance records it (:func:`align.provenance.file_record`: a
    file's bytes; a log folder's files, where the provenance reads folders); fixed tags for no file and a missing
    (unreadable) one."""
    from align.provenance import file_record

    if path is None:
        return b"none"
    hexed = file_record("", path).sha256
    return bytes.fromhex(hexed) if hexed else b"missing"
