"""Calibration results: CalibrationSet and MagCalibration as registered results (round trips, sensor choice, imucal)."""

import json

import numpy as np
import pytest
from magsim import F, capture, truth

from align.calibration import Calibration, CalibrationSet, MagCalibration, calibrate_magnetometer
from align.calibration.results import CONVENTION
from align.errors import InputError
from align.io.consumers import imucal_dict
from align.results import load_result, result_from_dict, save_result
from align.values import approx_equal


def _calibration(sensor: str, units: str, seed: int = 0, kga: bool = False) -> Calibration:
    rng = np.random.default_rng(seed)
    return Calibration(sensor, np.eye(3) + rng.normal(0, 0.01, (3, 3)), rng.normal(0, 0.1, 3),
                       np.full((3, 3), 1e-4), np.full(3, 1e-3), units, "test",
                       {"x_p": rng.normal(0, 1e-3, 3)}, {"45 xz": rng.normal(0, 1e-3, 3)}, ("a note",),
                       rng.normal(0, 1e-4, (3, 3)) if kga else None)


def _pair() -> CalibrationSet:
    return CalibrationSet({"gyroscope": _calibration("gyroscope", "deg/s", 1, kga=True),
                           "accelerometer": _calibration("accelerometer", "m/s^2")},
                          {"log": "session.csv", "sections": "sections.json"})


def test_calibration_set_file_form_and_round_trip(tmp_path):
    cs = _pair()
    d = cs.to_dict()
    # today's file: the envelope, inputs, then one key per sensor in a fixed order
    assert list(d) == ["format", "version", "generator", "convention", "units", "inputs", "accelerometer", "gyroscope"]
    assert d["format"] == "imu-align.calibration" and d["version"] == 1 and d["convention"] == CONVENTION
    assert d["units"] == {"accelerometer": "m/s^2", "gyroscope": "deg/s"}
    assert d["gyroscope"] == cs.sensors["gyroscope"].to_dict()
    assert approx_equal(CalibrationSet.from_dict(d), cs, rtol=1e-12)
    path = tmp_path / "cal.json"
    save_result(path, cs)
    back = load_result(path)
    assert type(back) is CalibrationSet and approx_equal(back, cs, rtol=1e-12)
    assert back.inputs == {"log": "session.csv", "sections": "sections.json"}
    assert approx_equal(result_from_dict(json.loads(path.read_text())), cs, rtol=1e-12)
    legacy = {k: v for k, v in d.items() if k != "units"}  # files written before the envelope had units
    assert approx_equal(CalibrationSet.from_dict(legacy), cs, rtol=1e-12)
    counts = CalibrationSet({"accelerometer": _calibration("accelerometer", "counts")})
    assert CalibrationSet.from_dict(counts.to_dict()) == counts  # no unit conversion: exact


def test_calibration_set_picks_its_sensor():
    cs = _pair()
    assert cs.sensor("gyroscope") is cs.sensors["gyroscope"]
    with pytest.raises(InputError, match="holds accelerometer, gyroscope: choose one") as exc:
        cs.sensor(None, "cal.json")
    assert exc.value.fields == ["sensor"] and str(exc.value).startswith("cal.json: ")
    one = CalibrationSet({"accelerometer": cs.sensors["accelerometer"]})
    assert one.sensor(None) is one.sensors["accelerometer"]
    with pytest.raises(InputError, match="no gyroscope calibration") as exc:
        one.sensor("gyroscope")
    assert exc.value.fields == ["sensor"]


def test_calibration_set_refuses_bad_files():
    d = _pair().to_dict()
    with pytest.raises(InputError, match="holds no accelerometer or gyroscope"):
        CalibrationSet.from_dict({k: v for k, v in d.items() if k not in ("accelerometer", "gyroscope")})
    with pytest.raises(InputError, match="malformed calibration"):
        CalibrationSet.from_dict({**d, "gyroscope": {"sensor": "gyroscope"}}, "cal.json")
    with pytest.raises(InputError, match="newer"):
        CalibrationSet.from_dict({**d, "version": 99})
    with pytest.raises(ValueError):
        CalibrationSet({"magnetometer": _calibration("accelerometer", "m/s^2")})


def test_calibration_is_a_frozen_value():
    c = _calibration("gyroscope", "deg/s", kga=True)
    with pytest.raises(ValueError):
        c.M[0, 0] = 2.0
    with pytest.raises(ValueError):
        c.residuals["x_p"][0] = 2.0
    assert c == c.replace() and c != c.replace(bias=c.bias + 1e-9)
    assert approx_equal(Calibration.from_dict(c.to_dict()), c, rtol=1e-12)


def test_imucal_export_from_plain_values():
    cs = _pair()
    acc, gyr = cs.sensors["accelerometer"], cs.sensors["gyroscope"]
    d = cs.as_imucal()
    assert d == imucal_dict(acc.M, acc.bias, gyr.M, gyr.bias, gyr.g_sensitivity)
    k, r = np.array(d["K_a"]), np.array(d["R_a"])
    assert np.allclose(k @ r, acc.M, atol=1e-14) and np.allclose(np.linalg.norm(r, axis=1), 1)
    assert np.allclose(np.array(d["b_g"]) * np.pi / 180, gyr.bias, atol=1e-15)
    assert np.allclose(np.array(d["K_ga"]) * np.pi / 180, gyr.g_sensitivity, atol=1e-15)
    assert imucal_dict(acc.M, acc.bias, gyr.M, gyr.bias)["K_ga"] == np.zeros((3, 3)).tolist()
    with pytest.raises(InputError, match="needs both sensors"):
        CalibrationSet({"accelerometer": acc}).as_imucal()


def test_magnetometer_result_round_trip(tmp_path):
    s, h = truth(0)
    m, acc = capture("sphere", s, h, seed=5)
    for c in (calibrate_magnetometer(m, "uT", acc=acc), calibrate_magnetometer(m / 1e-4, "counts", field=F / 1e-4)):
        c = c.replace(inputs={"log": "mag.csv", "columns": "mx,my,mz", "mag_units": c.units},
                      misalignment=np.eye(3) if c.units == "counts" else None)
        d = c.to_dict()
        assert list(d)[:5] == ["format", "version", "generator", "convention", "units"]
        assert d["format"] == "imu-align.magnetometer" and d["sensor"] == "magnetometer" and d["inputs"]["log"] == "mag.csv"
        assert {"hard_iron", "soft_iron", "field", "uncertainty", "quality", "notes", "model"} <= set(d)
        assert approx_equal(MagCalibration.from_dict(d), c, rtol=1e-12)
        legacy = {k: v for k, v in d.items() if k != "inputs"}  # to_dict wrote no inputs before
        assert approx_equal(MagCalibration.from_dict(legacy), c.replace(inputs={}), rtol=1e-12)
        path = tmp_path / f"mag-{c.units}.json"
        save_result(path, c)
        back = load_result(path, expect=(MagCalibration,))
        assert type(back) is MagCalibration and approx_equal(back, c, rtol=1e-12)
    with pytest.raises(InputError, match="expected imu-align.magnetometer"):
        save_result(tmp_path / "cal.json", _pair())
        load_result(tmp_path / "cal.json", expect=(MagCalibration,))
    with pytest.raises(InputError, match="not an imu-align.magnetometer result"):
        MagCalibration.from_dict(_pair().to_dict())
