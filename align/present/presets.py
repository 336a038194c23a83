"""The datasheet presets as text: the ``parts`` listing, and the preset values a result used with their sources.

A preset value is shown everywhere with its source and whether it is confirmed (read from the part's own
datasheet); an unconfirmed value says so in capitals, so that nobody signs off a budget or a test plan on a
figure that was recalled or borrowed from the part family.

Public names
------------
parts_listing, part_text, preset_rows, preset_lines
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from align.parts import FIGURES, Part

#: what each figure is, for the listing
_MEANING = {
    "axis_to_package": "axis-to-package misalignment (theta_IMU of Eq 1; budget)",
    "axis_to_axis": "axis-to-axis misalignment (Eq 32-34)",
    "arw": "angle random walk N (plan)",
    "noise_density": "rate noise density (plan, when no arw)",
    "bias_instability": "bias instability B (plan)",
    "package_x": "package length L (Eq 3; for reference: the mount file gives the one used)",
    "package_y": "package width W (Eq 2; for reference: the mount file gives the one used)",
    "hole_spacing_x": "hole spacing along x (R_S of Eq 4; for reference: the mount file gives the one used)",
    "hole_spacing_y": "hole spacing along y (R_S of Eq 4; for reference: the mount file gives the one used)",
}


def _flag(confirmed: bool) -> str:
    return "confirmed" if confirmed else "NOT confirmed"


def _split(value: str) -> tuple[str, str]:
    number, _, unit = value.strip().partition(" ")
    return number, unit.strip()


def part_text(part: Part, full: bool = False) -> str:
    """One part: each figure's value, unit, confirmed flag and source (``full``: with what each figure is for)."""
    lines = [f"{part.name} ({part.kind or 'kind not given'})"]
    for name, fig in part.figures():
        number, unit = _split(fig.value)
        lines.append(f"  {name:<17} {number:>8} {unit:<18} {_flag(fig.confirmed):<14} {fig.source}")
        if full:
            lines.append(f"  {'':<17} for: {_MEANING[name]}")
    if full:
        missing = [n for n in FIGURES if getattr(part, n) is None]
        if missing:
            lines.append("  not stated: " + ", ".join(missing))
    return "\n".join(lines)


def parts_listing(table: Mapping[str, Part], user_file: str | None = None) -> str:
    """The listing ``imu-align parts`` prints: every part of ``table`` with every figure's source and flag.

    Parameters
    ----------
    table : mapping of str to Part
        The built-in presets, with a user's parts laid over them (:func:`align.parts.merge_parts`).
    user_file : str, optional
        The user's parts file, named in the header.
    """
    confirmed = sum(f.confirmed for p in table.values() for _, f in p.figures())
    total = sum(len(p.figures()) for p in table.values())
    head = [f"Datasheet presets: {len(table)} parts, {total} figures, {confirmed} confirmed "
            "(confirmed = read from the part's own datasheet)",
            f"user parts file: {user_file or 'none'}", "",
            f"  {'figure':<17} {'value':>8} {'unit':<18} {'flag':<14} source"]
    return "\n".join(head + ["\n" + part_text(p) for p in table.values()])


def _get(obj: Any, name: str, default: Any = None) -> Any:
    return obj.get(name, default) if isinstance(obj, Mapping) else getattr(obj, name, default)


def preset_rows(result: Any) -> list[dict]:
    """The preset values a budget or a plan used, for a table: one dict per value.

    Parameters
    ----------
    result : Budget, PlanResult, or the dict of either (``to_dict()``)
        A budget records its preset values in ``mount.preset``, a plan in ``inputs["preset"]``.

    Returns
    -------
    list of dict
        ``{"part", "figure", "value", "source", "confirmed"}`` per value (empty when no preset value was used).
    """
    mount = _get(result, "mount")
    if mount is not None:
        part, figures = _get(mount, "part"), _get(mount, "preset") or {}
    else:
        inputs = _get(result, "inputs") or {}
        part, figures = inputs.get("imu"), inputs.get("preset") or {}
    return [{"part": part, "figure": k, "value": v["value"], "source": v["source"], "confirmed": bool(v["confirmed"])}
            for k, v in figures.items()]


def preset_lines(result: Any, indent: str = "  ") -> list[str]:
    """The preset values a budget or a plan used, one line each with its source and flag (see :func:`preset_rows`);
    a named part whose values all came from elsewhere says so. Empty when no part is named."""
    rows = preset_rows(result)
    mount = _get(result, "mount")
    part = _get(mount, "part") if mount is not None else (_get(result, "inputs") or {}).get("imu")
    if not rows:
        return [] if not part else [f"{indent}part {part}: no preset value used (every value given with the input)"]
    return [f"{indent}preset {r['part']}: {r['figure']} {r['value']} ({_flag(r['confirmed'])}; source: {r['source']})"
            for r in rows]
