"""The MPU-6050 session of tomisuarez2/ImuCalibration: imu-align's calibration against the authors' published
parameters, and the authors' validation file (a hand rotation of about +90 deg about x) integrated with both.

Run from the repo root: ``python examples/calibration/mpu6050_compare.py``. The numbers are in README.md.

The authors' model (ImuCalibrationModules/imu_calibration.py), raw int16 counts::

    acc  = T_a K_a (raw + b_a),  T_a = [[1, -m0, m1], [0, 1, -m2], [0, 0, 1]]
    gyro = T_g K_g (raw - b_g),  T_g = [[1, -m0, m1], [m2, 1, -m3], [-m4, m5, 1]]

with ``K`` diagonal (SI per count). In imu-align's ``raw = M true + bias``: ``M = (T K)^-1`` (counts per SI
unit) and ``bias = -b_a`` (accelerometer), ``bias = b_g`` (gyro). ``T_a`` is upper triangular, so their
frame is imu-align's accelerometer frame (x along the accelerometer's x axis, y in its x-y plane) and the
two gyro matrices compare element by element.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from align.attitude import integrate, quat_to_matrix
from align.calibration.gyro import calibrate_gyro_session
from align.calibration.statics import static_intervals
from align.io.formats import LogFormat
from align.io.logs import read_sensor_log
from align.units import DEG

HERE = Path(__file__).resolve().parent
DATA = HERE.parents[2] / "shared" / "data" / "multiposition" / "mpu6050_tomisuarez2"
FMT = LogFormat(skip_rows=4)


def authors() -> dict:
    """The authors' published parameters as ``M`` and ``bias`` (counts per SI unit, counts)."""
    pa = np.loadtxt(DATA / "authors_result_params_acc.csv")
    pg = np.loadtxt(DATA / "authors_result_params_gyro.csv")
    m = pa[:3]
    t_a = np.array([[1, -m[0], m[1]], [0, 1, -m[2]], [0, 0, 1]])
    m = pg[:6]
    t_g = np.array([[1, -m[0], m[1]], [m[2], 1, -m[3]], [-m[4], m[5], 1]])
    return {"acc_M": np.linalg.inv(t_a @ np.diag(pa[3:6])), "acc_bias": -pa[6:9],
            "gyr_M": np.linalg.inv(t_g @ np.diag(pg[6:9])), "gyr_bias": pg[9:12]}


def read(name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Time (s), accelerometer and gyro counts (n, 3) of one of the folder's logs (100 Hz, no time column)."""
    acc = read_sensor_log(DATA / name, ["ax", "ay", "az"], "counts", None, 100.0, "acceleration", FMT, counts=True)
    gyr = read_sensor_log(DATA / name, ["gx", "gy", "gz"], "counts", None, 100.0, "angular_rate", FMT, counts=True)
    return gyr.t, acc.data, gyr.data


def ours(drop: tuple = (1, 5, 8), force: bool = False):
    """imu-align's calibration of the session (saturated rotations 1, 5, 8 left out, or forced in)."""
    t, a, g = read("example_data_calibration.csv")
    return calibrate_gyro_session(t, a, g, "counts", "counts", detector=detector_for(36.5), gyro_range=1e9 if force else None,
                                  drop=() if force else drop, where="example_data_calibration.csv")


def detector_for(init_s: float):
    from align.calibration.accel import StaticDetector

    return StaticDetector(init_static_s=init_s)


def validate(m_g: np.ndarray, m_a: np.ndarray, b_a: np.ndarray) -> dict:
    """The validation file's rotation integrated with ``m_g`` (bias: the file's own initial rest):
    turn (deg), rotation vector (deg, accelerometer frame) and the angle between the integrated and the
    accelerometer's gravity direction at the end (deg, with the same calibration's accelerometer)."""
    t, a, g = read("imu_90_x_rot.csv")
    rest = static_intervals(a, 100.0, 1.0, 6.0, 10.0, 1.0)
    (s0, e0), (s1, e1) = rest[0], rest[1]
    w = np.linalg.solve(m_g, (g - g[s0:e0].mean(axis=0)).T).T
    c = quat_to_matrix(integrate(w[e0 - 1:s1 + 1], np.diff(t[e0 - 1:s1 + 1]))[-1])
    from scipy.spatial.transform import Rotation

    rv = Rotation.from_matrix(c).as_rotvec() / DEG

    def up(x):
        f = np.linalg.solve(m_a, x.mean(axis=0) - b_a)
        return f / np.linalg.norm(f)

    u0, u1 = up(a[s0:e0]), up(a[s1:e1])
    pred = c.T @ u0
    gap = np.degrees(np.arctan2(np.linalg.norm(np.cross(pred, u1)), pred @ u1))
    return {"turn": float(np.linalg.norm(rv)), "rotvec": rv, "gravity_gap": float(gap),
            "gravity_turn": float(np.degrees(np.arccos(np.clip(u0 @ u1, -1, 1)))), "times": (t[e0 - 1], t[s1])}


def main() -> None:
    ref = authors()
    runs = {"imu-align (rotations 1, 5, 8 left out)": ours(), "imu-align (all 9, saturated forced in)": ours(force=True)}
    np.set_printoptions(precision=5, suppress=True)
    print("authors' gyro M (counts per rad/s):\n", ref["gyr_M"], "\nbias", ref["gyr_bias"])
    print("authors' accel M (counts per m/s^2):\n", ref["acc_M"], "\nbias", ref["acc_bias"])
    for name, s in runs.items():
        g = s.gyroscope
        print(f"\n{name}: gyro M\n", g.M, "\n1-sigma\n", g.sigma_M)
        print("difference / sigma\n", (g.M - ref["gyr_M"]) / g.sigma_M)
        print("diagonal vs authors (%)", 100 * (np.diag(g.M) / np.diag(ref["gyr_M"]) - 1))
        print("residuals (deg):", [round(r.residual / DEG, 2) for r in s.rotations])
        print("accel M\n", s.accelerometer.M, "\nbias", s.accelerometer.bias, "+/-", s.accelerometer.sigma_bias)
    print("\nvalidation (imu_90_x_rot.csv): gap = angle between the integrated and the measured gravity direction")
    mine = runs["imu-align (rotations 1, 5, 8 left out)"].accelerometer
    accels = {"authors' accelerometer": (ref["acc_M"], ref["acc_bias"]), "imu-align's": (mine.M, mine.bias)}
    gyros = {"authors": ref["gyr_M"], **{k: s.gyroscope.M for k, s in runs.items()},
             "nominal 131 LSB/(deg/s)": np.eye(3) * 131 / DEG}
    for name, m_g in gyros.items():
        got = {k: validate(m_g, *a) for k, a in accels.items()}
        v = next(iter(got.values()))
        gaps = ", ".join(f"{g['gravity_gap']:.2f} deg with the {k}" for k, g in got.items())
        print(f"  {name}: turn {v['turn']:.2f} deg, rotation vector {np.round(v['rotvec'], 2)} deg; gap {gaps} "
              f"(gravity turned {v['gravity_turn']:.2f} deg; t={v['times'][0]:.2f}-{v['times'][1]:.2f} s)")


if __name__ == "__main__":
    main()
