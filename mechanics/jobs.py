"""The ``budget`` job: a mount description -> its mounting-misalignment budget, as one library call.

``imu-align budget``, the report's mount step and a notebook all run :data:`BUDGET` with a
:class:`BudgetOptions`::

    from mechanics.jobs import budget
    b = budget(mount="examples/budget/example1.toml", monte_carlo=10_000, seed=1)

Public names
------------
BudgetOptions, BudgetInputs, BUDGET, budget, read, compute, files, read_mount, PartsFileTable
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from align.job import Job, Progress, fields_signature
from mechanics.budget import Budget
from mechanics.budget import budget as compute_budget
from mechanics.montecarlo import monte_carlo as run_monte_carlo
from mechanics.mount import Mount

__all__ = ["BudgetOptions", "BudgetInputs", "BUDGET", "budget", "read", "compute", "files", "read_mount",
           "PartsFileTable"]


class PartsFileTable(Mapping):
    """The presets with a user's parts file laid over them, read on first use (a mount that looks no part up
    never reads the file).

    Parameters
    ----------
    path : Path
        The user's parts file (TOML, one table per part, :func:`align.parts.parts_from_dict`).
    """

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self._table: Mapping | None = None

    def _load(self) -> Mapping:
        if self._table is None:
            from align.io import read_toml
            from align.parts import merge_parts, parts_from_dict

            self._table = merge_parts(parts_from_dict(read_toml(self.path), str(self.path)))
        return self._table

    def __getitem__(self, key: str) -> Any:
        return self._load()[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._load())

    def __len__(self) -> int:
        return len(self._load())


@dataclass(frozen=True, kw_only=True)
class BudgetOptions:
    """What the budget is computed from.

    Attributes
    ----------
    mount : Path
        Mount description TOML (``[imu]``, ``[package]``, ``[ledges]`` or ``[baseplate]``, ``[screws]``).
    monte_carlo : int
        Monte Carlo draws of the assembly (0: none), dimensionless count.
    seed : int
        Seed of the Monte Carlo's random streams.
    parts : Path or None
        A user's parts file laid over the presets (the mount's ``[imu] part`` is looked up in it); None:
        the presets alone.
    parts_table : mapping of str to Part, or None
        The table of parts to look the mount's part up in, already made (a caller's own, read lazily);
        None: the presets with ``parts`` laid over them. Not part of the provenance.
    """

    mount: Path
    monte_carlo: int = 0
    seed: int = 0
    parts: Path | None = None
    parts_table: Mapping | None = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "mount", Path(self.mount))
        if self.parts is not None:
            object.__setattr__(self, "parts", Path(self.parts))
        if int(self.monte_carlo) != self.monte_carlo or self.monte_carlo < 0:
            from align.errors import InputError

            raise InputError(f"give a whole number >= 0, not {self.monte_carlo!r}", "{monte_carlo}")

    def table(self) -> Mapping | None:
        """The parts table the mount's part is looked up in (None: the built-in presets)."""
        if self.parts_table is not None:
            return self.parts_table
        return None if self.parts is None else PartsFileTable(self.parts)


@dataclass(frozen=True)
class BudgetInputs:
    """The checked inputs of the budget.

    Attributes
    ----------
    mount : Mount
        The mount, its part looked up.
    """

    mount: Mount


def read_mount(options: BudgetOptions, source: Callable[[Path], Path] = Path) -> Mount:
    """The mount of ``options``, its ``[imu] part`` looked up in :meth:`BudgetOptions.table`.

    Parameters
    ----------
    options : BudgetOptions
    source : callable, optional
        Maps the mount's path (as named in the result) to the file to read (a staged copy).

    Returns
    -------
    Mount
    """
    from align.io import read_toml
    from mechanics.mount import mount_from_dict

    path = options.mount
    table: Any = options.table()  # any mapping of name -> Part (a lazy one reads its file on first use)
    return mount_from_dict(read_toml(source(path)), str(path), path.parent, parts=table)


def read(options: BudgetOptions, source: Callable[[Path], Path] = Path) -> BudgetInputs:
    """Read and check the mount (:func:`read_mount`)."""
    return BudgetInputs(read_mount(options, source))


def compute(inputs: BudgetInputs, options: BudgetOptions, progress: Progress | None = None) -> Budget:
    """The budget of the mount: source formulas (Eq 1-4), per-axis RSS, 3-D worst case, and the Monte Carlo
    of ``options.monte_carlo`` draws (``progress`` called with the draws done)."""
    result = compute_budget(inputs.mount)
    if options.parts is not None:
        result = result.replace(inputs={**result.inputs, "parts": str(options.parts)})
    if options.monte_carlo:
        result = result.replace(monte_carlo=run_monte_carlo(inputs.mount, options.monte_carlo, options.seed,
                                                            progress=progress))
    return result


def files(options: BudgetOptions) -> dict[str, Path | None]:
    """The input files: the mount and the user's parts file."""
    return {"mount": options.mount, "parts": options.parts}


BUDGET: Job[BudgetOptions, BudgetInputs, Budget] = Job(
    "budget", BudgetOptions, read, compute, files,
    "mounting-misalignment budget: source formulas, worst case and Monte Carlo")


@fields_signature(BudgetOptions)
def budget(*, progress: Progress | None = None, **fields: Any) -> Budget:
    """The mounting-misalignment budget of a mount, as ``imu-align budget`` computes it.

    Parameters
    ----------
    progress : callable, optional
        Called with the Monte Carlo draws done.
    **fields
        The fields of :class:`BudgetOptions` (``mount`` as a str or Path, ``monte_carlo``, ``seed``,
        ``parts``, ``parts_table``).

    Returns
    -------
    Budget
        Angles in rad: ``tilt_x``, ``tilt_y``, ``skew_z``, ``total`` (Eq 1), ``per_axis`` (3,),
        ``worst_case_per_axis`` (3,), the ``monte_carlo`` (or None); with its provenance.

    Examples
    --------
    The reference's Example 1 (ADIS16485 on 6 mm ledges): Eq 4's skew and Eq 1's total.

    >>> from pathlib import Path
    >>> import mechanics
    >>> example = Path(mechanics.__file__).parents[1] / "examples" / "budget" / "example1.toml"
    >>> b = budget(mount=example)
    >>> round(b.skew_z * 57.29577951308232, 4), round(b.total * 57.29577951308232, 4)
    (0.8374, 1.3043)
    """
    return BUDGET.run(BudgetOptions(**fields), progress=progress)
