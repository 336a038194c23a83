"""The manifest (CSV and TOML) and the content hash that decides what a rerun skips."""

from __future__ import annotations

import pytest

from align.errors import InputError
from align.production import input_hash, read_manifest

JOBS = {"matrix": "required", "calibrate accel": "optional", "calibrate mag": "none", "allan": "none"}


def test_csv_rows_become_units_with_paths_relative_to_the_manifest(tmp_path):
    folder = tmp_path / "lot"
    folder.mkdir()
    (folder / "m.csv").write_text(
        "\ufeff# a comment line\n"
        "Serial, Job ,log,plan,options,slot\n"
        "A1,matrix,logs/a1.csv,plan.toml,\"--gyro-units 'rad/s' --plot p/{serial}.png\",3\n"
        "\n"
        "A2,calibrate   accel,../b.csv,,,\n"
        "A3,allan,c.csv,,--grid octave\n")
    m = read_manifest(folder / "m.csv", JOBS)
    a1, a2, a3 = m.units
    assert (a1.serial, a1.job, a1.slot, a1.order, a1.row) == ("A1", "matrix", "3", 0, "line 3")
    assert a1.log == (folder / "logs" / "a1.csv").resolve() and a1.plan == (folder / "plan.toml").resolve()
    assert a1.options == ("--gyro-units", "rad/s", "--plot", "p/A1.png")
    assert (a2.job, a2.log, a2.plan, a2.options, a2.slot, a2.row) == ("calibrate accel", (tmp_path / "b.csv").resolve(),
                                                                      None, (), None, "line 5")
    assert a3.options == ("--grid", "octave") and a3.order == 2


def test_toml_units_take_the_defaults(tmp_path):
    (tmp_path / "m.toml").write_text('''
[defaults]
job = "matrix"
plan = "plan.toml"
options = ["--min-dwell", "2 s"]

[[unit]]
serial = 17
log = "a.csv"

[[unit]]
serial = "B"
job = "allan"
plan = ""
log = "b.csv"
options = ""
''')
    a, b = read_manifest(tmp_path / "m.toml", JOBS).units
    assert (a.serial, a.job, a.options, a.row) == ("17", "matrix", ("--min-dwell", "2 s"), "[[unit]] 1")
    assert (b.job, b.plan, b.options) == ("allan", None, ())


@pytest.mark.parametrize("text, words", [
    ("serial,job\nA,matrix\n", "line 1: the header has no column log"),
    ("serial,job,log,log\n", "line 1: column log is named twice"),
    ("serial,job,log,plan\nA,matrix,a.csv,p.toml,x\n", "line 2: 5 fields but the header names 4 columns"),
    ("serial,job,log\n,allan,a.csv\n", "line 2, column serial: empty; give the unit's serial number"),
    ("serial,job,log\n.hidden,allan,a.csv\n", "line 2, column serial: '.hidden' cannot name a file"),
    ("serial,job,log\nA,,a.csv\n", "line 2, column job: empty; give one of matrix, calibrate accel"),
    ("serial,job,log\nA,calibrate acel,a.csv\n", "unknown job 'calibrate acel' (did you mean calibrate accel?)"),
    ("serial,job,log\nA,allan,\n", "line 2, column log: empty; give the unit's log file"),
    ("serial,job,log,plan\nA,allan,a.csv,p.toml\n", "line 2, column plan: the allan job takes no plan; leave it empty"),
    ("serial,job,log\n", "lists no units"),
    ("", "is empty; give a header"),
])
def test_a_bad_csv_manifest_names_the_row_and_the_column(tmp_path, text, words):
    (tmp_path / "m.csv").write_text(text)
    with pytest.raises(InputError, match=None) as exc:
        read_manifest(tmp_path / "m.csv", JOBS)
    assert words in str(exc.value) and str(exc.value).startswith(str(tmp_path / "m.csv"))


@pytest.mark.parametrize("text, words", [
    ('[[unit]]\nserial = "A"\njob = "allan"\nlog = "a"\ncolour = "red"\n', "[[unit]] 1: unknown key 'colour'"),
    ('[[unit]]\nserial = "A"\njob = "allan"\nlog = 3.5\n', "[[unit]] 1, column log: give a string (got 3.5)"),
    ('[units]\nx = 1\n', "unknown table or key 'units'"),
    ('[defaults]\njob = "allan"\n', "lists no units"),
])
def test_a_bad_toml_manifest_names_the_unit_and_the_key(tmp_path, text, words):
    (tmp_path / "m.toml").write_text(text)
    with pytest.raises(InputError) as exc:
        read_manifest(tmp_path / "m.toml", JOBS)
    assert words in str(exc.value)


def test_the_content_hash_follows_the_contents_not_the_names_or_times(tmp_path):
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    a.write_bytes(b"time,x\n0,1\n")
    b.write_bytes(b"time,x\n0,1\n")
    h = input_hash("matrix", ("--margin", "0.1 s"), [a, None])
    assert h == input_hash("matrix", ("--margin", "0.1 s"), [b, None])  # another name, the same bytes
    a.write_bytes(b"time,x\n0,1\n")  # written again
    assert h == input_hash("matrix", ("--margin", "0.1 s"), [a, None])
    assert h != input_hash("matrix", ("--margin", "0.2 s"), [a, None])
    assert h != input_hash("matrix", ("--margin 0.1", "s"), [a, None])  # the options' split counts
    assert h != input_hash("allan", ("--margin", "0.1 s"), [a, None])
    assert h != input_hash("matrix", ("--margin", "0.1 s"), [a, a])
    assert h != input_hash("matrix", ("--margin", "0.1 s"), [tmp_path / "missing.csv", None])
    a.write_bytes(b"time,x\n0,2\n")
    assert h != input_hash("matrix", ("--margin", "0.1 s"), [a, None])
