"""Foundation, keys: unknown keys refused with the nearest valid one; every bundled input still loads."""

import pytest
from support import ROOT

from align.alignment.plan import Plan
from align.errors import InputError
from align.io import read_toml
from align.io.keys import check_keys, require_keys, table, tables
from align.sensitivity.manoeuvre import manoeuvre_from_dict
from mechanics.mount import mount_from_dict

TEST_KEYS = ("latitude", "rate_accuracy", "angle_accuracy")


def test_unknown_key_names_key_table_and_nearest_valid_key():
    with pytest.raises(InputError) as err:
        check_keys({"latitud": "48 deg"}, TEST_KEYS, "plan.toml: [test]")
    assert str(err.value) == ("plan.toml: [test]: unknown key 'latitud' (did you mean 'latitude'? "
                              "known: latitude, rate_accuracy, angle_accuracy)")
    assert "\n" not in str(err.value) and err.value.fields == []


def test_unknown_key_far_from_every_known_key_lists_them_without_a_guess():
    with pytest.raises(InputError) as err:
        check_keys({"latitude": "1 deg", "colour": "red"}, TEST_KEYS, "p.toml: [test]")
    msg = str(err.value)
    assert "'colour'" in msg and "did you mean" not in msg and "known: latitude, rate_accuracy" in msg


def test_known_keys_pass_and_braces_in_a_key_never_read_as_an_input_placeholder():
    check_keys({}, TEST_KEYS, "x")
    check_keys({"latitude": 1, "angle_accuracy": 2}, TEST_KEYS, "x")
    with pytest.raises(InputError) as err:
        check_keys({"{rate_hz}": 1}, TEST_KEYS, "x")
    assert err.value.fields == [] and "unknown key '{rate_hz}'" in str(err.value)
    with pytest.raises(InputError, match="x: unknown key 'a' .known: none"):
        check_keys({"a": 1}, (), "x")


def test_require_keys_names_the_missing_key_with_an_example():
    require_keys({"start": 0, "end": 1}, {"start": '"start": 0', "end": '"end": 9'}, "s.json: a")
    with pytest.raises(InputError, match=r"s\.json: a: missing key 'end' \(e\.g\. \"end\": 9\)"):
        require_keys({"start": 0}, {"start": '"start": 0', "end": '"end": 9'}, "s.json: a")


def test_table_and_tables_refuse_the_wrong_shape_in_one_line():
    assert table({}, "test", "p") == {} and tables({}, "step", "p") == []
    assert table({"test": {"a": 1}}, "test", "p") == {"a": 1}
    with pytest.raises(InputError, match=r"p: missing table \[imu\]"):
        table({}, "imu", "p", required=True)
    with pytest.raises(InputError, match=r"p: \[test\] must be a table"):
        table({"test": 3}, "test", "p")
    with pytest.raises(InputError, match=r"p: \[step\] must be an array of tables: write \[\[step\]\]"):
        tables({"step": {"axis": "x"}}, "step", "p")
    with pytest.raises(InputError, match=r"p: 'step' must be \[\[step\]\] tables"):
        tables({"step": [{"axis": "x"}, 3]}, "step", "p")


def _reader(data: dict):
    """The reader a bundled TOML is for, told by its tables."""
    if "unit" in data:  # a lot's manifest
        from align.cli.batch import _jobs
        from align.production.manifest import read_manifest

        return lambda d, where, folder: read_manifest(where, _jobs())
    if any("_" in k and isinstance(v, dict) and v.keys() & {"min", "max", "abs_max"} for k, v in data.items()):
        from align.production.spec import read_spec

        return lambda d, where, folder: read_spec(where)  # a lot's limits
    if "step" in data:
        return lambda d, where, folder: Plan.from_dict(d, where)
    if "imu" in data:
        return mount_from_dict
    if "limits" in data:
        return manoeuvre_from_dict
    raise AssertionError(f"a bundled TOML of unknown kind: {sorted(data)}")


BUNDLED = sorted((ROOT / "examples").glob("*/*.toml")) + sorted((ROOT / "align").rglob("*.toml"))


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_bundled_input_file_loads_with_its_strict_reader(path):
    data = read_toml(path)
    assert _reader(data)(data, str(path), path.parent) is not None


def test_the_bundled_inputs_cover_every_kind():
    kinds = {("step" in d, "imu" in d, "limits" in d, "unit" in d) for d in map(read_toml, BUNDLED)}
    assert len(BUNDLED) >= 6 and kinds == {(True, False, False, False), (False, True, False, False),
                                           (False, False, True, False), (False, False, False, True),
                                           (False, False, False, False)}  # the last: a lot's spec


def test_file_name_resolves_in_the_input_folder_and_refuses_a_non_name(tmp_path):
    from align.io.keys import file_name, referenced_file

    assert file_name({"file": "r.csv"}, "file", "m: series.file", "rates.csv", tmp_path) == tmp_path / "r.csv"
    assert file_name({"file": "/abs/r.csv"}, "file", "w", "rates.csv", tmp_path).as_posix() == "/abs/r.csv"
    with pytest.raises(InputError, match=r"m: series\.file: missing field file = \"rates\.csv\""):
        file_name({}, "file", "m: series.file", "rates.csv")
    with pytest.raises(InputError, match=r"w: expected a file name \(stl = \"plate\.stl\"\), got 3"):
        file_name({"stl": 3}, "stl", "w", "plate.stl")
    assert referenced_file({"series": {"file": "r.csv"}}, "series", "file", tmp_path) == tmp_path / "r.csv"
    assert referenced_file({"series": 3}, "series", "file") is None and referenced_file({}, "series", "file") is None


def test_the_data_files_a_mount_or_manoeuvre_reads_are_listed_for_output_checks(tmp_path):
    from align.sensitivity.manoeuvre import manoeuvre_inputs
    from mechanics.mount import mount_inputs

    assert manoeuvre_inputs({"series": {"file": "rates.csv"}}, tmp_path) == [tmp_path / "rates.csv"]
    assert manoeuvre_inputs({"rotation": [{"axis": "z", "angle": "30 deg"}]}, tmp_path) == []
    assert mount_inputs({"baseplate": {"stl": "plate.stl"}}, tmp_path) == [tmp_path / "plate.stl"]
    assert mount_inputs(read_toml(ROOT / "examples" / "budget" / "example1.toml")) == []
