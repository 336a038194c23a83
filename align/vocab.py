"""The closed vocabularies every module shares: sensor kinds, verdicts, coded notes.

A word that takes one of a fixed set of values is a type here, not a string
written again in every module: code and tests compare members, and the text a
person reads is derived from them.

* :class:`Sensor`: gyroscope, accelerometer, magnetometer, each with the
  dimension of its readings, its SI unit, the unit its readings are shown in by
  default, its default column names and the old default names still accepted.
* :class:`Status`: the one verdict type (PASS / WARN / FAIL / NOT CHECKED /
  INFO) used by checks, margins, the report and the lot statistics.
* :class:`Note`: a result's note, a ``str`` that carries a stable ``code``
  beside its text, so that a reader (or a test) asks for the code, not the words.

Members are ``StrEnum``: a member equals its value (``Sensor.GYROSCOPE ==
"gyroscope"``), so files written before these types existed read back unchanged.

Public names
------------
Sensor, Status, Note, notes_with_code
"""

from __future__ import annotations

from collections.abc import Iterable
from enum import StrEnum

__all__ = ["Sensor", "Status", "Note", "notes_with_code"]

#: sensor -> (dimension, SI unit, unit shown by default, default columns, old default columns, short name)
_SENSORS: dict[str, tuple[str, str, str, tuple[str, str, str], tuple[tuple[str, str, str], ...], str]] = {
    "gyroscope": ("angular_rate", "rad/s", "deg/s", ("gyro_x", "gyro_y", "gyro_z"),
                  (("gyr_x", "gyr_y", "gyr_z"), ("gx", "gy", "gz")), "gyro"),
    "accelerometer": ("acceleration", "m/s^2", "m/s^2", ("acc_x", "acc_y", "acc_z"),
                      (("accel_x", "accel_y", "accel_z"), ("ax", "ay", "az")), "accel"),
    "magnetometer": ("magnetic_field", "T", "uT", ("mag_x", "mag_y", "mag_z"),
                     (("mx", "my", "mz"),), "mag"),
}


class Sensor(StrEnum):
    """A kind of inertial or magnetic sensor, and what goes with it.

    Examples
    --------
    >>> Sensor.GYROSCOPE.dimension, Sensor.GYROSCOPE.columns
    ('angular_rate', ('gyro_x', 'gyro_y', 'gyro_z'))
    >>> Sensor.parse("accel") is Sensor.ACCELEROMETER
    True
    """

    GYROSCOPE = "gyroscope"
    ACCELEROMETER = "accelerometer"
    MAGNETOMETER = "magnetometer"

    @property
    def dimension(self) -> str:
        """The dimension of the readings, a key of :data:`align.units.DIMENSIONS` (``"angular_rate"``)."""
        return _SENSORS[self.value][0]

    @property
    def si(self) -> str:
        """The SI unit the program holds the readings in (``"rad/s"``, ``"m/s^2"``, ``"T"``)."""
        return _SENSORS[self.value][1]

    @property
    def unit(self) -> str:
        """The unit readings are given and shown in by default (``"deg/s"``, ``"m/s^2"``, ``"uT"``)."""
        return _SENSORS[self.value][2]

    @property
    def columns(self) -> tuple[str, str, str]:
        """The default names of the x, y, z data columns (``gyro_x, gyro_y, gyro_z``)."""
        return _SENSORS[self.value][3]

    @property
    def old_columns(self) -> tuple[tuple[str, str, str], ...]:
        """Default names of earlier versions and common loggers, still accepted when the defaults are absent."""
        return _SENSORS[self.value][4]

    @property
    def short(self) -> str:
        """The short word of option names and column prefixes (``"gyro"``, ``"accel"``, ``"mag"``)."""
        return _SENSORS[self.value][5]

    @classmethod
    def parse(cls, text: str | Sensor) -> Sensor:
        """The sensor a word names: its value, its short word or the member's name (any case).

        Raises
        ------
        ValueError
            For a word that names no sensor.
        """
        if isinstance(text, Sensor):
            return text
        word = str(text).strip().lower()
        for s in cls:
            if word in (s.value, s.short, s.name.lower(), s.value[:3]):
                return s
        raise ValueError(f"{text!r} is not a sensor; give one of {', '.join(s.value for s in cls)}")


#: statuses from the best to the worst outcome (INFO judges nothing: it ranks below PASS)
_RANK = ("INFO", "PASS", "NOT CHECKED", "WARN", "NOT USABLE", "FAIL")


class Status(StrEnum):
    """The outcome of a check: the one verdict type of checks, margins, the report and the lot.

    ``PASS`` met its requirement; ``WARN`` within the guard band of a limit, or a caution that fails
    nothing; ``FAIL`` did not meet it; ``NOT_USABLE`` a figure the test did not determine well enough for
    its use (its 1-sigma above the limit's ``sigma_max``): it fails as FAIL does; ``NOT_CHECKED`` could not
    be judged (no data, no limit): never counted as a pass; ``INFO`` a figure shown without a requirement.

    Examples
    --------
    >>> Status.parse("warn") is Status.WARN
    True
    >>> Status.worst([Status.PASS, Status.NOT_CHECKED, Status.INFO]).value
    'NOT CHECKED'
    """

    PASS = "PASS"
    WARN = "WARN"
    FAIL = "FAIL"
    NOT_USABLE = "NOT USABLE"
    NOT_CHECKED = "NOT CHECKED"
    INFO = "INFO"

    @property
    def rank(self) -> int:
        """Position from the best (INFO, 0) to the worst (FAIL, 5)."""
        return _RANK.index(self.value)

    @property
    def judged(self) -> bool:
        """Whether a requirement was judged (PASS, WARN, NOT USABLE, FAIL), not NOT CHECKED or INFO."""
        return self in (Status.PASS, Status.WARN, Status.NOT_USABLE, Status.FAIL)

    @property
    def fails(self) -> bool:
        """Whether it fails what it judges (FAIL, NOT USABLE): a command exits 4."""
        return self in (Status.FAIL, Status.NOT_USABLE)

    @classmethod
    def parse(cls, text: str | Status) -> Status:
        """The status a word names, in any case, ``_`` or blank (``"not checked"``, ``"NOT_CHECKED"``).

        Raises
        ------
        ValueError
            For a word that is no status.
        """
        if isinstance(text, Status):
            return text
        word = str(text).strip().upper().replace("_", " ")
        try:
            return cls(word)
        except ValueError:
            raise ValueError(f"{text!r} is not a status; give one of {', '.join(s.value for s in cls)}") from None

    @classmethod
    def worst(cls, statuses: Iterable[str | Status]) -> Status:
        """The worst of ``statuses`` (INFO for none)."""
        return max((cls.parse(s) for s in statuses), key=lambda s: s.rank, default=cls.INFO)


class Note(str):
    """A result's note: its text, read by a person, and a stable ``code``, read by programs and tests.

    A ``Note`` is a ``str`` (its text), so every place that shows or writes notes keeps working; the
    code survives in memory and in the files that write ``note_codes`` beside ``notes``.

    Examples
    --------
    >>> n = Note("bias drift allowed for: 0.1 deg/h", code="bias-drift")
    >>> n.code, n == "bias drift allowed for: 0.1 deg/h"
    ('bias-drift', True)
    """

    code: str

    def __new__(cls, text: str, code: str = "") -> Note:
        note = super().__new__(cls, text)
        note.code = code
        return note

    def __reduce__(self):  # pickled across processes (the batch's workers) with its code
        return (Note, (str(self), self.code))


def notes_with_code(notes: Iterable[str], code: str) -> list[Note]:
    """The notes of ``notes`` that carry ``code`` (plain strings carry none)."""
    return [n for n in notes if isinstance(n, Note) and n.code == code]
