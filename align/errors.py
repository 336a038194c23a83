"""User-facing errors.

Every problem a user can fix (a bad file, a bad field, a bad test) raises a
subclass of :class:`AlignError`. The library names the inputs it concerns in
its own terms (``gyro_units``, ``rate_hz``); the command line alone turns such
a name into its flag, the error into one line on stderr and an exit status.
The library never prints and never exits.

A message may name an input as a placeholder: ``{gyro_units}`` (the input) or
``{gyro_units=deg/s}`` (the input set to a value); ``where`` may be one
placeholder alone (``"{gyro_units}"``), otherwise it is taken as it is (a file
name may hold braces). ``str(error)`` renders placeholders in Python terms
(``gyro_units``, ``gyro_units='deg/s'``); :meth:`AlignError.render` takes the
caller's own spelling (the CLI's flags). User text put into a message goes
through :func:`literal`, so that its braces are never read as placeholders.

Public names
------------
AlignError, InputError, UnitError, TestError, HandednessError, CheckFailed, field_names, literal
"""

from __future__ import annotations

import re
from collections.abc import Callable

#: a placeholder for an input: ``{name}`` or ``{name=value}``
_PLACEHOLDER = re.compile(r"\{([a-z][a-z0-9_]*)(?:=([^{}]*))?\}")


def _python_spelling(name: str, value: str | None) -> str:
    return name if value is None else f"{name}={value!r}"


def literal(text: object) -> str:
    """``text`` for a message, its braces doubled so that no placeholder is read in it."""
    return str(text).replace("{", "{{").replace("}", "}}")


def _sub(text: str, spell: Callable[[str, str | None], str]) -> str:
    """Placeholders replaced by ``spell(name, value)``; doubled braces become single ones."""
    parts = re.split(r"(\{\{|\}\})", text)
    return "".join("{" if p == "{{" else "}" if p == "}}" else
                   _PLACEHOLDER.sub(lambda m: spell(m.group(1), m.group(2)), p) for p in parts)


def field_names(text: str) -> list[str]:
    """The input names used as placeholders in ``text`` (in order)."""
    return [m.group(1) for p in re.split(r"\{\{|\}\}", text) for m in _PLACEHOLDER.finditer(p)]


class AlignError(Exception):
    """Base class of every error a user can act on.

    Parameters
    ----------
    message : str
        One line: what is wrong and what to do. May hold ``{name}`` /
        ``{name=value}`` placeholders for inputs.
    where : str, optional
        The file, field, segment or input (a placeholder) concerned; prefixed
        to the message.
    """

    exit_code = 2

    def __init__(self, message: str, where: str | None = None) -> None:
        self.where = where
        self.message = message
        super().__init__(self.render())

    def _where_is_field(self) -> bool:
        return self.where is not None and _PLACEHOLDER.fullmatch(self.where) is not None

    @property
    def fields(self) -> list[str]:
        """Inputs named by the error (a placeholder ``where`` and the message's placeholders)."""
        named = field_names(self.where) if self.where is not None and self._where_is_field() else []
        return named + field_names(self.message)

    def render(self, spell: Callable[[str, str | None], str] = _python_spelling) -> str:
        """The error as one line, inputs spelled by ``spell(name, value_or_None)``."""
        text = _sub(self.message, spell)
        if not self.where:
            return text
        where = _sub(self.where, spell) if self._where_is_field() else self.where
        return f"{where}: {text}"


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


class CheckFailed(AlignError):
    """A result failed a stated requirement (a budget against its allowance)."""

    exit_code = 4
