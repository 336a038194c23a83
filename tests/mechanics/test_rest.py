"""Mechanics, rest model: Eq 2-3 on two levels, the closed form against the hull and an LP, a baseplate STL."""

import numpy as np
import pytest
from mounts import EXAMPLE1
from scipy.optimize import linprog

from align.io import read_toml
from mechanics.formulas import tilt_from_ledges
from mechanics.mount import mount_from_dict
from mechanics.rest import corner_geometry, plane_tilt, rest_plane_hull, rest_planes


def _corner_pads(L=0.047, W=0.044, s=0.006):
    cx, cy, h = L / 2 - s / 2, W / 2 - s / 2, s / 2
    sq = np.array([[-h, -h], [h, -h], [h, h], [-h, h]])
    return np.array([[cx, cy], [-cx, cy], [-cx, -cy], [cx, -cy]])[:, None, :] + sq[None]


def test_rest_model_reproduces_eq2_and_eq3_on_two_levels():
    pads = _corner_pads()
    geo = corner_geometry(pads)
    H = 0.2e-3
    for heights, want_x, want_y in (([H, H, 0, 0], tilt_from_ledges(H, 0.044, 0.006), 0.0),
                                    ([0, H, H, 0], 0.0, tilt_from_ledges(H, 0.047, 0.006))):
        for a, b, _ in (rest_planes(geo, np.array([heights])), rest_plane_hull(pads, np.array(heights))):
            tx, ty = plane_tilt(np.atleast_1d(a), np.atleast_1d(b))
            assert tx[0] == pytest.approx(want_x, abs=1e-12)
            assert ty[0] == pytest.approx(want_y, abs=1e-12)


@pytest.mark.parametrize("size", [(0.047, 0.044, 0.006), (0.04, 0.04, 0.005), (0.03, 0.05, 0.008)])
@pytest.mark.slow
def test_closed_form_rest_equals_hull_and_linear_programme(size):
    pads = _corner_pads(*size)
    geo = corner_geometry(pads)
    rng = np.random.default_rng(2)
    heights = rng.uniform(0, 0.3e-3, (150, 4))
    a, b, c = rest_planes(geo, heights, rng)
    pts = pads.reshape(-1, 2)
    for i in range(len(heights)):
        z = np.repeat(heights[i], 4)
        # every ledge vertex on or below the plane, and the centre as low as the hull / LP says
        assert np.max(z - (a[i] * pts[:, 0] + b[i] * pts[:, 1] + c[i])) <= 1e-15
        assert c[i] == pytest.approx(rest_plane_hull(pads, heights[i])[2], abs=1e-15)
    lp = linprog([0, 0, 1], A_ub=-np.column_stack([pts, np.ones(16)]), b_ub=-np.repeat(heights[0], 4),
                 bounds=[(None, None)] * 3)
    assert c[0] == pytest.approx(lp.x[2], abs=1e-9)


def test_baseplate_stl(tmp_path):
    """Ledge tops found in an STL as upward facets; the rest plane matches the table form."""
    import trimesh

    pads = _corner_pads()
    heights = [0.2e-3, 0.2e-3, 0.0, 0.0]
    parts = [trimesh.creation.box(extents=[0.06, 0.06, 0.002])]
    parts[0].apply_translation([0, 0, -0.001 - 0.004])
    for pad, h in zip(pads, heights):
        lo, hi = pad.min(axis=0), pad.max(axis=0)
        box = trimesh.creation.box(extents=[hi[0] - lo[0], hi[1] - lo[1], 0.004 + h])
        box.apply_translation([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (h - 0.004) / 2])
        parts.append(box)
    mesh = trimesh.util.concatenate(parts)
    mesh.apply_scale(1000.0)  # millimetres, as CAD exports
    stl = tmp_path / "plate.stl"
    mesh.export(stl)
    data = read_toml(EXAMPLE1)
    del data["ledges"]
    data["baseplate"] = {"stl": "plate.stl"}
    m = mount_from_dict(data, "mount", tmp_path)
    assert len(m.pads) == 4
    a, b, _ = rest_plane_hull(m.pads, m.pad_heights)
    assert np.degrees(np.arctan(b)) == pytest.approx(0.30155, abs=5e-5)
