"""The drift result's file round trip, its refusals, and its report section and picture."""

from __future__ import annotations

import json

import numpy as np
import pytest

from align.errors import InputError
from align.navigation import drift, static_mission
from align.navigation.residuals import ResidualErrors, SensorErrors
from align.results import result_from_dict
from align.units import DEG_H
from align.values import approx_equal


@pytest.fixture(scope="module")
def result():
    errors = ResidualErrors(SensorErrors("gyroscope", bias=10 * DEG_H, white=1e-4, sources={"bias": "stated"}),
                            SensorErrors("accelerometer", bias=1e-3, matrix=np.full((3, 3), 1e-4)))
    return drift(static_mission(30.0, 100.0), errors, runs=40, seed=3, inputs={"imu": "test"})


def test_the_file_reads_back(result):
    back = result_from_dict(json.loads(json.dumps(result.to_dict())), "drift.json")
    assert approx_equal(back, result, rtol=1e-12)
    assert back.errors.gyro.sources == {"bias": "stated"}


def test_a_misspelled_or_newer_file_is_refused(result):
    d = result.to_dict()
    with pytest.raises(InputError, match="newer"):
        result_from_dict({**d, "version": 99}, "drift.json")
    with pytest.raises(InputError, match="posiiton_m"):
        result_from_dict({**d, "posiiton_m": d["position_m"]}, "drift.json")
    broken = json.loads(json.dumps(d))
    del broken["position_m"]["down"]["sigma"]
    with pytest.raises(InputError, match="malformed imu-align.drift"):
        result_from_dict(broken, "drift.json")


def test_the_dominance_is_stated_plainly(result):
    assert result.dominance.splitlines()[2].startswith("heading: angle random walk up to ")
    assert "then gyro bias to the end" in result.dominance
    assert all({"quantity", "from_s", "to_s", "term", "share"} <= set(r) for r in result.dominant)


@pytest.mark.slow
def test_picture_and_report_section(result):
    from align.present.navigation import drift_plot_png, drift_summary, navigation_section

    png = drift_plot_png(result)
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 20_000
    section = navigation_section(result, png)
    assert section.title == "What the residual errors cost in navigation"
    assert "data:image/png;base64," in section.body and "gyro bias" in section.body and "<table>" in section.body
    text = drift_summary(result)
    assert "heading (deg)" in text and "which error dominates when" in text


def test_no_residual_error_is_refused():
    with pytest.raises(InputError, match="no residual error"):
        drift(static_mission(10.0, 100.0), ResidualErrors(), runs=10)
