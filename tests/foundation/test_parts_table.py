"""The presets and a user's parts table: parsing, overriding, labels, and a refusal that names the field."""

import pytest
from support import ROOT

from align.errors import InputError
from align.io import read_toml
from align.parts import FIGURES, PARTS, find_part, get_part, merge_parts, parts_from_dict
from align.units import DEG, parse_quantity
from mechanics import budget, mount_from_dict

USER = {
    "MY-IMU": {"kind": "module", "axis_to_package": {"value": "0.6 deg", "source": "MY-IMU datasheet rev B, table 3",
                                                    "confirmed": True},
               "arw": "0.2 deg/sqrt(h)"},
    "adis16485": {"axis_to_package": "0.8 deg"},   # a preset's name, any case: overrides that figure only
}


def test_every_preset_figure_parses_in_its_dimension_and_has_a_source():
    for part in PARTS.values():
        assert part.figures(), part.name
        for name, fig in part.figures():
            assert parse_quantity(fig.value, FIGURES[name]) > 0
            assert fig.source.strip() and isinstance(fig.confirmed, bool)


def test_user_parts_extend_and_override_the_presets():
    table = merge_parts(parts_from_dict(USER, "my.toml"))
    assert set(PARTS) < set(table) and "MY-IMU" in table
    mine = get_part("my-imu", "x", table)
    assert mine.axis_to_package.confirmed and "MY-IMU datasheet rev B" in mine.axis_to_package.source
    assert "my.toml" in mine.axis_to_package.source                      # where it came from is kept
    assert not mine.arw.confirmed and mine.arw.source == "user parts file my.toml"
    over = table["ADIS16485"]                                            # the preset's name is kept
    assert over.axis_to_package.value == "0.8 deg" and "my.toml" in over.axis_to_package.source
    assert over.arw == PARTS["ADIS16485"].arw and over.package_x == PARTS["ADIS16485"].package_x
    assert PARTS["ADIS16485"].axis_to_package.value == "1 deg"           # the built-in table is untouched
    assert find_part("MY-IMU") is None and find_part("adis16485") is PARTS["ADIS16485"]


@pytest.mark.parametrize("data,words", [
    ({"X": 1}, ["my.toml", "'X' must be a table"]),
    ({"X": {"axis_to_pakage": "1 deg"}}, ["my.toml: [X]", "unknown key 'axis_to_pakage'", "did you mean 'axis_to_package'"]),
    ({"X": {"arw": "1 deg"}}, ["my.toml: X.arw", "angle random walk"]),
    ({"X": {"arw": 0.3}}, ["my.toml: X.arw", "with its unit", "0.3"]),
    ({"X": {"arw": "-0.3 deg/sqrt(h)"}}, ["my.toml: X.arw", "> 0"]),
    ({"X": {"kind": "board", "arw": "0.3 deg/sqrt(h)"}}, ["my.toml: X.kind", "module, chip"]),
    ({"X": {"arw": {"source": "ds"}}}, ["my.toml: X.arw", "missing key 'value'"]),
    ({"X": {"arw": {"value": "0.3 deg/sqrt(h)", "confirmed": "yes"}}}, ["X.arw.confirmed", "true or false"]),
    ({"X": {"arw": {"value": "0.3 deg/sqrt(h)", "sorce": "ds"}}}, ["X.arw", "unknown key 'sorce'"]),
    ({"X": {"kind": "chip"}}, ["my.toml: [X]", "gives no figure"]),
    ({}, ["my.toml", "holds no part"]),
])
def test_malformed_parts_file_names_the_field(data, words):
    with pytest.raises(InputError) as exc:
        parts_from_dict(data, "my.toml")
    text = str(exc.value)
    assert "\n" not in text
    for w in words:
        assert w in text, (w, text)


def test_unknown_part_names_the_nearest_and_the_parts_file():
    with pytest.raises(InputError, match="did you mean 'ADIS16485'.*parts file") as exc:
        get_part("ADIS1648", "mount.toml: imu.part")
    assert exc.value.fields == ["parts"]


def _mount(**imu):
    data = read_toml(ROOT / "examples" / "budget" / "example1.toml")
    data["imu"] = imu
    return data


def test_mount_takes_a_user_part_records_its_source_and_accepts_a_label():
    table = merge_parts(parts_from_dict(USER, "my.toml"))
    m = mount_from_dict(_mount(part="MY-IMU"), "m.toml", parts=table)
    assert m.part == "MY-IMU" and m.axis_to_package[0] == pytest.approx(0.6 * DEG)
    assert m.preset["axis_to_package"]["confirmed"] is True and "rev B" in m.preset["axis_to_package"]["source"]
    b = budget(m)
    assert b.to_dict()["mount"]["preset"] == m.preset and type(b).from_dict(b.to_dict()) == b
    # a name that is no preset, with every value the budget needs: a label, no preset value used
    label = mount_from_dict(_mount(part="BENCH-IMU-7", axis_to_package="0.4 deg"), "m.toml")
    assert label.part == "BENCH-IMU-7" and label.preset == {} and label.axis_to_package[0] == pytest.approx(0.4 * DEG)
    # a preset whose value the file gives: the file's value, no preset value used
    own = mount_from_dict(_mount(part="ADIS16485", axis_to_package="0.3 deg"), "m.toml")
    assert own.part == "ADIS16485" and own.preset == {}
    with pytest.raises(InputError, match="m.toml: imu.part: unknown part 'BENCH-IMU-7'.*as a label"):
        mount_from_dict(_mount(part="BENCH-IMU-7"), "m.toml")
    with pytest.raises(InputError, match="imu.part: must be a part name"):
        mount_from_dict(_mount(part=7, axis_to_package="1 deg"), "m.toml")
