"""Mechanics, mount: refusals name the field; the mount's dictionary form."""

import numpy as np
import pytest
from mounts import example1

from align.errors import InputError
from align.values import approx_equal
from mechanics.mount import Mount, corner_ledges


@pytest.mark.parametrize("section,field,value,words", [
    ("screws", "hole_diameter", "1.5 mm", "screws.hole_diameter"),
    ("ledges", "height_tolerance", "-0.2 mm", "ledges.height_tolerance"),
    ("package", "size_x", None, "package.size_x"),
    ("screws", "diameter", "2 deg", "screws.diameter"),
])
def test_bad_mount_input_names_the_field(section, field, value, words):
    with pytest.raises(InputError, match=words.replace(".", r"\.")):
        example1(**{f"{section}__{field}": value})


def test_unknown_part_is_refused_without_its_values_and_a_label_with_them():
    with pytest.raises(InputError, match=r"imu\.part: unknown part 'XYZ123'.*as a label"):
        example1(imu__part="XYZ123", imu__axis_to_package=None)
    m = example1(imu__part="XYZ123")
    assert m.part == "XYZ123" and m.preset == {}


def test_mount_is_a_frozen_value_and_round_trips():
    m = example1(screws__position_tolerance="0.1 mm")
    assert not m.pads.flags.writeable and not m.axis_to_package.flags.writeable
    assert m.pads.shape == (4, 4, 2) and np.allclose(m.pads, corner_ledges(0.047, 0.044, 0.006))
    back = Mount.from_dict(m.to_dict())
    assert approx_equal(back, m, rtol=1e-12)
    old = m.to_dict()
    del old["pads_mm"], old["pad_heights_mm"]   # a file written before the pads were kept: corner ledges
    assert approx_equal(Mount.from_dict(old), m, rtol=1e-12)
    with pytest.raises(InputError, match="malformed mount"):
        Mount.from_dict({"part": None}, "b.json: mount")


@pytest.mark.parametrize("section,field,value,words", [
    ("screws", "position_tolerence", "0.05 mm",
     "example1.toml: [screws]: unknown key 'position_tolerence' (did you mean 'position_tolerance'? known: diameter, "
     "hole_diameter, spacing_x, spacing_y, position_tolerance)"),
    ("imu", "axis_to_pakage", "1 deg", "[imu]: unknown key 'axis_to_pakage' (did you mean 'axis_to_package'?"),
    ("imu", "distribuion", "normal", "[imu]: unknown key 'distribuion' (did you mean 'distribution'?"),
    ("package", "sizex", "3 mm", "[package]: unknown key 'sizex' (did you mean 'size_x'?"),
    ("ledges", "height_tol", "0.1 mm", "[ledges]: unknown key 'height_tol' (did you mean 'height_tolerance'?"),
    ("screws", "hole", "3 mm", "[screws]: unknown key 'hole'"),
    ("imu", "axis_to_package", {"x": "1 deg", "y": "1 deg", "z": "1 deg", "w": "1 deg"},
     "imu.axis_to_package: unknown key 'w' (known: x, y, z)"),
    ("imu", "axis_to_package", "90 deg", "imu.axis_to_package: 90 deg is not a misalignment bound"),
    ("imu", "axis_to_package", "-1 deg", "imu.axis_to_package: must not be negative"),
    ("package", "size_z", "0 mm", "package.size_z: must be positive"),
    ("screws", "position_tolerance", "-0.01 mm", "screws.position_tolerance: must be zero or more"),
    ("screws", "spacing_y", "45 mm", "screws.spacing_y: the screw pattern (45 mm) is larger than the package (44 mm)"),
    ("screws", "spacing_x", "1e400 mm", "screws.spacing_x"),
    ("ledges", "size", "0 mm", "ledges.size: must be positive"),
    ("ledges", "height_tolerance", "1e300 mm", "ledges.height_tolerance: 1e+300 mm is not a dimension of an IMU mount"),
    ("package", "size_x", "2 m", "package.size_x: 2000 mm is not a dimension of an IMU mount (at most 1000 mm)"),
    ("imu", "axis_to_package", "400 deg", "imu.axis_to_package: 400 deg is not a misalignment bound"),
])
def test_misspelled_or_out_of_domain_mount_key_is_refused_by_name(section, field, value, words):
    with pytest.raises(InputError) as err:
        example1(**{f"{section}__{field}": value})
    assert words in str(err.value) and "\n" not in str(err.value)


def _mount(edit) -> Mount:
    from mounts import EXAMPLE1

    from align.io import read_toml
    from mechanics.mount import mount_from_dict

    data = read_toml(EXAMPLE1)
    edit(data)
    return mount_from_dict(data, "m.toml")


@pytest.mark.parametrize("edit,words", [
    (lambda d: d.update(screw={"diameter": "2 mm"}), "m.toml: unknown key 'screw' (did you mean 'screws'? known: imu, "
                                                     "package, ledges, baseplate, screws, extra)"),
    (lambda d: d.update(extras={"tilt": "0.1 deg"}), "m.toml: unknown key 'extras' (did you mean 'extra'?"),
    (lambda d: d.update(extra={"tilt": "0.1 deg", "distributon": "normal"}),
     "m.toml: [extra]: unknown key 'distributon' (did you mean 'distribution'?"),
    (lambda d: d.update(extra={"tilt": "95 deg"}), "m.toml: extra.tilt: 95 deg is not a misalignment bound"),
    (lambda d: d.update(extra={"tilt": "-0.1 deg"}), "m.toml: extra.tilt: must not be negative"),
    (lambda d: d.update(extra=[{"tilt": "0.1 deg"}]), "m.toml: [extra] must be a table"),
    (lambda d: d.update(baseplate={"stl": "plate.stl"}), "m.toml: ledges.size: the [baseplate] STL gives the ledges"),
    (lambda d: (d.pop("ledges"), d.update(baseplate={"stl": 3})), "m.toml: baseplate.stl: expected a file name"),
    (lambda d: (d.pop("ledges"), d.update(baseplate={"stl": "p.stl", "ledge_bnd": "1 mm"})),
     "m.toml: [baseplate]: unknown key 'ledge_bnd' (did you mean 'ledge_band'?"),
    (lambda d: d.pop("screws"), "m.toml: missing table [screws]"),
])
def test_misspelled_mount_table_is_refused_by_name(edit, words):
    with pytest.raises(InputError) as err:
        _mount(edit)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_every_documented_mount_key_is_accepted():
    m = _mount(lambda d: (d["imu"].update(distribution="normal"), d["ledges"].update(distribution="normal"),
                          d["screws"].update(position_tolerance="0.05 mm"),
                          d.update(extra={"pcb_solder_tilt": "0.2 deg", "distribution": "normal"})))
    assert m.distributions == {"imu": "normal", "ledges": "normal", "extras": "normal"}
    assert m.position_tolerance == pytest.approx(0.05e-3) and set(m.extras) == {"pcb_solder_tilt"}
