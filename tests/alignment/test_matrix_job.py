"""The ``matrix`` job as a Python call: a session simulated with a known M gives M within its 3-sigma, the result
carries its provenance (log and plan with size and SHA-256), and the one column convention holds."""

import hashlib

import numpy as np
import pytest
from support import truth_model, write_session

from align.alignment.jobs import MATRIX, MatrixOptions, matrix
from align.alignment.plan import Plan
from align.alignment.simulate import SessionSpec, simulate_session
from align.errors import InputError
from align.io import write_csv
from align.io.source import LogSource
from align.units import DEG
from align.units import parse_quantity as q
from align.values import approx_equal

PLAN = Plan.standard_rate(100 * DEG)
SPEC = SessionSpec(noise_density=q("0.3 deg/sqrt(h)", "angle_random_walk"))


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    folder = tmp_path_factory.mktemp("session")
    model = truth_model(2)
    t, g, _ = simulate_session(PLAN, model, SPEC, 2)
    log, plan = write_session(folder, t, g, PLAN)
    return model, t, g, log, plan


def test_a_simulated_session_gives_the_true_m_within_its_three_sigma(session):
    model, _, _, log, plan = session
    r = matrix(log=str(log), plan=str(plan))
    assert np.all(np.abs(r.M - model.M) <= 3 * r.sigma_M), (r.M - model.M) / r.sigma_M
    assert np.all(np.abs(r.bias - model.bias) <= 3 * r.sigma_bias)
    assert np.allclose(r.A @ r.M, np.eye(3), atol=1e-12)


def test_the_result_names_its_files_with_size_and_sha256(session):
    _, _, _, log, plan = session
    r = matrix(log=log, plan=plan)
    prov = r.provenance
    assert prov is not None and prov.job == "matrix"
    files = {f.role: f for f in prov.files}
    assert set(files) == {"log", "plan"}
    for role, path in (("log", log), ("plan", plan)):
        assert files[role].path == str(path)
        assert files[role].size == path.stat().st_size
        assert files[role].sha256 == hashlib.sha256(path.read_bytes()).hexdigest()
    assert prov.options["method"] == "auto" and prov.options["min_dwell"] == 1.0
    assert r.inputs["log"] == str(log) and r.inputs["columns"] == "time,gyro_x,gyro_y,gyro_z"


def test_options_in_si_change_the_result_as_the_command_does(session):
    _, _, _, log, plan = session
    default = MATRIX.run(MatrixOptions(log=log, plan=plan))
    rate = MATRIX.run(MatrixOptions(log=log, plan=plan, method="rate"))
    assert rate.method == "rate" and default.method == "lsq"
    assert not approx_equal(rate.M, default.M, rtol=1e-12)


def test_a_time_column_of_another_name_with_three_data_columns_reads_the_same_log(session, tmp_path):
    _, t, g, log, plan = session
    other = tmp_path / "renamed.csv"
    write_csv(other, ["stamp", "wx", "wy", "wz"], np.column_stack([t, g / DEG]))
    ref = matrix(log=log, plan=plan)
    for src in (LogSource(path=other, columns=("wx", "wy", "wz"), time_column="stamp"),
                LogSource(path=other, columns="stamp,wx,wy,wz")):
        got = matrix(log=src, plan=plan)
        assert approx_equal(got.M, ref.M, rtol=1e-12) and got.inputs["columns"] == "stamp,wx,wy,wz"


@pytest.mark.parametrize("columns, words", [("gyro_x,gyro_x,gyro_z", "named twice"),
                                            ("time,gyro_x,time,gyro_z", "both the time column and a data column"),
                                            ("gyro_x,gyro_y", "give 3 names")])
def test_a_wrong_column_list_is_one_input_error_on_columns(session, columns, words):
    _, _, _, log, plan = session
    with pytest.raises(InputError) as exc:
        matrix(log=LogSource(path=log, columns=columns), plan=plan)
    assert words in str(exc.value) and exc.value.where == "{columns}", str(exc.value)


def test_an_unknown_method_is_refused_before_any_file_is_read(tmp_path):
    with pytest.raises(InputError, match="unknown method 'best'"):
        MatrixOptions(log=tmp_path / "none.csv", plan=tmp_path / "none.toml", method="best")
