"""imu-align parts, and a user's parts file used by budget, check and plan (--parts or IMU_ALIGN_PARTS)."""

import json
import math

import pytest
from support import ROOT

from align.parts import PARTS

EXAMPLE1 = ROOT / "examples" / "budget" / "example1.toml"
MANOEUVRE = ROOT / "examples" / "sensitivity" / "example2.toml"
PARTS_FILE = """
[MY-IMU]
kind = "module"
axis_to_package = { value = "0.6 deg", source = "MY-IMU datasheet rev B, table 3", confirmed = true }
arw = "0.2 deg/sqrt(h)"
"""


@pytest.fixture(autouse=True)
def _no_user_parts(monkeypatch):
    monkeypatch.delenv("IMU_ALIGN_PARTS", raising=False)


@pytest.fixture
def files(tmp_path):
    parts = tmp_path / "parts.toml"
    parts.write_text(PARTS_FILE)
    mount = tmp_path / "mount.toml"
    mount.write_text(EXAMPLE1.read_text().replace('part = "ADIS16485"', 'part = "MY-IMU"')
                     .replace('axis_to_package = "1 deg"\n', ""))
    return parts, mount


def _one_line_error(res, *words):
    assert res.code == 2, (res.out, res.err)
    lines = res.err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in res.err, res.err
    for w in words:
        assert w in lines[0], (w, lines[0])


def test_parts_lists_every_preset_figure_with_value_unit_flag_and_source(run_cli):
    res = run_cli("parts")
    assert res.code == 0, res.err
    lines = res.out.splitlines()
    for part in PARTS.values():
        assert any(line.startswith(part.name) for line in lines), part.name
        for name, fig in part.figures():
            number, unit = fig.value.split(" ", 1)
            flag = "confirmed" if fig.confirmed else "NOT confirmed"
            assert any(line.split()[:1] == [name] and f" {number} " in line and f" {unit} " in line and
                       f" {flag} " in line and line.endswith(fig.source) for line in lines), (part.name, name)
    n = sum(len(p.figures()) for p in PARTS.values())
    assert f"{len(PARTS)} parts, {n} figures, {sum(f.confirmed for p in PARTS.values() for _, f in p.figures())} confirmed" \
        in res.out


def test_parts_name_shows_one_part_in_full_and_refuses_an_unknown_one(run_cli):
    res = run_cli("parts", "adis16470")
    assert res.code == 0, res.err
    assert res.out.startswith("ADIS16470 (module)") and "ADIS16485" not in res.out
    assert "NOT confirmed" in res.out and "for: axis-to-package misalignment" in res.out and "not stated:" in res.out
    _one_line_error(run_cli("parts", "ADIS1648"), "unknown part 'ADIS1648'", "did you mean 'ADIS16485'", "--parts")


def test_a_user_parts_file_adds_a_part_listed_with_its_source(run_cli, files, monkeypatch):
    parts, _ = files
    res = run_cli("parts", "--parts", parts)
    assert res.code == 0, res.err
    assert f"user parts file: {parts}" in res.out and "MY-IMU (module)" in res.out
    assert "MY-IMU datasheet rev B, table 3 (user parts file" in res.out
    monkeypatch.setenv("IMU_ALIGN_PARTS", str(parts))
    res = run_cli("parts", "my-imu")
    assert res.code == 0, res.err
    assert "0.6 deg" in res.out


def test_budget_and_check_use_a_user_part_and_show_its_source(run_cli, files, tmp_path):
    parts, mount = files
    out = tmp_path / "b.json"
    res = run_cli("budget", mount, "--parts", parts, "--json", out)
    assert res.code == 0, res.err
    assert "preset MY-IMU: axis_to_package 0.6 deg (confirmed; source: MY-IMU datasheet rev B, table 3" in res.out
    d = json.loads(out.read_text())
    # Eq 1 with the user's 0.6 deg and the reference's skew of Example 1's screws (theta_Z = 0.83736 deg)
    assert d["total_deg"] == pytest.approx(math.hypot(0.6, 0.83736), abs=1e-5)
    assert d["mount"]["part"] == "MY-IMU" and d["mount"]["preset"]["axis_to_package"]["confirmed"] is True
    assert d["inputs"]["parts"] == str(parts)
    res = run_cli("check", mount, MANOEUVRE, "--parts", parts)
    assert res.code in (0, 4), res.err
    assert "preset MY-IMU: axis_to_package 0.6 deg (confirmed" in res.out
    # without the parts file, MY-IMU is no preset and the mount gives no axis_to_package: refused, naming both fixes
    _one_line_error(run_cli("budget", mount), f"{mount}: imu.part", "unknown part 'MY-IMU'", "--parts",
                    "axis_to_package")


def test_budget_of_an_unconfirmed_preset_says_so(run_cli, tmp_path):
    mount = tmp_path / "m.toml"
    mount.write_text(EXAMPLE1.read_text().replace('"ADIS16485"', '"ADIS16470"').replace('axis_to_package = "1 deg"\n', ""))
    res = run_cli("budget", mount)
    assert res.code == 0, res.err
    assert ("preset ADIS16470: axis_to_package 1 deg (NOT confirmed; source: typical value of the part family, not read "
            "from its datasheet)") in res.out


def test_plan_uses_a_user_part_from_the_environment_and_records_its_sources(run_cli, files, tmp_path, monkeypatch):
    parts, _ = files
    monkeypatch.setenv("IMU_ALIGN_PARTS", str(parts))
    out = tmp_path / "p.json"
    res = run_cli("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--imu", "MY-IMU", "--json", out)
    assert res.code == 0, res.err
    d = json.loads(out.read_text())
    # Example 3 with the user's white noise alone: sigma = N / sqrt(tau), N = 0.2 deg/sqrt(h) = 12 deg/h sqrt(s)
    target = 100 * 3600 * math.sin(math.radians(0.1)) / 10
    assert d["averaging_time_s"] == pytest.approx((12 / target) ** 2, rel=1e-6)
    assert d["inputs"]["imu"] == "MY-IMU" and d["inputs"]["preset"]["arw"]["value"] == "0.2 deg/sqrt(h)"
    assert d["inputs"]["preset"]["arw"]["confirmed"] is False
    assert "preset MY-IMU: arw 0.2 deg/sqrt(h) (NOT confirmed; source: user parts file" in res.out


def test_plan_shows_the_presets_it_uses_and_takes_a_label(run_cli, tmp_path):
    res = run_cli("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--imu", "ADIS16470")
    assert res.code == 0, res.err
    assert "preset ADIS16470: arw 0.34 deg/sqrt(h) (NOT confirmed" in res.out
    assert "preset ADIS16470: bias_instability 8 deg/h (confirmed" in res.out
    out = tmp_path / "p.json"
    res = run_cli("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--imu", "BENCH-7", "--arw", "0.2 deg/sqrt(h)",
                  "--json", out)
    assert res.code == 0, res.err
    d = json.loads(out.read_text())
    assert d["noise_source"].startswith("BENCH-7 (a label, not a preset)") and d["inputs"] == {"imu": "BENCH-7"}
    assert "part BENCH-7: no preset value used" in res.out
    _one_line_error(run_cli("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--imu", "BENCH-7"),
                    "--imu", "unknown part 'BENCH-7'", "--arw", "label")


@pytest.mark.parametrize("text,words", [
    ("[MY-IMU\naxis_to_package = 1", ["not valid TOML"]),
    ("[MY-IMU]\naxis_to_pakage = \"0.6 deg\"\n", ["[MY-IMU]", "unknown key 'axis_to_pakage'", "axis_to_package"]),
    ("[MY-IMU]\narw = \"0.2 deg\"\n", ["MY-IMU.arw", "angle random walk"]),
])
def test_a_malformed_parts_file_is_one_line_and_writes_nothing(run_cli, files, tmp_path, text, words):
    parts, mount = files
    parts.write_text(text)
    out = tmp_path / "b.json"
    _one_line_error(run_cli("budget", mount, "--parts", parts, "--json", out), str(parts), *words)
    assert not out.exists()
    _one_line_error(run_cli("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--imu", "MY-IMU", "--parts", parts,
                            "--json", out), str(parts), *words)
    assert not out.exists()


def test_a_bad_parts_file_in_the_environment_names_the_variable(run_cli, files, tmp_path, monkeypatch):
    _, mount = files
    monkeypatch.setenv("IMU_ALIGN_PARTS", str(tmp_path / "missing.toml"))
    _one_line_error(run_cli("budget", mount), "missing.toml", "IMU_ALIGN_PARTS")
    _one_line_error(run_cli("parts"), "missing.toml", "IMU_ALIGN_PARTS")
    # --parts wins over the variable
    parts, _ = files
    assert run_cli("budget", mount, "--parts", parts).code == 0
