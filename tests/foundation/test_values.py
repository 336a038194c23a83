"""Value types: read-only arrays, equality by value, approx_equal; errors rendered per caller."""

from __future__ import annotations

import numpy as np
import pytest

from align.errors import InputError, UnitError
from align.model import SensorModel
from align.units import parse_quantity
from align.values import approx_equal


def test_arrays_are_copied_read_only_and_inputs_untouched():
    m = np.eye(3)
    model = SensorModel(m, [1.0, 2.0, 3.0])
    m[0, 0] = 5.0  # the caller's array is not the model's
    assert model.M[0, 0] == 1.0
    with pytest.raises(ValueError):
        model.M[0, 0] = 2.0
    with pytest.raises(ValueError):
        model.bias[:] = 0.0


def test_equality_by_value_and_tolerance():
    a = SensorModel(np.eye(3), [0.1, 0.2, 0.3])
    assert a == SensorModel(np.eye(3), (0.1, 0.2, 0.3))
    b = SensorModel(np.eye(3) + 1e-13, [0.1, 0.2, 0.3])
    assert a != b
    assert approx_equal(a, b, rtol=1e-12, atol=1e-12)
    assert not approx_equal(a, b, rtol=1e-14)
    assert not approx_equal(a, {"M": a.M})
    nan = SensorModel(np.eye(3), [np.nan, 0.0, 0.0])
    assert nan == SensorModel(np.eye(3), [np.nan, 0.0, 0.0])


def test_errors_name_inputs_in_the_callers_terms():
    err = InputError("no time column: give {rate_hz}", "log.csv")
    assert str(err) == "log.csv: no time column: give rate_hz"
    flags = err.render(lambda name, value: "--" + name.replace("_", "-") + ("" if value is None else f" {value}"))
    assert flags == "log.csv: no time column: give --rate-hz"
    hint = InputError("deg/s read as rad/s: set {gyro_units=deg/s}")
    assert str(hint) == "deg/s read as rad/s: set gyro_units='deg/s'"
    assert hint.fields == ["gyro_units"]
    with pytest.raises(UnitError) as bad:
        parse_quantity("10 mm", "angle", "{axis_to_axis}")
    assert str(bad.value).startswith("axis_to_axis: 'mm' is not an angle")
    # user text with braces that are not placeholders is left alone
    assert str(InputError("bad value {'a': 1}", "f.json")) == "f.json: bad value {'a': 1}"


def test_user_text_with_braces_is_never_read_as_a_placeholder():
    from align.errors import literal

    err = InputError("file not found", "/tmp/{run_a}/nope.csv")
    assert err.render(lambda n, v: "--" + n) == "/tmp/{run_a}/nope.csv: file not found"
    err = InputError(f"folder {literal('/x/{y}')} does not exist; set {{rate_hz=100}}", "{json_out}")
    assert str(err) == "json_out: folder /x/{y} does not exist; set rate_hz='100'"
    assert err.fields == ["json_out", "rate_hz"]
