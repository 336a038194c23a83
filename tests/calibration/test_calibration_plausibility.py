"""Plausibility and handedness of every calibrated sensor, and results refused before they correct a log.

Truth comes from outside the code: simulated sessions of known M written in a known unit and declared in
another, imucal's real Ferraris session, the real HMC5883L capture (recorded in gauss, SOURCE.txt).
"""

import json

import numpy as np
import pandas as pd
import pytest
from accelsim import attitudes, six_faces
from magsim import F, capture, truth
from support import SHARED

from align.calibration import (
    Calibration,
    CalibrationSet,
    MagCalibration,
    accel_session,
    calibrate_accel,
    calibrate_accel_free,
    calibrate_accel_log,
    calibrate_magnetometer,
    ferraris,
    sections_from_dict,
)
from align.errors import HandednessError, InputError, TestError
from align.plausible import check_at_rest
from align.results import load_result, save_result
from align.units import DEG, STANDARD_GRAVITY

G = STANDARD_GRAVITY
FERRARIS = SHARED / "data" / "multiposition" / "imucal_ferraris"
HMC = SHARED / "data" / "magnetometer" / "hmc5883l_sunsided" / "hmc5883l_compass.csv"
M_TRUE, B_TRUE = np.diag([1.01, 0.99, 1.0]) + 0.003, np.array([0.1, -0.2, 0.05])


def _session(m_true=M_TRUE, g=G, n=200):
    a, positions = six_faces(m_true, B_TRUE, g, n)
    return np.arange(len(a)) / 100.0, a, [(k * n, (k + 1) * n) for k in range(6)], positions


# ---------------------------------------------------------------- accelerometer: unit mix-ups caught by gravity

def test_accel_log_in_g_declared_m_s2_is_refused_with_the_fix():
    t, a, intervals, positions = _session()
    cal = accel_session(t, a, intervals, positions, G, "m/s^2")  # in m/s^2: passes, the truth comes back
    assert np.allclose(cal.M, M_TRUE, atol=1e-3)
    in_g = a / G  # the same session written in g, read as m/s^2
    with pytest.raises(TestError, match=r"mean \|a\| at rest is 1.0\d m/s\^2, gravity is 9.81 m/s\^2: "
                                        r"the log looks like g read as m/s\^2; set units='g'") as exc:
        accel_session(t, in_g, intervals, positions, G, "m/s^2", "acc.csv")
    assert exc.value.fields == ["units"] and str(exc.value).startswith("acc.csv: ")
    with pytest.raises(TestError, match="m/s\\^2 read as g; set units='m/s\\^2'"):
        calibrate_accel({p["name"]: a[s:e].mean(axis=0) * G for p, (s, e) in zip(positions, intervals)},
                        {p["name"]: np.eye(3)[" xyz".index(p["up"][1]) - 1] * (1 if p["up"][0] == "+" else -1)
                         for p in positions}, G, "g")
    with pytest.raises(TestError, match="mg read as g; set units='mg'"):
        accel_session(t, a / G * 1000 * G, intervals, positions, G, "g")
    counts = accel_session(t, a / G * 4096, intervals, positions, G, "counts")  # counts: exempt, the scale is measured
    assert np.allclose(np.diag(counts.M), np.diag(M_TRUE) * 4096 / G, rtol=1e-3)


def test_accel_free_fit_refuses_a_unit_mix_up():
    means, log, intervals = attitudes(M_TRUE, B_TRUE, G)
    cal = calibrate_accel_free(means, G)
    assert np.all(np.diag(cal.M) > 0) and np.linalg.det(cal.M) > 0
    with pytest.raises(TestError, match="g read as m/s\\^2; set units='g'") as exc:
        calibrate_accel_free(means / G, G, "m/s^2")
    assert exc.value.fields == ["units"]
    with pytest.raises(TestError, match="g read as m/s\\^2"):
        accel_session(np.arange(len(log)) / 100.0, log / G, intervals, None, G, "m/s^2")
    with pytest.raises(TestError, match="the readings are zero"):
        calibrate_accel_free(np.zeros((12, 3)), G)


def test_real_accelerometer_in_g_read_as_m_s2(run_cli):
    log = SHARED / "data" / "magnetometer" / "ck_explorer" / "acc_log.csv"  # SOURCE.txt: accelerometer in g, slow turns
    a = pd.read_csv(log)[["ax", "ay", "az"]].to_numpy()
    with pytest.raises(TestError, match="g read as m/s\\^2; set units='g'"):
        check_at_rest(np.linalg.norm(a, axis=1), G, "m/s^2")
    check_at_rest(np.linalg.norm(a * G, axis=1), G, "g")
    res = run_cli("calibrate", "accel", log, "--columns", "ax,ay,az", "--rate-hz", "100")
    assert res.code == 3 and "g read as m/s^2" in res.err and "--accel-units g" in res.err, res.err


def test_simulated_log_in_g_through_the_command_line(tmp_path, run_cli):
    t, a, intervals, positions = _session()
    log, pos = tmp_path / "acc.csv", tmp_path / "pos.toml"
    pd.DataFrame({"time": t, "acc_x": a[:, 0] / G, "acc_y": a[:, 1] / G, "acc_z": a[:, 2] / G}).to_csv(log, index=False)
    pos.write_text("".join(f'[[position]]\nname = "{p["name"]}"\nup = "{p["up"]}"\nstart = {s}\nend = {e}\n\n'
                           for p, (s, e) in zip(positions, intervals)))
    res = run_cli("calibrate", "accel", log, "--positions", pos, "--json", tmp_path / "never.json")
    assert res.code == 3 and "--accel-units g" in res.err and not (tmp_path / "never.json").exists(), res.err
    res = run_cli("calibrate", "accel", log, "--positions", pos, "--accel-units", "g")
    assert res.code == 0, res.err


# ---------------------------------------------------------------- accelerometer: handedness, gravity, positions

def test_flipped_axis_and_swapped_positions_are_handedness_errors():
    flipped = M_TRUE @ np.diag([1.0, -1.0, 1.0])
    t, a, intervals, positions = _session(flipped)
    with pytest.raises(HandednessError, match=r"det\(M\) = -\d.*the y axis reads gravity when -y is up.*\+y, -y") as exc:
        accel_session(t, a, intervals, positions, G, "m/s^2", positions_file="pos.toml")
    assert str(exc.value).startswith("pos.toml: ")
    t, a, intervals, positions = _session()
    swapped = [dict(p) for p in positions]
    swapped[0]["up"], swapped[1]["up"] = "-x", "+x"  # +x and -x swapped in the positions file
    with pytest.raises(HandednessError, match="the x axis reads gravity when -x is up"):
        accel_session(t, a, intervals, swapped, G, "m/s^2")
    across = [dict(p) for p in positions]
    across[0]["up"], across[2]["up"] = "+y", "+x"  # +x and +y swapped
    with pytest.raises(HandednessError, match="det"):
        accel_session(t, a, intervals, across, G, "m/s^2")
    two = M_TRUE @ np.diag([-1.0, -1.0, 1.0])  # det > 0 but two axes backwards: still refused, not a 180 deg "mount"
    t, a, intervals, positions = _session(two)
    with pytest.raises(TestError, match="the x axis reads gravity when -x is up; the y axis") as exc:
        accel_session(t, a, intervals, positions, G, "m/s^2")
    assert not isinstance(exc.value, HandednessError)


def test_negative_zero_or_foreign_gravity_is_an_input_error():
    t, a, intervals, positions = _session()
    for g in (-G, 0.0, float("nan"), 98.1):
        with pytest.raises(InputError) as exc:
            accel_session(t, a, intervals, positions, g, "m/s^2")
        assert exc.value.fields == ["gravity"]
    spec = {"gravity": "-9.81 m/s^2", "position": positions}
    with pytest.raises(InputError, match="positive") as exc:
        calibrate_accel_log(t, a, spec, "m/s^2", positions_file="pos.toml")
    assert str(exc.value).startswith("pos.toml: gravity: ")


def test_one_face_recorded_twice_is_named():
    t, a, intervals, positions = _session()
    twice = [{**p, "start": s, "end": e} for p, (s, e) in zip(positions, intervals)]
    twice[1].update(start=intervals[0][0], end=intervals[0][1])  # "-x" given the samples of "+x"
    with pytest.raises(TestError, match=r"positions \+x and -x read the same"):
        accel_session(t, a, [], twice, G, "m/s^2", positions_file="pos.toml")


@pytest.mark.parametrize("spec,match", [
    ({}, "no \\[\\[position\\]\\] tables"),
    ({"position": []}, "no \\[\\[position\\]\\] tables"),
    ({"gravity": "9.81 m/s^2"}, "no \\[\\[position\\]\\] tables"),
    ({"gravty": "9.81 m/s^2", "position": [{"up": "+x"}]}, "unknown key 'gravty' \\(did you mean 'gravity'"),
    ({"position": [{"upp": "+x"}]}, "unknown key 'upp' \\(did you mean 'up'"),
    ({"position": {"up": "+x"}}, "must be an array of tables"),
    ({"position": [{"up": "+x", "name": "a"}, {"up": "-x", "name": "a"}]}, "two positions are named 'a'"),
    ({"position": [{"up": "+x", "start": 0}]}, "both start and end"),
    ({"position": [{"up": "+x", "start": 10, "end": 5}]}, "end 5 must be after start 10"),
    ({"position": [{"up": "+x", "start": 1.5, "end": 5}]}, "start must be a sample number"),
    ({"position": [{"up": "+x", "holdout": "yes"}]}, "holdout must be true or false"),
    ({"position": [{"up": [0, 0, 0]}]}, "up must be an axis"),
])
def test_positions_file_refusals_name_the_file(spec, match):
    t, a, _, _ = _session()
    with pytest.raises(InputError, match=match) as exc:
        calibrate_accel_log(t, a, spec, "m/s^2", positions_file="pos.toml")
    assert str(exc.value).startswith("pos.toml")


def test_empty_positions_file_does_not_switch_method(tmp_path, run_cli):
    t, a, _, _ = _session()
    log, pos = tmp_path / "acc.csv", tmp_path / "pos.toml"
    pd.DataFrame({"time": t, "acc_x": a[:, 0], "acc_y": a[:, 1], "acc_z": a[:, 2]}).to_csv(log, index=False)
    for text in ("", 'gravity = "9.81 m/s^2"\n', "position = []\n"):
        pos.write_text(text)
        res = run_cli("calibrate", "accel", log, "--positions", pos)
        assert res.code == 2 and str(pos) in res.err and "static intervals" not in res.out, res.err


# ---------------------------------------------------------------- Ferraris: unit mix-ups, section lists, handedness

def _ferraris():
    df = pd.read_csv(FERRARIS / "example_ferraris_session.csv")
    sections = sections_from_dict(json.loads((FERRARIS / "example_ferraris_session_list.json").read_text()))
    return df[["acc_x", "acc_y", "acc_z"]].to_numpy(), df[["gyr_x", "gyr_y", "gyr_z"]].to_numpy() * DEG, sections


def test_ferraris_accelerometer_unit_mix_ups():
    acc, gyr, sections = _ferraris()  # recorded in m/s^2
    with pytest.raises(TestError, match="g read as m/s\\^2; set acc_units='g'") as exc:
        ferraris(acc / 9.81, gyr, 102.4, sections, -2 * np.pi, 9.81)
    assert exc.value.fields == ["acc_units"]
    with pytest.raises(TestError, match="m/s\\^2 read as g; set acc_units='m/s\\^2'"):
        ferraris(acc * 9.81, gyr, 102.4, sections, -2 * np.pi, 9.81, acc_units="g")
    acc_cal, _ = ferraris(acc / 9.81 * G, gyr, 102.4, sections, -2 * np.pi, 9.81, acc_units="g")  # in g, declared g
    assert np.allclose(np.linalg.norm(acc_cal.M, axis=1), 1, atol=0.05)
    with pytest.raises(TestError, match="the readings are zero"):
        ferraris(np.zeros_like(acc), gyr, 102.4, sections, -2 * np.pi)


def test_ferraris_section_list_errors_name_the_sections():
    acc, gyr, sections = _ferraris()
    same = {**sections, "x_a": sections["x_p"]}
    with pytest.raises(InputError, match=r"x_p \(540..1271\) has the same samples as x_a") as exc:
        ferraris(acc, gyr, 102.4, same, -2 * np.pi)
    assert exc.value.fields == ["sections"]
    overlap = {**sections, "y_p": (sections["x_a"][1] - 10, sections["y_p"][1])}
    with pytest.raises(InputError, match="x_a .* has samples shared with y_p"):
        ferraris(acc, gyr, 102.4, overlap, -2 * np.pi)
    turns = {**sections, "z_rot": sections["y_rot"]}
    with pytest.raises(InputError, match="y_rot .* has the same samples as z_rot"):
        ferraris(acc, gyr, 102.4, turns, -2 * np.pi)
    swapped = {**sections, "x_p": sections["x_a"], "x_a": sections["x_p"]}
    with pytest.raises(HandednessError, match="the x axis reads gravity when -x is up.*x_p, x_a") as exc:
        ferraris(acc, gyr, 102.4, swapped, -2 * np.pi)
    assert exc.value.fields == ["sections"]
    flipped = acc * np.array([1.0, -1.0, 1.0])
    with pytest.raises(HandednessError, match="the y axis reads gravity when -y is up"):
        ferraris(flipped, gyr, 102.4, sections, -2 * np.pi)
    with pytest.raises(InputError) as exc:
        ferraris(acc, gyr, 102.4, sections, -2 * np.pi, gravity=-9.81)
    assert exc.value.fields == ["gravity"]
    for kwargs, field in (({"fs": 0.0}, "fs"), ({"turn_angle": 0.0}, "turn_angle")):
        args = {"fs": 102.4, "turn_angle": -2 * np.pi, **kwargs}
        with pytest.raises(InputError) as exc:
            ferraris(acc, gyr, args["fs"], sections, args["turn_angle"])
        assert exc.value.fields == [field]


@pytest.mark.parametrize("raw,match", [
    ({"x_pp": {"start": 0, "end": 5}}, "unknown key 'x_pp' \\(did you mean 'x_p'"),
    ({"x_p": {"stat": 0, "end": 5}}, "unknown key 'stat' \\(did you mean 'start'"),
    ({"x_p": {"start": 0.5, "end": 5}}, "integer start and end"),
    ({"x_p": {"start": True, "end": 5}}, "integer start and end"),
    ({"x_p": [0, 5]}, "integer start and end"),
    ([1, 2], "expected a JSON object"),
])
def test_section_list_keys(raw, match):
    with pytest.raises(InputError, match=match) as exc:
        sections_from_dict(raw, "list.json")
    assert str(exc.value).startswith("list.json")


# ---------------------------------------------------------------- magnetometer: Earth's field, dip

def test_real_capture_in_gauss_read_as_ut_is_refused(run_cli):
    m = pd.read_csv(HMC)[["mag_x_gauss", "mag_y_gauss", "mag_z_gauss"]].to_numpy()
    with pytest.raises(TestError, match=r"field strength is 0.5\d+ uT, Earth's field is 20-70 uT: the log looks like "
                                        r"gauss read as uT; set units='gauss'") as exc:
        calibrate_magnetometer(m * 1e-6, "uT")
    assert exc.value.fields == ["units"]
    with pytest.raises(TestError, match="gauss read as uT"):
        calibrate_magnetometer(m * 1e-6, "uT", field=48e-6)  # a known field does not hide it
    assert calibrate_magnetometer(m * 1e-4, "gauss").field == pytest.approx(53e-6, rel=0.1)
    columns = "mag_x_gauss,mag_y_gauss,mag_z_gauss"
    res = run_cli("calibrate", "mag", HMC, "--columns", columns)
    assert res.code == 3 and "--mag-units gauss" in res.err, res.err
    res = run_cli("calibrate", "mag", HMC, "--columns", columns, "--field", "48 uT")
    assert res.code == 3 and "--mag-units gauss" in res.err, res.err


@pytest.mark.parametrize("written,declared,fix", [
    (1e-9, "uT", "nT"),      # nT read as uT: 50,000 "uT"
    (1e-7, "uT", "mG"),      # mG read as uT: 500 "uT"
    (1e-6, "gauss", "uT"),   # uT read as gauss: 5,000 gauss
    (1e-6, "nT", "uT"),      # uT read as nT: 0.05 uT
])
def test_simulated_field_unit_mix_ups(written, declared, fix):
    s, h = truth(0)
    m, _ = capture("sphere", s, h, seed=3)
    numbers = m / written  # the capture as the sensor wrote it
    from align.units import parse_unit

    with pytest.raises(TestError, match=f"{fix} read as {declared}; set units='{fix}'"):
        calibrate_magnetometer(numbers * parse_unit(declared).factor, declared)
    assert calibrate_magnetometer(numbers * parse_unit(fix).factor, fix).field == pytest.approx(F, rel=0.1)


def test_known_field_and_dip_are_checked(run_cli):
    s, h = truth(1)
    m, _ = capture("sphere", s, h, seed=4)
    with pytest.raises(InputError, match="0.500 uT is not Earth's field") as exc:
        calibrate_magnetometer(m, "uT", field=0.5e-6)
    assert exc.value.fields == ["field"]
    with pytest.raises(TestError, match=r"the field given is 0.\d+x the readings'") as exc:
        calibrate_magnetometer(m, "uT", field=0.4 * F)
    assert exc.value.fields == ["field", "units"]
    with pytest.raises(InputError, match="positive") as exc:
        calibrate_magnetometer(m, "uT", field=-F)
    assert calibrate_magnetometer(m / 1e-4, "counts", field=F / 1e-4 * 0.9).field == pytest.approx(F / 1e-4 * 0.9)
    for dip in (120 * DEG, -91 * DEG, float("nan")):
        with pytest.raises(InputError, match="within -90..90 deg") as exc:
            calibrate_magnetometer(m, "uT", dip=dip)
        assert exc.value.fields == ["dip"]
    assert calibrate_magnetometer(m, "uT", dip=-90 * DEG).dip == pytest.approx(-90 * DEG)
    res = run_cli("calibrate", "mag", SHARED / "data" / "magnetometer" / "bazhin" / "mag_out.txt", "--columns",
                  "col0,col1,col2", "--mag-units", "counts", "--dip", "120 deg")
    assert res.code == 2 and "--dip" in res.err, res.err


# ---------------------------------------------------------------- results refused before they correct a log

def _cal(m, sensor="accelerometer", units="m/s^2"):
    return Calibration(sensor, m, np.zeros(3), np.full((3, 3), 1e-4), np.full(3, 1e-3), units, "test")


def test_calibration_results_that_cannot_correct_are_refused(tmp_path, run_cli):
    good = CalibrationSet({"accelerometer": _cal(np.eye(3))})
    assert good.correction(None, "cal.json") is good.sensors["accelerometer"]
    flipped = CalibrationSet({"accelerometer": _cal(np.diag([1.0, -0.998, 1.0]))})
    with pytest.raises(HandednessError) as exc:
        flipped.correction(None, "cal.json")
    assert str(exc.value) == "cal.json: accelerometer: M has det -0.998 <= 0: a handedness error; regenerate the result"
    singular = CalibrationSet({"accelerometer": _cal(np.diag([1.0, 1.0, 1e-19]))})
    with pytest.raises(TestError, match="M is singular"):
        singular.correction(None, "cal.json")
    d = good.to_dict()
    d["accelerometer"]["M"][1] = [None, None, None]
    with pytest.raises(InputError, match="malformed calibration: M holds null"):
        CalibrationSet.from_dict(d, "cal.json")
    d = good.to_dict()
    d["accelerometer"]["bias"] = [0.0, None, 0.0]
    with pytest.raises(InputError, match="bias holds null"):
        CalibrationSet.from_dict(d, "cal.json")
    # apply refuses the flipped result and writes nothing
    path, log, out = tmp_path / "cal.json", tmp_path / "acc.csv", tmp_path / "out.csv"
    save_result(path, flipped)
    pd.DataFrame({"time": [0.0, 0.01], "acc_x": [0.0, 0.0], "acc_y": [0.0, 0.0], "acc_z": [9.8, 9.8]}).to_csv(log, index=False)
    res = run_cli("apply", log, "--alignment", path, "--out", out, "--columns", "time,acc_x,acc_y,acc_z")
    assert res.code == 3 and "det -0.998 <= 0" in res.err and str(path) in res.err and not out.exists(), res.err


def test_magnetometer_results_that_cannot_correct_are_refused(tmp_path):
    s, h = truth(0)
    m, _ = capture("sphere", s, h, seed=5)
    c = calibrate_magnetometer(m, "uT", field=F)
    assert c.correction(None, "mag.json") is c
    with pytest.raises(TestError, match="soft_iron is not positive definite"):
        c.replace(soft_iron=np.diag([-1.0, -1.0, 1.0])).correction(None, "mag.json")
    with pytest.raises(HandednessError, match="mag.json: soft_iron has det -1.00 <= 0"):
        c.replace(soft_iron=np.diag([1.0, 1.0, -1.0])).correction(None, "mag.json")
    with pytest.raises(TestError, match="soft_iron is singular"):
        c.replace(soft_iron=np.diag([1.0, 1.0, 0.0])).correction(None, "mag.json")
    d = c.to_dict()
    d["soft_iron"][0][0] = None
    with pytest.raises(InputError, match="malformed magnetometer calibration: soft_iron holds null"):
        MagCalibration.from_dict(d, "mag.json")
    d = c.to_dict()
    d["hard_iron"] = [None, 0.0, 0.0]
    path = tmp_path / "mag.json"
    path.write_text(json.dumps(d))
    with pytest.raises(InputError, match="hard_iron holds null"):
        load_result(path)


def test_result_files_with_unknown_keys_are_refused():
    cs = CalibrationSet({"accelerometer": _cal(np.eye(3) * 1.01)}, {"log": "acc.csv"})
    d = cs.to_dict()
    with pytest.raises(InputError, match="cal.json: unknown key 'calibraton_note'") as exc:
        CalibrationSet.from_dict({**d, "calibraton_note": "typo'd key"}, "cal.json")
    assert exc.value.fields == []
    typo = {k: v for k, v in d.items() if k != "accelerometer"} | {"accelerometr": d["accelerometer"]}
    with pytest.raises(InputError, match="unknown key 'accelerometr' \\(did you mean 'accelerometer'"):
        CalibrationSet.from_dict(typo, "cal.json")
    inner = {**d, "accelerometer": {**d["accelerometer"], "bais": [0, 0, 0]}}
    with pytest.raises(InputError, match="cal.json: accelerometer: unknown key 'bais' \\(did you mean 'bias'"):
        CalibrationSet.from_dict(inner, "cal.json")
    s, h = truth(2)
    m, _ = capture("sphere", s, h, seed=6)
    md = calibrate_magnetometer(m, "uT").to_dict()
    with pytest.raises(InputError, match="mag.json: unknown key 'soft_irn' \\(did you mean 'soft_iron'"):
        MagCalibration.from_dict({**md, "soft_irn": md["soft_iron"]}, "mag.json")
