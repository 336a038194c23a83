"""The mount description: IMU, package, ledges (or a baseplate STL), screws and extra terms.

A mount is read from TOML with unit strings (see README) into a frozen
:class:`Mount` in SI units. Geometry is in the package frame: origin at the
package centre, x along ``size_x``, y along ``size_y``, z up.

Public names
------------
Mount, mount_from_dict, mount_inputs, corner_ledges, DISTRIBUTIONS, MOUNT_KEYS
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from align.errors import InputError, literal
from align.io.keys import check_keys, file_name, referenced_file, table
from align.parts import Part, find_part, get_part
from align.units import DEG, parse_quantity
from align.values import Value
from mechanics.formulas import screw_radius

#: how a tolerance is drawn in the Monte Carlo (normal: the band or bound is +/- 3 sigma)
DISTRIBUTIONS = ("uniform", "normal")


@dataclass(frozen=True, eq=False)
class Mount(Value):
    """A mount in SI units (m, rad).

    Attributes
    ----------
    axis_to_package : ndarray, shape (3,)
        Datasheet axis-to-package misalignment bound of each gyro, rad.
    package : ndarray, shape (3,)
        Package size x, y, z, m.
    pads : ndarray, shape (P, V, 2)
        Outline vertices of each ledge top (package frame), m.
    pad_heights : ndarray, shape (P,)
        Nominal height of each ledge top, m.
    ledge_size : float
        ``W1`` of Eq 2-3 (square ledges), m.
    height_tolerance : float
        Total band of ledge heights, m.
    screw_diameter, hole_diameter, spacing_x, spacing_y : float
        m.
    position_tolerance : float
        Diameter of each screw's positional tolerance zone, m.
    extras : dict
        Further independent misalignment terms (name -> rad), e.g. PCB solder tilt.
    distributions : dict
        ``{"imu": ..., "ledges": ..., "extras": ...}``, each "uniform" or "normal"
        (normal: the band or bound is +/- 3 sigma).
    part : str or None
        The part the ``[imu]`` table names: a preset, or a label (a name that is not a preset, its
        values all given in the file).
    preset : dict
        The preset values the mount uses, ``{figure: {"value", "source", "confirmed"}}`` (empty for a label,
        for no part, or when the file gives every value itself).
    """

    axis_to_package: np.ndarray
    package: np.ndarray
    pads: np.ndarray
    pad_heights: np.ndarray
    ledge_size: float
    height_tolerance: float
    screw_diameter: float
    hole_diameter: float
    spacing_x: float
    spacing_y: float
    position_tolerance: float = 0.0
    extras: dict = field(default_factory=dict)
    distributions: dict = field(default_factory=lambda: {"imu": "uniform", "ledges": "uniform", "extras": "uniform"})
    part: str | None = None
    baseplate: str | None = None
    preset: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in ("axis_to_package", "package", "pad_heights"):
            object.__setattr__(self, name, np.asarray(getattr(self, name), dtype=float).reshape(-1))
        object.__setattr__(self, "pads", np.asarray(self.pads, dtype=float).reshape(len(self.pad_heights), -1, 2))
        super().__post_init__()

    @property
    def screws(self) -> np.ndarray:
        """Nominal screw centres, shape (4, 2), m."""
        sx, sy = self.spacing_x / 2, self.spacing_y / 2
        return np.array([[sx, sy], [-sx, sy], [-sx, -sy], [sx, -sy]])

    @property
    def clearance(self) -> float:
        """Radial clearance of a screw in its hole, m."""
        return (self.hole_diameter - self.screw_diameter) / 2.0

    def to_dict(self) -> dict:
        """The mount in file units (deg, mm): the ``mount`` of a budget result."""
        return {
            "part": self.part, "axis_to_package_deg": (self.axis_to_package / DEG).tolist(),
            "package_mm": (self.package * 1e3).tolist(), "ledge_size_mm": self.ledge_size * 1e3,
            "height_tolerance_mm": self.height_tolerance * 1e3, "screw_diameter_mm": self.screw_diameter * 1e3,
            "hole_diameter_mm": self.hole_diameter * 1e3, "spacing_mm": [self.spacing_x * 1e3, self.spacing_y * 1e3],
            "screw_radius_mm": screw_radius(self.spacing_x, self.spacing_y) * 1e3,
            "position_tolerance_mm": self.position_tolerance * 1e3,
            "extras_deg": {k: v / DEG for k, v in self.extras.items()}, "distributions": dict(self.distributions),
            "baseplate": self.baseplate, "preset": {k: dict(v) for k, v in self.preset.items()},
            "pads_mm": (self.pads * 1e3).tolist(), "pad_heights_mm": (self.pad_heights * 1e3).tolist(),
        }

    @classmethod
    def from_dict(cls, d: dict, where: str = "mount") -> Mount:
        """Read the form written by :meth:`to_dict` (a file without ``pads_mm`` has the corner ledges
        of ``ledge_size_mm``)."""
        try:
            package = np.array(d["package_mm"], float).reshape(3) * 1e-3
            size = float(d["ledge_size_mm"]) * 1e-3
            if "pads_mm" in d:
                pads, heights = np.array(d["pads_mm"], float) * 1e-3, np.array(d["pad_heights_mm"], float) * 1e-3
            else:
                pads, heights = corner_ledges(package[0], package[1], size), np.zeros(4)
            spacing = [float(v) * 1e-3 for v in d["spacing_mm"]]
            return cls(np.array(d["axis_to_package_deg"], float).reshape(3) * DEG, package, pads, heights, size,
                       float(d["height_tolerance_mm"]) * 1e-3, float(d["screw_diameter_mm"]) * 1e-3,
                       float(d["hole_diameter_mm"]) * 1e-3, spacing[0], spacing[1],
                       float(d.get("position_tolerance_mm", 0.0)) * 1e-3,
                       {k: float(v) * DEG for k, v in d.get("extras_deg", {}).items()},
                       dict(d["distributions"]), d.get("part"), d.get("baseplate"), dict(d.get("preset") or {}))
        except (KeyError, TypeError, ValueError, IndexError) as exc:
            raise InputError(f"malformed mount ({literal(repr(exc))})", where) from None


def corner_ledges(size_x: float, size_y: float, size: float) -> np.ndarray:
    """Outlines of four square ledges of side ``size`` in the corners of a ``size_x`` by ``size_y`` package.

    Returns
    -------
    ndarray, shape (4, 4, 2)
        Corner order (+x,+y), (-x,+y), (-x,-y), (+x,-y), as :data:`mechanics.rest.CORNERS`; m.
    """
    cx, cy, h = size_x / 2 - size / 2, size_y / 2 - size / 2, size / 2
    square = np.array([[-h, -h], [h, -h], [h, h], [-h, h]])
    centres = np.array([[cx, cy], [-cx, cy], [-cx, -cy], [cx, -cy]])
    return centres[:, None, :] + square[None, :, :]


#: the longest length a mount file may give, m: beyond, the number or its unit is wrong
MAX_LENGTH_M = 1.0


def _length(t: dict, key: str, section: str, where: str, default: str | None = None, positive: bool = True) -> float:
    """A length of ``[section]``: finite, at most :data:`MAX_LENGTH_M`; positive (a dimension) or, when not
    ``positive``, zero or more (a tolerance)."""
    if key not in t:
        if default is None:
            raise InputError(f"missing field (e.g. {key} = \"2 mm\")", f"{where}: {section}.{key}")
        value = parse_quantity(default, "length")
    else:
        value = parse_quantity(t[key], "length", f"{where}: {section}.{key}")
    if not np.isfinite(value) or value < 0 or (positive and value == 0):
        raise InputError(f"must be {'positive' if positive else 'zero or more'}, got {literal(repr(t.get(key)))}",
                         f"{where}: {section}.{key}")
    if value > MAX_LENGTH_M:
        raise InputError(f"{value * 1e3:.4g} mm is not a dimension of an IMU mount (at most {MAX_LENGTH_M * 1e3:g} mm); "
                         "check the number and its unit", f"{where}: {section}.{key}")
    return value


def _distribution(t: dict, section: str, where: str) -> str:
    d = t.get("distribution", "uniform")
    if d not in DISTRIBUTIONS:
        raise InputError(f"distribution '{literal(d)}' is not one of {', '.join(DISTRIBUTIONS)}",
                         f"{where}: {section}.distribution")
    return d


def _misalignment(value: np.ndarray, here: str) -> np.ndarray:
    """A misalignment bound (rad): finite, zero or more, under 90 deg."""
    if np.any(value < 0):
        raise InputError("must not be negative", here)
    if np.any(value >= np.pi / 2):
        raise InputError(f"{np.max(value) / DEG:g} deg is not a misalignment bound: it must be under 90 deg", here)
    return value


def _preset(imu: dict, where: str, parts: dict[str, Part] | None) -> tuple[Part | None, str | None]:
    """The preset ``[imu] part`` names (None for no part, or a label: a name that is not a preset, accepted
    when the file gives every value itself) and the name the mount records."""
    name = imu.get("part")
    if name is None:
        return None, None
    if not isinstance(name, str) or not name.strip():
        raise InputError(f"must be a part name (a string), not {literal(repr(name))}", f"{where}: imu.part")
    preset = find_part(name, parts)
    if preset is None and "axis_to_package" not in imu:
        try:
            get_part(name, f"{where}: imu.part", parts)
        except InputError as exc:  # naming the known parts and the parts file; or the label
            raise InputError(f"{exc.message}, or give axis_to_package in [imu] to use '{literal(name)}' as a label",
                             exc.where) from None
    return preset, (preset.name if preset else name.strip())


def _axis_to_package(imu: dict, where: str, parts: dict[str, Part] | None = None) -> tuple[np.ndarray, str | None, dict]:
    preset, part = _preset(imu, where, parts)
    raw = imu.get("axis_to_package")
    here = f"{where}: imu.axis_to_package"
    used = {}
    if raw is None:
        if preset is None or preset.axis_to_package is None:
            raise InputError("missing field (e.g. axis_to_package = \"1 deg\", or a part whose preset states it)", here)
        value = np.full(3, preset.si("axis_to_package", "angle"))
        used = preset.provenance(["axis_to_package"])
    elif isinstance(raw, dict):
        check_keys(raw, "xyz", here)
        missing = [a for a in "xyz" if a not in raw]
        if missing:
            raise InputError(f"per-axis table needs x, y and z (missing {', '.join(missing)})", here)
        value = np.array([parse_quantity(raw[a], "angle", f"{here}.{a}") for a in "xyz"])
    else:
        value = np.full(3, parse_quantity(raw, "angle", here))
    return _misalignment(value, here), part, used


def _extras(extras_t: dict, where: str) -> dict:
    """The ``[extra]`` terms (name -> rad); ``distribution`` is the one key that is not a term."""
    extras = {}
    for name, value in extras_t.items():
        if name == "distribution":
            continue
        if isinstance(value, str) and value.strip() in DISTRIBUTIONS:   # a misspelled 'distribution'
            check_keys({name: value}, ("distribution",), f"{where}: [extra]")
        here = f"{where}: extra.{name}"
        extras[name] = float(_misalignment(np.array([parse_quantity(value, "angle", here)]), here)[0])
    return extras


def _ledge_pads(ledges: dict, plate: dict, size_x: float, size_y: float, where: str, base_dir: Path | None):
    """Ledge outlines, heights, ledge size and the STL used: square corner ledges, or from ``[baseplate]``."""
    if not plate:
        size = _length(ledges, "size", "ledges", where)
        if 2 * size >= min(size_x, size_y):
            raise InputError("ledges overlap: size must be under half the package size", f"{where}: ledges.size")
        return corner_ledges(size_x, size_y, size), np.zeros(4), size, None
    from mechanics.rest import ledges_from_stl

    if "size" in ledges:
        raise InputError("the [baseplate] STL gives the ledges: drop size (keep height_tolerance) or [baseplate]",
                         f"{where}: ledges.size")
    stl = file_name(plate, "stl", f"{where}: baseplate.stl", "plate.stl", base_dir)
    band = _length(plate, "ledge_band", "baseplate", where, default="1 mm")
    pads, heights = ledges_from_stl(stl, band, f"{where}: baseplate.stl")
    return pads, heights, float(np.median([np.ptp(p[:, 0]) for p in pads])), str(stl)


def mount_inputs(data: dict, base_dir: Path | None = None) -> list[Path]:
    """The data files a mount file reads (its ``[baseplate]`` STL), resolved as the reader resolves them.

    For output checks before any work: an output must not overwrite one of these.
    Nothing is validated here (an unusable file is refused by :func:`mount_from_dict`).
    """
    return [p for p in [referenced_file(data, "baseplate", "stl", base_dir)] if p is not None]


#: the tables of a mount file and the keys of each (``[extra]`` holds free term names and ``distribution``)
MOUNT_KEYS = {
    "imu": ("part", "axis_to_package", "distribution"),
    "package": ("size_x", "size_y", "size_z"),
    "ledges": ("size", "height_tolerance", "distribution"),
    "baseplate": ("stl", "ledge_band"),
    "screws": ("diameter", "hole_diameter", "spacing_x", "spacing_y", "position_tolerance"),
    "extra": None,
}


def mount_from_dict(data: dict, where: str = "mount", base_dir: Path | None = None,
                    parts: dict[str, Part] | None = None) -> Mount:
    """Build a :class:`Mount` from parsed TOML; every problem names the field.

    Unknown tables and keys are refused (:data:`MOUNT_KEYS`); dimensions must be
    positive, tolerances zero or more, misalignment bounds under 90 deg, the hole
    larger than the screw and the screw pattern inside the package. ``[imu] part`` is looked up in
    ``parts`` (default the built-in presets, :data:`align.parts.PARTS`; a user's table from
    :func:`align.parts.merge_parts`); a name that is not a preset is kept as a label when the file gives
    ``axis_to_package`` itself. The preset values used are recorded in :attr:`Mount.preset`.
    """
    check_keys(data, MOUNT_KEYS, where)
    sections = {name: table(data, name, where, required=name in ("imu", "package", "screws")) for name in MOUNT_KEYS}
    for name, known in MOUNT_KEYS.items():
        if known is not None:
            check_keys(sections[name], known, f"{where}: [{name}]")
    imu, package, screws = sections["imu"], sections["package"], sections["screws"]
    axis_to_package, part, used = _axis_to_package(imu, where, parts)
    size_x = _length(package, "size_x", "package", where)
    size_y = _length(package, "size_y", "package", where)
    size_z = _length(package, "size_z", "package", where, default="10 mm")
    screw_d = _length(screws, "diameter", "screws", where)
    hole_d = _length(screws, "hole_diameter", "screws", where)
    if hole_d <= screw_d:
        raise InputError(f"hole ({hole_d * 1e3:g} mm) must be larger than the screw ({screw_d * 1e3:g} mm)",
                         f"{where}: screws.hole_diameter")
    spacing_x = _length(screws, "spacing_x", "screws", where)
    spacing_y = _length(screws, "spacing_y", "screws", where)
    pos_tol = _length(screws, "position_tolerance", "screws", where, default="0 mm", positive=False)
    for axis, spacing, size in (("x", spacing_x, size_x), ("y", spacing_y, size_y)):
        if spacing > size:
            raise InputError(f"the screw pattern ({spacing * 1e3:g} mm) is larger than the package "
                             f"({size * 1e3:g} mm)", f"{where}: screws.spacing_{axis}")

    ledges, plate = sections["ledges"], sections["baseplate"]
    if not ledges and not plate:
        raise InputError("give [ledges] (size, height_tolerance) or [baseplate] stl = \"FILE.stl\"", where)
    tol = _length(ledges, "height_tolerance", "ledges", where, default="0 mm", positive=False)
    pads, heights, size, baseplate = _ledge_pads(ledges, plate, size_x, size_y, where, base_dir)
    extras = _extras(sections["extra"], where)
    dists = {"imu": _distribution(imu, "imu", where), "ledges": _distribution(ledges, "ledges", where),
             "extras": _distribution(sections["extra"], "extra", where)}
    return Mount(axis_to_package, np.array([size_x, size_y, size_z]), pads, heights, size, tol, screw_d, hole_d,
                 spacing_x, spacing_y, pos_tol, extras, dists, part, baseplate, used)
