"""Mounting budget: the reference's Example 1, the rest model, worst case and Monte Carlo."""

from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import linprog

from align.errors import InputError
from align.io import read_toml
from align.units import DEG
from mechanics.budget import budget, monte_carlo
from mechanics.formulas import rss, screw_radius, skew_from_screws, tilt_from_ledges
from mechanics.mount import mount_from_dict
from mechanics.rest import corner_geometry, plane_tilt, rest_plane_hull, rest_planes

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE1 = ROOT / "examples" / "budget" / "example1.toml"


def example1(**changes):
    data = read_toml(EXAMPLE1)
    for key, value in changes.items():
        section, field = key.split("__")
        if value is None:
            data[section].pop(field, None)
        else:
            data[section][field] = value
    return mount_from_dict(data, "example1.toml")


def test_example1_source_numbers():
    # reference section 2, Example 1 (recomputed values; the source prints 1.28 for the total)
    assert np.degrees(tilt_from_ledges(0.2e-3, 44e-3, 6e-3)) == pytest.approx(0.30155, abs=5e-6)
    assert np.degrees(tilt_from_ledges(0.2e-3, 47e-3, 6e-3)) == pytest.approx(0.27949, abs=5e-6)
    assert screw_radius(39.6e-3, 42.6e-3) * 1e3 == pytest.approx(29.0814, abs=5e-5)
    assert np.degrees(skew_from_screws(2.85e-3, 2e-3, screw_radius(39.6e-3, 42.6e-3))) == pytest.approx(0.83736, abs=5e-6)
    d = budget(example1()).to_dict()
    assert d["tilt_x_deg"] == pytest.approx(0.30155, abs=5e-6)
    assert d["tilt_y_deg"] == pytest.approx(0.27949, abs=5e-6)
    assert d["skew_z_deg"] == pytest.approx(0.83736, abs=5e-6)
    assert d["mounting_deg"] == pytest.approx(0.83736, abs=5e-6)
    assert d["total_deg"] == pytest.approx(1.3043, abs=5e-5)
    assert d["total_deg"] != pytest.approx(1.28, abs=0.01)  # the source's printed value does not follow
    assert rss(1.0, 0.83) == pytest.approx(1.2996, abs=1e-4)


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


def test_worst_case_bounds_monte_carlo_and_is_approached():
    m = example1()
    b = budget(m)
    mc = monte_carlo(m, 200_000, seed=3)
    assert np.all(mc.maximum[:3] <= b.worst_case_per_axis * (1 + 1e-9))
    assert np.all(mc.maximum[:3] >= 0.85 * b.worst_case_per_axis)
    # each mechanical term alone reaches its own extreme
    ledges = monte_carlo(m, 200_000, seed=4, include=("ledges",))
    # the z axis is moved by the tilts only; its worst is Eq 2's two-level case
    assert 0.9 * b.tilt_x <= ledges.maximum[2] <= b.tilt_x * (1 + 1e-9)
    assert b.worst_case_per_axis[2] == pytest.approx(b.tilt_x + m.axis_to_package[2])
    screws = monte_carlo(m, 200_000, seed=5, include=("screws",))
    assert screws.maximum[0] <= b.skew_z * (1 + 1e-9)
    assert screws.maximum[0] >= 0.9 * b.skew_z
    assert screws.maximum[2] == pytest.approx(0.0, abs=1e-12)   # skew about z leaves the z axis alone


def test_monte_carlo_mean_squares_add_where_rss_is_valid():
    # independent, zero-mean, small terms: the mean square of the whole equals the sum of the parts
    m = example1()
    whole = monte_carlo(m, 300_000, seed=6)
    parts = [monte_carlo(m, 300_000, seed=7 + k, include=(name,)) for k, name in enumerate(("ledges", "screws", "imu"))]
    predicted = np.sqrt(sum(p.rms[:3] ** 2 for p in parts))
    assert np.allclose(whole.rms[:3], predicted, rtol=0.01)
    # and the x axis does not feel the tilt about x
    ledges = parts[0]
    assert ledges.rms[0] == pytest.approx(ledges.tilt_rms[1], rel=0.01)


def test_monte_carlo_reproducible_and_independent_of_threads():
    m = example1()
    one = monte_carlo(m, 50_000, seed=9, chunk=10_000, workers=1)
    two = monte_carlo(m, 50_000, seed=9, chunk=10_000, workers=2)
    assert np.array_equal(one.maximum, two.maximum)
    assert np.array_equal(one.hist_counts, two.hist_counts)


def test_position_tolerance_widens_the_skew():
    wide = budget(example1(screws__position_tolerance="0.1 mm"))
    assert wide.skew_worst == pytest.approx(np.arcsin((0.425e-3 + 0.05e-3) / screw_radius(42.6e-3, 39.6e-3)))
    assert wide.skew_z == pytest.approx(0.83736 * DEG, abs=1e-7)  # the source's Eq 4 ignores it


def test_per_axis_terms_and_extras():
    m = example1(imu__axis_to_package={"x": "1 deg", "y": "0.5 deg", "z": "0.2 deg"})
    b = budget(m)
    assert b.per_axis[2] == pytest.approx(rss(b.tilt_x, b.tilt_y, 0.2 * DEG))
    assert b.per_axis[0] == pytest.approx(rss(b.tilt_y, b.skew_z, 1.0 * DEG))
    data = read_toml(EXAMPLE1)
    data["extra"] = {"pcb_solder_tilt": "0.3 deg"}
    b2 = budget(mount_from_dict(data))
    assert b2.total == pytest.approx(rss(1.0 * DEG, b2.mounting, 0.3 * DEG))


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


def test_budget_cli_writes_json_and_pictures(tmp_path, run_cli):
    import json

    out, png, pic, glb = tmp_path / "b.json", tmp_path / "h.png", tmp_path / "a.png", tmp_path / "a.glb"
    res = run_cli("budget", EXAMPLE1, "--monte-carlo", "20000", "--seed", "1", "--json", out, "--plot", png,
                  "--picture", pic, "--glb", glb)
    assert res.code == 0, res.err
    d = json.loads(out.read_text())
    for key in ("tilt_x_deg", "tilt_y_deg", "skew_z_deg", "mounting_deg", "total_deg", "worst_case_deg",
                "per_axis_deg", "monte_carlo"):
        assert key in d
    assert set(d["monte_carlo"]["percentiles_deg"]) == {"50", "95", "99.73"}
    for path in (png, pic):
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    import trimesh

    scene = trimesh.load(glb)
    assert len(scene.geometry) == 5  # four ledges and the package
    bad = tmp_path / "bad.toml"
    bad.write_text(EXAMPLE1.read_text().replace('hole_diameter = "2.85 mm"', 'hole_diameter = "1.9 mm"'))
    res = run_cli("budget", bad, "--json", tmp_path / "never.json")
    assert res.code == 2 and "screws.hole_diameter" in res.err and "Traceback" not in res.err
    assert not (tmp_path / "never.json").exists()


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


def test_rotation_composition_matches_scipy():
    from scipy.spatial.transform import Rotation

    from mechanics.budget import _rotate_axes

    rng = np.random.default_rng(0)
    n = 50
    a, b, skew = rng.normal(0, 0.02, n), rng.normal(0, 0.02, n), rng.normal(0, 0.02, n)
    axes = np.eye(3)[None] + rng.normal(0, 0.02, (n, 3, 3))
    got = _rotate_axes(a, b, skew, axes)
    for i in range(n):
        normal = np.array([-a[i], -b[i], 1.0]) / np.sqrt(1 + a[i] ** 2 + b[i] ** 2)
        k = np.cross([0, 0, 1.0], normal)
        tilt = Rotation.from_rotvec(k / np.linalg.norm(k) * np.arctan2(np.linalg.norm(k), normal[2]))
        u = (tilt * Rotation.from_rotvec([0, 0, skew[i]])).apply(axes[i] / np.linalg.norm(axes[i], axis=1, keepdims=True))
        assert np.allclose(np.arccos(np.clip(np.diag(u), -1, 1)), got[i], atol=1e-9)
