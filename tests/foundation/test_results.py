"""The result envelope, registry and loader (align.results), on a real alignment result."""

from __future__ import annotations

import json

import numpy as np
import pytest
from support import ROOT

from align.alignment import Plan, align
from align.alignment.result import AlignmentResult
from align.errors import InputError
from align.io import read_log, read_toml
from align.results import KNOWN, load_result, result_from_dict, save_result
from align.values import approx_equal


@pytest.fixture(scope="module")
def result() -> AlignmentResult:
    plan = Plan.from_dict(read_toml(ROOT / "examples/alignment/plan.toml"))
    t, g = read_log(ROOT / "examples/alignment/session.csv", ["gyro_x", "gyro_y", "gyro_z"], "deg/s")
    return align(t, g, plan).replace(inputs={"log": "session.csv"})


def test_alignment_result_round_trips_through_the_loader(tmp_path, result):
    path = tmp_path / "r.json"
    save_result(path, result)
    back = load_result(path)
    assert type(back) is AlignmentResult
    # the file holds deg/s: back in rad/s the values agree to rounding, and exactly once more round
    assert approx_equal(back, result, rtol=1e-12, atol=1e-18)
    assert AlignmentResult.from_dict(back.to_dict()) == back
    d = json.loads(path.read_text())
    assert list(d)[:5] == ["format", "version", "generator", "convention", "units"]
    assert d["convention"].startswith("g = M w + b")
    # the loaded result corrects as the original: w = A (g - b)
    g = np.array([[1.0, -2.0, 0.5]])
    assert np.allclose(back.correct(g), np.linalg.solve(result.M, (g - result.bias).T).T, rtol=1e-10)


@pytest.mark.parametrize("change, says", [
    ({"format": "someone.else"}, "not an imu-align result (format 'someone.else')"),
    ({"format": None}, "not an imu-align result"),
    ({"version": 99}, "version 99 is newer than this imu-align"),
    ({"version": "1"}, "without a valid version"),
    ({"version": None}, "without a valid version"),
])
def test_unknown_format_or_newer_version_is_refused_in_one_line(tmp_path, result, change, says):
    d = {**result.to_dict(), **change}
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(d))
    with pytest.raises(InputError) as err:
        load_result(path)
    text = str(err.value)
    assert says in text and str(path) in text and "\n" not in text


def test_expected_kind_is_enforced(tmp_path, result):
    from align.calibration.magnetometer import MagCalibration

    path = tmp_path / "r.json"
    save_result(path, result)
    with pytest.raises(InputError, match="expected imu-align.magnetometer"):
        load_result(path, expect=(MagCalibration,))


def test_every_known_format_is_registered_by_its_module():
    for fmt in KNOWN:
        with pytest.raises(InputError) as err:  # an empty body of each format: its own type refuses it
            result_from_dict({"format": fmt, "version": 1}, "x.json")
        assert "x.json" in str(err.value)
