"""Mechanics, render: the histogram and the assembly as PNG and GLB."""

import math

import pytest
from mounts import example1

from mechanics.budget import budget
from mechanics.montecarlo import monte_carlo
from mechanics.render import assembly_glb, assembly_png, histogram_png, resting_pose

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.mark.slow
def test_pictures_of_example1():
    m = example1()
    b = budget(m)
    with pytest.raises(ValueError, match="no Monte Carlo"):
        histogram_png(b)
    assert histogram_png(b.replace(monte_carlo=monte_carlo(m, 5_000, seed=2)))[:8] == PNG
    assert assembly_png(m)[:8] == PNG
    import io

    import trimesh

    scene = trimesh.load(io.BytesIO(assembly_glb(m)), file_type="glb")
    assert len(scene.geometry) == 5  # four ledges and the package


def test_resting_pose_is_eq2_for_the_pictures_configuration():
    m = example1()
    heights = m.pad_heights + [m.height_tolerance, m.height_tolerance, 0.0, 0.0]   # +y ledges high
    a, b, _, skew = resting_pose(m, heights, 0.0)
    assert math.atan(b) == pytest.approx(budget(m).tilt_x, rel=1e-12)   # slope of the plane: tan of Eq 2's tilt
    assert a == pytest.approx(0.0, abs=1e-15) and skew == 0.0
