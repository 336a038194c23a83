"""The calibration jobs as Python calls (align.api): each on an independent simulated session of known truth,
estimates inside 3 sigma, the result stamped with its provenance (the log's SHA-256); the one column convention."""

import hashlib

import numpy as np
import pytest
from magtruth import axis_down_turn, draw_truth, tumble

import align.api as ia
from align.calibration.accel import face_ups
from align.calibration.posesim import PoseSessionSpec, random_sensors, simulate_poses
from align.errors import InputError
from align.io.source import LogSource

G = 9.80665


def sha(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def within(got, truth, sigma, k=3.0):
    z = np.abs((np.asarray(got) - np.asarray(truth)) / np.asarray(sigma))
    assert np.all(z < k), z


def provenance_names(result, role, path):
    rec = {f.role: f for f in result.provenance.files}
    assert rec[role].sha256 == sha(path) and rec[role].size == path.stat().st_size
    return rec


# ---------------------------------------------------------------- sessions of known truth

def faces_log(tmp_path, m, b, header="time,acc_x,acc_y,acc_z", n=400, noise=2e-3, seed=1):
    """Six faces (``n`` samples each) separated by moves, with a positions file that names each face's samples."""
    rng = np.random.default_rng(seed)
    blocks, rows, start = [], [], 0
    for name, up in face_ups().items():
        blocks.append(m @ (G * np.asarray(up, float)) + b + rng.normal(0, noise, (n, 3)))
        sign = "+" if name.endswith("p") else "-"
        rows.append(f'[[position]]\nname = "{name}"\nup = "{sign}{name[0]}"\nstart = {start}\nend = {start + n}\n')
        blocks.append(rng.normal(0, 3.0, (100, 3)))
        start += n + 100
    a = np.vstack(blocks)
    log = tmp_path / "acc.csv"
    np.savetxt(log, np.column_stack([np.arange(len(a)) / 100.0, a]), delimiter=",", header=header, comments="")
    pos = tmp_path / "positions.toml"
    pos.write_text("\n".join(rows))
    return log, pos


def ferraris_log(tmp_path, m_a, b_a, m_g, b_g, fs=100.0, seed=3):
    """A Ferraris session: the six faces, then a -360 deg turn about each axis pointing up; imucal's names."""
    rng = np.random.default_rng(seed)
    acc, gyr, sections, n = [], [], {}, 0
    ups = {"x_p": (1, 0, 0), "x_a": (-1, 0, 0), "y_p": (0, 1, 0), "y_a": (0, -1, 0), "z_p": (0, 0, 1),
           "z_a": (0, 0, -1)}

    def add(name, f, w, k):
        nonlocal n
        acc.append(m_a @ f + b_a + rng.normal(0, 2e-3, (k, 3)))
        gyr.append(np.asarray(w, float) @ m_g.T + b_g + rng.normal(0, 2e-4, (k, 3)))
        if name:
            sections[name] = {"start": n, "end": n + k}
        n += k

    for name, up in ups.items():
        add(name, G * np.array(up, float), np.zeros((300, 3)), 300)
        add(None, G * np.array(up, float), np.zeros((50, 3)), 50)
    turn_s = 8.0
    for i, axis in enumerate("xyz"):
        k = int(turn_s * fs)
        w = np.zeros((k, 3))
        w[:, i] = np.deg2rad(-360.0) / turn_s
        add(f"{axis}_rot", G * np.eye(3)[i], w, k)
        add(None, G * np.eye(3)[i], np.zeros((50, 3)), 50)
    a, g = np.vstack(acc), np.vstack(gyr)
    log = tmp_path / "ferraris.csv"
    np.savetxt(log, np.column_stack([a, np.rad2deg(g)]), delimiter=",",
               header="acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z", comments="")
    import json

    sec = tmp_path / "sections.json"
    sec.write_text(json.dumps(sections))
    return log, sec


def poses_log(tmp_path, seed=11, gyro_header=("gyr_x", "gyr_y", "gyr_z")):
    rng = np.random.default_rng(seed)
    m_a, b_a, m_g, b_g = random_sensors(rng)
    s = simulate_poses(PoseSessionSpec(fs=50.0, poses=16, init_s=20.0), m_a, b_a, m_g, b_g, rng)
    log = tmp_path / "poses.csv"
    header = ",".join(["time", "acc_x", "acc_y", "acc_z", *gyro_header])
    np.savetxt(log, np.column_stack([s.t, s.acc, np.rad2deg(s.gyr)]), delimiter=",", header=header, comments="")
    return log, s


# ---------------------------------------------------------------- each job against its truth

def test_calibrate_accel_recovers_the_truth_with_provenance(tmp_path):
    m = np.array([[1.01, 0.004, -0.003], [0.0, 0.985, 0.002], [0.0, 0.0, 1.012]])
    b = np.array([0.12, -0.2, 0.07])
    log, pos = faces_log(tmp_path, m, b)
    got = ia.calibrate_accel(log=log, positions=pos)
    cal = got.sensor("accelerometer")
    within(cal.M, m, cal.sigma_M + 1e-12)
    within(cal.bias, b, cal.sigma_bias + 1e-12)
    provenance_names(got, "log", log)
    provenance_names(got, "positions", pos)
    assert got.provenance.job == "calibrate accel"
    assert got.inputs["columns"] == "time,acc_x,acc_y,acc_z" and got.inputs["positions"] == str(pos)
    # the same job through the registry and an explicit options value
    again = ia.job("calibrate accel").run(ia.AccelOptions(log=LogSource(path=log), positions=pos))
    assert np.array_equal(again.sensor("accelerometer").M, cal.M)


def test_calibrate_accel_time_column_and_old_names(tmp_path):
    m, b = np.diag([1.01, 0.99, 1.0]), np.array([0.1, -0.2, 0.05])
    ref = ia.calibrate_accel(log=faces_log(tmp_path, m, b)[0], positions=tmp_path / "positions.toml")
    other = tmp_path / "o"
    other.mkdir()
    log, pos = faces_log(other, m, b, header="stamp,ax,ay,az")
    got = ia.calibrate_accel(log=log, positions=pos, time_column="stamp")  # ax,ay,az: old default names
    assert np.allclose(got.sensor("accelerometer").M, ref.sensor("accelerometer").M)
    assert got.inputs["columns"] == "stamp,ax,ay,az"
    with pytest.raises(InputError, match="named twice") as exc:
        ia.calibrate_accel(log=log, columns="ax,ay,ax", time_column="stamp")
    assert exc.value.where == "{columns}"


def test_ferraris_recovers_the_truth(tmp_path):
    rng = np.random.default_rng(5)
    m_a, b_a, m_g, b_g = random_sensors(rng)
    log, sec = ferraris_log(tmp_path, m_a, b_a, m_g, b_g)
    got = ia.ferraris(log=log, rate_hz=100.0, sections=sec, g_sensitivity=False)
    acc, gyr = got.sensor("accelerometer"), got.sensor("gyroscope")
    within(acc.M, m_a, acc.sigma_M + 1e-12)
    within(gyr.M, m_g, gyr.sigma_M + 1e-12)
    within(gyr.bias, b_g, gyr.sigma_bias + 1e-12)
    provenance_names(got, "log", log)
    provenance_names(got, "sections", sec)
    with pytest.raises(InputError, match="rate_hz"):
        ia.ferraris(log=log, sections=sec)


def test_calibrate_mag_recovers_the_truth_with_provenance(tmp_path):
    rng = np.random.default_rng(21)
    truth = draw_truth(rng)
    raw = tumble(truth, rng, 1500, "sphere", 0.3e-6)
    log = tmp_path / "mag.csv"
    np.savetxt(log, raw * 1e6, delimiter=",", header="mx,my,mz", comments="")  # old default names
    got = ia.calibrate_mag(log=log, field=truth.field)
    within(got.hard_iron, truth.hard, got.sigma_hard_iron)
    provenance_names(got, "log", log)
    assert got.inputs["columns"] == "mx,my,mz"
    with pytest.raises(InputError, match="named twice") as exc:
        ia.calibrate_mag(log=log, columns="mx,my,mx")
    assert exc.value.where == "{columns}"


def test_calibrate_mag_axis_down_files_enter_the_provenance(tmp_path):
    rng = np.random.default_rng(13)
    truth = draw_truth(rng)
    raw = tumble(truth, rng, 1000, "sphere", 0.5e-6)
    log = tmp_path / "tumble.csv"
    np.savetxt(log, raw * 1e6, delimiter=",", header="mag_x,mag_y,mag_z", comments="")
    files = {}
    for i, a in enumerate("xyz"):
        files[a] = tmp_path / f"{a}down.csv"
        np.savetxt(files[a], axis_down_turn(truth, i, rng)[0] * 1e6, delimiter=",", header="mag_x,mag_y,mag_z",
                   comments="")
    text = ",".join(f"{a}={files[a]}" for a in "xyz")
    got = ia.calibrate_mag(log=log, axis_down=text)
    assert got.misalignment_method == "axis-down" and got.inputs["axis_down"] == text
    for a in "xyz":
        provenance_names(got, f"axis_down.{a}", files[a])
    same = ia.calibrate_mag(log=log, axis_down=files)  # a mapping of paths: the same job
    assert np.array_equal(same.misalignment, got.misalignment)


def test_calibrate_gyro_recovers_the_truth_with_provenance(tmp_path):
    log, s = poses_log(tmp_path)
    got = ia.calibrate_gyro(log=log)  # gyr_x...: the old default names of calibrate gyro
    gyr, acc = got.sensor("gyroscope"), got.sensor("accelerometer")
    # the frame the session reports in (the accelerometer's, M_a = M_c Q): Q from the estimate, whichever
    # triangular convention fixes it; then the gyro's truth in it is M_g Q^T
    u, _, vt = np.linalg.svd(np.linalg.solve(acc.M, s.M_a))
    q = u @ vt
    assert np.abs(acc.M @ q - s.M_a).max() < 5e-3
    within(gyr.M, s.M_g @ q.T, gyr.sigma_M + 1e-12, k=3.5)
    provenance_names(got, "log", log)
    assert got.inputs["gyro_columns"] == "time,gyr_x,gyr_y,gyr_z" and got.inputs["accel_columns"] == "acc_x,acc_y,acc_z"
    assert got.provenance.options["log"]["path"] == str(log)


def test_calibrate_gyro_accelerometer_in_a_second_file(tmp_path):
    log, s = poses_log(tmp_path, seed=12, gyro_header=("gyro_x", "gyro_y", "gyro_z"))
    acc_log = tmp_path / "acc.csv"
    np.savetxt(acc_log, np.column_stack([s.t, s.acc]), delimiter=",", header="t,a1,a2,a3", comments="")
    ref = ia.calibrate_gyro(log=log)
    got = ia.calibrate_gyro(log=log, accel=LogSource(path=acc_log, columns="t,a1,a2,a3"))
    assert np.allclose(got.sensor("gyroscope").M, ref.sensor("gyroscope").M, atol=1e-9)
    rec = provenance_names(got, "accel_log", acc_log)
    assert "log" in rec and got.inputs["accel_log"] == str(acc_log)
    with pytest.raises(InputError) as exc:  # a1..a3 without the time column: 'time' is not in that file
        ia.calibrate_gyro(log=log, accel=LogSource(path=acc_log, columns="a1,a2,a3"))
    assert "time" in exc.value.message


def test_a_log_source_beside_source_fields_is_refused(tmp_path):
    with pytest.raises(TypeError, match="inside the LogSource"):
        ia.calibrate_accel(log=LogSource(path=tmp_path / "x.csv"), columns="a,b,c")
