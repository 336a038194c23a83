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
    ("imu", "part", "XYZ123", "imu.part"),
])
def test_bad_mount_input_names_the_field(section, field, value, words):
    with pytest.raises(InputError, match=words.replace(".", r"\.")):
        example1(**{f"{section}__{field}": value})


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
