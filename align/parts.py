"""Datasheet presets: one table of IMU figures shared by the budget and the Allan planner.

Every value is a unit string with its source; ``confirmed`` is False where the
figure was not read from the datasheet itself (a secondary source, a typical
value of the family, or a cross-axis sensitivity standing in for a missing
axis-to-package figure). Look a part up with :func:`get_part`.

Public names
------------
Part, PARTS, get_part
"""

from __future__ import annotations

from dataclasses import dataclass

from align.errors import InputError
from align.units import parse_quantity


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
        ``"module"`` (a packaged IMU with mounting holes) or ``"chip"``.
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
        for key in ("package_x", "package_y", "hole_spacing_x", "hole_spacing_y", "axis_to_package",
                    "axis_to_axis", "arw", "bias_instability", "noise_density"):
            fig = getattr(self, key)
            if fig is not None:
                out[key] = {"value": fig.value, "source": fig.source, "confirmed": fig.confirmed}
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


def get_part(name: str, where: str = "imu.part") -> Part:
    """Look up a preset by name (case-insensitive); an unknown name lists the known ones.

    Parameters
    ----------
    name : str
        Part number, e.g. ``"adis16485"``.
    where : str
        The file field or input the name came from, for the error message.

    Returns
    -------
    Part

    Raises
    ------
    InputError
        For a name that is not in :data:`PARTS`.
    """
    for key, part in PARTS.items():
        if key.lower() == str(name).strip().lower():
            return part
    raise InputError(f"unknown part '{name}'; known parts: {', '.join(PARTS)}", where)
