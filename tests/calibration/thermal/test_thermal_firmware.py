"""The ArduPilot and PX4 parameter files of a thermal calibration, applied to the raw log with each firmware's
documented formula, written out here from the firmware's source (not from imu-align's code), reproduce the
tool's compensated data (issue 25's "Done means", second point).

ArduPilot, libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp::

    polynomial_eval(tdiff, c) = (c[0] + (c[1] + c[2]*tdiff)*tdiff)*tdiff*INV_SCALE_FACTOR     (1e-6)
    correct_sensor: T = constrain(T, temp_min, temp_max); cal_temp likewise;
                    v -= polynomial_eval(T - TEMP_REFERENCE, coeff);  v += polynomial_eval(cal_temp - 35, coeff)

PX4, src/modules/temperature_compensation/TemperatureCompensation.cpp::

    delta_temp = clip(measured_temp, min_temp, max_temp) - ref_temp
    offset[i] = x0[i] + x1[i]*d + x2[i]*d^2 + x3[i]*d^3;   Correct(data) = R (data - thermal_offset - offset)
"""

from __future__ import annotations

import numpy as np
import pytest
from support import SHARED

from align.calibration.thermal import calibrate_thermal, firmware
from align.errors import InputError
from align.io.formats import LogFormat
from align.io.source import LogSource
from align.vocab import Sensor

LOG = SHARED / "data" / "thermal" / "tofupilot_cycle" / "imu_raw_data.csv"
FMT = LogFormat(delimiter="tab", time_units="us")
COLUMNS = {"gyroscope": ("imu.gyro.x", "imu.gyro.y", "imu.gyro.z"),
           "accelerometer": ("imu.acc.x", "imu.acc.y", "imu.acc.z")}

pytestmark = pytest.mark.skipif(not LOG.exists(), reason="the shared thermal cycle is not here")


def _source(sensor: str) -> LogSource:
    return LogSource(path=LOG, columns=COLUMNS[sensor], time_column="timestamp", format=FMT,
                     temperature_column="imu.temperature")


@pytest.fixture(scope="module")
def cubic():
    """The real cycle calibrated with cubics (the firmware take no more), and the raw log in SI."""
    result = calibrate_thermal(log=_source("gyroscope"), accel=LogSource(path=LOG, columns=COLUMNS["accelerometer"]),
                               max_order=3)
    raw = {s: _source(s).read(Sensor(s)) for s in COLUMNS}
    return result, raw


def _ardupilot(params: dict, n: int, kind: str, raw: np.ndarray, T: np.ndarray, cal_temp: float) -> np.ndarray:
    """AP_InertialSensor::TCal::correct_sensor, as its source says."""
    assert params[f"INS_TCAL{n}_ENABLE"] == 1
    tmin, tmax = params[f"INS_TCAL{n}_TMIN"], params[f"INS_TCAL{n}_TMAX"]
    c = np.array([[params[f"INS_TCAL{n}_{kind}{k}_{axis}"] for axis in "XYZ"] for k in (1, 2, 3)])

    def poly(tdiff):
        tdiff = np.asarray(tdiff, float)[:, None]
        return (c[0] + (c[1] + c[2] * tdiff) * tdiff) * tdiff * 1e-6

    T = np.clip(T, tmin, tmax)
    cal = np.clip(np.full(len(T), cal_temp), tmin, tmax)
    return raw - poly(T - 35.0) + poly(cal - 35.0)


def _px4(params: dict, prefix: str, raw: np.ndarray, T: np.ndarray) -> np.ndarray:
    """TemperatureCompensation::calc_thermal_offsets_3D and Correct, as their source says."""
    d = np.clip(T, params[f"{prefix}_TMIN"], params[f"{prefix}_TMAX"]) - params[f"{prefix}_TREF"]
    x = np.array([[params[f"{prefix}_X{k}_{j}"] for j in range(3)] for k in range(4)])
    offset = x[0] + x[1] * d[:, None] + x[2] * d[:, None] ** 2 + x[3] * d[:, None] ** 3
    return raw - offset


def _close(fw: np.ndarray, tool: np.ndarray) -> None:
    """Agreement to 1e-6 of the data's size, per axis."""
    for i in range(3):
        np.testing.assert_allclose(fw[:, i], tool[:, i], rtol=1e-6, atol=1e-6 * float(np.abs(tool[:, i]).max()))


@pytest.mark.parametrize("cal_temp", [35.0, 20.0])
def test_ardupilot_file_reproduces_the_compensated_log(cubic, cal_temp):
    result, raw = cubic
    models = {k: s.model for k, s in result.sensors.items()}
    params = firmware.read_ardupilot(firmware.ardupilot(models, instance=1))
    assert set(params) >= {"INS_TCAL2_ENABLE", "INS_TCAL2_TMIN", "INS_TCAL2_TMAX", "INS_TCAL2_ACC3_Z",
                           "INS_TCAL2_GYR1_X"}
    for sensor, kind in (("accelerometer", "ACC"), ("gyroscope", "GYR")):
        got, model = raw[sensor], models[sensor]
        tool = model.compensate(got.data, got.temperature).data
        fw = _ardupilot(params, 2, kind, got.data, got.temperature, cal_temp)
        # the firmware leaves the constant to the ordinary offsets, calibrated at cal_temp: the tool's bias there
        _close(fw - model.bias(np.array([cal_temp]))[0][0], tool)


def test_px4_file_reproduces_the_compensated_log(cubic):
    result, raw = cubic
    models = {k: s.model for k, s in result.sensors.items()}
    params = firmware.read_px4(firmware.px4(models, {"gyroscope": 2293768, "accelerometer": 2293776}))
    assert params["TC_A_ENABLE"] == 1 and params["TC_G0_ID"] == 2293768 and params["TC_A0_ID"] == 2293776
    assert params["TC_A0_TREF"] == pytest.approx(0.5 * (params["TC_A0_TMIN"] + params["TC_A0_TMAX"]))
    for sensor, prefix in (("accelerometer", "TC_A0"), ("gyroscope", "TC_G0")):
        got, model = raw[sensor], models[sensor]
        tool = model.compensate(got.data, got.temperature).data
        fw = _px4(params, prefix, got.data, got.temperature)
        if sensor == "accelerometer":  # its level at TREF (gravity at rest) is left to the ordinary calibration
            assert all(params[f"TC_A0_X0_{j}"] == 0.0 for j in range(3))
            fw = fw - model.bias(np.array([params["TC_A0_TREF"]]))[0][0]
        _close(fw, tool)


def test_both_clamp_as_the_tool_does_outside_the_range(cubic):
    result, _ = cubic
    models = {k: s.model for k, s in result.sensors.items()}
    ap = firmware.read_ardupilot(firmware.ardupilot(models))
    px = firmware.read_px4(firmware.px4(models, {"gyroscope": 1, "accelerometer": 2}))
    T = np.linspace(-45.0, 110.0, 32)
    zero = np.zeros((len(T), 3))
    model = models["accelerometer"]
    tool = model.compensate(zero, T)
    assert tool.clamped > 0 and "clamped" in tool.note
    _close(_px4(px, "TC_A0", zero, T) - model.bias(np.array([px["TC_A0_TREF"]]))[0][0], tool.data)
    _close(_ardupilot(ap, 1, "ACC", zero, T, 35.0) - model.bias(np.array([35.0]))[0][0], tool.data)


def test_a_model_above_cubic_is_refused_for_the_firmware():
    result = calibrate_thermal(log=_source("gyroscope"), accel=LogSource(path=LOG, columns=COLUMNS["accelerometer"]),
                               sensors=("accelerometer",), order=4)
    with pytest.raises(InputError, match="order 4, and the firmware takes a cubic") as err:
        firmware.ardupilot({"accelerometer": result.model("accelerometer")})
    assert err.value.fields == ["max_order", "max_order"]


def test_px4_needs_each_sensor_s_device_id(cubic):
    result, _ = cubic
    with pytest.raises(InputError, match="the log states none for the gyroscope") as err:
        firmware.px4({k: s.model for k, s in result.sensors.items()}, {"accelerometer": 2})
    assert "gyro_id" in err.value.fields


def test_the_files_state_their_conventions_in_comments(cubic):
    result, _ = cubic
    models = {k: s.model for k, s in result.sensors.items()}
    ap, px = firmware.ardupilot(models), firmware.px4(models, {"gyroscope": 1, "accelerometer": 2})
    assert "d = " not in ap.splitlines()[-1]  # parameters last
    for words in ("- 35", "1e-6", "constant term", "lag term"):
        assert words in ap
    for words in ("X0 + X1 d + X2 d^2 + X3 d^3", "clip(T, TMIN, TMAX) - TREF", "lag term"):
        assert words in px
    assert all(line.startswith("#") or line.count("\t") == 4 for line in px.splitlines())


def test_px4_file_keeps_gravity_in_the_accelerometer(cubic):
    """Applied by PX4's formula, the file leaves a resting accelerometer reading gravity (|a| near 9.8 m/s^2):
    a thermal offset that carried the level at TREF would zero it."""
    result, raw = cubic
    models = {k: s.model for k, s in result.sensors.items()}
    params = firmware.read_px4(firmware.px4(models, {"gyroscope": 1, "accelerometer": 2}))
    got = raw["accelerometer"]
    fw = _px4(params, "TC_A0", got.data, got.temperature)
    assert abs(np.median(np.linalg.norm(fw, axis=1)) - np.median(np.linalg.norm(got.data, axis=1))) < 0.2
    assert np.median(np.linalg.norm(fw, axis=1)) > 9.0
