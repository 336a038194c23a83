"""Value parsers of the command line's options: each checks its value's domain where it is parsed.

A parser raises ``ValueError`` with what to type (``give a time > 0, e.g. '10 s'``); typer turns
it into a usage error naming the option (exit status 2). :mod:`align.cli.options` builds the
typed options from these and re-exports them. Nothing here imports numpy or the library's heavy
modules (the library's unit and format parsers are imported when a value is parsed).

Public names
------------
Domain, ANY, POSITIVE, NONNEGATIVE, NONZERO, ACCURACY, DURATION, PAUSE, TOLERANCE, DIP, MAX_RATE_HZ
(the domains of values); hertz, quantity, checked_text, number, whole, delimiter, comment, time_units, topic, rate_list,
stamps (values at the edge)
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

# ---- value parsers (a ValueError becomes a usage error naming the option) ----
#
# Every parser checks its value's domain where it is parsed: finite always, and the domain the
# option states (``> 0``, ``>= 0``, a range). A refusal says what to type: ``give a time > 0, e.g. '10 s'``.

_DEG = math.pi / 180.0
#: the highest sample rate accepted, Hz (a MEMS IMU samples at kHz at most)
MAX_RATE_HZ = 1e7


@dataclass(frozen=True)
class Domain:
    """Where a number may lie: above ``low`` (``open_low``: strictly), up to ``high``, or anywhere but 0.

    ``text`` is how the domain reads in a refusal (``"> 0"``, ``"within -90 deg and 90 deg"``).
    """

    text: str
    low: float | None = None
    high: float | None = None
    open_low: bool = True
    nonzero: bool = False

    def holds(self, x: float) -> bool:
        """``x`` is finite and inside the domain."""
        if not math.isfinite(x) or (self.nonzero and x == 0):
            return False
        if self.low is not None and (x <= self.low if self.open_low else x < self.low):
            return False
        return self.high is None or x <= self.high


#: any finite number
ANY = Domain("")
#: > 0
POSITIVE = Domain("> 0", low=0.0)
#: >= 0
NONNEGATIVE = Domain(">= 0", low=0.0, open_low=False)
#: any finite number but 0
NONZERO = Domain("other than 0", nonzero=True)
#: an alignment goal: (0, 90] deg
ACCURACY = Domain("> 0 and <= 90 deg", low=0.0, high=90 * _DEG)
#: a duration > 0 of at most a day (a moving window, a dwell, a static interval), s
DURATION = Domain("> 0 and <= 86400 s (a day)", low=0.0, high=86400.0)
#: a duration >= 0 of at most a day (a margin, a gap, a settling time), s
PAUSE = Domain(">= 0 and <= 86400 s (a day)", low=0.0, high=86400.0, open_low=False)
#: a relative tolerance: (0, 100 %]
TOLERANCE = Domain("> 0 and <= 100 %", low=0.0, high=1.0)
#: a magnetic dip: [-90, 90] deg
DIP = Domain("within -90 deg and 90 deg", low=-90 * _DEG, high=90 * _DEG, open_low=False)


def _give(what: str, domain: Domain, example: str) -> str:
    """``give a time > 0, e.g. '10 s'``."""
    return f"give {what}{' ' + domain.text if domain.text else ''}, e.g. {example}"


def hertz(text: str | float) -> float:
    """A sample rate: a bare number of Hz (``100``) or a frequency (``'100 Hz'``, ``'2 kHz'``), in Hz,
    above 0 and at most :data:`MAX_RATE_HZ`."""
    advice = "give a sample rate > 0 Hz and <= 1e7 Hz, e.g. 100 or '100 Hz'"
    if isinstance(text, (int, float)):
        value = float(text)
    else:
        try:
            value = float(text)
        except ValueError:
            from align.errors import AlignError
            from align.units import parse_quantity

            try:
                value = parse_quantity(text, "frequency")
            except AlignError:
                raise ValueError(advice) from None
    if not (math.isfinite(value) and 0 < value <= MAX_RATE_HZ):
        raise ValueError(advice)
    return value


def _si(text: str | float, expect: str, domain: Domain, example: str | None) -> float:
    """``text`` (``'<number> <unit>'`` of dimension ``expect``) in SI, checked against ``domain``."""
    from align.errors import AlignError
    from align.units import DIMENSIONS, parse_quantity

    what, _, default_example = DIMENSIONS[expect][1].partition(", e.g. ")
    if isinstance(text, (int, float)):
        value = float(text)
    else:
        try:
            value = parse_quantity(text, expect)
        except AlignError as exc:
            raise ValueError(exc.render()) from None
    if not domain.holds(value):
        raise ValueError(_give(what, domain, example or default_example))
    return value


def quantity(expect: str, domain: Domain = ANY, example: str | None = None) -> Callable[[str], float]:
    """A parser of ``'<number> <unit>'`` of dimension ``expect`` (a key of ``align.units.DIMENSIONS``), to SI,
    refusing a value outside ``domain`` (the refusal shows ``example``, by default the dimension's own)."""

    def parse(text: str | float) -> float:
        return _si(text, expect, domain, example)

    parse.__name__ = expect
    return parse


def checked_text(expect: str, domain: Domain = ANY, example: str | None = None) -> Callable[[str], str]:
    """Like :func:`quantity`, but the command receives the text itself (stripped), once checked
    (for options the command shows as typed, e.g. a plan's noise source)."""

    def parse(text: str) -> str:
        _si(text, expect, domain, example)
        return str(text).strip()

    parse.__name__ = expect
    return parse


def number(domain: Domain = ANY, example: str = "10") -> Callable[[str], float]:
    """A parser of a plain finite number in ``domain``."""

    def parse(text: str | float) -> float:
        try:
            value = float(text)
        except (TypeError, ValueError):
            raise ValueError(_give("a number", domain, example)) from None
        if not domain.holds(value):
            raise ValueError(_give("a number", domain, example))
        return value

    parse.__name__ = "number"
    return parse


def whole(low: int = 0, high: int | None = None, example: str = "100000") -> Callable[[str], int]:
    """A parser of a whole number ``low <= n <= high`` (``'1e5'`` is read as 100000)."""
    shown = f">= {low}" + (f" and <= {high}" if high is not None else "")

    def parse(text: str | int) -> int:
        advice = f"give a whole number {shown}, e.g. {example}"
        if isinstance(text, int):
            value = text
        else:
            try:
                value = int(str(text).strip())
            except ValueError:
                try:
                    f = float(text)
                except ValueError:
                    f = math.nan
                if not (math.isfinite(f) and f.is_integer()):
                    raise ValueError(advice) from None
                value = int(f)
        if value < low or (high is not None and value > high):
            raise ValueError(advice)
        return value

    parse.__name__ = "whole"
    return parse


# ---- a logger file's format (align.io.formats.LogFormat) ----

def delimiter(text: str) -> str:
    """A field separator: one character (``,``, ``;``, ``|``) or ``tab`` (also ``\\t``) or ``space``."""
    from align.errors import AlignError
    from align.io.formats import delimiter_char

    try:
        return delimiter_char(text)
    except AlignError:
        raise ValueError("give one character such as ',' or ';', or tab or space") from None


def comment(text: str) -> str:
    """A comment character: one character that is not part of a number, a letter or a blank (``#``, ``%``)."""
    from align.errors import AlignError
    from align.io.formats import LogFormat

    try:
        LogFormat(comment=text)
    except AlignError:
        raise ValueError("give one character that starts a comment, e.g. '#' or '%'") from None
    return text


def time_units(text: str) -> str:
    """The unit of a time column: ``s``, ``ms``, ``us`` (or ``µs``) or ``ns``."""
    text = str(text).strip().replace("µ", "u")
    if text not in ("s", "ms", "us", "ns"):
        raise ValueError("give s, ms, us or ns (leave it out to detect it from the sample interval)")
    return text


def topic(text: str) -> str:
    """The stream of a log of several (a ROS topic ``/imu0``, a ULog ``sensor_gyro:1``, a DataFlash ``IMU:1``),
    stripped; blank text is refused."""
    text = str(text).strip()
    if not text:
        raise ValueError("give the stream's name, e.g. /imu0, sensor_gyro:1 or IMU:1")
    return text


def stamps(text: str) -> str:
    """Which time stamps a stream's samples carry: ``header`` (the sensor's) or ``record`` (the recorder's)."""
    text = str(text).strip().lower()
    if text not in ("header", "record"):
        raise ValueError("give header (the sensor's time stamps) or record (when the recorder wrote them)")
    return text


def rate_list(text: str) -> list[float]:
    """``'10,30,100 deg/s'`` (``--rates``) -> rad/s, two or more different positive rates."""
    from align.errors import InputError
    from align.units import parse_quantity

    *numbers, unit = text.replace(",", " ").split() or [""]
    if not numbers or unit.replace(".", "", 1).lstrip("+-").isdigit():
        raise InputError(f"'{text}': give rates with their unit, e.g. '10,30,100,300 deg/s'", "{rates}")
    out = [parse_quantity(f"{n} {unit}", "angular_rate", "{rates}") for n in numbers]
    if any(r <= 0 for r in out) or len(set(out)) < 2:
        raise InputError(f"'{text}': give two or more different positive rates", "{rates}")
    return out
