"""Alignment, plan and segments files: strict keys and values, each refusal naming file, table and key."""

import json
import math

import pytest
from support import ROOT, SHARED

from align.alignment.plan import Plan, Step
from align.alignment.segment import segments_from_ranges
from align.errors import InputError
from align.io import read_json, read_toml
from align.units import DEG

EXAMPLE = ROOT / "examples" / "alignment"
STEP = '[[step]]\naxis = "+x"\nrate = "100 deg/s"\n'


def _plan(tmp_path, text):
    f = tmp_path / "plan.toml"
    f.write_text(text)
    return Plan.from_dict(read_toml(f), "plan.toml")


@pytest.mark.parametrize("text,words", [
    ('[test]\nlatitud = "48.1 deg"\n' + STEP,
     "plan.toml: [test]: unknown key 'latitud' (did you mean 'latitude'? known: latitude, rate_accuracy, angle_accuracy, "
     "table_axis, rest)"),
    ('[test]\nrate_acuracy = "0.01 %"\n' + STEP, "[test]: unknown key 'rate_acuracy' (did you mean 'rate_accuracy'?"),
    ('[[step]]\naxis = "+x"\nrat = "100 deg/s"\n', "plan.toml: step 1: unknown key 'rat' (did you mean 'rate'?"),
    (STEP + '[[step]]\naxis = "+y"\nangle = "90 deg"\nangel = "9 deg"\n', "step 2: unknown key 'angel' (did you mean 'angle'?"),
    ('[[steps]]\naxis = "+x"\nrate = "100 deg/s"\n',
     "plan.toml: unknown key 'steps' (did you mean 'step'? known: test, step, mounting)"),
    ('[tests]\nlatitude = "48 deg"\n' + STEP, "plan.toml: unknown key 'tests' (did you mean 'test'?"),
    ('latitude = "48 deg"\n' + STEP, "plan.toml: unknown key 'latitude' (known: test, step, mounting)"),
    ('[step]\naxis = "+x"\nrate = "100 deg/s"\n', "plan.toml: [step] must be an array of tables: write [[step]]"),
    ('[test]\nlatitude = "48 deg"\n', "plan.toml: no [[step]] tables"),
    ('test = 3\n' + STEP, "plan.toml: [test] must be a table"),
    ('[test]\nrate_accuracy = nan\n' + STEP, "plan.toml: test.rate_accuracy: nan is not a finite number"),
    ('[test]\nrate_accuracy = "-1 %"\n' + STEP, "test.rate_accuracy: must be a finite accuracy, zero or more"),
    ('[test]\nrate_accuracy = "150 %"\n' + STEP, "test.rate_accuracy: 150 % is not a table-rate accuracy"),
    ('[test]\nangle_accuracy = "-0.1 deg"\n' + STEP, "test.angle_accuracy: must be a finite accuracy"),
    ('[test]\nlatitude = "91 deg"\n' + STEP, "test.latitude: latitude must lie within +/-90 deg"),
    ('[[step]]\naxis = "+x"\nrate = "0 deg/s"\n', "step 1.rate: rate is zero; a step must turn the table"),
    ('[[step]]\naxis = "+x"\nangle = "-0 deg"\n', "step 1.angle: angle is zero"),
    ('[[step]]\naxis = "+x"\nangle = "100001 deg"\n', "step 1.angle: 1e+05 deg is beyond any rate table"),
    ('[[step]]\naxis = "+x"\nrate = "1e400 deg/s"\n', "step 1.rate"),
    ('[[step]]\nrate = "100 deg/s"\n', "step 1: missing 'axis'"),
    ('[[step]]\naxis = "+x"\nrate = "1e300 deg/s"\n',
     "step 1.rate: 1e+300 deg/s is beyond any rate table (at most 100000 deg/s)"),
    ('[[step]]\naxis = "+x"\nangle = "-2e5 deg"\n', "step 1.angle: -2e+05 deg is beyond any rate table"),
])
def test_bad_plan_file_is_refused_naming_table_and_key(tmp_path, text, words):
    with pytest.raises(InputError) as err:
        _plan(tmp_path, text)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_every_valid_plan_key_is_accepted_and_the_written_plan_reads_back(tmp_path):
    plan = _plan(tmp_path, '[test]\nlatitude = "48.1 deg"\nrate_accuracy = "0.01 %"\nangle_accuracy = "0.002 deg"\n'
                 '[[step]]\naxis = "-y"\nrate = "-50 deg/s"\n[[step]]\naxis = "z"\nangle = "360 deg"\n')
    assert plan.latitude == pytest.approx(48.1 * DEG) and plan.rate_accuracy == pytest.approx(1e-4)
    assert plan.angle_accuracy == pytest.approx(0.002 * DEG)
    assert plan.steps == (Step(1, -1, rate=pytest.approx(-50 * DEG)), Step(2, 1, angle=pytest.approx(2 * math.pi)))
    assert _plan(tmp_path, plan.to_toml()) == plan
    bundled = Plan.from_dict(read_toml(EXAMPLE / "plan.toml"), "plan.toml")
    assert len(bundled.steps) == 6 and _plan(tmp_path, bundled.to_toml()) == bundled


def test_misspelled_latitude_is_refused_by_matrix_and_nothing_is_written(tmp_path, run_cli):
    plan = tmp_path / "plan.toml"
    plan.write_text('[test]\nlatitud = "48.1 deg"\n\n' + (EXAMPLE / "plan.toml").read_text())
    out = tmp_path / "r.json"
    res = run_cli("matrix", EXAMPLE / "session.csv", "--plan", plan, "--json", out)
    assert res.code == 2 and "unknown key 'latitud' (did you mean 'latitude'?" in res.err
    assert res.err.strip().count("\n") == 0 and not out.exists()


PLAN2 = Plan((Step(0, 1, rate=DEG), Step(1, 1, rate=DEG)))


def test_explicit_segments_read_names_kinds_and_steps():
    segs = segments_from_ranges({"static 1": {"start": 0, "end": 10}, "x": {"start": 10, "end": 20},
                                 "y": {"start": 25, "end": 40}}, PLAN2, 50, "s.json")
    assert [(s.name, s.kind, s.start, s.end, s.step) for s in segs] == [
        ("static 1", "static", 0, 10, None), ("x", "rate", 10, 20, 0), ("y", "rate", 25, 40, 1)]


@pytest.mark.parametrize("ranges,words", [
    ({"x": {"start": 0, "end": 10, "ned": 12}, "y": {"start": 10, "end": 20}},
     "s.json: x: unknown key 'ned' (did you mean 'end'? known: start, end)"),
    ({"x": {"start": 0, "stop": 10}, "y": {"start": 10, "end": 20}}, "s.json: x: unknown key 'stop'"),
    ({"x": {"start": 0}, "y": {"start": 10, "end": 20}}, "s.json: x: missing key 'end'"),
    ({"x": [0, 10], "y": {"start": 10, "end": 20}}, "s.json: x: must be an object"),
    ({"x": {"start": True, "end": 10}, "y": {"start": 10, "end": 20}},
     "s.json: x: start=True, end=10: sample indices must be whole numbers"),
    ({"x": {"start": 0.5, "end": 10}, "y": {"start": 10, "end": 20}}, "sample indices must be whole numbers"),
    ({"x": {"start": 10, "end": 10}, "y": {"start": 10, "end": 20}}, "is not a sample range inside the log's 50 rows"),
    ({"x": {"start": 0, "end": 51}, "y": {"start": 10, "end": 20}}, "s.json: x: start=0, end=51 is not a sample range"),
    ({"x": {"start": 0, "end": 12}, "y": {"start": 10, "end": 20}}, "s.json: y: samples 10-20 overlap 'x' (0-12)"),
    ({"x": {"start": 0, "end": 10}, "static": {"start": 5, "end": 8}, "y": {"start": 10, "end": 20}},
     "s.json: static: samples 5-8 overlap 'x'"),
    ({"x": {"start": 0, "end": 10}}, "s.json: 1 step segments for a plan of 2 steps"),
    ({"x": {"start": 0, "end": 10}, "y": {"start": 10, "end": 20}, "z": {"start": 20, "end": 30}},
     "s.json: z: more step segments than the plan's 2 steps"),
])
def test_bad_segments_file_is_refused_naming_the_range_and_key(ranges, words):
    with pytest.raises(InputError) as err:
        segments_from_ranges(ranges, PLAN2, 50, "s.json")
    assert words in str(err.value) and "\n" not in str(err.value)


def test_imucal_section_list_reads_as_explicit_segments():
    data = read_json(SHARED / "data" / "multiposition" / "imucal_ferraris" / "example_ferraris_session_list.json")
    plan = Plan(tuple(Step(k % 3, 1, rate=DEG) for k in range(len(data))))
    segs = segments_from_ranges(data, plan, 10_000, "sections.json")
    assert [s.name for s in segs] == list(data) and all(s.kind == "rate" for s in segs)


def test_duplicate_range_names_in_a_segments_file_are_refused(tmp_path):
    f = tmp_path / "s.json"
    f.write_text('{"x": {"start": 0, "end": 10}, "x": {"start": 10, "end": 20}}')
    with pytest.raises(InputError, match="key 'x' is given twice"):
        read_json(f)
    f.write_text(json.dumps({"x": {"start": 0, "end": 10}, "y": {"start": 10, "end": 20}}))
    assert len(segments_from_ranges(read_json(f), PLAN2, 50, str(f))) == 2


def test_standard_plans_refuse_a_zero_or_impossible_turn_naming_the_input():
    assert len(Plan.standard_rate(100 * DEG).steps) == 6 and len(Plan.standard_angle(-360 * DEG).steps) == 6
    for make, value, words in [(Plan.standard_rate, 0.0, "rate: rate is zero"),
                               (Plan.standard_rate, 1e300, "rate: 5.73e+301 deg/s is beyond any rate table"),
                               (Plan.standard_rate, float("nan"), "rate: rate is nan, not a finite number"),
                               (Plan.standard_angle, 0.0, "angle: angle is zero"),
                               (Plan.standard_angle, 1e4, "angle: 5.73e+05 deg is beyond")]:
        with pytest.raises(InputError) as err:
            make(value)
        assert str(err.value).startswith(words) and err.value.fields == [words.split(":")[0]]
