"""The lot's store: a folder of Parquet parts appended without rewriting, read back as one table by pandas, pyarrow
and DuckDB; a store of one file (before 0.3) read as it is and moved into the folder on the first append."""

from __future__ import annotations

import json
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


def _parts(path):
    return sorted(p.relative_to(path) for p in path.rglob("*") if p.is_file())


def test_appends_make_one_table_every_reader_takes_as_it_is(tmp_path):
    path = tmp_path / "results.parquet"
    assert append_rows(path, [_row("U1", 0), _row("U2", 1)]) == 2
    first = _parts(path)
    before = (path / first[0]).read_bytes()
    assert append_rows(path, [_row("U1", 60, "r2", phi=0.002)]) == 1
    assert append_rows(path, []) == 0
    parts = _parts(path)
    assert len(parts) == 2 and first[0] in parts and (path / first[0]).read_bytes() == before  # nothing rewritten
    assert all(p.parts[0].startswith("date=20") and p.name.startswith("part-") for p in parts)  # Hive: by day
    df = pd.read_parquet(path).sort_values(["time"])  # pandas: the folder is one table (plus the partition `date`)
    assert len(df) == 3 and list(df.columns[:3]) == ["serial", "slot", "order"]
    assert set(FIGURES) <= set(df.columns) and df.phi_xy.tolist() == [0.001, 0.001, 0.002]
    assert df.arw_x.isna().all() and str(df.time.dt.tz) == "UTC"
    assert ds.dataset(path).to_table().num_rows == 3  # a dataset reader too
    meta = pq.read_schema(path / parts[0])
    assert meta.field("phi_xy").metadata[b"unit"] == b"rad" and meta.metadata[b"format"] == b"imu-align.lot-table"
    assert [p.name for p in tmp_path.iterdir()] == ["results.parquet"]  # no temporary left
    latest = latest_rows(read_table(path))
    assert [(r["serial"], r["run"]) for r in latest] == [("U1", "r2"), ("U2", "r1")]
    with pytest.raises(InputError, match="is one part of the results store .*results.parquet, which holds 2"):
        read_table(path / parts[0])  # a part alone is not the lot
    keys = read_table(path, ["serial", "run", "no_such_column"])  # a resume reads its keys alone
    assert keys.column_names == ["serial", "run"] and keys.num_rows == 3


def test_duckdb_query_on_the_store(tmp_path):
    duckdb = pytest.importorskip("duckdb")
    path = tmp_path / "results.parquet"
    append_rows(path, [_row("U1", 0), _row("U2", 1)])
    append_rows(path, [_row("U1", 60, "r2", phi=0.002)])
    got = duckdb.sql(f"SELECT serial, max(phi_xy) FROM read_parquet('{path}/**/*.parquet', union_by_name = true) "
                     "GROUP BY serial ORDER BY serial").fetchall()
    assert got == [("U1", 0.002), ("U2", 0.001)]


def test_a_store_of_one_file_is_read_as_it_is_and_moved_whole_on_the_first_append(tmp_path):
    from align.production.table import SCHEMA, _clean, _table

    path = tmp_path / "results.parquet"
    pq.write_table(_table([_clean(_row("U1", 0))]).replace_schema_metadata(SCHEMA.metadata), path)
    old = path.read_bytes()
    assert [r["serial"] for r in latest_rows(read_table(path))] == ["U1"]  # read as it is, untouched
    assert path.is_file() and path.read_bytes() == old
    append_rows(path, [_row("U2", 1)])
    assert path.is_dir() and old in [(path / p).read_bytes() for p in _parts(path)]
    assert sorted(r["serial"] for r in latest_rows(read_table(path))) == ["U1", "U2"]


def test_a_table_with_a_column_this_release_does_not_know_keeps_it(tmp_path):
    path = tmp_path / "results.parquet"
    append_rows(path, [_row("U1", 0)])
    part = path / _parts(path)[0]
    newer = read_table(path).append_column("temperature", pa.array([21.5]))
    pq.write_table(newer, part)
    append_rows(path, [_row("U2", 1)])
    got = read_table(path)
    assert got.column("temperature").to_pylist() == [21.5, None]


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
    with open(journal.path, "w") as fh:  # a kill after the part's rename, before the journal's removal
        fh.write(json.dumps({**_row("U1", 0), "time": T0.isoformat()}) + "\n")
    assert Journal(path).recover() == 0 and read_table(path).num_rows == 3
    df = pd.read_parquet(path)
    assert df.serial.tolist() == ["U1", "U2", "U2"] and df.time.iloc[0] == pd.Timestamp(T0)


def test_a_file_that_is_not_a_table_is_one_error(tmp_path):
    bad = tmp_path / "results.parquet"
    bad.write_text("serial,job\n")
    with pytest.raises(InputError, match="results.parquet: not a readable Parquet table"):
        read_table(bad)
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "notes.txt").write_text("x")
    with pytest.raises(InputError, match="other: holds no Parquet part of a lot"):
        read_table(tmp_path / "other")
    store = tmp_path / "store"
    append_rows(store, [_row("U1", 0)])
    (store / "date=2026-01-01").mkdir()
    (store / "date=2026-01-01" / "part-x.parquet").write_text("not parquet")
    with pytest.raises(InputError, match="store: part-x.parquet: not a readable Parquet table"):
        read_table(store)


def test_rows_are_built_as_pyarrow_builds_them_from_python_objects(tmp_path):
    # the table is built from Arrow buffers (no pandas); pyarrow's own converter is the reference
    from align.production.table import SCHEMA, _clean, _table

    rows = [_row("U1", 0), {**_row("U2", 1.5), "message": "naïve µ", "slot": None, "phi_xy": -0.0, "exit_code": 3},
            {**_row("U3", 2), "time": "2026-03-01T09:00:00.000001+00:00", "sensor": None, "order": None},
            {**_row("U4", 3), "time": datetime(2026, 3, 1, 9, 30), "phi_xy": math.inf, "scale_x": 1e-300}]
    clean = [_clean(r) for r in rows]
    assert _table(clean).equals(pa.Table.from_pylist(clean, schema=SCHEMA))
    path = tmp_path / "results.parquet"
    append_rows(path, rows)
    back = pq.read_table(path / _parts(path)[0])
    assert back.column("time").to_pylist() == pa.Table.from_pylist(clean, schema=SCHEMA).column("time").to_pylist()
    assert back.column("message").to_pylist()[1] == "naïve µ" and back.column("phi_xy").to_pylist()[3] is None
    with pytest.raises(TypeError, match="column serial"):
        _table([_clean({**_row("U5", 0), "serial": 5})])
    with pytest.raises(TypeError, match="column order"):
        _table([_clean({**_row("U5", 0), "order": 1.5})])


def test_rows_read_back_as_pyarrow_reads_them(tmp_path):
    from align.production.table import rows_of

    path = tmp_path / "results.parquet"
    append_rows(path, [_row("U1", 0), {**_row("U2", 1), "time": T0 + timedelta(microseconds=7)}])
    table = read_table(path)
    got, ref = rows_of(table), table.to_pylist()  # the times from the integers, not pyarrow's converter
    assert [list(r) for r in got] == [list(r) for r in ref]
    for a, b in zip(got, ref):
        for k, v in b.items():
            assert a[k] == v or (v is None and k in FIGURES and math.isnan(a[k])), k
    assert got[1]["time"] == T0 + timedelta(microseconds=7) and got[1]["time"].utcoffset() == timedelta(0)


def test_a_batch_parent_folding_its_journal_imports_no_pandas(tmp_path):
    # pandas costs a batch a third of a second: pyarrow imports it for Python objects and the dataset reader
    import subprocess
    import sys

    code = ("import sys\n"
            "from datetime import datetime, UTC\n"
            "from align.production import Journal, latest_rows, read_table\n"
            "path = sys.argv[1] + '/results.parquet'\n"
            "for run in ('r1', 'r2'):\n"
            "    j = Journal(path)\n"
            "    j.recover()\n"
            "    latest_rows(read_table(path))\n"
            "    j.add([{'serial': 'U1', 'order': 0, 'run': run, 'time': datetime.now(UTC), 'job': 'matrix',\n"
            "            'status': 'ok', 'exit_code': 0, 'phi_xy': 0.001}])\n"
            "    j.fold()\n"
            "assert read_table(path).num_rows == 2 and len(latest_rows(read_table(path))) == 1\n"
            "print('pandas' in sys.modules)\n")
    got = subprocess.run([sys.executable, "-c", code, str(tmp_path)], capture_output=True, text=True, check=True)
    assert got.stdout.strip() == "False"
