"""Unit identity (issue 27): station, fixture, operator, the sensor's device id and the test time, stated in the
manifest, in every row of the lot's store; a test time without its zone, or not a time, refused naming the row."""

from __future__ import annotations

from datetime import UTC, datetime, timedelta, timezone

import pytest

from align.alignment.simulate import SessionSpec
from align.errors import InputError
from align.production import latest_rows, read_manifest, read_table, simulate_lot

JOBS = {"matrix": "required"}


def test_the_identity_columns_reach_every_row(tmp_path, run_cli):
    lot = simulate_lot(tmp_path / "lot", 2, session=SessionSpec(fs=200.0, dwell_s=2.0, static_s=1.0), bad=0, seed=5)
    manifest = lot.folder / "ids.toml"
    manifest.write_text(
        '[defaults]\njob = "matrix"\nplan = "plan.toml"\nstation = "ST-2"\noperator = "kim"\n'
        '[[unit]]\nserial = "SN0001"\nlog = "sessions/SN0001.csv"\nfixture = "F7"\ndevice_id = 2293768\n'
        'test_time = 2026-11-27T09:15:00+01:00\n'
        '[[unit]]\nserial = "SN0002"\nlog = "sessions/SN0002.csv"\ntest_time = "2026-11-27T10:00:00Z"\n')
    out = tmp_path / "out"
    res = run_cli("batch", manifest, "--out", out, "--workers", 1)
    assert res.code == 0, res.err
    rows = {r["serial"]: r for r in latest_rows(read_table(out / "results.parquet"))}
    a, b = rows["SN0001"], rows["SN0002"]
    assert (a["station"], a["operator"], a["fixture"], a["device_id"]) == ("ST-2", "kim", "F7", "2293768")
    assert (b["station"], b["fixture"], b["device_id"]) == ("ST-2", None, None)
    assert a["test_time"] == datetime(2026, 11, 27, 8, 15, tzinfo=UTC)  # the zone honoured, stored in UTC
    assert b["test_time"] == datetime(2026, 11, 27, 10, 0, tzinfo=UTC)
    assert a["time"] - a["test_time"] > timedelta(hours=1)  # the row's time is when it was made, not the test's
    from align.results import load_result  # the unit's result file says which unit it is of, and reads back

    unit = load_result(out / "units" / "SN0001.matrix.json").provenance.unit
    assert unit == {"serial": "SN0001", "station": "ST-2", "fixture": "F7", "operator": "kim", "device_id": "2293768",
                    "test_time": "2026-11-27T09:15:00+01:00"}


@pytest.mark.parametrize("value, words", [("2026-11-27 09:15", "states no zone"),
                                          ("yesterday", "is not an ISO 8601 time")])
def test_a_test_time_that_cannot_be_placed_is_refused_naming_the_row(tmp_path, value, words):
    (tmp_path / "log.csv").write_text("x\n")
    (tmp_path / "plan.toml").write_text("")
    manifest = tmp_path / "m.csv"
    manifest.write_text(f"serial,job,log,plan,test_time\nSN1,matrix,log.csv,plan.toml,{value}\n")
    with pytest.raises(InputError, match=f"line 2, column test_time: '{value}' {words}"):
        read_manifest(manifest, JOBS)


def test_a_zone_other_than_utc_is_kept_as_the_same_instant(tmp_path):
    (tmp_path / "log.csv").write_text("x\n")
    (tmp_path / "plan.toml").write_text("")
    manifest = tmp_path / "m.csv"
    manifest.write_text("serial,job,log,plan,station,test_time\nSN1,matrix,log.csv,plan.toml,A,2026-01-02T03:04:05-05:00\n")
    unit = read_manifest(manifest, JOBS).units[0]
    got = dict(unit.identity)
    assert got["station"] == "A"
    assert datetime.fromisoformat(got["test_time"]) == datetime(2026, 1, 2, 3, 4, 5, tzinfo=timezone(timedelta(hours=-5)))


def test_the_trend_over_time_follows_the_test_time_not_when_the_rows_were_made(tmp_path):
    """Units tested one per 6 h over 10 days, their rows all made in one batch a minute apart: the trend per day is
    the test time's (1e-4 per day), not the processing time's."""
    from align.production import lot_statistics, read_spec

    (tmp_path / "s.toml").write_text('scale_x = { min = 0.99, max = 1.01 }\n')
    t0, run = datetime(2026, 1, 5, tzinfo=UTC), datetime(2026, 2, 1, tzinfo=UTC)
    rows = [{"serial": f"U{k}", "job": "matrix", "order": 0, "time": run + timedelta(minutes=39 - k),
             "test_time": t0 + timedelta(hours=6 * k), "status": "ok", "sensor": "gyroscope", "message": "",
             "scale_x": 1.0 + 1e-4 * (k / 4)} for k in range(40)]
    (fs,) = lot_statistics(rows, read_spec(tmp_path / "s.toml"), "time").figures
    assert fs.slope == pytest.approx(1e-4) and fs.x[-1] == pytest.approx(39 / 4)
