"""imu-align export --to kalibr|openvins|vins|px4|ardupilot: every number follows from the Allan result file by the
conversion the consumer's documentation states (written out here: densities for Kalibr and OpenVINS, per-step
standard deviations N sqrt(f), K sqrt(f) for VINS-Fusion, PX4 and ArduPilot; see tests/io/test_noise_consumers.py
for the consumers' own update rules), the files load as their readers load them, and every refusal of issue 28 is
one line, exit 2, no file.

The Allan files' terms are in engineering units (deg/sqrt(h), deg/h/sqrt(h), m/s/sqrt(h), ug/sqrt(h)); the SI
conversions below are the units' definitions, not the tool's.
"""

import json
import math

import numpy as np
import pytest
import yaml
from support import ROOT

from align.calibration import Calibration, CalibrationSet
from align.noise.sim import NoiseSpec, simulate_noise
from align.results import save_result
from align.units import DEG

FS = 100.0
#: engineering unit of a term in the Allan file -> SI continuous density (rad/s/sqrt(Hz), m/s^2/sqrt(Hz), ...)
SI = {"deg/sqrt(h)": DEG / 60, "deg/h/sqrt(h)": DEG / 3600 / 60, "m/s/sqrt(h)": 1 / 60, "ug/sqrt(h)": 9.80665e-6 / 60}
TERMS = {("gyroscope", "white"): "angle_random_walk", ("gyroscope", "random_walk"): "rate_random_walk",
         ("accelerometer", "white"): "velocity_random_walk", ("accelerometer", "random_walk"): "acceleration_random_walk"}
#: the consumer's key -> (sensor, term, per-step), from each consumer's documentation
KEYS = {
    "kalibr": {"gyroscope_noise_density": ("gyroscope", "white", False), "gyroscope_random_walk": ("gyroscope",
               "random_walk", False), "accelerometer_noise_density": ("accelerometer", "white", False),
               "accelerometer_random_walk": ("accelerometer", "random_walk", False)},
    "vins": {"gyr_n": ("gyroscope", "white", True), "gyr_w": ("gyroscope", "random_walk", True),
             "acc_n": ("accelerometer", "white", True), "acc_w": ("accelerometer", "random_walk", True)},
    "px4": {"EKF2_GYR_NOISE": ("gyroscope", "white", True), "EKF2_GYR_B_NOISE": ("gyroscope", "random_walk", True),
            "EKF2_ACC_NOISE": ("accelerometer", "white", True), "EKF2_ACC_B_NOISE": ("accelerometer", "random_walk",
                                                                                      True)},
    "ardupilot": {"EK3_GYRO_P_NSE": ("gyroscope", "white", True), "EK3_GBIAS_P_NSE": ("gyroscope", "random_walk", True),
                  "EK3_ACC_P_NSE": ("accelerometer", "white", True), "EK3_ABIAS_P_NSE": ("accelerometer",
                                                                                          "random_walk", True)},
}
KEYS["openvins"] = KEYS["kalibr"]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Allan results of a gyroscope (deg/s) and an accelerometer at rest (m/s^2, reading gravity), 10 min at 100 Hz
    with white noise and a bias random walk; a 3-minute white-noise gyroscope (no random walk identified); an
    alignment of the bundled example."""
    from align.cli import run

    d, n = tmp_path_factory.mktemp("consumers"), int(FS * 600)
    gyro = simulate_noise(n, FS, NoiseSpec(white=0.3 * DEG / 60, random_walk=300 * DEG / 3600 / 60), 3, seed=21) / DEG
    acc = simulate_noise(n, FS, NoiseSpec(white=6e-4, random_walk=2e-3), 3, seed=22) + np.array([0.3, -0.2, 9.79])
    short = simulate_noise(int(FS * 180), FS, NoiseSpec(white=0.3 * DEG / 60), 3, seed=23) / DEG
    for name, x in (("g", gyro), ("a", acc), ("s", short)):
        np.save(d / f"{name}.npy", x)
    runs = [["allan", d / "g.npy", "--rate-hz", FS, "--json", d / "g.json"],
            ["allan", d / "a.npy", "--rate-hz", FS, "--units", "m/s^2", "--columns", "acc_x,acc_y,acc_z", "--json",
             d / "a.json"],
            ["allan", d / "s.npy", "--rate-hz", FS, "--json", d / "s.json"],
            ["matrix", ROOT / "examples" / "alignment" / "session.csv", "--plan", ROOT / "examples" / "alignment" /
             "plan.toml", "--json", d / "align.json"]]
    for args in runs:
        assert run([str(a) for a in args]) == 0, args
    return d


def figure(path, sensor: str, term: str) -> tuple[float, bool]:
    """The largest over the channels of the file's term, SI (its upper bound where not identified), and whether any
    channel was bounded."""
    d = json.loads(path.read_text())
    assert d["sensor"] == sensor
    vals, bounded = [], False
    for fit in d["fit"].values():
        t = fit["terms"][TERMS[(sensor, term)]]
        v = t["value"] if t["identifiable"] else t["upper_bound"]
        bounded |= not t["identifiable"]
        vals.append(v * SI[t["unit"]])
    return max(vals), bounded


def qgc_params(text: str) -> dict[str, float]:
    """QGroundControl's .params: '#' comments, tab-separated 'vehicle component name value type' (type 9: float)."""
    rows = [ln.split("\t") for ln in text.splitlines() if ln.strip() and not ln.startswith("#")]
    assert all(len(r) == 5 and r[:2] == ["1", "1"] and r[4] == "9" for r in rows), rows
    return {r[2]: float(r[3]) for r in rows}


def ardupilot_params(text: str) -> dict[str, float]:
    """ArduPilot's .parm as MAVProxy's 'param load' reads it: '#' comments, 'NAME VALUE'."""
    rows = [ln.split() for ln in text.splitlines() if ln.strip() and not ln.startswith("#")]
    assert all(len(r) == 2 for r in rows), rows
    return {r[0]: float(r[1]) for r in rows}


def kalibr_reads(d: dict) -> tuple[float, float]:
    """Kalibr's ImuParameters (kalibr_common/ConfigReader.py): every key present (a missing one raises), each noise
    value > 0, update_rate > 0; the discrete gyro sigma it uses is N / sqrt(1 / update_rate)."""
    for key in ("rostopic", "update_rate", *KEYS["kalibr"]):
        assert key in d, key
    assert d["update_rate"] > 0 and all(d[k] > 0 for k in KEYS["kalibr"])
    return d["gyroscope_noise_density"] / math.sqrt(1.0 / d["update_rate"]), d["gyroscope_random_walk"]


def read(to: str, text: str) -> dict[str, float]:
    """The noise keys of a file, read as its consumer reads it."""
    if to in ("kalibr", "vins"):
        return yaml.safe_load(text)
    if to == "openvins":
        assert text.startswith("%YAML:1.0\n")             # OpenCV's FileStorage directive, which PyYAML does not know
        return yaml.safe_load(text.split("\n", 1)[1])["imu0"]
    return qgc_params(text) if to == "px4" else ardupilot_params(text)


def _one_line(res, *words):
    assert res.code == 2, (res.out, res.err)
    lines = res.err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in res.err, res.err
    for w in words:
        assert w in lines[0], (w, lines[0])


@pytest.mark.parametrize(("to", "rate", "given"), [("kalibr", FS, None), ("openvins", FS, None), ("vins", FS, None),
                                                   ("vins", 200.0, "200"), ("px4", 100.0, None), ("px4", 250.0, "250"),
                                                   ("ardupilot", 1 / 0.012, None)])
def test_every_number_follows_from_the_allan_files_by_the_stated_conversion(files, run_cli, tmp_path, to, rate, given):
    out = tmp_path / "noise.out"
    args = ["export", files / "g.json", files / "a.json", "--to", to, "--inflate", "2", "--out", out]
    flag = "--predict-hz" if to in ("px4", "ardupilot") else "--rate-hz"
    res = run_cli(*args, *([flag, given] if given else []))
    assert res.code == 0, res.err
    text = out.read_text()
    got = read(to, text)
    assert set(KEYS[to]) <= set(got)
    if to in ("px4", "ardupilot"):
        assert set(got) == set(KEYS[to])                   # a parameter file sets the noise parameters, nothing else
    for key, (sensor, term, per_step) in KEYS[to].items():
        value, _ = figure(files / ("g.json" if sensor == "gyroscope" else "a.json"), sensor, term)
        want = 2 * value * (math.sqrt(rate) if per_step else 1.0)
        tol = 1e-7 if to in ("px4", "ardupilot") else 1e-12   # 32-bit floats in a parameter file
        assert got[key] == pytest.approx(want, rel=tol), key
        assert key in res.out                                # the terminal names every key written
    if to in ("kalibr", "openvins"):
        assert got["update_rate"] == rate and got["rostopic"] == "/imu0"
    if to == "kalibr":
        kalibr_reads(got)
    for words in ("imu-align 0.", "inflation: x2", f"f = {rate:g} Hz", "conversion:", "https://", "largest over"):
        assert words in text, words
    assert "inflation x2" in res.out


def test_vins_gets_gravity_as_the_accelerometer_reads_it(files, run_cli):
    res = run_cli("export", files / "g.json", files / "a.json", "--to", "vins")
    assert res.code == 0, res.err
    d = json.loads((files / "a.json").read_text())
    mean = np.array([d["figures"][ch]["bias"] for ch in ("acc_x", "acc_y", "acc_z")])
    assert d["units"]["bias"] == "m/s^2"
    assert yaml.safe_load(res.out)["g_norm"] == pytest.approx(float(np.linalg.norm(mean)), rel=1e-12)


def test_an_unidentified_random_walk_is_its_upper_bound_marked_so_everywhere(files, run_cli, tmp_path):
    out = tmp_path / "p.params"
    res = run_cli("export", files / "s.json", "--to", "px4", "--out", out)
    assert res.code == 0, res.err
    value, bounded = figure(files / "s.json", "gyroscope", "random_walk")
    assert bounded
    got = qgc_params(out.read_text())
    assert got["EKF2_GYR_B_NOISE"] == pytest.approx(value * 10.0, rel=1e-7)   # K sqrt(100 Hz), never 0
    assert set(got) == {"EKF2_GYR_NOISE", "EKF2_GYR_B_NOISE"}
    text = out.read_text()
    assert "95 % UPPER BOUND" in text and "not written" in text and "EKF2_ACC_NOISE" in text
    line = next(ln for ln in res.out.splitlines() if "EKF2_GYR_B_NOISE" in ln)
    assert "UPPER BOUND" in line


def test_a_datasheet_gives_the_gyroscope_and_its_random_walk_only_as_a_stated_bound(files, run_cli, tmp_path):
    """ADIS16470 (ADI datasheet, front page): noise density 0.008 deg/s/sqrt(Hz), in-run bias stability 8 deg/h; the
    bound K <= B sqrt(3/tau) at the floor's tau = 100 s."""
    out = tmp_path / "p.params"
    res = run_cli("export", files / "a.json", "--part", "ADIS16470", "--floor-tau", "100 s", "--to", "px4", "--out", out)
    assert res.code == 0, res.err
    got = qgc_params(out.read_text())
    assert got["EKF2_GYR_NOISE"] == pytest.approx(0.008 * DEG * 10.0, rel=1e-7)
    assert got["EKF2_GYR_B_NOISE"] == pytest.approx(8 * DEG / 3600 * math.sqrt(3 / 100) * 10.0, rel=1e-7)
    assert "datasheet of ADIS16470" in out.read_text() and "UPPER BOUND" in out.read_text()
    _one_line(run_cli("export", files / "a.json", "--part", "ADIS16470", "--to", "px4"), "random walk K", "--floor-tau")
    _one_line(run_cli("export", files / "g.json", "--part", "ADIS16470", "--floor-tau", "100 s", "--to", "px4"),
              "--part", "give one")


def test_refusals_are_one_line_and_write_nothing(files, run_cli, tmp_path):
    out = tmp_path / "x.out"
    for to in ("openvins", "vins", "px4", "ardupilot"):
        _one_line(run_cli("export", files / "align.json", "--to", to, "--out", out), "align.json", "no noise figures")
    _one_line(run_cli("export", files / "g.json", "--to", "openvins", "--out", out), "accelerometer", "Allan result")
    _one_line(run_cli("export", files / "align.json", "--to", "c", "--inflate", "2"), "--inflate", "--to c")
    _one_line(run_cli("export", files / "g.json", "--to", "px4", "--floor-tau", "100 s"), "--floor-tau", "--part")
    _one_line(run_cli("export", files / "g.json", "--to", "px4", "--inflate", "0.5"), "--inflate")
    _one_line(run_cli("export", files / "g.json", "--to", "px4", "--rate-hz", "400"), "--rate-hz", "--predict-hz")
    _one_line(run_cli("export", files / "g.json", "--to", "vins", "--predict-hz", "100"), "--predict-hz")
    # a term neither identified nor bounded (a hand-edited file): named, never written as 0
    d = json.loads((files / "g.json").read_text())
    t = d["fit"]["gyro_y"]["terms"]["rate_random_walk"]
    t.update(identifiable=False, value=None, upper_bound=None)
    (tmp_path / "unbounded.json").write_text(json.dumps(d))
    for to in ("kalibr", "px4"):
        _one_line(run_cli("export", tmp_path / "unbounded.json", files / "a.json", "--to", to, "--out", out),
                  "unbounded.json", "gyroscope K of gyro_y", "neither identified nor bounded")
    # an accelerometer in g read as m/s^2: |mean| = 1 at rest
    d = json.loads((files / "a.json").read_text())
    for ch, v in zip(("acc_x", "acc_y", "acc_z"), (0.03, -0.02, 0.999)):
        d["figures"][ch]["bias"] = v
    (tmp_path / "in_g.json").write_text(json.dumps(d))
    _one_line(run_cli("export", files / "g.json", tmp_path / "in_g.json", "--to", "vins", "--out", out),
              "in_g.json", "reads g, not m/s^2")
    assert not out.exists()


def test_a_hand_edited_a_and_an_overflowing_bias_are_refused_naming_the_field(files, run_cli, tmp_path):
    """Issue 28: A not M^-1 was written as is; a bias of 1e300 became 0.0 in the C header."""
    out = tmp_path / "x.h"
    d = json.loads((files / "align.json").read_text())
    d["A"][0][1] += 1e-3
    (tmp_path / "edited.json").write_text(json.dumps(d))
    for to in ("c", "csv"):
        _one_line(run_cli("export", tmp_path / "edited.json", "--to", to, "--out", out), "edited.json: A",
                  "not the inverse of M")
    d = json.loads((files / "align.json").read_text())
    d["bias"][1] = 1e300
    (tmp_path / "huge.json").write_text(json.dumps(d))
    _one_line(run_cli("export", tmp_path / "huge.json", "--to", "c", "--out", out), "huge.json: bias",
              "beyond the range of a C float")
    m = np.diag([1.01, 0.99, 1.0])
    cs = CalibrationSet({"accelerometer": Calibration("accelerometer", m, np.zeros(3), np.zeros((3, 3)), np.zeros(3),
                                                      "m/s^2", "test")})
    save_result(tmp_path / "cal.json", cs)
    d = json.loads((tmp_path / "cal.json").read_text())
    assert np.allclose(np.array(d["accelerometer"]["A"]) @ m, np.eye(3))
    d["accelerometer"]["A"][2][2] = 1.2
    (tmp_path / "cal_edited.json").write_text(json.dumps(d))
    _one_line(run_cli("export", tmp_path / "cal_edited.json", "--to", "c", "--out", out), "accelerometer.A")
    assert not out.exists()
    # within the tolerance (the JSON's own rounding) it exports
    assert run_cli("export", tmp_path / "cal.json", "--to", "c", "--out", out).code == 0


def test_a_hand_edited_a_is_refused_wherever_the_result_is_read(files, tmp_path):
    """A = M^-1 is checked by the result's reader (align.wellformed.check_inverse), so apply and the report refuse
    an edited file as export does, not only export."""
    from align.errors import InputError
    from align.results import load_result

    d = json.loads((files / "align.json").read_text())
    d["A"][1][2] += 1e-3
    (tmp_path / "edited.json").write_text(json.dumps(d))
    with pytest.raises(InputError, match="not the inverse of M") as exc:
        load_result(tmp_path / "edited.json")
    assert exc.value.where.endswith("edited.json: A")
