"""Issue 27: units grouped by thermal profile. Simulated lots whose units come from k known bias-versus-temperature
profiles (a cubic per axis; each unit scattered about its profile and given its own turn-on bias): the grouping
finds k and puts every unit with the others of its profile; each group's curve is its profile's."""

from __future__ import annotations

import numpy as np
import pytest

from align.calibration.thermal.model import AxisModel, ThermalModel
from align.errors import InputError
from align.production.thermal_groups import group_thermal, thermal_models

TREF, LOW, HIGH = 25.0, -20.0, 70.0
#: profiles: per axis (c1, c2, c3) of bias(T) = c0 + c1 d + c2 d^2 + c3 d^3, d = T - 25 C, rad/s per C^k
PROFILES = np.array([
    [[2e-5, 0.0, 0.0], [1e-5, 1e-7, 0.0], [-1e-5, 0.0, 0.0]],
    [[-2e-5, 3e-7, 0.0], [1e-5, -1e-7, 0.0], [0.0, 0.0, 2e-9]],
    [[0.0, -3e-7, 0.0], [-2e-5, 0.0, 0.0], [1e-5, 2e-7, 0.0]],
    [[2e-5, 0.0, -2e-9], [0.0, 2e-7, 0.0], [-1e-5, -2e-7, 0.0]],
])
#: a unit's scatter about its profile (1-sigma of c1, c2, c3) and of its turn-on bias c0 (much larger than the shapes)
SCATTER, TURN_ON = np.array([1.5e-6, 2e-8, 1.5e-10]), 5e-3


def _lot(k: int, per: int, seed: int):
    rng = np.random.default_rng(seed)
    models, truth = {}, {}
    sizes = [per + j for j in range(k)]  # groups of different sizes
    for j in range(k):
        for u in range(sizes[j]):
            axes = tuple(AxisModel(np.r_[rng.normal(0, TURN_ON), PROFILES[j, a] + rng.normal(0, SCATTER)], None,
                                   np.zeros((4, 4))) for a in range(3))
            serial = f"P{j}U{u:02d}"
            models[serial] = ThermalModel("gyroscope", TREF, LOW + rng.uniform(0, 5), HIGH - rng.uniform(0, 5), axes)
            truth[serial] = j
    keys = list(models)
    order = rng.permutation(len(keys))  # the lot's order mixes the profiles
    return {keys[i]: models[keys[i]] for i in order}, truth


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_the_grouping_finds_the_profiles_and_their_members(k):
    for seed in range(3):
        models, truth = _lot(k, 7, 100 * k + seed)
        g = group_thermal(models, seed=seed)
        assert g.count == k, (k, seed, g.bic)
        found = sorted(sorted(grp.members) for grp in g.groups)
        expected = sorted(sorted(s for s in truth if truth[s] == j) for j in range(k))
        assert found == expected
        # each group's curve: its profile's shape (levels removed) within the scatter of a mean of its members
        grid = g.grid
        d = grid - TREF
        for grp in g.groups:
            j = truth[grp.members[0]]
            true = np.column_stack([np.polynomial.polynomial.polyval(d, np.r_[0.0, PROFILES[j, a]]) for a in range(3)])
            shape = grp.bias(grid) - grp.bias(grid).mean(0)
            true -= true.mean(0)
            sigma = np.max(np.abs(np.polynomial.polynomial.polyval(np.abs(d), np.r_[0.0, SCATTER])))
            assert np.max(np.abs(shape - true)) < 5 * sigma / np.sqrt(len(grp.members)) + 1e-12
            assert np.allclose(grp.bias(grid), grp.curve, atol=1e-9)  # the polynomial reproduces the mean curve
        assert np.isclose(grid[0], max(m.tmin for m in models.values()))  # only where every model holds
        assert np.isclose(grid[-1], min(m.tmax for m in models.values()))


def test_ranges_that_do_not_overlap_and_mixed_sensors_are_refused():
    ax = AxisModel(np.array([0.0, 1e-5]), None, np.zeros((2, 2)))
    cold = ThermalModel("gyroscope", 0.0, -40.0, 0.0, (ax, ax, ax))
    hot = ThermalModel("gyroscope", 50.0, 10.0, 80.0, (ax, ax, ax))
    with pytest.raises(InputError, match="no temperature in common"):
        group_thermal({"a": cold, "b": hot})
    with pytest.raises(InputError, match="several sensors"):
        group_thermal({"a": cold, "b": ThermalModel("accelerometer", 0.0, -40.0, 0.0, (ax, ax, ax))})


@pytest.fixture(scope="module")
def fitted():
    """One thermal calibration fitted to a simulated chamber run (about a second: made once)."""
    from align.calibration.thermal.result import ThermalCalibration
    from align.calibration.thermal.sensor import Settings, fit_sensor
    from align.calibration.thermal.simulate import Profile, random_truth, simulate

    prof = Profile(-10.0, 50.0, 5 / 60, 5 / 60, 0.0, 1.0)
    rng = np.random.default_rng(1)
    run = simulate(prof, random_truth(rng, prof, 0.01), 2.0, 0.002, rng)
    return ThermalCalibration({"accelerometer": fit_sensor(run.t, run.temperature, run.data, "accelerometer", "m/s^2",
                                                           2.0, Settings(), "sim")})


def test_the_models_are_read_from_the_results_the_table_names(tmp_path, fitted):
    from align.results import save_result

    fit = fitted.sensors["accelerometer"]
    (tmp_path / "units").mkdir()
    save_result(tmp_path / "units" / "SN1.json", fitted)
    (tmp_path / "units" / "SN2.json").write_text("{}")  # not a result: left out
    rows = [{"serial": "SN1", "status": "ok", "result": "units/SN1.json"},
            {"serial": "SN2", "status": "ok", "result": "units/SN2.json"},
            {"serial": "SN3", "status": "error", "result": ""}]
    got = thermal_models(rows, tmp_path, "accelerometer")
    assert list(got) == ["SN1"]
    assert np.allclose(got["SN1"].axes[0].coefficients, fit.model.axes[0].coefficients)
    assert thermal_models(rows, tmp_path, "gyroscope") == {}


def test_lot_groups_the_units_whose_thermal_results_the_table_names(tmp_path, fitted):
    """``imu-align lot`` on a table whose units ran ``calibrate thermal``: two profiles of 4 and 5 units (one fitted
    calibration file, its curve changed per profile by a known slope and curvature, each unit scattered) come out as
    two groups with their members, in the terminal and in ``--json``."""
    import json
    from datetime import UTC, datetime, timedelta

    from _lots import cli

    from align.production import append_rows

    rng = np.random.default_rng(1)
    base = fitted.to_dict()
    units = tmp_path / "out" / "units"
    units.mkdir(parents=True)
    rows, truth = [], {}
    t0 = datetime(2026, 11, 4, 9, 0, tzinfo=UTC)
    for k in range(9):
        j = k % 2  # profiles alternate in the lot's order
        doc = json.loads(json.dumps(base))
        for ax in doc["accelerometer"]["axes"]:
            c = ax["coefficients"]
            c[0] += rng.normal(0, 0.01)  # the unit's own level
            c[1] += (4e-4 if j else -4e-4) + rng.normal(0, 2e-5)
            c[2] += (-2e-5 if j else 1e-5) + rng.normal(0, 5e-7)
        serial = f"SN{k:02d}"
        (units / f"{serial}.json").write_text(json.dumps(doc))
        truth[serial] = j
        rows.append({"serial": serial, "order": k, "run": "r1", "time": t0 + timedelta(minutes=k),
                     "job": "calibrate thermal", "sensor": "accelerometer", "status": "ok", "verdict": "pass",
                     "message": "", "result": str(units / f"{serial}.json")})
    store = tmp_path / "out" / "results.parquet"
    append_rows(store, rows)
    code, out, err = cli("lot", store, "--json", tmp_path / "lot.json")
    assert code == 0, err
    assert "units grouped by thermal profile:" in out and "accelerometer: 2 groups of 9 units" in out
    doc = json.loads((tmp_path / "lot.json").read_text())
    (g,) = doc["thermal_groups"]
    found = sorted(sorted(grp["members"]) for grp in g["groups"])
    assert found == sorted(sorted(s for s in truth if truth[s] == j) for j in (0, 1))
    assert g["unit"] == "m/s^2" and len(g["groups"][0]["coefficients"]) == 3
