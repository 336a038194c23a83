"""User-facing errors.

Every problem a user can fix (a bad file, a bad field, a bad test) raises a
subclass of :class:`AlignError`. The command line turns it into one line on
stderr and a non-zero exit status; the library never prints and never exits.
"""

from __future__ import annotations


class AlignError(Exception):
    """Base class of every error a user can act on.

    Parameters
    ----------
    message : str
        One line: what is wrong and what to do.
    where : str, optional
        The file, field or segment concerned; prefixed to the message.
    """

    exit_code = 2

    def __init__(self, message: str, where: str | None = None) -> None:
        self.where = where
        self.message = message
        super().__init__(f"{where}: {message}" if where else message)


class InputError(AlignError):
    """A file, field or option is missing, malformed or inconsistent."""


class UnitError(InputError):
    """A unit string cannot be parsed or has the wrong dimension."""


class TestError(AlignError):
    """The recorded test does not support a trustworthy result (wrong direction,
    too short, saturated, not spanning 3-D, ...)."""

    __test__ = False  # not a pytest test class
    exit_code = 3


class HandednessError(TestError):
    """``det(M) <= 0``: an axis is wired or mounted backwards."""
