"""Keys: the tables and keys of an input file, checked against the ones a reader knows.

Every TOML or JSON input reader calls :func:`check_keys` on each table it reads,
so a misspelled key (``latitud``, ``position_tolerence``) is refused with the
nearest valid key instead of being silently ignored; :func:`table` and
:func:`tables` fetch a sub-table (``[test]``) or an array of tables
(``[[step]]``) with one-line refusals for the wrong shape.

Public names
------------
check_keys, require_keys, table, tables, file_name, referenced_file
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Mapping
from pathlib import Path

from align.errors import InputError, literal


def check_keys(data: Mapping, known: Iterable[str], where: str) -> None:
    """Refuse a key of ``data`` that is not in ``known``.

    Parameters
    ----------
    data : mapping
        A parsed table (TOML table, JSON object).
    known : iterable of str
        Every key the reader accepts there, in the order to list them.
    where : str
        The file and table, e.g. ``"plan.toml: [test]"``.

    Raises
    ------
    InputError
        Naming the first unknown key, the nearest known key (``difflib``) and
        the known keys, e.g. ``plan.toml: [test]: unknown key 'latitud' (did you
        mean 'latitude'? known: latitude, rate_accuracy, angle_accuracy)``.
    """
    names = list(known)
    for key in data:
        if key in names:
            continue
        near = difflib.get_close_matches(str(key), names, n=1, cutoff=0.6)
        hint = f"did you mean '{near[0]}'? " if near else ""
        listing = ", ".join(names) if names else "none"
        raise InputError(f"unknown key '{literal(key)}' ({hint}known: {listing})", where)


def require_keys(data: Mapping, required: Mapping[str, str], where: str) -> None:
    """Refuse ``data`` when a required key is missing.

    Parameters
    ----------
    data : mapping
    required : mapping of str to str
        Each required key and an example line for the message
        (``{"axis": 'axis = "+x"'}``).
    where : str
        The file and table.
    """
    for key, example in required.items():
        if key not in data:
            raise InputError(f"missing key '{key}' (e.g. {example})", where)


def _resolve(name: str, base_dir: str | Path | None) -> Path:
    path = Path(name)
    return Path(base_dir) / path if base_dir is not None and not path.is_absolute() else path


def file_name(data: Mapping, key: str, where: str, example: str, base_dir: str | Path | None = None) -> Path:
    """The file named by ``key`` of ``data``; a relative name is taken in ``base_dir`` (the input file's folder).

    Parameters
    ----------
    data : mapping
        The table, e.g. ``[series]``.
    key : str
        The key, e.g. ``"file"``.
    where : str
        The file and field, e.g. ``"m.toml: series.file"``.
    example : str
        An example name for the message (``"rates.csv"``).
    base_dir : str or Path, optional
        The folder relative names are read from.

    Raises
    ------
    InputError
        When the key is missing or is not a non-empty string.
    """
    if key not in data:
        raise InputError(f"missing field {key} = \"{example}\"", where)
    value = data[key]
    if not isinstance(value, str) or not value.strip():
        raise InputError(f"expected a file name ({key} = \"{example}\"), got {literal(repr(value))}", where)
    return _resolve(value, base_dir)


def referenced_file(data: Mapping, name: str, key: str, base_dir: str | Path | None = None) -> Path | None:
    """The file ``[name] key = "FILE"`` of ``data`` refers to, resolved as :func:`file_name` does; None when absent.

    Lenient (nothing is refused here): for the output checks made before any
    work, so that no output overwrites a data file an input file reads.
    """
    t = data.get(name)
    value = t.get(key) if isinstance(t, Mapping) else None
    return _resolve(value, base_dir) if isinstance(value, str) and value.strip() else None


def table(data: Mapping, name: str, where: str, required: bool = False) -> dict:
    """The sub-table ``[name]`` of ``data``; ``{}`` when absent and not ``required``.

    Raises
    ------
    InputError
        When it is missing but required, or is not a table (``name = 3``, ``[[name]]``).
    """
    t = data.get(name)
    if t is None:
        if required:
            raise InputError(f"missing table [{name}]", where)
        return {}
    if not isinstance(t, dict):
        raise InputError(f"[{name}] must be a table (a [{name}] header followed by key = value lines)", where)
    return t


def tables(data: Mapping, name: str, where: str) -> list[dict]:
    """The array of tables ``[[name]]`` of ``data`` (``[]`` when absent).

    Raises
    ------
    InputError
        When ``name`` is not a list of tables (``[name]`` written for ``[[name]]``).
    """
    t = data.get(name)
    if t is None:
        return []
    if isinstance(t, dict):
        raise InputError(f"[{name}] must be an array of tables: write [[{name}]] before each entry", where)
    if not isinstance(t, list) or not all(isinstance(item, dict) for item in t):
        raise InputError(f"'{name}' must be [[{name}]] tables", where)
    return t
