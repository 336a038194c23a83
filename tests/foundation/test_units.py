import math

import pytest

from align.errors import UnitError
from align.units import DEG, parse_quantity, parse_unit, to_unit


@pytest.mark.parametrize("text,expect,si", [
    ("100 deg/s", "angular_rate", 100 * math.pi / 180),
    ("100 dps", "angular_rate", 100 * math.pi / 180),
    ("2500 mdps", "angular_rate", 2.5 * math.pi / 180),
    ("1 rad/s", "angular_rate", 1.0),
    ("15 deg/h", "angular_rate", 15 * math.pi / 180 / 3600),
    ("0.2 mm", "length", 2e-4),
    ("0.3 deg/sqrt(h)", "angle_random_walk", 0.3 * math.pi / 180 / 60),
    ("3 deg/h/sqrt(h)", "rate_random_walk", 3 * math.pi / 180 / 3600 / 60),
    ("-360 deg", "angle", -2 * math.pi),
    ("1 g", "acceleration", 9.80665),
    ("25 ug", "acceleration", 25e-6 * 9.80665),
    ("9.81 m/s^2", "acceleration", 9.81),
    ("50 uT", "magnetic_field", 50e-6),
    ("0.5 gauss", "magnetic_field", 50e-6),
    ("10 %", "dimensionless", 0.1),
    ("100 Hz", "frequency", 100.0),
    ("0.05 m/s/sqrt(h)", "velocity_random_walk", 0.05 / 60),
    ("1e-3 deg/s/sqrt(Hz)", "angle_random_walk", 1e-3 * math.pi / 180),
])
def test_parse_quantity_to_si(text, expect, si):
    assert parse_quantity(text, expect) == pytest.approx(si, rel=1e-12)


def test_noise_density_equals_arw_in_deg_per_sqrt_s():
    # reference section 6: ARW in deg/sqrt(h) = 60 x N in deg/sqrt(s)
    assert parse_quantity("0.3 deg/sqrt(h)", "angle_random_walk") == pytest.approx(
        parse_quantity("0.005 deg/s/sqrt(Hz)", "angle_random_walk"))


@pytest.mark.parametrize("text,expect", [
    ("0.2 mm", "angle"), ("100 deg", "angular_rate"), ("100", "angular_rate"),
    ("5 furlongs", "length"), ("deg/s", "angular_rate"), ("1 deg/s", "length"),
])
def test_bad_quantities_raise_naming_field(text, expect):
    with pytest.raises(UnitError, match="plan.rate"):
        parse_quantity(text, expect, "plan.rate")


def test_round_trip_to_unit():
    assert to_unit(parse_quantity("62.83 deg/h", "angular_rate"), "deg/h") == pytest.approx(62.83)
    assert parse_unit("deg").factor == DEG
