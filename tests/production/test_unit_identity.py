"""Unit identity (issue 27): station, fixture, operator, the sensor's device id and the test time, stated in the
manifest, in every row of the lot's store; a test time without its zone, or not a time, refused naming the row."""

from __future__ import annotations

import math
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
    got = lot_statistics(rows, read_spec(tmp_path / "s.toml"), "time")
    (fs,) = got.figures
    assert fs.slope == pytest.approx(1e-4) and fs.x[-1] == pytest.approx(39 / 4) and not got.notes
    some = [{**r, "test_time": None} if k % 10 == 3 else r for k, r in enumerate(rows)]  # 4 units not dated: said
    (note,) = lot_statistics(some, read_spec(tmp_path / "s.toml"), "time").notes
    assert note.startswith("4 of 40 units have no test time (e.g. U13, U23, U3): the trend places them when")
    same = [{**r, "test_time": t0} for r in rows]  # every unit tested at one time: no trend, and said why
    got = lot_statistics(same, read_spec(tmp_path / "s.toml"), "time")
    assert math.isnan(got.figures[0].slope)
    assert got.notes == ("no trend over time: every unit has the same test time (the manifest's test_time, or the "
                         "log's, else when its row was made); give each unit its own, or trend over the lot's order",)


# ---- identity from the log (issue 27: "test time from the log where it has one") ----

GYRO_FMT = ("sensor_gyro:uint64_t timestamp;uint64_t timestamp_sample;uint32_t device_id;float x;float y;float z;"
            "float temperature;uint32_t error_count;")
GPS_FMT = "vehicle_gps_position:uint64_t timestamp;uint64_t time_utc_usec;int32_t timestamp_time_relative;"


def _ulog(path, device: int, utc_boot_us: int | None, seconds: float = 120.0, fs: float = 100.0, seed: int = 0):
    """A ULog (format from PX4's ULog documentation: header, F, A and D messages) of a static gyro at ``fs``:
    ``sensor_gyro:0`` of ``device``, from 5 s after power-on; with ``utc_boot_us``, GPS fixes dating the log
    (``time_utc_usec`` at ``timestamp + timestamp_time_relative``)."""
    import struct

    import numpy as np

    out = bytearray(b"ULog\x01\x12\x35\x01" + struct.pack("<Q", 0))

    def msg(kind: str, body: bytes) -> None:
        out.extend(struct.pack("<HB", len(body), ord(kind)) + body)

    msg("B", bytes(40))
    msg("F", GYRO_FMT.encode())
    msg("F", GPS_FMT.encode())
    msg("A", struct.pack("<BH", 0, 1) + b"sensor_gyro")
    msg("A", struct.pack("<BH", 0, 2) + b"vehicle_gps_position")
    rng = np.random.default_rng(seed)
    w = rng.normal(0, 2e-3, (int(seconds * fs), 3)) + [1e-3, -2e-3, 5e-4]
    for k, row in enumerate(w):
        t = 5_000_000 + int(k * 1e6 / fs)
        msg("D", struct.pack("<H", 1) + struct.pack("<QQI4fI", t + 300, t, device, *row, 35.0, 0))
        if utc_boot_us is not None and k % int(fs) == 50:  # a fix a second, published 20 ms after its time
            msg("D", struct.pack("<H", 2) + struct.pack("<QQi", t + 20_000, utc_boot_us + t, -20_000))
    path.write_bytes(bytes(out))
    return path


@pytest.mark.slow
def test_device_id_and_test_time_from_the_log_where_the_manifest_gives_none(tmp_path, run_cli):
    from align.results import load_result

    boot = int(datetime(2026, 5, 4, 7, 30, 0, tzinfo=UTC).timestamp() * 1e6)
    _ulog(tmp_path / "a.ulg", 2424842, boot)
    _ulog(tmp_path / "b.ulg", 3670050, None, seed=1)  # no GPS: no test time
    _ulog(tmp_path / "c.ulg", 2621474, boot + 3_600_000_000, seed=2)
    manifest = tmp_path / "m.csv"
    manifest.write_text("serial,job,log,options,device_id,test_time\n"
                        "A1,allan,a.ulg,--topic sensor_gyro:0,,\n"
                        "B1,allan,b.ulg,--topic sensor_gyro:0,,\n"
                        "C1,allan,c.ulg,--topic sensor_gyro:0,999,2026-05-04T12:00:00+02:00\n")
    res = run_cli("batch", manifest, "--out", tmp_path / "out", "--workers", 1)
    assert res.code == 0, res.err + res.out
    rows = {r["serial"]: r for r in latest_rows(read_table(tmp_path / "out" / "results.parquet"))}
    a, b, c = rows["A1"], rows["B1"], rows["C1"]
    first = datetime(2026, 5, 4, 7, 30, 5, tzinfo=UTC)  # the first sample, 5 s after power-on
    assert (a["device_id"], a["test_time"]) == ("2424842", first)
    assert (b["device_id"], b["test_time"]) == ("3670050", None)
    # the manifest wins; a log of another device id is said in the unit's message
    assert (c["device_id"], c["test_time"]) == ("999", datetime(2026, 5, 4, 10, 0, tzinfo=UTC))
    assert "the log states device id 2621474, the manifest 999" in c["message"] and not a["message"]
    assert c["verdict"] == "warn" and "units passing with a warning (1):" in res.out and "C1  " in res.out
    assert load_result(tmp_path / "out" / "units" / "A1.allan.json").provenance.unit == {
        "serial": "A1", "device_id": "2424842", "test_time": first.isoformat()}


def test_a_clock_since_power_on_dates_nothing():
    from types import SimpleNamespace

    from align.production.identity import log_identity

    now = int(datetime(2026, 11, 29, tzinfo=UTC).timestamp()) * 10**9
    bag = SimpleNamespace(inputs={"stream": {"time_origin_ns": 1_700_000_000 * 10**9}})  # 2023-11-14T22:13:20Z
    assert log_identity(bag, now) == {"test_time": "2023-11-14T22:13:20+00:00"}
    for origin in (12 * 10**9, now + 2 * 86_400 * 10**9):  # since power-on; in the future
        assert log_identity(SimpleNamespace(inputs={"stream": {"time_origin_ns": origin}}), now) == {}
    runs = SimpleNamespace(inputs={"streams": [{"units_stated": "rad/s"}, {"stream": {"device_id": 7}}]})
    assert log_identity(runs, now) == {"device_id": "7"}


@pytest.mark.slow
def test_an_euroc_folder_of_epoch_stamps_dates_its_unit(tmp_path, run_cli):
    # an ASL (EuRoC) dataset's data.csv: "#timestamp [ns]" since 1970 (MH_01_easy's first stamp: 2014-06-24)
    import numpy as np

    imu = tmp_path / "MH" / "mav0" / "imu0"
    imu.mkdir(parents=True)
    first = 1403636579758555392
    rng = np.random.default_rng(3)
    rows = ["#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],"
            "a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]"]
    for k in range(12_000):  # 60 s at 200 Hz, at rest
        g, a = rng.normal(0, 2e-3, 3), rng.normal([0, 0, 9.81], 0.02, 3)
        rows.append(",".join([str(first + 5_000_000 * k), *(f"{v:.6g}" for v in (*g, *a))]))
    (imu / "data.csv").write_text("\n".join(rows) + "\n")
    (tmp_path / "m.csv").write_text("serial,job,log\nE1,allan,MH/mav0\n")
    res = run_cli("batch", tmp_path / "m.csv", "--out", tmp_path / "out", "--workers", 1)
    assert res.code == 0, res.err + res.out
    (row,) = latest_rows(read_table(tmp_path / "out" / "results.parquet"))
    assert row["test_time"] == datetime(2014, 6, 24, 19, 2, 59, 758555, tzinfo=UTC) and row["device_id"] is None


def test_the_device_id_remark_survives_a_spec_and_a_rejudge(tmp_path):
    from align.production import read_spec
    from align.production.stats import judge_rows, rejudge_rows

    (tmp_path / "tight.toml").write_text('scale_x = { min = 0.999, max = 1.001 }\n')
    said = "the log states device id 2621474, the manifest 999: is it the unit's log?"
    row = {"serial": "C1", "job": "allan", "status": "ok", "sensor": "gyroscope", "verdict": "warn",
           "checks": "identity: warn", "message": said, "scale_x": 1.01}
    (failed,) = judge_rows([row], read_spec(tmp_path / "tight.toml"))
    assert failed["verdict"] == "fail" and failed["message"].startswith(said + "; outside the spec: scale_x")
    (again,) = rejudge_rows([failed], None)  # judged again without the spec: the warning and its remark are back
    assert (again["verdict"], again["message"]) == ("warn", said)


def test_a_long_ulog_read_in_blocks_is_dated_like_one_read_whole(tmp_path):
    # a log of 200 MB or more is read in blocks (align.io.ulog.iter_chunks): every block dated by the stream's first
    # sample, as the whole read is
    from align.io import ulog
    from align.io.formats import LogFormat

    boot = int(datetime(2026, 5, 4, 7, 30, 0, tzinfo=UTC).timestamp() * 1e6)
    path = _ulog(tmp_path / "a.ulg", 2424842, boot, seconds=30.0)
    fmt = LogFormat(topic="sensor_gyro:0")
    whole = ulog.read(path, None, "time", fmt).source["time_origin_utc_ns"]
    blocks = list(ulog.iter_chunks(path, fmt, None, rows=700))
    assert len(blocks) > 3 and {b.source["time_origin_utc_ns"] for b in blocks} == {whole}
    assert whole == int(datetime(2026, 5, 4, 7, 30, 5, tzinfo=UTC).timestamp()) * 10**9
