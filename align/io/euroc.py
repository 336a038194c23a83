"""EuRoC / ASL dataset folders: the IMU of ``mav0/imu0`` (``data.csv`` and ``sensor.yaml``).

The ASL dataset format (the EuRoC MAV datasets, Burri et al. 2016, and those written like them: TUM-VI, many
visual-inertial recordings) keeps each sensor in a folder of ``mav0``; the IMU's ``imu0/data.csv`` holds one
sample a line under the header ``#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],
a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]`` (the angular rate and specific force of the sensor frame
S, in S), and ``imu0/sensor.yaml`` its nominal rate (``rate_hz``), its noise densities and random walks, and
``T_BS`` (the sensor's pose in the body frame, 4 x 4).

The dataset folder, its ``mav0`` or the ``imu0`` folder itself is a log here (a ``data.csv`` given alone is a
CSV). Its columns follow the one convention (:mod:`align.io.readers`) with the units the header states: ``time``
(s from the first sample; the first stamp in ns is ``Columns.source["time_origin_ns"]``), ``gyro_x..z``
(rad/s), ``accel_x..z`` (m/s^2); ``sensor.yaml``'s figures go into ``Columns.source["sensor_yaml"]``, their documented units into
``Columns.source["figure_units"]``.

Public names
------------
READER, read, describe, sniff, sensor_yaml
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from align.errors import InputError, literal
from align.io.formats import LogFormat
from align.io.readers import Columns, LogReader, Stream

__all__ = ["READER", "read", "describe", "sniff", "sensor_yaml"]

#: the header of ``imu0/data.csv``: the file's name of each column, its unit, and the column it becomes here
HEADER = (("timestamp", "ns", "time"),
          ("w_RS_S_x", "rad s^-1", "gyro_x"), ("w_RS_S_y", "rad s^-1", "gyro_y"), ("w_RS_S_z", "rad s^-1", "gyro_z"),
          ("a_RS_S_x", "m s^-2", "accel_x"), ("a_RS_S_y", "m s^-2", "accel_y"), ("a_RS_S_z", "m s^-2", "accel_z"))
COLUMNS = [c for _, _, c in HEADER]
UNITS = {"time": "s", **{f"gyro_{a}": "rad/s" for a in "xyz"}, **{f"accel_{a}": "m/s^2" for a in "xyz"}}
#: the units of ``sensor.yaml``'s figures, as the dataset documents them in its comments
FIGURE_UNITS = {"rate_hz": "Hz", "gyroscope_noise_density": "rad/s/sqrt(Hz)",
                "gyroscope_random_walk": "rad/s^2/sqrt(Hz)", "accelerometer_noise_density": "m/s^2/sqrt(Hz)",
                "accelerometer_random_walk": "m/s^3/sqrt(Hz)", "T_BS": "m (translation), 1 (rotation)"}
#: where the IMU's folder may be, from the folder given
_PLACES = ("mav0/imu0", "imu0", ".")


def sniff(listing: bytes) -> bool:
    """Whether a folder's listing (relative names, one a line) is an ASL dataset, its ``mav0`` or its ``imu0``.

    Examples
    --------
    >>> sniff(b"mav0/cam0/data.csv\\nmav0/imu0/data.csv\\nmav0/imu0/sensor.yaml"), sniff(b"data.csv\\nsensor.yaml")
    (True, True)
    >>> sniff(b"data\\ndata/1403636579763555584.png\\ndata.csv\\nsensor.yaml")  # a camera's folder
    False
    """
    names = set(listing.decode("utf-8", "replace").replace("\\", "/").splitlines())
    if {"mav0/imu0/data.csv", "imu0/data.csv"} & names:
        return True
    return {"data.csv", "sensor.yaml"} <= names and "data" not in names


def _imu_folder(path: Path) -> tuple[Path, str]:
    """The IMU's folder in the folder given, and its name there (``mav0/imu0``, ``imu0``)."""
    for place in _PLACES:
        if (path / place / "data.csv").is_file():
            return path / place, place if place != "." else path.resolve().name
    raise InputError("is not an ASL/EuRoC dataset folder (no mav0/imu0/data.csv, imu0/data.csv or data.csv in it); "
                     "give the dataset's folder, its mav0 or its imu0", str(path))


def _scalar(text: str) -> Any:
    text = text.strip()
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text.strip("'\"")


def sensor_yaml(text: str) -> dict[str, Any]:
    """The figures of an ASL ``sensor.yaml``: its top-level ``key: value`` lines and ``T_BS`` (4 x 4 rows).

    The dataset's files are plain: scalars one a line, ``#`` comments, and ``T_BS`` with ``rows``, ``cols`` and a
    flow list ``data`` over several lines; that is all read here (no YAML library needed).

    Examples
    --------
    >>> sensor_yaml("rate_hz: 200  # Hz\\ncomment: VI-Sensor IMU (ADIS16448)\\nT_BS:\\n  rows: 2\\n  cols: 2\\n"
    ...             "  data: [1.0, 0.0,\\n         0.0, 1.0]")
    {'rate_hz': 200, 'comment': 'VI-Sensor IMU (ADIS16448)', 'T_BS': [[1.0, 0.0], [0.0, 1.0]]}
    """
    figures: dict[str, Any] = {}
    block: dict[str, Any] = {}
    parent, pending = "", ""
    for raw in text.replace("\r", "").split("\n"):
        line = raw.split("#", 1)[0].rstrip()
        if pending:
            line, pending = pending + " " + line.strip(), ""
        if line.count("[") > line.count("]"):
            pending = line
            continue
        key, colon, value = line.strip().partition(":")
        if not colon or not key:
            continue
        if line[:1].isspace():
            block.setdefault(parent, {})[key.strip()] = value.strip()
        else:
            parent = key.strip()
            if value.strip():
                figures[parent] = _scalar(value)
    pose = block.get("T_BS", {})
    try:
        values = [float(v) for v in pose.get("data", "").strip("[] ").split(",") if v.strip()]
        rows, cols = int(pose.get("rows", 4)), int(pose.get("cols", 4))
    except ValueError:
        values, rows, cols = [], 0, 0
    if values and len(values) == rows * cols:
        figures["T_BS"] = [values[r * cols:(r + 1) * cols] for r in range(rows)]
    return figures


def _header(line: str, where: str) -> None:
    """The data.csv header must be the IMU's (names and units as the dataset writes them)."""
    cells = [c.strip() for c in line.strip().lstrip("#").split(",")]
    got = [(c.split("[", 1)[0].strip(), c.split("[", 1)[1].rstrip("]").strip() if "[" in c else "") for c in cells]
    if got != [(name, unit) for name, unit, _ in HEADER]:
        shown = literal(line.strip()[:120])
        raise InputError(f"its header '{shown}' is not the IMU's of an ASL/EuRoC dataset ('#timestamp [ns],w_RS_S_x "
                         "[rad s^-1],...,a_RS_S_z [m s^-2]'); give the dataset's IMU folder, or read the file as a CSV",
                         where)


def _samples(csv: Path) -> tuple[np.ndarray, np.ndarray]:
    """The time stamps (ns, int64, exact) and the six readings (n, 6) of ``imu0/data.csv``."""
    import pyarrow as pa
    import pyarrow.csv as pcsv

    where = str(csv)
    try:
        with open(csv, encoding="utf-8", errors="replace") as fh:
            first = fh.readline()
    except OSError as exc:
        raise InputError(f"cannot read ({literal(exc.strerror or exc)})", where) from None
    _header(first, where)
    names = [f"c{i}" for i in range(len(HEADER))]
    types = {n: (pa.int64() if i == 0 else pa.float64()) for i, n in enumerate(names)}
    try:
        table = pcsv.read_csv(csv, read_options=pcsv.ReadOptions(skip_rows=1, column_names=names),
                              convert_options=pcsv.ConvertOptions(column_types=types))
    except (pa.ArrowException, OSError, ValueError) as exc:
        text = " ".join(str(exc).split())[:160]
        raise InputError(f"a line is not a time stamp in ns and six numbers ({literal(text)}); clean the file",
                         where) from None
    if table.num_rows == 0:
        raise InputError("has no samples (its header alone); give a recorded dataset", where)
    if any(table.column(n).null_count for n in names):
        raise InputError("a line has an empty field; clean the file", where)
    return _numbers(table.column(names[0]), np.int64), np.column_stack([_numbers(table.column(n), np.float64)
                                                                         for n in names[1:]])


def _numbers(column, dtype) -> np.ndarray:
    """An Arrow column without nulls as numpy, from its buffer (``to_numpy`` would import pandas)."""
    array = column.combine_chunks()
    return np.frombuffer(array.buffers()[1], dtype=dtype, count=len(array) + array.offset)[array.offset:]


def _figures(folder: Path) -> tuple[dict[str, Any], list[str]]:
    path = folder / "sensor.yaml"
    if not path.is_file():
        return {}, ["no sensor.yaml beside data.csv: no nominal rate or noise figures"]
    try:
        return sensor_yaml(path.read_text(encoding="utf-8", errors="replace")), []
    except OSError as exc:
        raise InputError(f"cannot read ({literal(exc.strerror or exc)})", str(path)) from None


def read(path: Path, names: list[str] | None, time_column: str | None, fmt: LogFormat) -> Columns:
    """The IMU samples of an ASL/EuRoC dataset folder.

    Parameters
    ----------
    path : Path
        The dataset's folder, its ``mav0`` or its ``imu0``.
    names : list of str or None
        Columns asked for (``time``, ``gyro_x`` ..., ``accel_z``); None: all.
    time_column : str or None
        The name among ``names`` that is the time, for the message when it is missing.
    fmt : LogFormat
        Unused (an ASL folder has one IMU stream and no text options).

    Returns
    -------
    Columns
        ``data`` (n, k) float64: time in s from the first sample, angular rate rad/s, specific force m/s^2;
        ``source``: the sensor folder, the first stamp (ns) and ``sensor.yaml``'s figures (``figure_units``).

    Raises
    ------
    InputError
        No IMU folder; a header that is not the IMU's; a line that is not a stamp and six numbers; no samples;
        a column asked for that is not there.
    """
    folder, sensor = _imu_folder(path)
    csv = folder / "data.csv"
    if names is not None and (missing := [n for n in names if n not in COLUMNS]):
        advice = ("its time column is named 'time': give {time_column=time}" if missing == [time_column] else
                  "name the columns by the convention")
        raise InputError(f"no column {', '.join(repr(literal(m)) for m in missing)} (columns: {', '.join(COLUMNS)}); "
                         + advice, str(csv))
    ns, readings = _samples(csv)
    figures, notes = _figures(folder)
    origin = int(ns[0])
    columns = dict(zip(COLUMNS, [(ns - origin) / 1e9, *readings.T]))
    wanted = list(names) if names is not None else COLUMNS
    source = {"format": "euroc", "sensor": sensor, "time_origin_ns": origin, "sensor_yaml": figures,
              "figure_units": {k: u for k, u in FIGURE_UNITS.items() if k in figures}}
    rate = figures.get("rate_hz")
    if len(ns) > 1 and isinstance(rate, (int, float)) and rate > 0:
        median = 1e9 / float(np.median(np.diff(ns)))
        if abs(median - rate) > 0.01 * rate:
            notes.append(f"data.csv's median rate {median:.6g} Hz differs from sensor.yaml's rate_hz {rate:g}")
    data = np.column_stack([columns[n] for n in wanted]) if wanted else np.empty((len(ns), 0))
    return Columns(wanted, data, {n: UNITS[n] for n in wanted}, source, tuple(notes))


def describe(path: Path, fmt: LogFormat) -> list[Stream]:
    """The dataset's one IMU stream: its sample count, columns, units and ``sensor.yaml``'s figures."""
    folder, sensor = _imu_folder(path)
    ns, _ = _samples(folder / "data.csv")
    figures, _ = _figures(folder)
    return [Stream(sensor, "ASL/EuRoC IMU (data.csv)", len(ns), tuple(COLUMNS), dict(UNITS), figures)]


#: ASL/EuRoC dataset folders (the dataset, its mav0 or its imu0), told by their listing
READER = LogReader("euroc", (), read, sniff, describe=describe, folder=True)
