"""The seams the column convention left (a new user's study): a log read at a rate nobody gave, one column
named for two sensors, a unit option the report ignored. Truth from the files written here: the sample rate
and the columns are what the test wrote."""

import numpy as np
import pytest

FS = 200.0


@pytest.fixture(scope="module")
def renamed(tmp_path_factory):
    """A multi-position session (simulate poses) at 200 Hz with its columns renamed: no 'time' column."""
    from align.cli import run

    folder = tmp_path_factory.mktemp("renamed")
    assert run(["simulate", "poses", str(folder / "p"), "--seed", "3", "--rate-hz", str(FS), "--poses", "6"]) == 0
    lines = (folder / "p" / "session.csv").read_text().splitlines()
    path = folder / "renamed.csv"
    path.write_text("\n".join(["stamp,ax,ay,az,gx,gy,gz", *lines[1:]]) + "\n")
    return path


def _one_line(r, *words):
    assert r.code == 2, r.out + r.err
    assert r.err.count("\n") == 1 and "Traceback" not in r.err
    for w in words:
        assert w in r.err, r.err


def test_drift_refuses_a_trajectory_without_its_time_instead_of_reading_it_at_100_hz(run_cli, renamed):
    r = run_cli("drift", "--trajectory", renamed, "--gyro-columns", "gx,gy,gz", "--accel-columns", "ax,ay,az",
                "--imu", "MPU-6050", "--runs", "20")
    _one_line(r, "no column 'time'", "--time-column", "--rate-hz")
    r = run_cli("drift", "--trajectory", renamed, "--gyro-columns", "gx,gy,gz", "--accel-columns", "ax,ay,az",
                "--time-column", "stamp", "--imu", "MPU-6050", "--runs", "20")
    assert r.code == 0, r.err
    assert f"at {FS:g} Hz" in r.out


@pytest.mark.parametrize("command", [
    ("drift", "--trajectory", "{log}", "--gyro-columns", "gx,gy,gz", "--accel-columns", "ax,ay,gz", "--time-column",
     "stamp", "--imu", "MPU-6050", "--runs", "20"),
    ("calibrate", "gyro", "{log}", "--gyro-columns", "gx,gy,gz", "--accel-columns", "ax,ay,gz", "--time-column", "stamp"),
    ("calibrate", "ferraris", "{log}", "--sections", "{log}", "--rate-hz", "200", "--gyro-columns", "gx,gy,gz",
     "--accel-columns", "ax,ay,gz"),
], ids=["drift", "calibrate gyro", "calibrate ferraris"])
def test_one_column_named_for_two_sensors_is_one_line_on_every_command(run_cli, renamed, command):
    r = run_cli(*[str(renamed) if w == "{log}" else w for w in command])
    _one_line(r, "--accel-columns", "'gz' is both a gyroscope and an accelerometer column")


def test_report_without_a_log_reads_the_static_record_in_its_gyro_units_as_allan_does(run_cli, tmp_path):
    rng = np.random.default_rng(5)
    n, lsb = 60_000, 131.0  # 10 min at 100 Hz of white noise, 0.3 deg/sqrt(h), in counts of 1/131 deg/s
    sigma = 0.3 / 60 * np.sqrt(100.0)  # deg/s per sample: N sqrt(fs)
    counts = np.round(rng.normal(0, sigma, (n, 3)) * lsb)
    path = tmp_path / "static.csv"
    np.savetxt(path, np.column_stack([np.arange(n) / 100.0, counts]), delimiter=",", header="stamp,wx,wy,wz",
               comments="")
    common = ["--columns", "wx,wy,wz", "--time-column", "stamp", "--gyro-units", "131 LSB/(deg/s)"]
    a = run_cli("allan", path, *common, "--json", tmp_path / "a.json")
    assert a.code == 0, a.err
    r = run_cli("report", "--allan", path, *common, "--out", tmp_path / "r.html")
    assert r.code in (0, 4), r.err
    import json

    fit = json.loads((tmp_path / "a.json").read_text())["fit"]
    n_allan = fit["gyro_x"]["ieee_point_readouts"]["N_at_tau_1s"] if "gyro_x" in fit else \
        next(iter(fit.values()))["ieee_point_readouts"]["N_at_tau_1s"]
    assert n_allan == pytest.approx(0.3, rel=0.1)  # the truth written above
    assert f"{n_allan:.4g}" in (tmp_path / "r.html").read_text()
    r = run_cli("report", "--allan", path, *common, "--units", "0.0076336 deg/s", "--out", tmp_path / "r3.html")
    _one_line(r, "--units", "--gyro-units")
