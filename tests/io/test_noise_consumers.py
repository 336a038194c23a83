"""The noise consumers' writers (align.io.noise_consumers) against the consumers' own rules, written out here from
their documentation and code, not from the writer:

* Kalibr (wiki "IMU Noise Model", https://github.com/ethz-asl/kalibr/wiki/IMU-Noise-Model) and OpenVINS
  (config/euroc_mav/kalibr_imu_chain.yaml, VioManagerOptions.h): the continuous-time densities themselves, in
  rad/s/sqrt(Hz), rad/s^2/sqrt(Hz), m/s^2/sqrt(Hz), m/s^3/sqrt(Hz); Kalibr discretises them as
  sigma_d = sigma / sqrt(dt) and sigma_bd = sigma_b sqrt(dt).
* PX4 EKF2 (src/modules/ekf2/EKF/covariance.cpp, predictCovariance): each prediction step dt adds
  (dt * EKF2_GYR_NOISE)^2 to a delta angle's variance and (dt * EKF2_GYR_B_NOISE)^2 to the gyro bias variance.
* ArduPilot EKF3 (AP_NavEKF3_core.cpp, CovariancePrediction): (dt * EK3_GYRO_P_NSE)^2 to a delta angle's variance
  and (dt^2 * EK3_GBIAS_P_NSE)^2 to the delta-angle bias state (rad).
* VINS-Fusion: the VINS-Mono paper (Qin, Li, Shen, T-RO 2018, Sec. IV-B, eq. 10) propagates the pre-integration
  covariance per IMU sample dt as (I + F dt) P (I + F dt)^T + (G dt) Q (G dt)^T with Q = diag(acc_n^2, gyr_n^2,
  acc_w^2, gyr_w^2); vins_estimator/src/factor/integration_base.h adds (dt acc_w)^2 to the bias (V(9,12) = I dt).

A continuous white noise N makes an angle (velocity) variance grow as N^2 T and a random walk K a bias variance as
K^2 T: the values are right when the consumer's own rule gives the same growth. Files parse (PyYAML; a .params
reader written here from QGroundControl's format page and MAVProxy's NAME VALUE lines).
"""

import math

import numpy as np
import pytest
import yaml

from align.errors import InputError
from align.io.noise_consumers import CONSUMERS, NoiseTerm, entries, float32_text, header_lines, noise_yaml, params_text

N_G, K_G, N_A, K_A = 1.7e-4, 2.0e-5, 2.0e-3, 3.0e-3      # EuRoC's ADIS16448 figures, OpenVINS's example file
FIGS = [NoiseTerm("gyroscope", "white", N_G, "fitted", "test"), NoiseTerm("gyroscope", "random_walk", K_G,
                                                                           "upper bound", "test"),
        NoiseTerm("accelerometer", "white", N_A, "fitted", "test"), NoiseTerm("accelerometer", "random_walk", K_A,
                                                                               "datasheet", "test")]
#: the keys each consumer documents, in its own spelling
DOCUMENTED = {
    "kalibr": {"gyroscope_noise_density", "gyroscope_random_walk", "accelerometer_noise_density",
               "accelerometer_random_walk"},
    "openvins": {"gyroscope_noise_density", "gyroscope_random_walk", "accelerometer_noise_density",
                 "accelerometer_random_walk"},
    "vins": {"gyr_n", "gyr_w", "acc_n", "acc_w"},
    "px4": {"EKF2_GYR_NOISE", "EKF2_GYR_B_NOISE", "EKF2_ACC_NOISE", "EKF2_ACC_B_NOISE"},
    "ardupilot": {"EK3_GYRO_P_NSE", "EK3_GBIAS_P_NSE", "EK3_ACC_P_NSE", "EK3_ABIAS_P_NSE"},
}


def _values(name: str, inflate: float, rate: float) -> dict[str, float]:
    return {e.key.name: e.value for e in entries(CONSUMERS[name], FIGS, inflate, rate)}


def qgc_params(text: str) -> dict[str, tuple[float, int]]:
    """QGroundControl's parameter file (https://docs.qgroundcontrol.com/master/en/qgc-dev-guide/file_formats/
    parameters.html): '#' comments; 'vehicle-id component-id name value type', tab-separated."""
    out = {}
    for line in text.splitlines():
        if not line.strip() or line.startswith("#"):
            continue
        vid, cid, name, value, kind = line.split("\t")
        assert (int(vid), int(cid)) == (1, 1), line
        out[name] = (float(value), int(kind))
    return out


def mavproxy_params(text: str) -> dict[str, float]:
    """ArduPilot's .parm as MAVProxy's 'param load' reads it: '#' comments, 'NAME VALUE' (a comma also separates)."""
    out = {}
    for line in text.splitlines():
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        name, value = line.replace(",", " ").split()
        out[name] = float(value)
    return out


@pytest.mark.parametrize("name", sorted(CONSUMERS))
def test_each_consumer_takes_exactly_its_documented_keys(name):
    assert {k.name for k in CONSUMERS[name].keys} == DOCUMENTED[name]
    assert all(u.startswith("http") for u in CONSUMERS[name].sources)


def test_kalibr_and_openvins_take_the_densities_and_kalibr_discretises_them_as_its_wiki_says():
    for name in ("kalibr", "openvins"):
        v = _values(name, 1.0, 200.0)
        assert v == {"gyroscope_noise_density": N_G, "gyroscope_random_walk": K_G, "accelerometer_noise_density": N_A,
                     "accelerometer_random_walk": K_A}
    v2 = _values("kalibr", 3.0, 200.0)
    assert v2["gyroscope_random_walk"] == pytest.approx(3 * K_G, rel=1e-15)
    # Kalibr's discrete forms at 200 Hz: sigma_gd = 1.7e-4 * sqrt(200) = 2.404e-3, sigma_bgd = 2e-5 / sqrt(200)
    dt = 1 / 200
    assert v["gyroscope_noise_density"] / math.sqrt(dt) == pytest.approx(2.4041630560342617e-3, rel=1e-12)
    assert v["gyroscope_random_walk"] * math.sqrt(dt) == pytest.approx(1.414213562373095e-6, rel=1e-12)


@pytest.mark.parametrize("f", [50.0, 100.0, 400.0])
def test_px4_values_give_the_growth_of_the_continuous_noise_under_px4s_own_covariance_update(f):
    v, dt, steps = _values("px4", 1.0, f), 1 / f, int(60 * f)   # one minute of prediction steps
    t = steps * dt
    angle_var = steps * (dt * v["EKF2_GYR_NOISE"]) ** 2            # covariance.cpp: d_ang_var = sq(dt * gyro_noise)
    bias_var = steps * (dt * v["EKF2_GYR_B_NOISE"]) ** 2           # gyro_bias_process_noise = sq(dt * gyro_bias_p_noise)
    vel_var = steps * (dt * v["EKF2_ACC_NOISE"]) ** 2
    abias_var = steps * (dt * v["EKF2_ACC_B_NOISE"]) ** 2
    assert angle_var == pytest.approx(N_G ** 2 * t, rel=1e-12)     # angle random walk: N^2 T
    assert bias_var == pytest.approx(K_G ** 2 * t, rel=1e-12)      # rate random walk: K^2 T
    assert vel_var == pytest.approx(N_A ** 2 * t, rel=1e-12)
    assert abias_var == pytest.approx(K_A ** 2 * t, rel=1e-12)


def test_ardupilot_values_give_the_same_growth_under_ekf3s_delta_angle_bias_update():
    f = 1 / 0.012
    v, dt, steps = _values("ardupilot", 1.0, f), 0.012, 5000
    t = steps * dt
    dang_bias_var = steps * (dt ** 2 * v["EK3_GBIAS_P_NSE"]) ** 2  # delta-angle bias (rad): sq(sq(dt) * noise)
    assert dang_bias_var / dt ** 2 == pytest.approx(K_G ** 2 * t, rel=1e-12)    # as a rate bias (rad/s)
    assert steps * (dt * v["EK3_GYRO_P_NSE"]) ** 2 == pytest.approx(N_G ** 2 * t, rel=1e-12)
    assert steps * (dt * v["EK3_ACC_P_NSE"]) ** 2 == pytest.approx(N_A ** 2 * t, rel=1e-12)
    assert steps * (dt ** 2 * v["EK3_ABIAS_P_NSE"]) ** 2 / dt ** 2 == pytest.approx(K_A ** 2 * t, rel=1e-12)


def test_vins_values_are_per_sample_standard_deviations():
    f = 200.0
    v, dt, steps = _values("vins", 2.0, f), 1 / f, 2000       # inflated x2
    t = steps * dt
    # (G dt) Q (G dt)^T per sample: velocity, angle and bias variances grow by (dt x value)^2
    assert steps * (dt * v["acc_n"]) ** 2 == pytest.approx((2 * N_A) ** 2 * t, rel=1e-12)
    assert steps * (dt * v["gyr_n"]) ** 2 == pytest.approx((2 * N_G) ** 2 * t, rel=1e-12)
    assert steps * (dt * v["acc_w"]) ** 2 == pytest.approx((2 * K_A) ** 2 * t, rel=1e-12)
    assert steps * (dt * v["gyr_w"]) ** 2 == pytest.approx((2 * K_G) ** 2 * t, rel=1e-12)
    # the white noise is Kalibr's discrete sigma_d = N / sqrt(dt) of a sample
    assert v["acc_n"] == pytest.approx(2 * N_A / math.sqrt(dt), rel=1e-12)


def test_yaml_files_parse_and_hold_the_values_with_their_statements():
    c = CONSUMERS["openvins"]
    items = entries(c, FIGS, 2.0, 200.0)
    text = noise_yaml(header_lines(c, "a.json", 2.0, 200.0, "as given"), items, [("rostopic", "/imu0", "")],
                      nest="imu0", directive=True)
    assert text.startswith("%YAML:1.0\n")                         # OpenCV's FileStorage wants it first
    d = yaml.safe_load(text.split("\n", 1)[1])                     # PyYAML (YAML 1.1) does not know OpenCV's directive
    assert d["imu0"]["gyroscope_random_walk"] == 2 * K_G and d["imu0"]["rostopic"] == "/imu0"
    assert "inflation: x2" in text and "UPPER BOUND" in text and "rad/s^2/sqrt(Hz)" in text
    v = noise_yaml(["fragment"], entries(CONSUMERS["vins"], FIGS, 1.0, 100.0))
    assert yaml.safe_load(v) == pytest.approx({"gyr_n": N_G * 10, "gyr_w": K_G * 10, "acc_n": N_A * 10, "acc_w": K_A * 10})


def test_parameter_files_parse_as_their_ground_stations_read_them():
    px4 = params_text(CONSUMERS["px4"], ["PX4 test"], entries(CONSUMERS["px4"], FIGS, 1.0, 100.0))
    got = qgc_params(px4)
    assert set(got) == DOCUMENTED["px4"] and {k for _, k in got.values()} == {9}   # MAV_PARAM_TYPE_REAL32
    assert np.float32(got["EKF2_GYR_NOISE"][0]) == np.float32(N_G * 10)            # the very float PX4 stores
    assert np.float32(got["EKF2_ACC_B_NOISE"][0]) == np.float32(K_A * 10)
    ap = params_text(CONSUMERS["ardupilot"], ["ArduPilot test"], entries(CONSUMERS["ardupilot"], FIGS[:2], 1.0, 80.0))
    got2 = mavproxy_params(ap)
    assert set(got2) == {"EK3_GYRO_P_NSE", "EK3_GBIAS_P_NSE"}
    assert np.float32(got2["EK3_GBIAS_P_NSE"]) == np.float32(K_G * math.sqrt(80.0))
    assert "95 % UPPER BOUND" in ap and "not a fitted value" in ap


def test_a_value_outside_the_documented_range_is_written_and_said():
    tiny = [NoiseTerm("accelerometer", "white", 5e-5, "fitted", "test")]     # 5e-4 m/s^2 per step: below 0.01
    e = entries(CONSUMERS["px4"], tiny, 1.0, 100.0)[0]
    assert e.remark is not None and "OUTSIDE the documented range 0.01 .. 1" in e.remark
    assert "OUTSIDE" in params_text(CONSUMERS["px4"], ["x"], [e])


def test_refusals():
    with pytest.raises(InputError, match="inflation factor must be >= 1") as exc:
        entries(CONSUMERS["px4"], FIGS, 0.5, 100.0)
    assert exc.value.fields == ["inflate"]
    with pytest.raises(InputError, match="needs a rate"):
        entries(CONSUMERS["vins"], FIGS, 1.0, None)
    for bad in (1e300, float("inf"), float("nan"), 1e-60):
        with pytest.raises(InputError, match="float"):
            float32_text(bad, "EKF2_GYR_NOISE")
    assert np.float32(float32_text(0.1, "x")) == np.float32(0.1)
