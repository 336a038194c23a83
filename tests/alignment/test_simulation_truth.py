"""The simulation's truth file: written by simulate, read back by the loader, equal to the model simulated."""

from __future__ import annotations

import numpy as np

from align.alignment.simulate import SimulationTruth, random_model
from align.results import load_result, save_result
from align.units import DEG
from align.values import approx_equal


def test_truth_round_trips_and_the_random_model_has_the_size_asked(tmp_path):
    model = random_model(np.random.default_rng(3), 0.8 * DEG)
    # the mounting rotation's size is what was asked (scale and non-orthogonality apart)
    assert abs(np.linalg.norm(model.angles().mounting_rotvec) - 0.8 * DEG) < 0.2 * DEG
    truth = SimulationTruth(model, "deg/s", 3, {"log": "session.csv"})
    save_result(tmp_path / "truth.json", truth)
    back = load_result(tmp_path / "truth.json")
    assert type(back) is SimulationTruth and back.seed == 3 and back.inputs == {"log": "session.csv"}
    assert approx_equal(back.model, model, rtol=1e-12, atol=1e-18)
    assert SimulationTruth.from_dict(back.to_dict()) == back


def test_bundled_truth_of_version_0_1_still_loads():
    from support import ROOT

    truth = load_result(ROOT / "examples/alignment/truth.json")
    assert isinstance(truth, SimulationTruth) and truth.seed == 7
    assert np.allclose(truth.model.M @ np.array(truth.to_dict()["A"]), np.eye(3), atol=1e-12)
