"""Input and output: logs (every reader), files (TOML, JSON, atomic writes), exports.

Public names
------------
read_sensor_log, SensorLog, read_log, read_static_log, StaticLog, read_static, read_columns, sensor_scale, NpyChunks,
check_finite, check_readings, check_time, check_log, MAX_READING (from ``logs``);
LogFormat, TIME_UNITS, DELIMITERS (a logger file's format, from ``formats``);
existing_file, read_text, decode_text, read_toml, read_json, write_json, write_text, write_bytes, write_csv
(from ``files``); check_keys and the key helpers (``keys``);
Outputs (``outputs``: a run's files written all together or not at all); c_header (from ``export``)
"""

from align.io.consumers import c_header
from align.io.files import (
           decode_text,
           existing_file,
           read_json,
           read_text,
           read_toml,
           write_bytes,
           write_csv,
           write_json,
           write_text,
)
from align.io.formats import DELIMITERS, TIME_UNITS, LogFormat
from align.io.keys import check_keys
from align.io.logs import (
           MAX_READING,
           NpyChunks,
           SensorLog,
           StaticLog,
           check_finite,
           check_log,
           check_readings,
           check_time,
           read_columns,
           read_log,
           read_sensor_log,
           read_static,
           read_static_log,
           sensor_scale,
)
from align.io.outputs import Outputs

__all__ = ["c_header", "decode_text", "read_text", "existing_file", "read_json", "read_toml", "write_bytes", "write_csv",
           "write_json", "write_text", "check_keys", "Outputs", "MAX_READING", "check_readings", "NpyChunks",
           "check_finite", "check_log", "check_time", "read_columns", "read_log", "read_static", "read_sensor_log",
           "SensorLog", "read_static_log", "StaticLog", "sensor_scale", "LogFormat", "TIME_UNITS", "DELIMITERS"]
