"""Foundation, input files: read_toml / read_json refuse every unreadable file in one line naming it."""

import os

import pytest

from align.errors import InputError
from align.io.files import decode_text, read_json, read_text, read_toml

PLAN = '[[step]]\naxis = "+x"\nrate = "100 deg/s"\n'


def _refused(reader, path, *words):
    with pytest.raises(InputError) as err:
        reader(path)
    msg = str(err.value)
    assert msg.startswith(str(path)) and "\n" not in msg, msg
    for w in words:
        assert w in msg, (w, msg)
    return msg


@pytest.mark.parametrize("reader", [read_toml, read_json])
def test_non_utf8_file_names_the_byte_offset_and_line(tmp_path, reader):
    f = tmp_path / "latin1.toml"
    f.write_bytes('[test]\nlatitude = "48 deg"\n# M\u00fcnchen\n'.encode("latin-1"))
    _refused(reader, f, "not UTF-8 text (byte 0xfc at offset 30, line 3); save it as UTF-8")


@pytest.mark.parametrize("reader", [read_toml, read_json])
def test_utf16_binary_folder_missing_and_empty_files_are_one_line(tmp_path, reader):
    f = tmp_path / "f"
    f.write_bytes(PLAN.encode("utf-16"))
    _refused(reader, f, "is UTF-16 text; save it as UTF-8")
    f.write_bytes(b"\x00\x01\x02 binary")
    _refused(reader, f, "NUL bytes", "binary")
    _refused(reader, tmp_path, "is a folder, not a file")
    _refused(reader, tmp_path / "absent.toml", "file not found")
    f.write_text("")
    _refused(reader, f, "is empty")


def test_utf8_with_a_byte_order_mark_reads(tmp_path):
    f = tmp_path / "bom.toml"
    f.write_bytes(b"\xef\xbb\xbf" + PLAN.encode())
    assert read_toml(f)["step"][0]["axis"] == "+x"
    j = tmp_path / "bom.json"
    j.write_bytes(b"\xef\xbb\xbf" + b'{"a": {"start": 0, "end": 3}}')
    assert read_json(j) == {"a": {"start": 0, "end": 3}}
    with pytest.raises(InputError, match=r"w: not UTF-8 text \(byte 0xff at offset 5, line 2\)"):
        decode_text(b"\xef\xbb\xbfa\n\xff", "w")


def test_toml_syntax_comments_only_and_pathological_nesting(tmp_path):
    f = tmp_path / "p.toml"
    f.write_text("this is not toml = = =\n")
    _refused(read_toml, f, "not valid TOML", "line 1")
    f.write_text("# only a comment\n\n")
    _refused(read_toml, f, "is empty: no tables or keys")
    f.write_text("a = " + "[" * 100_000 + "\n")
    _refused(read_toml, f, "not valid TOML")
    f.write_text("a = " + "1" * 5000 + "\n")
    _refused(read_toml, f, "not valid TOML")


def test_json_duplicate_keys_syntax_nesting_and_top_level(tmp_path):
    f = tmp_path / "s.json"
    f.write_text('{"step 1": {"start": 0, "end": 10, "start": 5}}')
    _refused(read_json, f, "key 'start' is given twice")
    f.write_text('{"a": 1,}')
    _refused(read_json, f, "not valid JSON", "line 1")
    f.write_text("[" * 100_000)
    _refused(read_json, f, "not valid JSON", "nested too deeply")
    f.write_text("[1, 2]")
    _refused(read_json, f, "expected a JSON object")
    f.write_text("   \n")
    _refused(read_json, f, "is empty")


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="root reads every file")
def test_unreadable_file_is_one_line(tmp_path):
    f = tmp_path / "locked.toml"
    f.write_text(PLAN)
    f.chmod(0)
    try:
        _refused(read_text, f, "cannot read")
        _refused(read_toml, f, "cannot read")
    finally:
        f.chmod(0o644)
