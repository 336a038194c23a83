"""Input and output: logs (every reader), files (TOML, JSON, atomic writes), exports.

Public names
------------
read_columns, read_log, read_static, NpyChunks, check_finite, check_time, check_log (from ``logs``);
existing_file, read_toml, read_json, write_json, write_text, write_bytes, write_csv (from ``files``);
c_header (from ``export``)
"""

from align.io.export import c_header
from align.io.files import existing_file, read_json, read_toml, write_bytes, write_csv, write_json, write_text
from align.io.logs import NpyChunks, check_finite, check_log, check_time, read_columns, read_log, read_static

__all__ = ["c_header", "existing_file", "read_json", "read_toml", "write_bytes", "write_csv", "write_json", "write_text",
           "NpyChunks", "check_finite", "check_log", "check_time", "read_columns", "read_log", "read_static"]
