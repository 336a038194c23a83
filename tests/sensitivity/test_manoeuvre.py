"""Sensitivity, manoeuvre: rate series, refusals naming the field, the dictionary form."""

import numpy as np
import pytest
from support import ROOT

from align.errors import InputError
from align.io import read_toml
from align.sensitivity.allowable import allowable
from align.sensitivity.manoeuvre import Manoeuvre, manoeuvre_from_dict
from align.units import DEG
from align.values import approx_equal

EXAMPLE2 = ROOT / "examples" / "sensitivity" / "example2.toml"


def test_slow_rate_series_time_is_seconds_unless_stated(tmp_path):
    """A 5 Hz trajectory's steps (0.2) would look like ms to a detector: a series' time is stated, not guessed."""
    t = np.arange(0, 10.0, 0.2)
    csv = tmp_path / "rates.csv"
    csv.write_text("time,wx,wy,wz\n" + "\n".join(f"{a:.6f},0,0,10" for a in t) + "\n")
    man = manoeuvre_from_dict({"series": {"file": "rates.csv"}, "limits": {"y": "1 deg"}}, "m", tmp_path)
    assert man.increments.sum(axis=0)[2] == pytest.approx(10 * DEG * t[-1], rel=1e-9)  # 98 deg, not 0.098
    csv.write_text("time,wx,wy,wz\n" + "\n".join(f"{1000 * a:.3f},0,0,10" for a in t) + "\n")
    man = manoeuvre_from_dict({"series": {"file": "rates.csv", "time_units": "ms"}, "limits": {"y": "1 deg"}}, "m",
                              tmp_path)
    assert man.increments.sum(axis=0)[2] == pytest.approx(10 * DEG * t[-1], rel=1e-9)


@pytest.mark.slow
def test_rate_series_fixed_axis_matches_and_gap_is_refused(tmp_path):
    t = np.arange(0, 3.0, 0.01)
    rate = 20.0 * np.sin(np.pi * t / 3.0)  # deg/s about z, a smooth 38 deg turn
    csv = tmp_path / "rates.csv"
    csv.write_text("time,wx,wy,wz\n" + "\n".join(f"{a:.6f},0,0,{r:.9f}" for a, r in zip(t, rate)) + "\n")
    man = manoeuvre_from_dict({"series": {"file": "rates.csv"}, "limits": {"y": "1 deg", "z": "1 deg"}}, "m", tmp_path)
    total = man.increments.sum(axis=0)
    a = allowable(man, directions=50)
    theta = abs(total[2])
    assert a.allowable["phi_yz"] == pytest.approx(np.arcsin(1 * DEG / theta), rel=1e-6)
    rows = csv.read_text().splitlines()
    del rows[100:110]
    csv.write_text("\n".join(rows) + "\n")
    with pytest.raises(InputError, match="gap in the time series at t=0.98"):
        manoeuvre_from_dict({"series": {"file": "rates.csv"}, "limits": {"y": "1 deg"}}, "m", tmp_path)


@pytest.mark.parametrize("text,words", [
    ('[limits]\ny = "1 deg"\n', "no [[rotation]]"),
    ('[[rotation]]\naxis = "z"\nangle = "30 deg"\n[limits]\ny = "0 deg"\n', "limits.y"),
    ('[[rotation]]\naxis = "w"\nangle = "30 deg"\n[limits]\ny = "1 deg"\n', "rotation 1.axis"),
    ('[[rotation]]\naxis = "z"\nangle = "30 mm"\n[limits]\ny = "1 deg"\n', "rotation 1.angle"),
])
def test_bad_manoeuvre_gets_one_line_naming_the_field(tmp_path, run_cli, text, words):
    f = tmp_path / "m.toml"
    f.write_text(text)
    with pytest.raises(InputError, match=words.replace("[", r"\[").replace(".", r"\.")):
        manoeuvre_from_dict(read_toml(f), str(f))
    res = run_cli("allowable", f, "--json", tmp_path / "never.json")
    assert res.code == 2 and words in res.err and res.err.strip().count("\n") == 0
    assert not (tmp_path / "never.json").exists()


def test_example2_reads_as_one_fixed_axis_turn_and_round_trips():
    man = manoeuvre_from_dict(read_toml(EXAMPLE2), str(EXAMPLE2))
    assert man.fixed_axis and man.segments == (("z", pytest.approx(30 * DEG)),)
    assert np.allclose(man.increments, [[0, 0, 30 * DEG]]) and set(man.limits) == {"y", "z"}
    assert not man.increments.flags.writeable
    back = Manoeuvre.from_dict(man.to_dict())
    assert approx_equal(back, man, rtol=1e-12)
    assert man.replace(fixed_axis=False).fixed_axis is False and man.fixed_axis


def _rates_csv(tmp_path, scale=1.0):
    """A smooth 38 deg turn about z in 3 s, written in deg/s times ``scale``."""
    t = np.arange(0, 3.0, 0.01)
    rate = 20.0 * np.sin(np.pi * t / 3.0) * scale
    csv = tmp_path / "rates.csv"
    csv.write_text("time,wx,wy,wz\n" + "\n".join(f"{a:.6f},0,0,{r:.9f}" for a, r in zip(t, rate)) + "\n")
    return csv


LIMITS = '[limits]\ny = "1 deg"\nz = "1 deg"\n'


@pytest.mark.parametrize("text,words", [
    ('[series]\nfile = "rates.csv"\nunit = "rad/s"\n' + LIMITS,
     "m.toml: [series]: unknown key 'unit' (did you mean 'units'? known: file, columns, units, time_units)"),
    ('[series]\nfile = "rates.csv"\ncolumn = "t,a,b,c"\n' + LIMITS, "[series]: unknown key 'column' (did you mean 'columns'?"),
    ('[series]\nfile = "rates.csv"\nunits = "rad"\n' + LIMITS, "m.toml: series.units"),
    ('[series]\nfile = "rates.csv"\nunits = 57.3\n' + LIMITS, "series.units: expected a unit string"),
    ('[series]\nfile = "rates.csv"\ncolumns = "time,wx,wy"\n' + LIMITS, "series.columns: columns must name time and three"),
    ('[series]\nfile = 3\n' + LIMITS, "series.file: expected a file name"),
    ('[series]\ncolumns = "time,wx,wy,wz"\n' + LIMITS, "series.file: missing field file = \"rates.csv\""),
    ('[[rotation]]\naxis = "z"\nangle = "30 deg"\nangel = "3 deg"\n' + LIMITS,
     "m.toml: rotation 1: unknown key 'angel' (did you mean 'angle'? known: axis, angle)"),
    ('[[rotations]]\naxis = "z"\nangle = "30 deg"\n' + LIMITS,
     "m.toml: unknown key 'rotations' (did you mean 'rotation'? known: rotation, series, limits)"),
    ('[rotation]\naxis = "z"\nangle = "30 deg"\n' + LIMITS, "m.toml: [rotation] must be an array of tables"),
    ('[[rotation]]\naxis = "z"\nangle = "30 deg"\n[limit]\ny = "1 deg"\n', "m.toml: unknown key 'limit' (did you mean 'limits'?"),
    ('[[rotation]]\naxis = "z"\nangle = "30 deg"\n[limits]\nazimut = "1 deg"\n',
     "m.toml: [limits]: unknown key 'azimut' (did you mean 'azimuth'? known: x, y, z, azimuth, elevation, roll)"),
    ('[[rotation]]\naxis = "z"\nangle = "30 deg"\n[limits]\ny = "-1 deg"\n', "m.toml: limits.y: a limit must be positive"),
    ('[[rotation]]\naxis = "z"\nangle = "0 deg"\n' + LIMITS, "m.toml: rotation 1.angle: angle is zero"),
    ('[[rotation]]\naxis = "z"\nangle = "1e300 deg"\n' + LIMITS, "rotation 1.angle: 1e+300 deg is beyond any manoeuvre"),
    ('[[rotation]]\naxis = "z"\nangle = "30 deg"\n[series]\nfile = "rates.csv"\n' + LIMITS, "not both"),
])
def test_misspelled_or_bad_manoeuvre_key_is_refused_by_name(tmp_path, text, words):
    _rates_csv(tmp_path)
    f = tmp_path / "m.toml"
    f.write_text(text)
    with pytest.raises(InputError) as err:
        manoeuvre_from_dict(read_toml(f), "m.toml", tmp_path)
    assert words in str(err.value) and "\n" not in str(err.value)


@pytest.mark.slow
def test_series_units_key_reads_rad_per_s_and_columns_may_be_a_list(tmp_path):
    _rates_csv(tmp_path, scale=DEG)   # the same turn written in rad/s
    ref = manoeuvre_from_dict({"series": {"file": "rates.csv", "units": "deg/s"}, "limits": {"z": "1 deg"}}, "m", tmp_path)
    f = tmp_path / "m.toml"
    f.write_text('[series]\nfile = "rates.csv"\ncolumns = ["time", "wx", "wy", "wz"]\nunits = "rad/s"\n' + LIMITS)
    man = manoeuvre_from_dict(read_toml(f), str(f), tmp_path)
    assert np.allclose(man.increments, ref.increments / DEG, rtol=1e-7, atol=1e-15)   # deg/s would be 57.3x smaller
    assert abs(man.increments.sum(axis=0)[2]) == pytest.approx(38.197 * DEG, rel=1e-3)
    a = allowable(man, directions=20)
    assert a.allowable["phi_yz"] is not None and np.isfinite(a.allowable["phi_yz"])


def test_misspelled_series_unit_is_refused_by_allowable_and_nothing_is_written(tmp_path, run_cli):
    _rates_csv(tmp_path, scale=DEG)
    f = tmp_path / "m.toml"
    f.write_text('[series]\nfile = "rates.csv"\nunit = "rad/s"\n' + LIMITS)
    res = run_cli("allowable", f, "--json", tmp_path / "never.json")
    assert res.code == 2 and "unknown key 'unit' (did you mean 'units'?" in res.err
    assert res.err.strip().count("\n") == 0 and not (tmp_path / "never.json").exists()
