"""The real thermal cycle of ../shared/data/thermal/tofupilot_cycle (static 6-axis IMU, -17.6 to 74 C, 70 min,
2 Hz; tab-separated, time in microseconds; SOURCE.txt), against the figures its SOURCE.txt states and issue 25's
claims.

SOURCE.txt recomputes the template's own method (one numpy.polyfit cubic over all samples): its residual std
(``res_std``) and the channels' std are the outside truth of "one cubic" and "before" here. Issue 25 claims that
the compensation judged on held-out data beats one cubic over all samples by at least 30 % rms on every
accelerometer axis, "fit one branch, test on the other, and the reverse". Measured here: held out as
contiguous blocks across the record (the cross-validation the order is chosen by) it does, by 37, 51 and 56 %;
held out as a whole branch it does not (heating -> cooling 0.81, 0.61, 1.14 of one cubic's rms; cooling ->
heating 1.66, 2.41, 1.61): a branch alone does not determine the lag term (its rate barely changes), so a model
fitted on one branch extrapolates badly to the other. That claim is kept below as a strict expected failure
with these figures, not weakened.
"""

from __future__ import annotations

import numpy as np
import pytest
from support import SHARED

from align.calibration.thermal import ThermalCalibration, calibrate_thermal
from align.io.formats import LogFormat
from align.io.source import LogSource
from align.results import load_result, save_result

LOG = SHARED / "data" / "thermal" / "tofupilot_cycle" / "imu_raw_data.csv"
DEG = np.pi / 180
#: SOURCE.txt: channel std and the template's cubic residual std, gyro in deg/s, acc in m/s^2
STD = {"gyroscope": (0.00633, 0.01773, 0.00205), "accelerometer": (0.04734, 0.05010, 0.18915)}
CUBIC = {"gyroscope": (0.004148, 0.000952, 0.001398), "accelerometer": (0.006404, 0.01731, 0.04430)}

pytestmark = pytest.mark.skipif(not LOG.exists(), reason="the shared thermal cycle is not here")


@pytest.fixture(scope="module")
def cycle() -> ThermalCalibration:
    fmt = LogFormat(delimiter="tab", time_units="us")
    gyro = LogSource(path=LOG, columns=("imu.gyro.x", "imu.gyro.y", "imu.gyro.z"), time_column="timestamp",
                     format=fmt, temperature_column="imu.temperature")  # deg/s: the template's unit (SOURCE.txt)
    return calibrate_thermal(log=gyro, accel=LogSource(path=LOG, columns=("imu.acc.x", "imu.acc.y", "imu.acc.z")))


def _si(sensor: str) -> float:
    return DEG if sensor == "gyroscope" else 1.0


@pytest.mark.parametrize("sensor", ["gyroscope", "accelerometer"])
def test_before_and_one_cubic_are_the_figures_source_txt_states(cycle, sensor):
    s = cycle.sensors[sensor]
    assert [a.rms_before for a in s.axes] == pytest.approx(np.array(STD[sensor]) * _si(sensor), rel=2e-3)
    assert [a.rms_cubic for a in s.axes] == pytest.approx(np.array(CUBIC[sensor]) * _si(sensor), rel=2e-3)
    assert (s.model.tmin, s.model.tmax) == pytest.approx((-17.60, 73.97), abs=0.01)  # SOURCE.txt's min and max


def test_the_result_states_the_hysteresis(cycle, tmp_path):
    path = tmp_path / "thermal.json"
    save_result(path, cycle)
    back = load_result(path)
    assert isinstance(back, ThermalCalibration)
    for s in back.sensors.values():
        for a in s.axes:
            h = a.hysteresis
            assert h is not None and h.sigma > 0 and h.lo < -10 and h.hi > 60  # compared over most of the cycle
    z = back.sensors["accelerometer"].axes[2].hysteresis
    # the issue saw heating and cooling differ by up to 0.12 m/s^2 on acc z; found here: 0.131 +- 0.006 at 31 C
    assert 0.10 < abs(z.value) < 0.16 and abs(z.value) > 10 * z.sigma


def test_the_compensation_beats_one_cubic_by_30_percent_on_held_out_blocks(cycle):
    for a in cycle.sensors["accelerometer"].axes:
        held_out = {(k, lag): rms for k, lag, rms in a.cv}
        assert a.lag and held_out[(a.order, a.lag)] <= 0.7 * held_out[(3, False)], a.cv
        assert a.rms_after <= 0.7 * a.rms_cubic


@pytest.mark.xfail(strict=True, reason="issue 25's branch-to-branch claim is not what the data show: the model "
                   "fitted on heating and judged on cooling leaves 0.81, 0.61, 1.14 of one cubic's rms (acc x, y, z), "
                   "fitted on cooling and judged on heating 1.66, 2.41, 1.61 (see the module docstring)")
def test_the_issue_s_claim_fit_one_branch_judge_on_the_other(cycle):
    for a in cycle.sensors["accelerometer"].axes:
        heat_to_cool, cool_to_heat = a.crosscheck
        assert max(heat_to_cool, cool_to_heat) <= 0.7 * a.rms_cubic


def test_the_branch_figures_are_the_ones_reported(cycle):
    # the figures quoted in the module docstring and the report, so that a change of method is seen
    got = np.array([a.crosscheck for a in cycle.sensors["accelerometer"].axes]) / np.array(
        [[a.rms_cubic] * 2 for a in cycle.sensors["accelerometer"].axes])
    assert got == pytest.approx(np.array([[0.81, 1.66], [0.61, 2.41], [1.14, 1.61]]), abs=0.01)
