"""align.plausible: what physics allows (gravity, Earth's field), handedness, and matrices fit to correct a log."""

import re

import numpy as np
import pytest

from align.alignment.result import AlignmentResult
from align.errors import HandednessError, InputError, TestError
from align.plausible import (
    check_at_rest,
    check_axes,
    check_corrected,
    check_dip,
    check_field_strength,
    check_gravity,
    check_known_field,
    check_positive_definite,
    check_scale_factors,
    check_usable_model,
    mixup_hint,
)
from align.units import DEG, STANDARD_GRAVITY
from align.wellformed import require_finite

G = STANDARD_GRAVITY


@pytest.mark.parametrize("written,declared,fix", [
    (G, "m/s^2", "g"),           # g read as m/s^2: mean |a| 1.0 "m/s^2"
    (1.0, "g", "m/s^2"),         # m/s^2 read as g: 9.81 "g"
    (G / 1000, "g", "mg"),       # mg read as g: 1000 "g"
    (G, "mg", "g"),              # g read as mg: 0.001 "mg"
])
def test_gravity_at_rest_names_the_unit_mix_up(written, declared, fix):
    from align.units import parse_unit

    numbers = np.full(20, G / written)  # |a| at rest as the sensor wrote it
    said = re.escape(f"gravity is 9.81 m/s^2: the log looks like {fix} read as {declared}; set units='{fix}'")
    with pytest.raises(TestError, match=said) as exc:
        check_at_rest(numbers * parse_unit(declared).factor, G, declared, where="acc.csv")
    assert exc.value.fields == ["units"] and str(exc.value).startswith("acc.csv: mean |a| at rest is ")
    check_at_rest(numbers * parse_unit(fix).factor, G, fix)


def test_gravity_at_rest_other_cases():
    check_at_rest(np.full(5, 1.03 * G), G, "m/s^2")
    check_at_rest(np.full(5, 1e-9), G, "counts")  # counts: exempt
    with pytest.raises(TestError, match=r"mean \|a\| at rest is 1.00 m/s\^2, gravity is 9.81 m/s\^2: the log looks "
                                        r"like g read as m/s\^2; set acc_units='g'") as exc:
        check_at_rest(np.full(5, 1.0), G, "m/s^2", "acc_units")
    assert exc.value.fields == ["acc_units"]
    with pytest.raises(TestError, match="not a known unit mix-up") as exc:
        check_at_rest(np.full(5, 3.0), G, "m/s^2")
    with pytest.raises(TestError, match="the readings are zero"):
        check_at_rest(np.zeros(5), G, "m/s^2")
    with pytest.raises(TestError, match="the readings are zero"):
        check_at_rest(np.zeros(0), G, "m/s^2")


@pytest.mark.parametrize("strength_ut,declared,fix", [
    (0.5, "uT", "gauss"), (50_000, "uT", "nT"), (500, "uT", "mG"), (5000, "gauss", "uT"), (0.05, "nT", "uT"),
    (0.05, "uT", "mT"),
])
def test_earth_field_names_the_unit_mix_up(strength_ut, declared, fix):
    with pytest.raises(TestError, match=f"Earth's field is 20-70 uT: the log looks like {fix} read as {declared}; "
                                        f"set mag_units='{fix}'") as exc:
        check_field_strength(strength_ut * 1e-6, declared, "mag_units")
    assert exc.value.fields == ["mag_units"]


def test_earth_field_other_cases():
    for ut in (25, 48, 65):
        check_field_strength(ut * 1e-6, "uT")
    check_field_strength(3.0, "counts")
    check_field_strength(50e-6, "0.92 mG")  # a count size: readings were scaled to SI
    with pytest.raises(TestError, match="not a known unit mix-up"):
        check_field_strength(3e-6, "uT")
    check_known_field(48e-6, 50e-6, "uT")
    check_known_field(480.0, 500.0, "counts")
    with pytest.raises(InputError, match="not Earth's field") as exc:
        check_known_field(0.5e-6, 50e-6, "uT")
    assert exc.value.fields == ["field"]
    with pytest.raises(TestError, match="the field given is 0.1x"):
        check_known_field(50.0, 500.0, "counts")
    assert mixup_hint(0.5e-6, "counts", "magnetic_field", ("uT", "gauss"), (10e-6, 140e-6), "units") is None


def test_corrected_logs_of_apply():
    rng = np.random.default_rng(0)
    moving = rng.normal(0, 1.0, (500, 3)) + [0.0, 0.0, G]  # a log in motion: gravity on average
    check_corrected("accelerometer", moving, "m/s^2")
    with pytest.raises(TestError, match=r"mean \|a\| over the corrected log is 1.0\d m/s\^2.*g read as m/s\^2; "
                                        r"set units='g'") as exc:
        check_corrected("accelerometer", moving / G, "m/s^2", where="acc.csv")
    assert exc.value.fields == ["units"] and str(exc.value).startswith("acc.csv: ")
    field = rng.normal(0, 1, (500, 3))
    field = 48e-6 * field / np.linalg.norm(field, axis=1, keepdims=True)
    check_corrected("magnetometer", field, "uT")
    with pytest.raises(TestError, match="uT read as gauss; set units='uT'"):
        check_corrected("magnetometer", field * 100, "gauss")  # a log in uT read as gauss
    check_corrected("magnetometer", field * 100, "counts")
    check_corrected("gyroscope", field, "deg/s")


def test_gravity_and_dip_domains():
    assert check_gravity(9.81) == 9.81
    for g in (-9.81, 0.0, float("nan"), float("inf"), 98.1, 0.981):
        with pytest.raises(InputError) as exc:
            check_gravity(g)
        assert exc.value.fields == ["gravity"]
    with pytest.raises(InputError, match="positive"):
        check_gravity(-9.81, "pos.toml: gravity")
    assert check_dip(-90 * DEG) == pytest.approx(-90 * DEG)
    for dip in (120 * DEG, float("nan")):
        with pytest.raises(InputError, match="-90..90 deg") as exc:
            check_dip(dip)
        assert exc.value.fields == ["dip"]


def test_axes_handedness():
    faces = {0: ["x_p", "x_a"], 1: ["y_p", "y_a"], 2: ["z_p", "z_a"]}
    check_axes(np.eye(3) + 0.01, faces)
    with pytest.raises(HandednessError, match=r"det\(M\) = -1 <= 0, a handedness error: the z axis reads gravity when "
                                              r"-z is up; .*z_p, z_a"):
        check_axes(np.diag([1.0, 1.0, -1.0]), faces, "{sections}")
    swapped = np.array([[0.0, 1, 0], [1, 0, 0], [0, 0, 1]])  # x and y positions swapped: det -1
    with pytest.raises(HandednessError, match="the x axis reads gravity when \\+y is up; the y axis reads gravity when "
                                              "\\+x is up.*x_p, x_a, y_p, y_a"):
        check_axes(swapped, faces)
    with pytest.raises(TestError, match="the x axis reads gravity when -x is up") as exc:
        check_axes(np.diag([-1.0, -1.0, 1.0]), faces)
    assert type(exc.value) is TestError
    check_scale_factors(np.eye(3) * 1.1, 0.2, "m/s^2", "acceleration")
    check_scale_factors(np.eye(3) * 415, 0.2, "counts", "acceleration")
    with pytest.raises(TestError, match="x scale factor 0.102 is outside 1 \\+/- 0.2: wrong units") as exc:
        check_scale_factors(np.diag([0.102, 1, 1]), 0.2, "m/s^2", "acceleration")
    assert exc.value.fields == ["units"]


def test_usable_model():
    check_usable_model(np.eye(3))
    with pytest.raises(HandednessError) as exc:
        check_usable_model(np.diag([1.0, 1.0, -0.998]), "alignment.json")
    assert str(exc.value) == "alignment.json: M has det -0.998 <= 0: a handedness error; regenerate the result"
    with pytest.raises(TestError, match="M is singular \\(condition number"):
        check_usable_model(np.diag([1.0, 1.0, 1e-19]), "alignment.json")
    with pytest.raises(InputError, match="M is not a finite 3x3 matrix"):
        check_usable_model(np.full((3, 3), np.nan), "alignment.json")
    with pytest.raises(TestError, match="soft_iron is not positive definite"):
        check_positive_definite(np.diag([-1.0, -1.0, 1.0]), "mag.json")
    check_positive_definite(np.eye(3) * 1.2)
    require_finite("r.json", "result", M=np.eye(3), misalignment=None)
    with pytest.raises(InputError, match="r.json: malformed result: bias holds null"):
        require_finite("r.json", "result", M=np.eye(3), bias=np.array([0.0, np.nan, 0.0]))


def _alignment(m) -> dict:
    return {"format": "imu-align.alignment", "version": 1, "units": {"bias": "deg/s"}, "method": "lsq",
            "M": np.asarray(m).tolist(), "A": np.linalg.inv(m).tolist() if np.linalg.det(m) else np.eye(3).tolist(),
            "bias": [0.1, 0.0, -0.1]}


def test_alignment_result_refused_before_it_corrects(tmp_path, run_cli):
    ok = AlignmentResult.from_dict(_alignment(np.eye(3)), "alignment.json")
    assert ok.correction(None, "alignment.json") is ok
    flipped = AlignmentResult.from_dict(_alignment(np.diag([1.0, -0.998, 1.0])), "alignment.json")
    with pytest.raises(HandednessError) as exc:
        flipped.correction(None, "alignment.json")
    assert str(exc.value) == "alignment.json: M has det -0.998 <= 0: a handedness error; regenerate the result"
    singular = AlignmentResult.from_dict(_alignment(np.diag([1.0, 1.0, 0.0])), "alignment.json")
    with pytest.raises(TestError, match="singular"):
        singular.correction(None, "alignment.json")
    with pytest.raises(InputError, match="alignment.json: unknown key 'calibraton_note'"):
        AlignmentResult.from_dict({**_alignment(np.eye(3)), "calibraton_note": "typo'd key"}, "alignment.json")
    for bad in ([[1, 0, 0], [0, 1, 0]], "identity", [[1, 0, 0], [0, 1, 0], [0, 0, "x"]]):
        with pytest.raises(InputError) as exc:
            AlignmentResult.from_dict({**_alignment(np.eye(3)), "M": bad}, "alignment.json")
        assert str(exc.value) == ("alignment.json: malformed alignment result: M must be a 3x3 array of numbers; "
                                  "regenerate the result")
    with pytest.raises(InputError, match="missing key 'method'") as exc:
        AlignmentResult.from_dict({k: v for k, v in _alignment(np.eye(3)).items() if k != "method"}, "alignment.json")
    assert "Error" not in str(exc.value)
    null = _alignment(np.eye(3))
    null["M"][2] = [None, None, None]
    with pytest.raises(InputError, match="alignment.json: malformed alignment result: M holds null"):
        AlignmentResult.from_dict(null, "alignment.json")
    # apply: exit 3, one line naming the file, nothing written
    import json

    path, log, out = tmp_path / "alignment.json", tmp_path / "gyro.csv", tmp_path / "out.csv"
    path.write_text(json.dumps(_alignment(np.diag([1.0, -0.998, 1.0]))))
    log.write_text("time,gyro_x,gyro_y,gyro_z\n0,0,0,0\n0.01,0,0,0\n")
    res = run_cli("apply", log, "--alignment", path, "--out", out)
    assert res.code == 3 and "M has det -0.998 <= 0" in res.err and str(path) in res.err and not out.exists(), res.err
    assert len(res.err.strip().splitlines()) == 1
    path.write_text(json.dumps(null))
    res = run_cli("apply", log, "--alignment", path, "--out", out)
    assert res.code == 2 and "M holds null" in res.err and not out.exists(), res.err
