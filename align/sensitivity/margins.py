"""The budget against the allowance: element by element, pass or fail (``imu-align.check``).

:func:`check_margins` sets a predicted misalignment budget (per element of
``M``, Eq 5-10) against what a manoeuvre allows (:class:`~align.sensitivity.allowable.Allowable`);
:class:`MarginTable` is the result, registered with :mod:`align.results`.

Public names
------------
Margin, margins, MarginTable, check_margins
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

from align import CONVENTION
from align.errors import InputError
from align.results import Result
from align.sensitivity.allowable import Allowable, deg_for_file, rad_from_file
from align.sensitivity.symbolic import ELEMENTS
from align.units import DEG
from align.values import Value


@dataclass(frozen=True, eq=False)
class Margin(Value):
    """One element of the budget-versus-allowance check.

    Attributes
    ----------
    element : str
        One of :data:`~align.sensitivity.symbolic.ELEMENTS`.
    predicted, allowed : float
        The budget's figure for the element and its allowance (``inf``: unconstrained), rad.
    """

    element: str
    predicted: float
    allowed: float

    @property
    def margin(self) -> float:
        """``allowed - predicted``, rad."""
        return self.allowed - self.predicted

    @property
    def ok(self) -> bool:
        """The prediction is within the allowance (``predicted <= allowed``)."""
        return self.predicted <= self.allowed


def margins(predicted: dict, allow: Allowable) -> list[Margin]:
    """Element by element: the predicted misalignment against the allowable one (ValueError when one is missing).

    Parameters
    ----------
    predicted : dict
        Element -> predicted size (a budget's figure, Eq 1 per element), rad.
    allow : Allowable
        The allowance per element, rad.

    Returns
    -------
    list of Margin
        In :data:`~align.sensitivity.symbolic.ELEMENTS` order.
    """
    missing = [e for e in ELEMENTS if e not in predicted]
    if missing:
        raise ValueError(f"no prediction for {missing}")
    return [Margin(e, float(predicted[e]), float(allow.allowable[e])) for e in ELEMENTS]


class MarginTable(Result, format="imu-align.check", convention=CONVENTION):
    """The budget against the allowance, element by element (iterates over its rows).

    Attributes
    ----------
    basis : str
        Which budget figure was compared ("rss" or "worst").
    rows : tuple of Margin
        One per element, in :data:`~align.sensitivity.symbolic.ELEMENTS` order.
    inputs : dict
        Where the inputs came from (set with ``replace(inputs=...)``).
    """

    basis: str
    rows: tuple[Margin, ...]
    inputs: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "rows", tuple(self.rows))
        super().__post_init__()

    def __iter__(self) -> Iterator[Margin]:
        return iter(self.rows)

    def __len__(self) -> int:
        return len(self.rows)

    @property
    def passed(self) -> bool:
        """Every element within its allowance."""
        return all(r.ok for r in self.rows)

    @property
    def failed(self) -> list[str]:
        """The elements over their allowance."""
        return [r.element for r in self.rows if not r.ok]

    def to_dict(self) -> dict:
        """The versioned JSON form, angles in deg (``None`` for unconstrained).

        Returns
        -------
        dict
            The envelope, ``basis``, ``pass``, ``elements`` (each with its ``*_deg`` figures and ``pass``), ``inputs``.
        """
        return {
            **self.envelope({"angles": "deg"}),
            "basis": self.basis, "pass": self.passed,
            "elements": [{"element": r.element, "predicted_deg": r.predicted / DEG, "allowed_deg": deg_for_file(r.allowed),
                          "margin_deg": deg_for_file(r.margin), "pass": r.ok} for r in self.rows],
            "inputs": dict(self.inputs),
        }

    @classmethod
    def from_dict(cls, d: dict, where: str = "result") -> MarginTable:
        """The table a check file holds (parameters as :meth:`align.results.Result.from_dict`)."""
        cls.check_envelope(d, where)
        try:
            rows = tuple(Margin(str(r["element"]), rad_from_file(r["predicted_deg"]), rad_from_file(r["allowed_deg"]))
                         for r in d["elements"])
            return cls(str(d["basis"]), rows, dict(d.get("inputs", {})))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"malformed check result ({exc!r}); regenerate it with imu-align check", where) from None


def check_margins(budget_elements: dict, allow: Allowable, basis: str) -> MarginTable:
    """The predicted budget against the allowance, element by element.

    Parameters
    ----------
    budget_elements : dict
        Element -> predicted size, rad (``mechanics.budget.Budget.elements(basis)``).
    allow : Allowable
        The allowance per element, rad.
    basis : str
        The budget figure the prediction is ("rss" or "worst"), recorded in the table.

    Returns
    -------
    MarginTable
        One row per element; ``passed`` when every prediction is within its allowance.

    Examples
    --------
    Example 2's allowance (``phi_yz`` <= 1.9102 deg) against a budget of 0.5 deg per element, then 2 deg on ``phi_yz``:

    >>> from align.sensitivity.allowable import allowable
    >>> from align.sensitivity.manoeuvre import Manoeuvre
    >>> from align.units import DEG
    >>> man = Manoeuvre([[0, 0, 30 * DEG]], {"y": 1 * DEG, "z": 1 * DEG}, fixed_axis=True,
    ...                 segments=[("z", 30 * DEG)])
    >>> allow = allowable(man, directions=50)
    >>> check_margins(dict.fromkeys(allow.allowable, 0.5 * DEG), allow, "rss").passed
    True
    >>> table = check_margins({**dict.fromkeys(allow.allowable, 0.5 * DEG), "phi_yz": 2 * DEG}, allow, "rss")
    >>> table.passed, [m.element for m in table.rows if m.predicted > m.allowed]
    (False, ['phi_yz'])
    """
    return MarginTable(basis, tuple(margins(budget_elements, allow)))
