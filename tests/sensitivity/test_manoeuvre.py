"""Sensitivity, manoeuvre: rate series, refusals naming the field, the dictionary form."""

import numpy as np
import pytest
from conftest import ROOT

from align.errors import InputError
from align.io import read_toml
from align.sensitivity.allowable import allowable
from align.sensitivity.manoeuvre import Manoeuvre, manoeuvre_from_dict
from align.units import DEG
from align.values import approx_equal

EXAMPLE2 = ROOT / "examples" / "sensitivity" / "example2.toml"


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
