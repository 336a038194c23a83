"""The autopilots' own thermal parameter files, each in its firmware's convention, and their reading back.

ArduPilot (``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``; ``Tools/scripts/tempcal_IMU.py``
writes the same file): per IMU ``n`` (1 for the first), ``INS_TCALn_ENABLE`` (1: apply), ``INS_TCALn_TMIN``,
``INS_TCALn_TMAX`` (C) and ``INS_TCALn_ACCk_X/Y/Z``, ``INS_TCALn_GYRk_X/Y/Z`` for ``k = 1, 2, 3``: the
coefficients of ``d^k`` with ``d = T - 35`` (a fixed reference of 35 C), in m/s^2 and rad/s per C^k, times
1e6. The firmware corrects ``v -= P(clip(T) - 35) - P(clip(T_cal) - 35)``, ``P(d) = (c1 + (c2 + c3 d) d) d
1e-6``, ``T`` clipped to [TMIN, TMAX], ``T_cal`` the temperature of the ordinary calibration
(``INS_ACCn_CALTEMP``, ``INS_GYRn_CALTEMP``): the constant term is dropped, the offsets carry it. One ``NAME
VALUE`` per line, ``#`` comments (MAVProxy's ``.parm``).

PX4 (``src/modules/temperature_compensation/TemperatureCompensation.cpp``; ``Tools/process_sensor_caldata.py``
writes the same file): ``TC_A_ENABLE``, ``TC_G_ENABLE`` and per instance ``i`` (0 for the first)
``TC_Ai_ID`` (the sensor's device id, matched against the driver's), ``TC_Ai_TREF``, ``TC_Ai_TMIN``,
``TC_Ai_TMAX`` (C) and ``TC_Ai_Xk_j`` (``k = 0..3``, axis ``j = 0, 1, 2``) in m/s^2 (rad/s for ``TC_G``)
per C^k: ``offset = X0 + X1 d + X2 d^2 + X3 d^3``, ``d = clip(T, TMIN, TMAX) - TREF``, corrected ``= raw -
offset`` (before the board rotation). The accelerometer's ``X0`` is 0: its level at ``TREF`` (gravity on its
axes in the chamber, its offset) is the ordinary calibration's (PX4's script fits ``x - median(x)``); the gyro's
is its bias at ``TREF``. QGroundControl's parameter file: ``#`` comments, then ``1 <tab> 1 <tab>
NAME <tab> VALUE <tab> TYPE`` (6: int32, 9: float).

Both firmware take a cubic of the static curve only: a model of higher order is refused (refit with a
maximum order of 3), lower orders are padded with zeros, and the lag term (no firmware has dT/dt) is left out
and said so in the file. Values are written with 10 significant digits (the firmware stores float32).

Public names
------------
ardupilot, px4, read_ardupilot, read_px4, ARDUPILOT_TREF, ARDUPILOT_SCALE
"""

from __future__ import annotations

from typing import Any

import numpy as np

from align.calibration.thermal.model import ThermalModel
from align.errors import InputError, literal

__all__ = ["ardupilot", "px4", "read_ardupilot", "read_px4", "ARDUPILOT_TREF", "ARDUPILOT_SCALE"]

#: ArduPilot's fixed reference temperature, C (TEMP_REFERENCE)
ARDUPILOT_TREF = 35.0
#: ArduPilot's coefficient scale (SCALE_FACTOR)
ARDUPILOT_SCALE = 1e6
_AP = {"accelerometer": "ACC", "gyroscope": "GYR"}
_PX = {"accelerometer": "A", "gyroscope": "G"}


def _num(x: float) -> str:
    return f"{x:.10g}"


def _cubics(sensors: dict[str, ThermalModel], tref: float | None) -> dict[str, np.ndarray]:
    """Each sensor's static curves as cubics (3, 4) about ``tref`` (the model's own when None); refuses a higher
    order."""
    out = {}
    for name, model in sensors.items():
        m = model if tref is None else model.at_reference(tref)
        c = np.zeros((3, 4))
        for i, ax in enumerate(m.axes):
            if ax.order > 3:
                raise InputError(f"the {name}'s {'xyz'[i]} axis was fitted with order {ax.order}, and the firmware "
                                 "takes a cubic: calibrate again with {max_order=3} for its parameter file",
                                 "{max_order}")
            c[i, :ax.order + 1] = ax.coefficients
        out[name] = c
    return out


def _range(sensors: dict[str, ThermalModel]) -> tuple[float, float]:
    lo = max(m.tmin for m in sensors.values())
    hi = min(m.tmax for m in sensors.values())
    return lo, hi


def _lags(sensors: dict[str, ThermalModel]) -> list[str]:
    return [n for n, m in sensors.items() if any(ax.lag is not None for ax in m.axes)]


def ardupilot(sensors: dict[str, ThermalModel], instance: int = 0, source: str = "") -> str:
    """ArduPilot's parameter file (module docstring) for IMU ``instance`` (0 for the first: ``INS_TCAL1``).

    Parameters
    ----------
    sensors : dict of str -> ThermalModel
        ``accelerometer`` and/or ``gyroscope`` (readings in SI).
    instance : int
        0..2: ``INS_TCALn`` with ``n = instance + 1``.
    source : str
        What the calibration came from, for the header comment.

    Returns
    -------
    str

    Examples
    --------
    >>> from align.calibration.thermal.model import AxisModel
    >>> ax = AxisModel(np.array([0.1, 2e-3]), None, np.zeros((2, 2)))
    >>> text = ardupilot({"accelerometer": ThermalModel("accelerometer", 25.0, 0.0, 60.0, (ax, ax, ax))})
    >>> read_ardupilot(text)["INS_TCAL1_ACC1_X"]
    2000.0
    """
    if instance not in (0, 1, 2):
        raise InputError(f"ArduPilot has IMU instances 0 to 2 (INS_TCAL1 to INS_TCAL3), not {instance}", "{instance}")
    cubic = _cubics(sensors, ARDUPILOT_TREF)
    lo, hi = _range(sensors)
    n = instance + 1
    lines = [f"# ArduPilot IMU temperature calibration (INS_TCAL{n}), written by imu-align{': ' + source if source else ''}",
             f"# corrected = raw - (P(clip(T) - 35) - P(clip(INS_xxx{n}_CALTEMP) - 35)), P(d) = (c1 + (c2 + c3 d) d) d 1e-6,",
             "# T clipped to [TMIN, TMAX]; coefficients of d^k in m/s^2 and rad/s per degC^k, times 1e6 "
             "(AP_InertialSensor_tempcal.cpp)",
             "# the constant term (the bias at 35 C) is left out: the accelerometer offsets and the gyro's bias at boot "
             "carry it"]
    for name, c in cubic.items():
        lines.append(f"# {name} bias at 35 C (not a parameter): " + " ".join(_num(v) for v in c[:, 0]) +
                     (" m/s^2" if name == "accelerometer" else " rad/s"))
    if _lags(sensors):
        lines.append(f"# the thermal-lag term of the {' and '.join(_lags(sensors))} is left out: no firmware has dT/dt")
    if (lo, hi) != (min(m.tmin for m in sensors.values()), max(m.tmax for m in sensors.values())):
        lines.append("# the sensors' ranges differ: TMIN/TMAX is the range both cover")
    lines += [f"INS_TCAL{n}_ENABLE 1", f"INS_TCAL{n}_TMIN {_num(lo)}", f"INS_TCAL{n}_TMAX {_num(hi)}"]
    for name in ("accelerometer", "gyroscope"):
        if name in cubic:
            for k in (1, 2, 3):
                for i, axis in enumerate("XYZ"):
                    lines.append(f"INS_TCAL{n}_{_AP[name]}{k}_{axis} {_num(cubic[name][i, k] * ARDUPILOT_SCALE)}")
    return "\n".join(lines) + "\n"


def px4(sensors: dict[str, ThermalModel], ids: dict[str, int | None], instance: int = 0, source: str = "") -> str:
    """PX4's parameter file (module docstring) for sensor ``instance`` (0 for the first).

    Parameters
    ----------
    sensors : dict of str -> ThermalModel
        ``accelerometer`` and/or ``gyroscope`` (readings in SI).
    ids : dict of str -> int or None
        Each sensor's device id (``TC_A0_ID``); a sensor without one is refused (PX4 would ignore it).
    instance : int
        ``i`` of ``TC_Ai``, 0..3.
    source : str
        What the calibration came from, for the header comment.

    Returns
    -------
    str
    """
    if instance not in (0, 1, 2, 3):
        raise InputError(f"PX4 has sensor instances 0 to 3, not {instance}", "{instance}")
    cubic = _cubics(sensors, None)
    lines = [f"# PX4 sensor thermal compensation parameters, written by imu-align{': ' + source if source else ''}",
             "# offset = X0 + X1 d + X2 d^2 + X3 d^3, d = clip(T, TMIN, TMAX) - TREF; corrected = raw - offset "
             "(TemperatureCompensation.cpp); m/s^2 and rad/s per degC^k",
             "# load with QGroundControl, then repeat the ordinary accelerometer and gyro calibration",
             "# accelerometer: X0 = 0, its level at TREF (gravity on its axes at rest, its offset) is left to the "
             "ordinary calibration; gyro: X0 is its bias at TREF",
             "#", "# Vehicle-Id Component-Id Name Value Type"]
    if _lags(sensors):
        lines.insert(3, f"# the thermal-lag term of the {' and '.join(_lags(sensors))} is left out: no firmware has "
                        "dT/dt")
    body = []
    for name in ("accelerometer", "gyroscope"):
        if name not in cubic:
            continue
        dev = ids.get(name)
        if dev is None:
            field = "accel_id" if name == "accelerometer" else "gyro_id"
            raise InputError(f"PX4 applies TC_{_PX[name]}{instance}_ID only to the sensor with that device id, and the "
                             f"log states none for the {name}: give it with {{{field}}}", "{" + field + "}")
        p, m = f"TC_{_PX[name]}{instance}", sensors[name]
        body += [f"1\t1\tTC_{_PX[name]}_ENABLE\t1\t6", f"1\t1\t{p}_ID\t{int(dev)}\t6",
                 f"1\t1\t{p}_TMAX\t{_num(m.tmax)}\t9", f"1\t1\t{p}_TMIN\t{_num(m.tmin)}\t9",
                 f"1\t1\t{p}_TREF\t{_num(m.tref)}\t9"]
        c = cubic[name].copy()
        if name == "accelerometer":  # its level at TREF (gravity on its axes, its offset) is the ordinary
            c[:, 0] = 0.0            # calibration's, not a thermal offset (process_sensor_caldata.py removes it too)
        for k in range(4):
            for j in range(3):
                body.append(f"1\t1\t{p}_X{k}_{j}\t{_num(c[j, k])}\t9")
    return "\n".join(lines + body) + "\n"


def _pairs(text: str, where: str, fields: int) -> list[list[str]]:
    rows = []
    for k, line in enumerate(text.splitlines(), 1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        parts = line.replace(",", " ").split() if fields == 2 else line.split("\t")
        if len(parts) != fields:
            raise InputError(f"line {k}: '{literal(line)}' is not a parameter line of {fields} fields", where)
        rows.append(parts)
    return rows


def read_ardupilot(text: str, where: str = "parameter file") -> dict[str, float]:
    """The parameters of an ArduPilot ``.parm`` file (``NAME VALUE`` or ``NAME,VALUE``; ``#`` comments)."""
    try:
        return {name: float(value) for name, value in _pairs(text, where, 2)}
    except ValueError:
        raise InputError("a parameter value is not a number", where) from None


def read_px4(text: str, where: str = "parameter file") -> dict[str, Any]:
    """The parameters of a QGroundControl parameter file (``1 1 NAME VALUE TYPE``, tab-separated; ``#``
    comments): int32 (type 6) as int, float (9) as float."""
    out: dict[str, Any] = {}
    for _, _, name, value, kind in _pairs(text, where, 5):
        try:
            out[name] = int(value) if kind.strip() == "6" else float(value)
        except ValueError:
            raise InputError(f"{literal(name)}: '{literal(value)}' is not a number", where) from None
    return out
