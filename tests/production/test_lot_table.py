"""The lot's table: one Parquet file appended atomically, read back as one table by pandas and pyarrow."""

from __future__ import annotations

import math
from datetime import UTC, datetime, timedelta

import pandas as pd
import pyarrow as pa
import pyarrow.dataset as ds
import pyarrow.parquet as pq
import pytest

from align.errors import InputError
from align.production import FIGURES, Journal, append_rows, latest_rows, read_table

T0 = datetime(2026, 3, 1, 8, 0, tzinfo=UTC)


def _row(serial, minutes, run="r1", phi=0.001, status="ok", sensor="gyroscope"):
    return {"serial": serial, "order": int(serial[1:]), "run": run, "time": T0 + timedelta(minutes=minutes),
            "job": "matrix", "sensor": sensor, "status": status, "exit_code": 0, "phi_xy": phi, "scale_x": 1.001,
            "arw_x": math.nan}


def test_appends_make_one_table_every_reader_takes_as_it_is(tmp_path):
    path = tmp_path / "results.parquet"
    assert append_rows(path, [_row("U1", 0), _row("U2", 1)]) == 2
    assert append_rows(path, [_row("U1", 60, "r2", phi=0.002)]) == 1
    assert append_rows(path, []) == 0
    df = pd.read_parquet(path)  # pandas: one file, one table
    assert len(df) == 3 and list(df.columns[:3]) == ["serial", "slot", "order"]
    assert set(FIGURES) <= set(df.columns) and df.phi_xy.tolist() == [0.001, 0.001, 0.002]
    assert df.arw_x.isna().all() and str(df.time.dt.tz) == "UTC"
    assert ds.dataset(path).to_table().num_rows == 3  # a dataset reader too
    meta = pq.read_schema(path)
    assert meta.field("phi_xy").metadata[b"unit"] == b"rad" and meta.metadata[b"format"] == b"imu-align.lot-table"
    assert not [p for p in tmp_path.iterdir() if p.name != "results.parquet"]  # no temporary left
    latest = latest_rows(read_table(path))
    assert [(r["serial"], r["run"]) for r in latest] == [("U1", "r2"), ("U2", "r1")]


def test_a_table_with_a_column_this_release_does_not_know_keeps_it(tmp_path):
    path = tmp_path / "results.parquet"
    append_rows(path, [_row("U1", 0)])
    newer = read_table(path).append_column("temperature", pa.array([21.5]))
    pq.write_table(newer, path)
    append_rows(path, [_row("U2", 1)])
    df = pd.read_parquet(path)
    assert df.temperature.tolist()[0] == 21.5 and math.isnan(df.temperature.tolist()[1])


def test_the_journal_of_a_killed_run_is_folded_into_the_table(tmp_path):
    path = tmp_path / "results.parquet"
    journal = Journal(path)
    journal.add([_row("U1", 0)])
    journal.add([_row("U2", 1), _row("U2", 1, sensor="accelerometer")])
    journal._fh.close()  # the process dies here: the rows are on disk, the table is not written
    with open(journal.path, "a") as fh:
        fh.write('{"serial": "U3", "ti')  # the line being written when it died
    assert not path.exists()
    assert Journal(path).recover() == 3
    assert not journal.path.exists()
    df = pd.read_parquet(path)
    assert df.serial.tolist() == ["U1", "U2", "U2"] and df.time.iloc[0] == pd.Timestamp(T0)


def test_a_file_that_is_not_a_table_is_one_error(tmp_path):
    bad = tmp_path / "results.parquet"
    bad.write_text("serial,job\n")
    with pytest.raises(InputError, match="results.parquet: not a readable Parquet table"):
        read_table(bad)
    with pytest.raises(InputError, match="is a folder"):
        read_table(tmp_path)
