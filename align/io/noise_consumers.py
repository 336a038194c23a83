"""Noise figures in each consumer's own terms: Kalibr, OpenVINS, VINS-Fusion, PX4 EKF2, ArduPilot EKF3.

The figures are the continuous-time white noise ``N`` and bias random walk ``K`` of each sensor (IEEE Std 952's
terms, SI: ``N`` in rad/s/sqrt(Hz) or m/s^2/sqrt(Hz), ``K`` in rad/s^2/sqrt(Hz) or m/s^3/sqrt(Hz)). Each
consumer wants them in one of two forms (its documentation and code, cited in :data:`CONSUMERS`):

* **densities** (Kalibr ``imu.yaml``, OpenVINS ``kalibr_imu_chain.yaml``): ``N`` and ``K`` as they are; the
  consumer discretises them itself with its update rate (Kalibr wiki, "IMU Noise Model":
  ``sigma_d = sigma / sqrt(dt)`` for the white noise, ``sigma_bd = sigma_b sqrt(dt)`` for the random walk);
* **per-step standard deviations of a rate** (VINS-Fusion ``acc_n``.., PX4 ``EKF2_*_NOISE``, ArduPilot
  ``EK3_*_P_NSE``): the code adds ``(dt x value)^2`` to the variance of an angle (velocity) increment, or of the
  bias, at each step ``dt``; a continuous ``N`` gives ``N^2 dt`` there and ``K`` gives ``K^2 dt``, so the value is
  ``N sqrt(f)`` and ``K sqrt(f)`` with ``f = 1/dt``: the IMU rate for VINS-Fusion (a step per IMU sample), the
  filter's prediction rate for the autopilots (not the IMU rate: they integrate the IMU to that rate first).

Every value is then multiplied by the inflation factor (1: none), stated in the file. The bias *instability*
``B`` (the floor of the Allan curve) is not a random walk and goes nowhere here; ArduPilot's "bias stability"
parameters are random-walk process noises despite their name (their unit is rad/s/s).

The writers take :class:`NoiseTerm` figures and return text; which figures a result gives, and what to do
when one is missing, is :mod:`align.present.noise_figures`'s.

Public names
------------
NoiseTerm, Key, Consumer, Entry, CONSUMERS, FIGURE_UNITS, entries, noise_yaml, params_text, header_lines, float32_text
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from align.errors import InputError
from align.io.consumers import TOOL, float32_value, yaml_float

#: the SI unit of each continuous-time figure, (sensor, term) -> unit
FIGURE_UNITS = {("gyroscope", "white"): "rad/s/sqrt(Hz)", ("gyroscope", "random_walk"): "rad/s^2/sqrt(Hz)",
                ("accelerometer", "white"): "m/s^2/sqrt(Hz)", ("accelerometer", "random_walk"): "m/s^3/sqrt(Hz)"}
_SYMBOL = {"white": "N", "random_walk": "K"}
_WORDS = {"white": "white noise", "random_walk": "bias random walk"}


@dataclass(frozen=True)
class NoiseTerm:
    """One continuous-time noise figure of one sensor.

    Attributes
    ----------
    sensor : {"gyroscope", "accelerometer"}
    term : {"white", "random_walk"}
        ``N`` (white noise density) or ``K`` (bias random walk).
    value : float
        SI (:data:`FIGURE_UNITS`), > 0.
    basis : {"fitted", "upper bound", "datasheet", "datasheet bound"}
        A value the record identifies, the 95 % upper bound of one it does not, a datasheet's figure, or a bound
        from a datasheet's figures.
    how : str
        Where it comes from, one line (file, channel, fit or datasheet source).
    """

    sensor: str
    term: str
    value: float
    basis: str
    how: str

    @property
    def label(self) -> str:
        """``"gyroscope N"``, ``"accelerometer K"``."""
        return f"{self.sensor} {_SYMBOL[self.term]}"


@dataclass(frozen=True)
class Key:
    """One key a consumer reads: the figure it takes, its unit, and how the figure becomes its value.

    ``per_step``: the value is ``figure x sqrt(f)`` (a per-step standard deviation, module docstring); otherwise
    the figure itself. ``default``, ``low`` and ``high``: the consumer's documented default and range (None: none).
    """

    name: str
    sensor: str
    term: str
    unit: str
    per_step: bool
    default: float | None = None
    low: float | None = None
    high: float | None = None


@dataclass(frozen=True)
class Consumer:
    """A program that reads noise figures, and the form it reads them in.

    Attributes
    ----------
    name, title : str
        ``"px4"``; ``"PX4 EKF2 parameters"``.
    keys : tuple of Key
    rate : {"imu", "filter"}
        The rate ``f`` of the conversion and of ``update_rate``: the IMU's, or the filter's prediction rate.
    default_rate_hz : float or None
        The filter's documented default rate; None: the Allan record's sample rate.
    rate_source : str
        Where the default rate is documented.
    form : str
        The consumer's convention in one line (what its values are, and the code that shows it).
    sources : tuple of str
        Its documentation and code (URLs).
    complete : bool
        Every key is needed (a YAML file its reader refuses without one) or a subset may be set (a parameter file).
    """

    name: str
    title: str
    keys: tuple[Key, ...]
    rate: str
    default_rate_hz: float | None
    rate_source: str
    form: str
    sources: tuple[str, ...]
    complete: bool


def _keys(names: Sequence[str], units: Sequence[str], per_step: bool, limits: Sequence[tuple] = ()) -> tuple[Key, ...]:
    """Keys in the order gyro N, gyro K, accel N, accel K."""
    order = (("gyroscope", "white"), ("gyroscope", "random_walk"), ("accelerometer", "white"),
             ("accelerometer", "random_walk"))
    lim = list(limits) or [(None, None, None)] * 4
    return tuple(Key(n, s, t, u, per_step, *lm) for n, (s, t), u, lm in zip(names, order, units, lim))


_DENSITY = ("rad/s/sqrt(Hz)", "rad/s^2/sqrt(Hz)", "m/s^2/sqrt(Hz)", "m/s^3/sqrt(Hz)")
_KALIBR_NAMES = ("gyroscope_noise_density", "gyroscope_random_walk", "accelerometer_noise_density",
                 "accelerometer_random_walk")
_KALIBR_WIKI = "https://github.com/ethz-asl/kalibr/wiki/IMU-Noise-Model"

#: the consumers, by the name ``export`` takes
CONSUMERS: dict[str, Consumer] = {c.name: c for c in (
    Consumer("kalibr", "Kalibr imu.yaml", _keys(_KALIBR_NAMES, _DENSITY, False), "imu", None, "",
             "continuous-time densities (Kalibr's IMU noise model); Kalibr discretises them with update_rate: "
             "sigma_d = N sqrt(update_rate), sigma_bd = K / sqrt(update_rate)",
             (_KALIBR_WIKI, "https://github.com/ethz-asl/kalibr/wiki/yaml-formats"), True),
    Consumer("openvins", "OpenVINS kalibr_imu_chain.yaml", _keys(_KALIBR_NAMES, _DENSITY, False), "imu", None, "",
             "continuous-time densities, as Kalibr's (OpenVINS reads imu0's four keys into sigma_w, sigma_wb, "
             "sigma_a, sigma_ab and discretises them with each IMU step)",
             ("https://docs.openvins.com/propagation.html", "https://github.com/rpng/open_vins/blob/master/config/"
              "euroc_mav/kalibr_imu_chain.yaml", "https://github.com/rpng/open_vins/blob/master/ov_msckf/src/core/"
              "VioManagerOptions.h"), True),
    Consumer("vins", "VINS-Fusion IMU keys", _keys(("gyr_n", "gyr_w", "acc_n", "acc_w"),
                                                    ("rad/s", "rad/s^2", "m/s^2", "m/s^3"), True), "imu", None, "",
             "per-IMU-sample standard deviations: the VINS-Mono paper's pre-integration covariance (T-RO 2018, eq. "
             "10) adds (G dt) Q (G dt)^T per IMU sample dt, Q = diag(acc_n^2, gyr_n^2, acc_w^2, gyr_w^2), and "
             "integration_base.h adds (dt acc_w)^2 to the bias per sample; its configs say only 'standard deviation'",
             ("https://arxiv.org/abs/1708.03852", "https://github.com/HKUST-Aerial-Robotics/VINS-Fusion/blob/master/"
              "config/euroc/"
              "euroc_stereo_imu_config.yaml", "https://github.com/HKUST-Aerial-Robotics/VINS-Fusion/blob/master/"
              "vins_estimator/src/factor/integration_base.h",
              "https://github.com/HKUST-Aerial-Robotics/VINS-Mono/issues/102"), True),
    Consumer("px4", "PX4 EKF2 parameters", _keys(("EKF2_GYR_NOISE", "EKF2_GYR_B_NOISE", "EKF2_ACC_NOISE",
                                                   "EKF2_ACC_B_NOISE"), ("rad/s", "rad/s^2", "m/s^2", "m/s^3"), True,
                                                  ((0.015, 0.0001, 0.1), (0.001, 0.0, 0.01), (0.35, 0.01, 1.0),
                                                   (0.003, 0.0, 0.01))),
             "filter", 100.0, "EKF2_PREDICT_US = 10000 us by default",
             "per-prediction-step standard deviations of a rate: covariance.cpp (predictCovariance) adds "
             "(dt EKF2_GYR_NOISE)^2 to each delta angle's variance and (dt EKF2_GYR_B_NOISE)^2 to the bias variance, "
             "dt the EKF's prediction period",
             ("https://docs.px4.io/main/en/advanced_config/parameter_reference.html#EKF2_GYR_NOISE",
              "https://github.com/PX4/PX4-Autopilot/blob/main/src/modules/ekf2/EKF/covariance.cpp",
              "https://docs.qgroundcontrol.com/master/en/qgc-dev-guide/file_formats/parameters.html"), False),
    Consumer("ardupilot", "ArduPilot EKF3 parameters", _keys(("EK3_GYRO_P_NSE", "EK3_GBIAS_P_NSE", "EK3_ACC_P_NSE",
                                                              "EK3_ABIAS_P_NSE"), ("rad/s", "rad/s/s", "m/s/s",
                                                                                   "m/s/s/s"), True,
                                                             ((0.015, 0.0001, 0.1), (0.001, 0.00001, 0.001),
                                                              (0.35, 0.01, 1.0), (0.02, 0.00001, 0.02))),
             "filter", 1 / 0.012, "EKF_TARGET_DT = 12 ms in AP_NavEKF3_core.h (about 80 Hz at a 400 Hz loop)",
             "per-prediction-step standard deviations of a rate: AP_NavEKF3_core.cpp (CovariancePrediction) adds "
             "(dt EK3_GYRO_P_NSE)^2 to each delta angle's variance and (dt^2 EK3_GBIAS_P_NSE)^2 to the delta-angle "
             "bias, dt the EKF's prediction period; the 'bias stability' parameters are random-walk process noises",
             ("https://ardupilot.org/copter/docs/parameters.html#ek3-gyro-p-nse",
              "https://github.com/ArduPilot/ardupilot/blob/master/libraries/AP_NavEKF3/AP_NavEKF3_core.cpp",
              "https://github.com/ArduPilot/ardupilot/blob/master/libraries/AP_NavEKF3/AP_NavEKF3.cpp"), False),
)}


@dataclass(frozen=True)
class Entry:
    """One key's value as written: ``inflate x figure x (sqrt(rate_hz) when per_step)``.

    Attributes
    ----------
    key : Key
    figure : NoiseTerm
    inflate : float
    rate_hz : float
        The rate ``f`` of a per-step key (unused for a density).
    value : float
        In ``key.unit``.
    """

    key: Key
    figure: NoiseTerm
    inflate: float
    rate_hz: float
    value: float

    @property
    def conversion(self) -> str:
        """How the value follows from the figure, e.g. ``"2 x N x sqrt(100 Hz)"``."""
        parts = ([f"{self.inflate:g}"] if self.inflate != 1 else []) + [_SYMBOL[self.key.term]]
        if self.key.per_step:
            parts.append(f"sqrt({self.rate_hz:g} Hz)")
        return " x ".join(parts)

    @property
    def statement(self) -> str:
        """One line: the conversion, the figure and where it comes from."""
        unit = FIGURE_UNITS[(self.key.sensor, self.key.term)]
        bound = {"upper bound": "95 % UPPER BOUND, not a fitted value; ",
                 "datasheet bound": "UPPER BOUND from a datasheet, not a measured value; "}.get(self.figure.basis, "")
        return (f"{self.key.name} = {self.conversion} [{self.key.unit}]; {self.figure.label} = "
                f"{self.figure.value:.6g} {unit} ({_WORDS[self.key.term]}): {bound}{self.figure.how}")

    @property
    def remark(self) -> str | None:
        """The value against the consumer's documented range and default, or None."""
        k, out = self.key, []
        if k.low is not None and self.value < k.low or k.high is not None and self.value > k.high:
            out.append(f"OUTSIDE the documented range {k.low:g} .. {k.high:g} {k.unit}: check before use")
        if k.default is not None:
            out.append(f"the default {k.default:g} is {k.default / self.value:.3g} x this value")
        return "; ".join(out) or None


def entries(consumer: Consumer, figures: Sequence[NoiseTerm], inflate: float = 1.0,
            rate_hz: float | None = None) -> list[Entry]:
    """The consumer's keys that ``figures`` give, in its order.

    Parameters
    ----------
    consumer : Consumer
    figures : sequence of NoiseTerm
        At most one per sensor and term.
    inflate : float
        Multiplies every value (standard deviations: the variances by its square), >= 1.
    rate_hz : float, optional
        ``f`` of the per-step keys, Hz (needed when the consumer has any).

    Returns
    -------
    list of Entry

    Examples
    --------
    >>> n = NoiseTerm("gyroscope", "white", 1e-4, "fitted", "test")
    >>> [(e.key.name, round(e.value, 12)) for e in entries(CONSUMERS["px4"], [n], 2.0, 100.0)]
    [('EKF2_GYR_NOISE', 0.002)]
    """
    if not (math.isfinite(inflate) and inflate >= 1):
        raise InputError(f"the inflation factor must be >= 1 (1: the figures as measured), not {inflate:g}",
                         "{inflate}")
    have = {(f.sensor, f.term): f for f in figures}
    out = []
    for k in consumer.keys:
        f = have.get((k.sensor, k.term))
        if f is None:
            continue
        if k.per_step and not (rate_hz is not None and math.isfinite(rate_hz) and rate_hz > 0):
            raise InputError(f"{k.name} is a per-step value and needs a rate (Hz); give one",
                             "{rate_hz}" if consumer.rate == "imu" else "{predict_hz}")
        scale = math.sqrt(rate_hz) if k.per_step and rate_hz is not None else 1.0
        out.append(Entry(k, f, float(inflate), float(rate_hz or 0.0), inflate * f.value * scale))
    return out


def float32_text(x: float, where: str) -> str:
    """A parameter value as its nearest IEEE single (what the autopilot stores), 9 significant digits: reads back to
    the very float; a value a float cannot hold is refused (:func:`align.io.consumers.float32_value`).

    >>> float32_text(0.0015, "EKF2_GYR_NOISE")
    '0.00150000001'
    """
    return f"{float32_value(x, where, 'a parameter (a 32-bit float)'):.9g}"


def _comment(lines: Sequence[str]) -> list[str]:
    return [f"# {line}" if line else "#" for text in lines for line in text.splitlines() or [""]]


def noise_yaml(header: Sequence[str], items: Sequence[Entry], scalars: Sequence[tuple] = (), nest: str | None = None,
               directive: bool = False, extra: Sequence[str] = ()) -> str:
    """A YAML file (or fragment) of the noise keys: ``#`` comment lines, then each key after a comment line that
    states its conversion and source.

    Parameters
    ----------
    header : sequence of str
        The file's statement (comment lines).
    items : sequence of Entry
    scalars : sequence of (key, value, comment)
        Keys other than the noise keys (``rostopic``, ``update_rate``, ``g_norm``), written first, in order: a str
        value quoted, a float as :func:`align.io.consumers.yaml_float` writes it.
    nest : str, optional
        A mapping to nest every key under (OpenVINS's ``imu0``).
    directive : bool
        Start with ``%YAML:1.0``: OpenCV's FileStorage, which OpenVINS and VINS-Fusion read with, wants it first.
    extra : sequence of str
        Lines appended as they are (indented for ``nest``): matrices.

    Examples
    --------
    >>> e = entries(CONSUMERS["vins"], [NoiseTerm("gyroscope", "white", 1e-4, "fitted", "test")], 1.0, 400.0)
    >>> print(noise_yaml(["a fragment"], e).splitlines()[-1])
    gyr_n: 0.002  # rad/s
    """
    pad = "  " if nest else ""
    lines = (["%YAML:1.0"] if directive else []) + _comment(header) + ([f"{nest}:"] if nest else [])
    for key, value, note in scalars:
        text = f'"{value}"' if isinstance(value, str) else yaml_float(value, key)
        lines.append(f"{pad}{key}: {text}" + (f"  # {note}" if note else ""))
    for e in items:
        lines += [f"{pad}# {e.statement}"] + ([f"{pad}#   {e.remark}"] if e.remark else [])
        lines.append(f"{pad}{e.key.name}: {yaml_float(e.value, e.key.name)}  # {e.key.unit}")
    lines += list(extra)
    return "\n".join(lines) + "\n"


def params_text(consumer: Consumer, header: Sequence[str], items: Sequence[Entry]) -> str:
    """A parameter file: QGroundControl's ``.params`` for PX4 (tab-separated ``vehicle-id component-id name value
    type``, type 9 = MAV_PARAM_TYPE_REAL32, vehicle 1 and component 1 as PX4 sets them by default), or
    ``NAME VALUE`` lines for ArduPilot (the format of MAVProxy's ``param load`` and ArduPilot's own ``.parm``
    files, which Mission Planner loads too). ``#`` lines are comments in both; every value is the nearest 32-bit
    float, as the autopilot stores it.
    """
    lines = _comment(header)
    qgc = consumer.name == "px4"
    if qgc:
        lines += ["#", "# Vehicle-Id Component-Id Name Value Type"]
    for e in items:
        lines += _comment([e.statement] + ([e.remark] if e.remark else []))
        value = float32_text(e.value, e.key.name)
        lines.append(f"1\t1\t{e.key.name}\t{value}\t9" if qgc else f"{e.key.name} {value}")
    return "\n".join(lines) + "\n"


def header_lines(consumer: Consumer, sources: str, inflate: float, rate_hz: float | None, rate_how: str,
                 missing: Sequence[str] = ()) -> list[str]:
    """The statement every noise file opens with: what, from what, the conversion, the rate, the inflation, the
    rule for unidentified terms, and the consumer's documentation."""
    out = [f"{consumer.title} written by {TOOL}", f"from: {sources}",
           "figures: continuous-time white noise N and bias random walk K (IEEE Std 952) of each sensor, the largest "
           "over its axes, SI",
           f"conversion: {consumer.form}"]
    if rate_hz is not None:
        out.append(f"rate: f = {rate_hz:g} Hz, {rate_how}")
    out.append(("inflation: none (x1), the figures as measured" if inflate == 1 else
                f"inflation: x{inflate:g} on every value (standard deviations: the variances x{inflate * inflate:g})")
               + "; a rest record at constant temperature leaves out vibration, temperature and scale errors (Kalibr's "
               "wiki: 'increasing the noise model parameters by a factor of 10x or more may be necessary' for the "
               f"lowest-cost sensors, {_KALIBR_WIKI}#kalibr-imu-noise-parameters-in-practice)")
    out.append("unidentified terms: the record's 95 % upper bound (marked UPPER BOUND), never zero; a term with "
               "neither a value nor a bound is not exported")
    if any(k.default is not None for k in consumer.keys):
        out.append("defaults: each value is compared with the parameter's default, which allows for vibration, "
                   "temperature and model errors a rest test leaves out")
    if missing:
        out.append("not written (no figure given; the consumer keeps its own): " + ", ".join(missing))
    out.append("documentation: " + " ; ".join(consumer.sources))
    return out
