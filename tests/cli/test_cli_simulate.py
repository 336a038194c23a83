"""imu-align simulate: the sessions real benches produce (mounting, table axis, latitude, moves, head, flicker,
time units), their files and truth, and one clear line for every bad value."""

from __future__ import annotations

import json

import numpy as np
import pytest

from align.alignment.plan import Plan
from align.io import read_toml
from align.units import DEG

QUICK = ("--dwell", "1 s", "--gap", "0.5 s", "--rate-hz", "100")


def _csv(path):
    data = np.genfromtxt(path, delimiter=",", names=True)
    return data["time"], np.column_stack([data["gyro_x"], data["gyro_y"], data["gyro_z"]])


def _sim(run_cli, out, *args):
    res = run_cli("simulate", out, *QUICK, *args)
    assert res.code == 0, res.err
    return json.loads((out / "truth.json").read_text()), Plan.from_dict(read_toml(out / "plan.toml"))


def test_time_units_scale_the_time_column_only(tmp_path, run_cli):
    _sim(run_cli, tmp_path / "s", "--seed", "4")
    _sim(run_cli, tmp_path / "ms", "--seed", "4", "--time-units", "ms")
    _sim(run_cli, tmp_path / "ns", "--seed", "4", "--time-units", "ns")
    t, g = _csv(tmp_path / "s" / "session.csv")
    t_ms, g_ms = _csv(tmp_path / "ms" / "session.csv")
    t_ns, _ = _csv(tmp_path / "ns" / "session.csv")
    assert np.array_equal(g_ms, g)
    assert np.allclose(t_ms, 1000 * t, rtol=1e-12, atol=0) and t_ms[1] == 10.0  # 100 Hz: 10 ms
    assert np.allclose(t_ns, 1e9 * t, rtol=1e-12, atol=0) and t_ns[1] == 1e7
    assert (tmp_path / "ms" / "session.csv").read_text().startswith('"time",')  # the column keeps its name


def test_signed_permutation_mounting_is_left_for_detection_unless_declared(tmp_path, run_cli):
    truth, plan = _sim(run_cli, tmp_path / "a", "--mounting", "+y,-x,+z")
    n = np.array([[0, 1, 0], [-1, 0, 0], [0, 0, 1]], float)  # gyro x along +y, y along -x, z along +z
    assert plan.mounting is None and np.array_equal(truth["mounting"], n)
    m = np.array(truth["M"])
    assert np.abs(m @ n.T - np.eye(3)).max() < 0.03  # the small part, near identity
    _, declared = _sim(run_cli, tmp_path / "b", "--mounting", "+y -x +z", "--declare-mounting")
    assert np.array_equal(declared.nominal, n)
    assert 'axes = ["+y", "-x", "+z"]' in (tmp_path / "b" / "plan.toml").read_text()


@pytest.mark.parametrize("text, axis", [("30 deg about +z", (0, 0, 1)), ("30 deg about 1,1,0", (1, 1, 0))])
def test_an_arbitrary_rotation_is_declared_in_the_plan(tmp_path, run_cli, text, axis):
    from scipy.spatial.transform import Rotation

    truth, plan = _sim(run_cli, tmp_path, "--mounting", text, "--misalignment", "0 deg")
    # row i: gyro i's axis in the system frame, the IMU turned by 30 deg about the axis
    n = Rotation.from_rotvec(np.array(axis) / np.linalg.norm(axis) * 30 * DEG).as_matrix().T
    if axis == (0, 0, 1):  # the geometry module's example, by hand
        c, s = np.cos(30 * DEG), np.sin(30 * DEG)
        assert np.allclose(n, [[c, s, 0], [-s, c, 0], [0, 0, 1]], atol=1e-15)
    assert np.allclose(plan.nominal, n, atol=1e-12) and np.allclose(truth["mounting"], n, atol=1e-12)
    assert "matrix = " in (tmp_path / "plan.toml").read_text()
    m = np.array(truth["M"])
    assert np.abs(m @ n.T - np.eye(3)).max() < 0.02  # scale and non-orthogonality only


def test_geometry_latitude_and_moves_go_into_the_plan_and_the_truth(tmp_path, run_cli):
    truth, plan = _sim(run_cli, tmp_path / "a", "--table-axis", "east", "--latitude", "45 deg", "--reorient",
                       "--flicker", "0.005 deg/s")
    assert plan.table_axis == "east" and all(s.table_axis == "east" for s in plan.steps)
    assert plan.latitude == pytest.approx(45 * DEG)
    assert len(truth["moves"]) == 2 and truth["units"]["move_angle"] == "deg"
    assert [round(m["angle"], 9) for m in truth["moves"]] == [90.0, 90.0]
    plain, _ = _sim(run_cli, tmp_path / "b", "--kind", "angle")
    assert plain["moves"] == [] and plain["mounting"] is None


def test_head_zero_starts_the_first_step_at_the_first_row(tmp_path, run_cli):
    truth, _ = _sim(run_cli, tmp_path, "--head", "0 s", "--noise", "0 deg/sqrt(h)", "--seed", "2")
    t, g = _csv(tmp_path / "session.csv")
    w = (np.linalg.inv(np.array(truth["M"])) @ (g - np.array(truth["bias"])).T).T  # deg/s, system frame
    # +x at 100 deg/s on a vertical table: the ramp (0.5 s at 200 deg/s^2, 50 rows) holds (k + 1/2) / 50 of the
    # rate in row k, from the first row on
    assert w[0, 0] == pytest.approx(1.0, rel=1e-6) and w[25, 0] == pytest.approx(51.0, rel=1e-6)
    assert np.abs(w[:50, 1:]).max() < 1e-9
    _sim(run_cli, tmp_path / "d")
    default, _ = _csv(tmp_path / "d" / "session.csv")
    assert len(default) - len(t) == 50  # the 0.5 s head


@pytest.mark.parametrize("args, words", [
    (("--mounting", "+y,+x,+z"), ["--mounting", "mirrored"]),
    (("--mounting", "+x,+x,+z"), ["--mounting", "its own axis"]),
    (("--mounting", "30 deg about 0,0,0"), ["--mounting", "not all 0"]),
    (("--mounting", "30 m about +z"), ["--mounting", "not an angle"]),
    (("--table-axis", "sideways"), ["--table-axis", "north"]),
    (("--latitude", "100 deg"), ["--latitude", "90 deg"]),
    (("--time-units", "h"), ["--time-units", "ms"]),
    (("--flicker", "-1 deg/s"), ["--flicker", ">= 0"]),
    (("--head", "-1 s"), ["--head", ">= 0"]),
    (("--move-rate", "0 deg/s"), ["--move-rate", "> 0"]),
])
def test_bad_values_are_one_line_naming_the_option(tmp_path, run_cli, args, words):
    res = run_cli("simulate", tmp_path / "out", *args)
    assert res.code == 2 and res.err.strip().count("\n") == 0
    assert all(w in res.err for w in words), res.err
    assert not (tmp_path / "out").exists()


def test_options_that_contradict_the_plan_file_are_refused(tmp_path, run_cli):
    plan = tmp_path / "p.toml"
    plan.write_text('[mounting]\naxes = ["+y", "-x", "+z"]\n[test]\nlatitude = "45 deg"\n'
                    '[[step]]\naxis = "+z"\nrate = "10 deg/s"\n[[step]]\naxis = "+z"\nrate = "-10 deg/s"\n')
    for args, word in ((("--table-axis", "east"), "--table-axis"), (("--latitude", "40 deg"), "--latitude"),
                       (("--mounting", "+x,+y,+z"), "--mounting")):
        res = run_cli("simulate", tmp_path / "out", "--plan", plan, *args)
        assert res.code == 2 and word in res.err and res.err.strip().count("\n") == 0, res.err
    # the plan's own latitude and mounting are simulated, and stated again in the written plan
    truth, written = _sim(run_cli, tmp_path / "ok", "--plan", plan, "--latitude", "45 deg")
    assert written.latitude == pytest.approx(45 * DEG) and written.nominal is not None
    assert np.array_equal(truth["mounting"], written.nominal)
