"""Every TOML and JSON input refuses a key it does not know, naming it (a typo must never be ignored).

One misspelt key per table of every input file: the plan ([test], [[step]], [mounting]), the mount
file (every table, the per-axis axis_to_package, a misspelt [extra] distribution), the manoeuvre
([[rotation]], [limits], [series]), the accelerometer positions, the Ferraris sections, the explicit
segments and a result file.
"""

from __future__ import annotations

import copy
import json
import tomllib

import pytest
from support import ROOT

from align.errors import InputError

EXAMPLE1 = tomllib.loads((ROOT / "examples" / "budget" / "example1.toml").read_text())
PLAN = {"test": {"latitude": "45 deg"}, "mounting": {"axes": ["+x", "+y", "+z"]},
        "step": [{"axis": s + a, "rate": r} for a in "xyz" for s, r in (("+", "100 deg/s"), ("+", "-100 deg/s"))]}
MANOEUVRE = {"rotation": [{"axis": "z", "angle": "30 deg"}], "limits": {"y": "1 deg", "z": "1 deg"}}
POSITIONS = {"gravity": "9.81 m/s^2", "position": [{"up": u} for u in ("+x", "-x", "+y", "-y", "+z", "-z")]}


def _with(data: dict, path: tuple, key: str) -> dict:
    """``data`` with ``key`` added to the table at ``path`` (a list index picks an array element)."""
    out = copy.deepcopy(data)
    node = out
    for p in path:
        node = node[p]
    node[key] = "1 deg"
    return out


def _refused(call, key: str) -> str:
    with pytest.raises(InputError) as err:
        call()
    msg = str(err.value)
    assert f"'{key}'" in msg and "\n" not in msg, msg
    return msg


@pytest.mark.parametrize("path, key", [((), "tset"), (("test",), "latitud"), (("step", 2), "rat"),
                                       (("mounting",), "axis")])
def test_plan(path, key):
    from align.alignment.plan import Plan

    Plan.from_dict(PLAN, "plan.toml")
    _refused(lambda: Plan.from_dict(_with(PLAN, path, key), "plan.toml"), key)


@pytest.mark.parametrize("path, key", [((), "imuu"), (("imu",), "axis_to_packge"), (("package",), "size_zz"),
                                       (("ledges",), "heigth_tolerance"), (("screws",), "position_tolerence")])
def test_mount(path, key):
    from mechanics import mount_from_dict

    mount_from_dict(EXAMPLE1, "mount.toml")
    msg = _refused(lambda: mount_from_dict(_with(EXAMPLE1, path, key), "mount.toml"), key)
    assert "mount.toml" in msg


def test_mount_per_axis_bound_baseplate_and_extra_distribution():
    from mechanics import mount_from_dict

    per_axis = copy.deepcopy(EXAMPLE1)
    per_axis["imu"]["axis_to_package"] = {"x": "1 deg", "y": "1 deg", "z": "1 deg", "w": "1 deg"}
    _refused(lambda: mount_from_dict(per_axis, "mount.toml"), "w")
    plate = copy.deepcopy(EXAMPLE1)
    plate["baseplate"] = {"stl": "plate.stl", "ledge_bnd": "1 mm"}
    _refused(lambda: mount_from_dict(plate, "mount.toml"), "ledge_bnd")
    extra = copy.deepcopy(EXAMPLE1)
    extra["extra"] = {"pcb_tilt": "0.2 deg", "distributon": "normal"}
    _refused(lambda: mount_from_dict(extra, "mount.toml"), "distributon")


@pytest.mark.parametrize("data, key", [
    ({**MANOEUVRE, "limts": {}}, "limts"),
    ({**MANOEUVRE, "rotation": [{"axis": "z", "angel": "30 deg"}]}, "angel"),
    ({**MANOEUVRE, "limits": {"y": "1 deg", "elevaton": "1 deg"}}, "elevaton"),
    ({"series": {"file": "rates.csv", "unit": "rad/s"}, "limits": {"y": "1 deg"}}, "unit"),
])
def test_manoeuvre(tmp_path, data, key):
    from align.sensitivity import manoeuvre_from_dict

    (tmp_path / "rates.csv").write_text("time,wx,wy,wz\n" + "".join(f"{k / 100},0,0,1\n" for k in range(50)))
    _refused(lambda: manoeuvre_from_dict(data, "manoeuvre.toml", tmp_path), key)


@pytest.mark.parametrize("data, key", [({**POSITIONS, "gravty": "9.81 m/s^2"}, "gravty"),
                                       (_with(POSITIONS, ("position", 3), "hold_out"), "hold_out")])
def test_accelerometer_positions(data, key):
    from align.calibration.positions import parse_positions, positions_of

    _refused(lambda: parse_positions(positions_of(data, "positions.toml"), "positions.toml"), key)


def test_ferraris_sections_and_explicit_segments():
    from align.alignment.plan import Plan
    from align.alignment.segment import segments_from_ranges
    from align.calibration import sections_from_dict

    good = {n: {"start": 10 * k, "end": 10 * k + 5} for k, n in enumerate(
        ("x_p", "x_a", "y_p", "y_a", "z_p", "z_a", "x_rot", "y_rot", "z_rot"))}
    sections_from_dict(good, "sections.json")
    _refused(lambda: sections_from_dict({**good, "x_rott": {"start": 0, "end": 1}}, "sections.json"), "x_rott")
    _refused(lambda: sections_from_dict({**good, "x_p": {"start": 0, "ends": 5}}, "sections.json"), "ends")
    plan = Plan.from_dict({"step": PLAN["step"]}, "plan.toml")
    ranges = {f"step{k}": {"start": 100 * k, "end": 100 * k + 50} for k in range(6)}
    segments_from_ranges(ranges, plan, 1000, "segments.json")
    ranges["step0"] = {"start": 0, "strat": 3, "end": 50}
    _refused(lambda: segments_from_ranges(ranges, plan, 1000, "segments.json"), "strat")


def test_a_result_file(tmp_path):
    from align.results import load_result
    from mechanics import budget, mount_from_dict

    run = tmp_path / "budget.json"
    d = budget(mount_from_dict(EXAMPLE1, "mount.toml")).to_dict()
    d["totl_deg"] = 1.0
    run.write_text(json.dumps(d))
    _refused(lambda: load_result(run), "totl_deg")
