"""The ``allan`` job as a library call (align.noise.jobs): a known white noise found within its interval, the
provenance, the one column convention, and the checks of a record before any computing (issue 28).

Every record here is simulated with numpy alone (not the package's simulator): white noise of a known
per-sample standard deviation, whose angle random walk is ``sigma / sqrt(fs)``.
"""

from __future__ import annotations

import hashlib
import math

import numpy as np
import pytest

from align.errors import InputError, TestError, UnitError
from align.io.formats import LogFormat
from align.io.source import LogSource
from align.noise.jobs import ALLAN, AllanOptions, allan
from align.values import approx_equal

FS = 100.0
SIGMA = 0.05  # deg/s per sample
N_TRUE = SIGMA / math.sqrt(FS) * 60  # deg/sqrt(h): 0.3
N = 40_000


def _white(n: int, seed: int, channels: int = 3, sigma: float = SIGMA) -> np.ndarray:
    return np.random.default_rng(seed).standard_normal((n, channels)) * sigma


def _csv(path, header: str, *cols) -> None:
    np.savetxt(path, np.column_stack(cols), delimiter=",", header=header, comments="", fmt="%.10g")


def _same(a, b) -> bool:
    da, db = a.to_dict(), b.to_dict()
    for d in (da, db):
        d.pop("provenance", None)
        d.pop("generator", None)
    return approx_equal(da, db, rtol=1e-12)


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    d = tmp_path_factory.mktemp("allan_api")
    t = np.arange(N) / FS
    data = _white(N, 1) + np.array([0.1, -0.2, 0.05])
    _csv(d / "static.csv", "time,gyro_x,gyro_y,gyro_z", t, data)
    _csv(d / "stamp.csv", "stamp,gx,gy,gz", t, data)
    return d


def test_white_noise_found_within_its_interval_with_the_provenance(folder):
    rec = folder / "static.csv"
    res = allan(logs=rec)
    d = res.to_dict()
    for name in ("gyro_x", "gyro_y", "gyro_z"):
        term = d["fit"][name]["terms"]["angle_random_walk"]
        assert term["identifiable"] and term["unit"] == "deg/sqrt(h)"
        assert abs(term["value"] - N_TRUE) <= 3 * term["sigma"], (name, term)
    prov = res.provenance
    assert prov.job == "allan" and prov.version.startswith("imu-align")
    (f,) = prov.files
    assert f.role == "log" and f.path == str(rec) and f.size == rec.stat().st_size
    assert f.sha256 == hashlib.sha256(rec.read_bytes()).hexdigest()
    # no unit typed (None: the unit the file states, else deg/s); the unit used is the result's
    assert prov.options["logs"] == [str(rec)] and prov.options["gyro_units"] is None and res.units == "deg/s"
    assert d["provenance"]["job"] == "allan" and d["inputs"] == [str(rec)]


def test_the_job_the_call_and_a_log_source_agree(folder):
    rec = folder / "static.csv"
    by_job = ALLAN.run(AllanOptions(logs=(rec,)))
    assert _same(by_job, allan(logs=str(rec)))
    assert _same(by_job, allan(logs=LogSource(path=rec, columns=("gyro_x", "gyro_y", "gyro_z"))))
    with pytest.raises(TypeError, match="colums"):
        allan(logs=rec, colums="a,b,c")


def test_four_columns_mean_time_first_and_a_rate_drops_the_time_column(folder):
    rec = folder / "static.csv"
    plain = allan(logs=rec)
    assert _same(allan(logs=rec, columns="time,gyro_x,gyro_y,gyro_z"), plain)  # was an internal error
    at_rate = allan(logs=rec, columns="time,gyro_x,gyro_y,gyro_z", rate_hz=FS)
    assert at_rate.result.names == ("gyro_x", "gyro_y", "gyro_z")  # the time column is not analysed as a gyro
    assert approx_equal(at_rate.result.adev, plain.result.adev, rtol=1e-9)


def test_a_time_column_of_another_name(folder):
    rec = folder / "stamp.csv"
    named = allan(logs=rec, columns="gx,gy,gz", time_column="stamp")
    assert named.result.fs == pytest.approx(FS)
    assert _same(named, allan(logs=rec, columns="stamp,gx,gy,gz"))
    with pytest.raises(InputError):  # no column 'time': the time column must be named
        allan(logs=rec, columns="gx,gy,gz")


@pytest.mark.parametrize("columns, said", [("gyro_x,gyro_x,gyro_z", "named twice"),
                                           ("time,gyro_x,gyro_y", "both the time column and a data column")])
def test_a_column_named_twice_is_one_input_error(folder, columns, said):
    with pytest.raises(InputError, match=said) as exc:
        allan(logs=folder / "static.csv", columns=columns)
    assert exc.value.where == "{columns}"


# ---- the checks of a record (issue 28: allan analysed whatever it got) ----


def test_a_rate_table_session_is_not_a_static_record(tmp_path):
    n = 30_000
    rate = np.where((np.arange(n) // 1000) % 3 == 1, 100.0, np.where((np.arange(n) // 1000) % 3 == 2, -100.0, 0.0))
    data = _white(n, 2)
    data[:, 2] += rate  # +/-100 deg/s dwells about z
    rec = tmp_path / "table.csv"
    _csv(rec, "time,gyro_x,gyro_y,gyro_z", np.arange(n) / FS, data)
    with pytest.raises(InputError, match="not a static record") as exc:
        allan(logs=rec)
    assert exc.value.where == str(rec) and "gyro_z" in exc.value.message and "{columns}" in exc.value.message
    assert "-100" in exc.value.message and "100 deg/s" in exc.value.message


def test_a_drifting_but_static_gyro_is_accepted(tmp_path):
    n = 30_000
    data = _white(n, 3) + np.linspace(0, 2.0, n)[:, None]  # 2 deg/s of thermal drift: still at rest
    rec = tmp_path / "drift.npy"
    np.save(rec, data)
    assert allan(logs=rec, rate_hz=FS).runs == 1


def test_an_accelerometer_in_g_read_as_m_s2_is_refused_with_the_unit_to_give(tmp_path):
    n = 30_000
    acc_g = _white(n, 4, sigma=0.002) + np.array([0.01, -0.02, 1.0])  # at rest, z up, in g
    rec = tmp_path / "acc.csv"
    _csv(rec, "time,acc_x,acc_y,acc_z", np.arange(n) / FS, acc_g)
    with pytest.raises(UnitError) as exc:
        allan(logs=rec, columns="acc_x,acc_y,acc_z", units="m/s^2")
    assert exc.value.where == str(rec) and "1.00 m/s^2" in exc.value.message and "{units=g}" in exc.value.message
    in_g = allan(logs=rec, columns="acc_x,acc_y,acc_z", units="g")
    in_si = allan(logs=_si_copy(tmp_path, acc_g), columns="acc_x,acc_y,acc_z", units="m/s^2")
    # the same noise either way: the velocity random walk is not 9.8x too small
    assert approx_equal(in_g.result.adev, in_si.result.adev, rtol=1e-6)


def _si_copy(tmp_path, acc_g):
    rec = tmp_path / "acc_si.csv"
    _csv(rec, "time,acc_x,acc_y,acc_z", np.arange(len(acc_g)) / FS, acc_g * 9.80665)
    return rec


def test_a_rate_the_time_column_contradicts_is_refused(folder):
    rec = folder / "static.csv"
    with pytest.raises(InputError, match="100 Hz") as exc:
        allan(logs=rec, rate_hz=50.0)
    assert exc.value.where == str(rec) and "{rate_hz}" in exc.value.message
    assert allan(logs=rec, rate_hz=100.0).result.fs == 100.0  # agreeing: as before


def test_a_time_unit_that_gives_no_imu_rate_is_refused(folder, tmp_path):
    rec = folder / "static.csv"
    with pytest.raises(InputError) as exc:
        allan(logs=rec, format=LogFormat(time_units="ms"))
    assert exc.value.where == str(rec) and "100 kHz" in exc.value.message and "{time_units=s}" in exc.value.message
    ms = tmp_path / "ms.csv"  # a 1 kHz record stamped in ms: its unit given is accepted
    n = 20_000
    _csv(ms, "time,gyro_x,gyro_y,gyro_z", np.arange(n) * 1.0, _white(n, 5))
    assert allan(logs=ms, format=LogFormat(time_units="ms")).result.fs == pytest.approx(1000.0)


def test_raw_counts_read_as_deg_s_are_still_refused(tmp_path):
    n = 20_000
    counts = np.round((_white(n, 6) + np.array([3.0, -1.0, 0.5])) * 131)  # an MPU-6050 at +/-250 deg/s
    rec = tmp_path / "counts.npy"
    np.save(rec, counts)
    with pytest.raises(TestError, match="131 LSB"):
        allan(logs=rec, rate_hz=FS)
    assert allan(logs=rec, rate_hz=FS, gyro_units="131 LSB/(deg/s)").units == "deg/s"
