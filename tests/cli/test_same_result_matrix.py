"""``matrix`` gives one result whichever client runs it: the command line (--json), the library job and the
report (its alignment from a log and a plan), on the bundled example session; ``apply`` likewise for the CLI and
the library."""

import json

import numpy as np
from support import ROOT

from align.alignment.jobs import APPLY, ApplyOptions, MatrixOptions, apply, matrix
from align.cli.apply import apply_options
from align.cli.matrix import matrix_options
from align.results import load_result, result_from_dict
from align.values import approx_equal

SESSION = ROOT / "examples" / "alignment" / "session.csv"
PLAN = ROOT / "examples" / "alignment" / "plan.toml"


def test_cli_library_and_report_give_the_same_alignment(tmp_path, run_cli):
    out = tmp_path / "r.json"
    res = run_cli("matrix", SESSION, "--plan", PLAN, "--json", out)
    assert res.code == 0, res.err
    cli = load_result(out)
    lib = matrix(log=SESSION, plan=PLAN)
    from align.present.story import make_report

    rep = make_report(log=SESSION, plan=PLAN).results["alignment"]
    # the file holds numbers written in deg/s and read back: equal to the last bits
    assert approx_equal(cli, lib, rtol=1e-12, atol=1e-15)
    assert approx_equal(rep, lib, rtol=0.0, atol=0.0)
    assert cli.provenance.files == lib.provenance.files == rep.provenance.files
    assert cli.provenance.options == lib.provenance.options == rep.provenance.options


def test_the_command_s_options_are_the_job_s_options(tmp_path):
    given = matrix_options(log=SESSION, plan=PLAN, json_out=tmp_path / "x.json", unknown=1)
    assert given == MatrixOptions(log=SESSION, plan=PLAN)
    rows = apply_options(log=SESSION, alignment=tmp_path / "r.json", out=tmp_path / "c.csv", plot=None)
    assert rows == ApplyOptions(log=SESSION, alignment=tmp_path / "r.json")


def test_apply_cli_writes_what_the_library_returns(tmp_path, run_cli):
    result = tmp_path / "r.json"
    assert run_cli("matrix", SESSION, "--plan", PLAN, "--json", result).code == 0
    out = tmp_path / "c.csv"
    res = run_cli("apply", SESSION, "--alignment", result, "--out", out)
    assert res.code == 0, res.err
    lib = apply(log=SESSION, alignment=result)
    assert lib.provenance.job == "apply" and {f.role for f in lib.provenance.files} == {"log", "alignment"}
    stated, header = out.read_text().splitlines()[:2]
    assert header == ",".join(f'"{c}"' for c in lib.columns) or header == ",".join(lib.columns), header
    assert stated.endswith(f"units: time=s, {', '.join(f'{c}={lib.units}' for c in lib.columns[1:])}")
    written = np.loadtxt(out, delimiter=",", skiprows=2)
    assert np.allclose(written, lib.table(), rtol=1e-12, atol=1e-12)
    again = APPLY.run(ApplyOptions(log=SESSION, alignment=result))
    assert approx_equal(again, lib) and approx_equal(result_from_dict(json.loads(json.dumps(lib.to_dict()))), lib)
