"""Datasheet presets: one table of IMU figures shared by the budget and the Allan planner.

Every value is a unit string with its source; ``confirmed`` is False where the
figure was not read from the datasheet itself (a secondary source, a typical
value of the family, or a cross-axis sensitivity standing in for a missing
axis-to-package figure). Look a part up with :func:`get_part`.

A user's own parts (parsed TOML, the same fields as the built-in table: one table
per part, each figure a quantity string or ``{value, source, confirmed}``) are read
with :func:`parts_from_dict` and laid over the built-in table with :func:`merge_parts`:
a new name adds a part, a preset's name replaces the figures it gives (the others stay).
Nothing here reads a file or the environment: the caller passes the parsed table.

Public names
------------
Figure, Part, PARTS, FIGURES, PART_KEYS, KINDS, get_part, find_part, parts_from_dict, merge_parts
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

from align.errors import InputError, literal
from align.units import parse_quantity

#: every figure a part may state -> its dimension (a key of :data:`align.units.DIMENSIONS`), in listing order
FIGURES: dict[str, str] = {
    "axis_to_package": "angle", "axis_to_axis": "angle", "arw": "angle_random_walk",
    "noise_density": "angle_random_walk", "bias_instability": "angular_rate",
    "package_x": "length", "package_y": "length", "hole_spacing_x": "length", "hole_spacing_y": "length",
}
#: the kinds of part
KINDS = ("module", "chip")
#: the keys of one part's table in a parts file
PART_KEYS = ("kind", *FIGURES)


@dataclass(frozen=True)
class Figure:
    """One datasheet figure: a quantity string, where it comes from, and whether it is confirmed.

    Attributes
    ----------
    value : str
        The quantity with its unit, e.g. ``"1 deg"`` or ``"0.3 deg/sqrt(h)"``.
    source : str
        Where the figure comes from.
    confirmed : bool
        True when read from the part's datasheet itself.
    """

    value: str
    source: str
    confirmed: bool


@dataclass(frozen=True)
class Part:
    """A datasheet preset. Figures absent from a datasheet are None.

    Attributes
    ----------
    name : str
        Part number, e.g. ``"ADIS16485"``.
    kind : str
        ``"module"`` (a packaged IMU with mounting holes) or ``"chip"``; empty when a parts file does not say.
    package_x, package_y : Figure or None
        Package length ``L`` and width ``W`` (Eq 2-3, Example 1), a length.
    hole_spacing_x, hole_spacing_y : Figure or None
        Distances between mounting holes along x and y (``R_S`` of Eq 4), a length.
    axis_to_package : Figure or None
        Axis-to-package (axis-to-frame) misalignment, ``theta_IMU`` of Eq 1, an angle.
    axis_to_axis : Figure or None
        Axis-to-axis misalignment (Eq 32-34), an angle.
    arw : Figure or None
        Angle random walk ``N`` (reference section 6), e.g. ``"0.3 deg/sqrt(h)"``.
    bias_instability : Figure or None
        Bias instability ``B`` (reference section 6), an angular rate.
    noise_density : Figure or None
        Rate noise density, e.g. ``"0.008 deg/s/sqrt(Hz)"`` (numerically ``N`` in deg/sqrt(s)).
    """

    name: str
    kind: str
    package_x: Figure | None = None
    package_y: Figure | None = None
    hole_spacing_x: Figure | None = None
    hole_spacing_y: Figure | None = None
    axis_to_package: Figure | None = None
    axis_to_axis: Figure | None = None
    arw: Figure | None = None
    bias_instability: Figure | None = None
    noise_density: Figure | None = None

    def si(self, name: str, expect: str) -> float | None:
        """A figure in SI units, or None when the part has no such figure.

        Parameters
        ----------
        name : str
            The figure's attribute, e.g. ``"axis_to_package"`` or ``"arw"``.
        expect : str
            Its dimension, a key of :data:`align.units.DIMENSIONS` (``"angle"``,
            ``"length"``, ``"angle_random_walk"``, ...).

        Returns
        -------
        float or None
            The value in SI units (m, rad, rad/sqrt(s), rad/s).
        """
        fig = getattr(self, name)
        return None if fig is None else parse_quantity(fig.value, expect, f"part {self.name}.{name}")

    def to_dict(self) -> dict:
        """The preset as plain data, for a result's ``inputs`` or a report.

        Returns
        -------
        dict
            ``name``, ``kind`` and, for each figure the part has, ``{"value", "source",
            "confirmed"}`` (the value keeps its unit string).
        """
        out = {"name": self.name, "kind": self.kind}
        out.update(self.provenance(name for name, _ in self.figures()))
        return out

    def figures(self) -> list[tuple[str, Figure]]:
        """The figures the part states, in the order of :data:`FIGURES`."""
        return [(name, getattr(self, name)) for name in FIGURES if getattr(self, name) is not None]

    def provenance(self, names) -> dict:
        """``{figure: {"value", "source", "confirmed"}}`` for the figures ``names`` the part states: what a
        result records of the preset values it used (absent figures are left out)."""
        out = {}
        for name in names:
            fig = getattr(self, name)
            if fig is not None:
                out[name] = {"value": fig.value, "source": fig.source, "confirmed": fig.confirmed}
        return out


_REF = "reference alignment-basics.md (ADI article, Example 1/3)"
_ADI_FRONT = "ADI datasheet, front-page features"
_NOT_DS = "typical value of the part family, not read from its datasheet"

PARTS: dict[str, Part] = {p.name: p for p in (
    Part("ADIS16485", "module",
         package_x=Figure("47 mm", _REF, True), package_y=Figure("44 mm", _REF, True),
         hole_spacing_x=Figure("42.6 mm", _REF, True), hole_spacing_y=Figure("39.6 mm", _REF, True),
         axis_to_package=Figure("1 deg", _REF, True),
         axis_to_axis=Figure("0.05 deg", "ADI datasheet (as recalled; tactical ADIS1648x family)", False),
         arw=Figure("0.3 deg/sqrt(h)", _REF + ", Example 3", True),
         bias_instability=Figure("6.25 deg/h", "ADI datasheet in-run bias stability (as recalled)", False)),
    Part("ADIS16495", "module",
         axis_to_package=Figure("0.25 deg", _ADI_FRONT + " (ADIS16495 Rev. C)", True),
         axis_to_axis=Figure("0.05 deg", _ADI_FRONT + " (ADIS16495 Rev. C)", True),
         arw=Figure("0.09 deg/sqrt(h)", _ADI_FRONT + " (ADIS16495-1)", True),
         bias_instability=Figure("0.8 deg/h", _ADI_FRONT + " (ADIS16495-1)", True)),
    Part("ADIS16470", "module",
         axis_to_package=Figure("1 deg", _NOT_DS, False),
         axis_to_axis=Figure("0.25 deg", _NOT_DS, False),
         arw=Figure("0.34 deg/sqrt(h)", "ADI datasheet specification table (as recalled)", False),
         noise_density=Figure("0.008 deg/s/sqrt(Hz)", _ADI_FRONT + " (ADIS16470 Rev. C)", True),
         bias_instability=Figure("8 deg/h", _ADI_FRONT + " (ADIS16470 Rev. C)", True)),
    Part("ADIS16465", "module",
         axis_to_package=Figure("1 deg", _NOT_DS, False),
         axis_to_axis=Figure("0.05 deg", _ADI_FRONT + " (ADIS16465)", True),
         arw=Figure("0.15 deg/sqrt(h)", _ADI_FRONT + " (ADIS16465-1/-2)", True),
         bias_instability=Figure("2 deg/h", _ADI_FRONT + " (ADIS16465-1)", True)),
    Part("ADIS16475", "module",
         axis_to_package=Figure("1 deg", _NOT_DS, False),
         axis_to_axis=Figure("0.1 deg", _ADI_FRONT + " (ADIS16475)", True),
         arw=Figure("0.15 deg/sqrt(h)", _ADI_FRONT + " (ADIS16475-1/-2)", True),
         bias_instability=Figure("2 deg/h", _ADI_FRONT + " (ADIS16475-1)", True)),
    Part("ADIS16405", "module",
         axis_to_package=Figure("1 deg", _NOT_DS, False),
         noise_density=Figure("0.05 deg/s/sqrt(Hz)", "ADIS16405 datasheet figure quoted on ADI EngineerZone (thread 13821)",
                              False),
         bias_instability=Figure("0.007 deg/s", "ADIS16405 datasheet figure quoted on ADI EngineerZone (thread 13821)", False)),
    Part("BMI088", "chip",
         axis_to_package=Figure("0.5 deg", "cross-axis sensitivity ~1 % used as proxy; " + _NOT_DS, False),
         axis_to_axis=Figure("0.5 deg", _NOT_DS, False),
         noise_density=Figure("0.014 deg/s/sqrt(Hz)", "Bosch BMI088 datasheet (as recalled)", False),
         bias_instability=Figure("2 deg/h", "Bosch product page (as recalled)", False)),
    Part("ICM-42688-P", "chip",
         axis_to_package=Figure("0.7 deg", "cross-axis sensitivity +/-1.25 % used as proxy; " + _NOT_DS, False),
         axis_to_axis=Figure("0.7 deg", _NOT_DS, False),
         noise_density=Figure("0.0028 deg/s/sqrt(Hz)", "TDK ICM-42688-P datasheet (as recalled)", False)),
    Part("MPU-6050", "chip",
         axis_to_package=Figure("1.15 deg", "cross-axis sensitivity +/-2 % used as proxy; " + _NOT_DS, False),
         axis_to_axis=Figure("1.15 deg", _NOT_DS, False),
         noise_density=Figure("0.005 deg/s/sqrt(Hz)", "InvenSense MPU-6000/6050 product specification (as recalled)", False)),
)}


def find_part(name: str, table: Mapping[str, Part] | None = None) -> Part | None:
    """The part named ``name`` (case-insensitive) in ``table`` (default :data:`PARTS`), or None."""
    wanted = str(name).strip().lower()
    for key, part in (PARTS if table is None else table).items():
        if key.lower() == wanted:
            return part
    return None


def get_part(name: str, where: str = "imu.part", table: Mapping[str, Part] | None = None) -> Part:
    """Look up a preset by name (case-insensitive); an unknown name lists the known ones.

    Parameters
    ----------
    name : str
        Part number, e.g. ``"adis16485"``.
    where : str
        The file field or input the name came from, for the error message.
    table : mapping of str to Part, optional
        The parts to look in (:func:`merge_parts` of a user's file); default :data:`PARTS`.

    Returns
    -------
    Part

    Raises
    ------
    InputError
        For a name that is not in the table (naming the nearest and the known parts, and the parts file
        that would add it, ``{parts}``).
    """
    table = PARTS if table is None else table
    part = find_part(name, table)
    if part is None:
        near = difflib.get_close_matches(str(name).upper(), [k.upper() for k in table], n=1, cutoff=0.6)
        hint = f"did you mean '{next(k for k in table if k.upper() == near[0])}'? " if near else ""
        raise InputError(f"unknown part '{literal(name)}' ({hint}known parts: {', '.join(table)}); add it to a "
                         "parts file ({parts})", where)
    return part


def _figure(raw, name: str, here: str, origin: str) -> Figure:
    """One figure of a parts file: ``"1 deg"`` or ``{value = "1 deg", source = "...", confirmed = true}``;
    ``here`` names the field, ``origin`` the file (recorded in the figure's source)."""
    if isinstance(raw, Mapping):
        unknown = [k for k in raw if k not in ("value", "source", "confirmed")]
        if unknown:
            raise InputError(f"unknown key '{literal(unknown[0])}' (known: value, source, confirmed)", here)
        if "value" not in raw:
            raise InputError(f"missing key 'value' (e.g. {name} = {{{{ value = \"{_EXAMPLE[FIGURES[name]]}\", "
                             "source = \"datasheet rev A\", confirmed = true }})", here)
        value, source, confirmed = raw["value"], raw.get("source"), raw.get("confirmed", False)
        if source is not None and not (isinstance(source, str) and source.strip()):
            raise InputError("source must be a non-empty string (where the figure comes from)", f"{here}.source")
        if not isinstance(confirmed, bool):
            raise InputError(f"confirmed must be true or false, not {literal(repr(confirmed))}", f"{here}.confirmed")
    else:
        value, source, confirmed = raw, None, False
    if not isinstance(value, str):
        raise InputError(f"give the value with its unit as a string, e.g. {name} = \"{_EXAMPLE[FIGURES[name]]}\" "
                         f"(got {literal(repr(value))})", here)
    si = parse_quantity(value, FIGURES[name], here)
    if not (math.isfinite(si) and si > 0):
        raise InputError(f"must be finite and > 0 (got '{literal(value)}')", here)
    return Figure(value.strip(), origin if source is None else f"{source.strip()} ({origin})", confirmed)


_EXAMPLE = {"angle": "1 deg", "angle_random_walk": "0.3 deg/sqrt(h)", "angular_rate": "6 deg/h", "length": "44 mm"}


def parts_from_dict(data: Mapping, where: str = "parts") -> dict[str, Part]:
    """A user's parts file (parsed TOML): one table per part, the fields of :class:`Part`.

    ``[MY-IMU]`` with ``kind = "module"`` (or ``"chip"``) and any figures of :data:`FIGURES`,
    each a quantity string (source: the file, not confirmed) or a table
    ``{value = "0.5 deg", source = "datasheet rev B, table 2", confirmed = true}``.
    Every value is checked for its dimension and for being finite and > 0.

    Parameters
    ----------
    data : mapping
        The parsed file.
    where : str
        The file's name, for messages and for the figures' source.

    Returns
    -------
    dict of str to Part
        The parts as the file gives them (a preset's name may give only some figures: see :func:`merge_parts`).

    Raises
    ------
    InputError
        A part that is not a table, an unknown key (with the nearest known one), a kind that is not
        :data:`KINDS`, a value without a unit, of the wrong dimension, zero or negative.
    """
    if not data:
        raise InputError("holds no part; give one table per part, e.g. [MY-IMU] with axis_to_package = \"0.5 deg\"",
                         where)
    out: dict[str, Part] = {}
    for name, t in data.items():
        here = f"{where}: [{name}]"
        if not isinstance(t, Mapping):
            raise InputError(f"'{literal(name)}' must be a table of figures ([{literal(name)}] with "
                             "axis_to_package = \"0.5 deg\", ...), not a single value", where)
        for key in t:
            if key not in PART_KEYS:
                near = difflib.get_close_matches(str(key), PART_KEYS, n=1, cutoff=0.6)
                hint = f"did you mean '{near[0]}'? " if near else ""
                raise InputError(f"unknown key '{literal(key)}' ({hint}known: {', '.join(PART_KEYS)})", here)
        kind = t.get("kind", "")
        if kind and kind not in KINDS:
            raise InputError(f"kind '{literal(kind)}' is not one of {', '.join(KINDS)}", f"{where}: {name}.kind")
        figs = {k: _figure(t[k], k, f"{where}: {name}.{k}", f"user parts file {where}") for k in FIGURES if k in t}
        if not figs:
            raise InputError(f"gives no figure; give at least one of {', '.join(FIGURES)}", here)
        out[str(name).strip()] = Part(str(name).strip(), kind, **figs)
    return out


def merge_parts(user: Mapping[str, Part], base: Mapping[str, Part] | None = None) -> dict[str, Part]:
    """``base`` (default :data:`PARTS`) extended and overridden by ``user``.

    A user part whose name is a preset's (case-insensitive) replaces the figures it gives and keeps the
    preset's others (and its name and, unless given, its kind); any other name is a new part.
    """
    table = dict(PARTS if base is None else base)
    for name, part in user.items():
        old = find_part(name, table)
        if old is None:
            table[name] = part
            continue
        figs: dict[str, Any] = dict(part.figures())  # figure fields by name: replace() checks the names
        table[old.name] = replace(old, kind=part.kind or old.kind, **figs)
    return table
