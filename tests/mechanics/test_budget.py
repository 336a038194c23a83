"""Mechanics, budget: per-axis terms, the position tolerance, the budget command and the result file."""

import json

import numpy as np
import pytest
from mounts import EXAMPLE1, example1

from align.errors import InputError
from align.io import read_toml
from align.results import load_result, save_result
from align.units import DEG
from align.values import approx_equal
from mechanics.budget import Budget, budget
from mechanics.formulas import rss, screw_radius
from mechanics.montecarlo import monte_carlo
from mechanics.mount import mount_from_dict


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


def test_elements_by_basis_and_an_unknown_basis_names_the_input():
    b = budget(example1())
    rss_el, worst_el = b.elements("rss"), b.elements("worst")
    # phi_yz: gyro y leaning toward z moves with the tilt about x, with the y gyro's datasheet term (Eq 1)
    assert rss_el["phi_yz"] == pytest.approx(rss(b.tilt_x, 1.0 * DEG))
    assert worst_el["phi_yz"] == pytest.approx(b.tilt_x + 1.0 * DEG)
    assert rss_el["psi_z"] == b.per_axis[2] and worst_el["psi_z"] == b.worst_case_per_axis[2]
    with pytest.raises(InputError) as bad:
        b.elements("mean")
    assert bad.value.fields == ["basis"] and "--" not in str(bad.value)


def test_budget_round_trips_through_a_file_with_its_monte_carlo(tmp_path):
    m = example1(screws__position_tolerance="0.05 mm")
    b = budget(m).replace(inputs={"mount": str(EXAMPLE1)})
    assert approx_equal(Budget.from_dict(b.to_dict()), b, rtol=1e-12)
    save_result(tmp_path / "b.json", b)
    back = load_result(tmp_path / "b.json")
    assert type(back) is Budget and approx_equal(back, b, rtol=1e-12) and back.monte_carlo is None
    full = b.replace(monte_carlo=monte_carlo(m, 20_000, seed=1))
    save_result(tmp_path / "mc.json", full)
    back = load_result(tmp_path / "mc.json", expect=(Budget,))
    assert approx_equal(back, full, rtol=1e-12)
    assert back.monte_carlo.hist_counts.dtype.kind == "i" and back.monte_carlo.n == 20_000
    assert back.elements("worst") == pytest.approx(full.elements("worst"), rel=1e-12)


@pytest.mark.slow
def test_budget_cli_writes_json_and_pictures(tmp_path, run_cli):
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
    assert type(load_result(out)) is Budget
