"""The ``allowable`` and ``check`` jobs: what a manoeuvre allows, and a mounting budget against it.

``imu-align allowable``, ``imu-align check``, the report's manoeuvre step and a notebook all run
:data:`ALLOWABLE` and :data:`CHECK`::

    from align.sensitivity.jobs import allowable, check
    allow = allowable(manoeuvre="examples/sensitivity/example2.toml")
    table = check(mount="examples/budget/example1.toml", manoeuvre="examples/sensitivity/example2.toml")

Public names
------------
AllowableOptions, AllowableInputs, ALLOWABLE, allowable, CheckOptions, CheckInputs, CHECK, check, check_table, BASES,
read_manoeuvre, read_allowable, read_check
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from align.errors import InputError
from align.job import Job, Progress, fields_signature
from align.sensitivity.allowable import Allowable
from align.sensitivity.allowable import allowable as compute_allowable
from align.sensitivity.manoeuvre import Manoeuvre
from align.sensitivity.margins import MarginTable, check_margins

__all__ = ["AllowableOptions", "AllowableInputs", "ALLOWABLE", "allowable", "CheckOptions", "CheckInputs", "CHECK",
           "check", "check_table", "BASES", "read_manoeuvre", "read_allowable", "read_check"]

#: the budget figures a check compares: ``rss`` (the source's method) or ``worst`` (every tolerance at its extreme)
BASES = ("rss", "worst")


def read_manoeuvre(path: Path, source: Callable[[Path], Path] = Path) -> Manoeuvre:
    """A manoeuvre TOML (``[[rotation]]`` tables or a ``[series]``, and ``[limits]``), checked.

    Parameters
    ----------
    path : Path
        The file as named in messages and results; its folder is where a ``[series]`` file is looked up.
    source : callable, optional
        Maps ``path`` to the file to read (a staged copy).

    Returns
    -------
    Manoeuvre
    """
    from align.io import read_toml
    from align.sensitivity.manoeuvre import manoeuvre_from_dict

    path = Path(path)
    return manoeuvre_from_dict(read_toml(source(path)), str(path), path.parent)


# ---- allowable ----

@dataclass(frozen=True, kw_only=True)
class AllowableOptions:
    """What the allowance is computed from.

    Attributes
    ----------
    manoeuvre : Path
        Manoeuvre TOML: ``[[rotation]]`` tables with axis and angle (or a ``[series]``), and ``[limits]`` (angles).
    directions : int
        Directions on the sphere searched for the cone (the largest rigid rotation meeting every limit).
    """

    manoeuvre: Path
    directions: int = 200

    def __post_init__(self) -> None:
        object.__setattr__(self, "manoeuvre", Path(self.manoeuvre))


@dataclass(frozen=True)
class AllowableInputs:
    """The checked inputs of the allowance.

    Attributes
    ----------
    manoeuvre : Manoeuvre
        Body-frame increments (n, 3), rad, and the limits (output -> rad).
    """

    manoeuvre: Manoeuvre


def read_allowable(options: AllowableOptions, source: Callable[[Path], Path] = Path) -> AllowableInputs:
    """The manoeuvre of ``options``, read (from ``source(path)``: a staged copy) and checked."""
    return AllowableInputs(read_manoeuvre(options.manoeuvre, source))


def _compute_allowable(inputs: AllowableInputs, options: AllowableOptions,
                       progress: Progress | None = None) -> Allowable:
    return compute_allowable(inputs.manoeuvre, options.directions)


def _allowable_files(options: AllowableOptions) -> dict[str, Path | None]:
    return {"manoeuvre": options.manoeuvre}


ALLOWABLE: Job[AllowableOptions, AllowableInputs, Allowable] = Job(
    "allowable", AllowableOptions, read_allowable, _compute_allowable, _allowable_files,
    "allowable misalignment per element for a manoeuvre, the binding element and the cone")


@fields_signature(AllowableOptions)
def allowable(*, progress: Progress | None = None, **fields: Any) -> Allowable:
    """The allowable misalignment of each element for a manoeuvre, as ``imu-align allowable`` computes it.

    Parameters
    ----------
    progress : callable, optional
        Not called (the allowance is quick); accepted as every job's call accepts it.
    **fields
        The fields of :class:`AllowableOptions` (``manoeuvre`` as a str or Path, ``directions``).

    Returns
    -------
    Allowable
        Per element (``psi_x`` ... ``phi_zy``) the allowance, rad; the binding element and its value, rad;
        the cone, rad; with its provenance.

    Examples
    --------
    The reference's Example 2 (a 30 deg heading change, 1 deg allowed): ``asin(1/30)`` binds.

    >>> from pathlib import Path
    >>> import align
    >>> example = Path(align.__file__).parents[1] / "examples" / "sensitivity" / "example2.toml"
    >>> a = allowable(manoeuvre=example)
    >>> a.binding in ("phi_xz", "phi_yz"), round(a.binding_value * 57.29577951308232, 4)
    (True, 1.9102)
    """
    return ALLOWABLE.run(AllowableOptions(**fields), progress=progress)


# ---- check ----

@dataclass(frozen=True, kw_only=True)
class CheckOptions:
    """What the check compares: a mount's budget against a manoeuvre's allowance.

    Attributes
    ----------
    mount : Path
        Mount description TOML (see :class:`mechanics.jobs.BudgetOptions`).
    manoeuvre : Path
        Manoeuvre TOML (see :class:`AllowableOptions`).
    basis : str
        The budget figure compared: ``"rss"`` (the source's method) or ``"worst"``.
    parts : Path or None
        A user's parts file laid over the presets (see :class:`mechanics.jobs.BudgetOptions`).
    parts_table : mapping of str to Part, or None
        A parts table already made (overrides reading ``parts``); not part of the provenance.
    directions : int
        Directions searched for the allowance's cone.
    """

    mount: Path
    manoeuvre: Path
    basis: str = "rss"
    parts: Path | None = None
    parts_table: Mapping | None = field(default=None, repr=False, compare=False)
    directions: int = 200

    def __post_init__(self) -> None:
        object.__setattr__(self, "mount", Path(self.mount))
        object.__setattr__(self, "manoeuvre", Path(self.manoeuvre))
        if self.parts is not None:
            object.__setattr__(self, "parts", Path(self.parts))
        basis = str(getattr(self.basis, "value", self.basis))
        if basis not in BASES:
            raise InputError(f"choose rss or worst (got {basis!r})", "{basis}")
        object.__setattr__(self, "basis", basis)

    def budget_options(self) -> Any:
        """The :class:`mechanics.jobs.BudgetOptions` of the mount (no Monte Carlo: the check compares the
        deterministic figures)."""
        from mechanics.jobs import BudgetOptions

        return BudgetOptions(mount=self.mount, parts=self.parts, parts_table=self.parts_table)


@dataclass(frozen=True)
class CheckInputs:
    """The checked inputs of the check.

    Attributes
    ----------
    mount : Mount
        The mount, its part looked up.
    manoeuvre : Manoeuvre
    """

    mount: Any
    manoeuvre: Manoeuvre


def read_check(options: CheckOptions, source: Callable[[Path], Path] = Path) -> CheckInputs:
    """The mount and the manoeuvre of ``options``, read (from ``source(path)``: staged copies) and checked."""
    from mechanics.jobs import read_mount

    return CheckInputs(read_mount(options.budget_options(), source), read_manoeuvre(options.manoeuvre, source))


def check_table(budget: Any, allow: Allowable, options: CheckOptions) -> MarginTable:
    """The check's table from a budget and an allowance already computed (the report has both).

    Parameters
    ----------
    budget : mechanics.budget.Budget
        The mount's budget (its Monte Carlo, if any, plays no part).
    allow : Allowable
        The manoeuvre's allowance.
    options : CheckOptions
        The basis compared, and the files named in the table's ``inputs``.

    Returns
    -------
    MarginTable
        One row per element, rad; ``inputs`` names the mount, the manoeuvre, the part and its preset values.
    """
    table = check_margins(budget.elements(options.basis), allow, options.basis)
    return table.replace(inputs={"mount": str(options.mount), "manoeuvre": str(options.manoeuvre),
                                 "part": budget.mount.part, "preset": budget.mount.preset})


def _compute_check(inputs: CheckInputs, options: CheckOptions, progress: Progress | None = None) -> MarginTable:
    from mechanics.budget import budget as compute_budget

    return check_table(compute_budget(inputs.mount), compute_allowable(inputs.manoeuvre, options.directions), options)


def _check_files(options: CheckOptions) -> dict[str, Path | None]:
    return {"mount": options.mount, "manoeuvre": options.manoeuvre, "parts": options.parts}


CHECK: Job[CheckOptions, CheckInputs, MarginTable] = Job(
    "check", CheckOptions, read_check, _compute_check, _check_files,
    "the mounting budget against the allowance, element by element")


@fields_signature(CheckOptions)
def check(*, progress: Progress | None = None, **fields: Any) -> MarginTable:
    """A mount's budget against a manoeuvre's allowance, element by element, as ``imu-align check`` does.

    Parameters
    ----------
    progress : callable, optional
        Not called (the check is quick).
    **fields
        The fields of :class:`CheckOptions` (``mount``, ``manoeuvre`` as str or Path, ``basis``, ``parts``).

    Returns
    -------
    MarginTable
        One row per element (predicted, allowed and margin, rad); ``passed``; ``failed`` (element names);
        with its provenance. The command exits 4 when it did not pass; this call returns it either way.

    Examples
    --------
    >>> from pathlib import Path
    >>> import align
    >>> ex = Path(align.__file__).parents[1] / "examples"
    >>> table = check(mount=ex / "budget" / "example1.toml", manoeuvre=ex / "sensitivity" / "example2.toml")
    >>> table.basis, len(table.rows)
    ('rss', 9)
    """
    return CHECK.run(CheckOptions(**fields), progress=progress)
