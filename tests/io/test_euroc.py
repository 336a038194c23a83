"""ASL/EuRoC dataset folders (align.io.euroc).

Truth from outside the reader: the dataset is written here from the format's documentation (the EuRoC MAV
dataset's layout: ``mav0/imu0/data.csv`` under its header ``#timestamp [ns],w_RS_S_x [rad s^-1],...``,
``mav0/imu0/sensor.yaml`` as the dataset ships it for its ADIS16448, a camera folder and the ground truth beside
it), with known stamps in ns and readings printed with ``repr`` (so they read back bit for bit).
"""

from __future__ import annotations

import numpy as np
import pytest

from align.errors import InputError
from align.io import euroc, readers
from align.io.formats import LogFormat
from align.io.logs import read_sensor_log
from align.io.tables import read_table

HEADER = ("#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],"
          "a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]")
#: mav0/imu0/sensor.yaml of the EuRoC MAV datasets, as shipped (the VI-Sensor's ADIS16448)
SENSOR_YAML = """#Default imu sensor yaml file
sensor_type: imu
comment: VI-Sensor IMU (ADIS16448)

# Sensor extrinsics wrt. the body-frame.
T_BS:
  cols: 4
  rows: 4
  data: [1.0, 0.0, 0.0, 0.0,
         0.0, 1.0, 0.0, 0.0,
         0.0, 0.0, 1.0, 0.0,
         0.0, 0.0, 0.0, 1.0]
rate_hz: 200

# inertial sensor noise model parameters (static)
gyroscope_noise_density: 1.6968e-04     # [ rad / s / sqrt(Hz) ]   ( gyro "white noise" )
gyroscope_random_walk: 1.9393e-05       # [ rad / s^2 / sqrt(Hz) ] ( gyro bias diffusion )
accelerometer_noise_density: 2.0000e-3  # [ m / s^2 / sqrt(Hz) ]   ( accel "white noise" )
accelerometer_random_walk: 3.0000e-3    # [ m / s^3 / sqrt(Hz) ].  ( accel bias diffusion )
"""
N = 400
FIRST = 1403636579758555392  # ns: MH_01_easy's first IMU stamp
RNG = np.random.default_rng(2016)
STAMPS = FIRST + np.arange(N, dtype=np.int64) * 5_000_000 + RNG.integers(-300, 300, N)  # 200 Hz, ns jitter
GYRO, ACCEL = RNG.normal(0, 0.2, (N, 3)), RNG.normal([9.1, 0.1, -3.2], 0.3, (N, 3))
COLUMNS = ["time", "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]


def write_dataset(root, newline="\n", sensor_yaml=SENSOR_YAML, header=HEADER, rows=None):
    """An ASL dataset folder: mav0/imu0 (data.csv, sensor.yaml), a camera and the ground truth beside it."""
    imu = root / "mav0" / "imu0"
    imu.mkdir(parents=True)
    lines = [header] + (rows if rows is not None else
                        [",".join([str(int(s)), *map(repr, map(float, g)), *map(repr, map(float, a))])
                         for s, g, a in zip(STAMPS, GYRO, ACCEL)])
    (imu / "data.csv").write_bytes(newline.join(lines).encode() + newline.encode())
    if sensor_yaml is not None:
        (imu / "sensor.yaml").write_text(sensor_yaml)
    cam = root / "mav0" / "cam0"
    (cam / "data").mkdir(parents=True)
    (cam / "data" / f"{FIRST}.png").write_bytes(b"\x89PNG")
    (cam / "data.csv").write_text(f"#timestamp [ns],filename\n{FIRST},{FIRST}.png\n")
    (cam / "sensor.yaml").write_text("sensor_type: camera\nrate_hz: 20\n")
    truth = root / "mav0" / "state_groundtruth_estimate0"
    truth.mkdir()
    (truth / "data.csv").write_text(f"#timestamp, p_RS_R_x [m]\n{FIRST},4.688\n")
    return root


@pytest.fixture(autouse=True)
def registered():
    """The EuRoC reader registered for these tests (the registry restored after each)."""
    saved = list(readers.READERS)
    readers.register(euroc.READER)
    yield
    readers.READERS[:] = saved


@pytest.mark.parametrize("given, newline", [("", "\n"), ("mav0", "\r\n"), ("mav0/imu0", "\n")])
def test_the_dataset_its_mav0_or_its_imu0_reads_back_the_samples_written(tmp_path, given, newline):
    folder = write_dataset(tmp_path, newline) / given
    assert readers.reader_for(folder) is euroc.READER
    got = read_table(folder)
    assert got.names == COLUMNS
    np.testing.assert_allclose(got.data[:, 0], (STAMPS - STAMPS[0]) / 1e9, rtol=0, atol=1e-12)  # from the first
    np.testing.assert_array_equal(got.data[:, 1:4], GYRO)
    np.testing.assert_array_equal(got.data[:, 4:7], ACCEL)
    assert got.units == {"time": "s", "gyro_x": "rad/s", "gyro_y": "rad/s", "gyro_z": "rad/s",
                         "accel_x": "m/s^2", "accel_y": "m/s^2", "accel_z": "m/s^2"}
    assert got.source["time_origin_ns"] == STAMPS[0]
    assert got.source["sensor"] == {"": "mav0/imu0", "mav0": "imu0", "mav0/imu0": "imu0"}[given]
    figures = got.source["sensor_yaml"]
    assert figures["rate_hz"] == 200 and figures["sensor_type"] == "imu"
    assert figures["comment"] == "VI-Sensor IMU (ADIS16448)"
    assert (figures["gyroscope_noise_density"], figures["gyroscope_random_walk"]) == (1.6968e-04, 1.9393e-05)
    assert (figures["accelerometer_noise_density"], figures["accelerometer_random_walk"]) == (2.0e-3, 3.0e-3)
    assert figures["T_BS"] == np.eye(4).tolist()
    assert got.source["figure_units"]["gyroscope_random_walk"] == "rad/s^2/sqrt(Hz)"
    assert got.notes == ()


def test_a_sensor_log_takes_the_units_the_dataset_states(tmp_path):
    log = read_sensor_log(write_dataset(tmp_path), ["accel_x", "accel_y", "accel_z"], None, "time",
                          expect="acceleration", field="units")
    np.testing.assert_array_equal(log.data, ACCEL)
    assert log.stated and log.units == "m/s^2" and log.time_units == "s"
    assert log.rate_hz == pytest.approx(1e9 / np.median(np.diff(STAMPS)), rel=1e-12)


def test_describe_gives_the_one_imu_stream_with_its_figures(tmp_path):
    (stream,) = euroc.describe(write_dataset(tmp_path), LogFormat())
    assert (stream.topic, stream.count, stream.columns) == ("mav0/imu0", N, tuple(COLUMNS))
    assert stream.extra["accelerometer_noise_density"] == 2.0e-3


def test_other_folders_and_the_csv_alone_are_not_this_reader(tmp_path):
    root = write_dataset(tmp_path)
    with pytest.raises(InputError, match="not a log folder"):
        readers.reader_for(root / "mav0" / "cam0")  # a camera's folder: data.csv and sensor.yaml beside data/
    assert readers.reader_for(root / "mav0" / "imu0" / "data.csv").name == "csv"


def test_without_sensor_yaml_the_samples_are_read_and_it_is_said(tmp_path):
    got = read_table(write_dataset(tmp_path, sensor_yaml=None))
    np.testing.assert_array_equal(got.data[:, 1:4], GYRO)
    assert got.source["sensor_yaml"] == {} and "no sensor.yaml" in got.notes[0]


def test_a_rate_unlike_the_sensor_yaml_rate_is_said(tmp_path):
    got = read_table(write_dataset(tmp_path, sensor_yaml=SENSOR_YAML.replace("rate_hz: 200", "rate_hz: 100")))
    assert "differs from sensor.yaml's rate_hz 100" in got.notes[0]


def _refused(folder, names=None, time_column="time", fmt=None) -> str:
    with pytest.raises(InputError) as err:
        read_table(folder, names, time_column, fmt)
    text = str(err.value)
    assert "\n" not in text
    return text


@pytest.mark.parametrize("header", [HEADER.replace("rad s^-1", "deg s^-1"), "#timestamp [ns],filename",
                                    HEADER.replace("a_RS_S_z [m s^-2]", "")])
def test_a_header_that_is_not_the_imus_is_refused(tmp_path, header):
    assert "not the IMU's of an ASL/EuRoC dataset" in _refused(write_dataset(tmp_path, header=header))


@pytest.mark.parametrize("rows, words", [([f"{FIRST},0.1,0.2,0.3,9.8,0.0,x"], "clean the file"),
                                         ([f"{FIRST},0.1,0.2,0.3,9.8,0.0"], "clean the file"),
                                         ([f"{FIRST},0.1,0.2,,9.8,0.0,0.1"], "empty field"),
                                         ([], "has no samples")])
def test_a_bad_line_or_no_line_is_refused(tmp_path, rows, words):
    text = _refused(write_dataset(tmp_path, rows=rows))
    assert words in text and "data.csv" in text


def test_a_column_not_there_is_refused_naming_the_columns(tmp_path):
    root = write_dataset(tmp_path)
    text = _refused(root, ["time", "mag_x"])
    assert "no column 'mag_x'" in text and "gyro_x" in text
    assert "time_column='time'" in _refused(root, ["stamp", "gyro_x"], "stamp")
    assert "topic" in _refused(root, None, "time", LogFormat(topic="/imu0"))  # one stream: no topic to choose
