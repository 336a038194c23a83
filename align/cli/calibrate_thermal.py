"""``imu-align calibrate thermal``: each sensor axis' bias against temperature from a static log with a temperature
column, and the autopilots' parameter files; the work is the library job
:data:`align.calibration.thermal.THERMAL`.

Public names
------------
thermal, thermal_options, thermal_files
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from align.cli import options as opt
from align.cli.options import DURATION, POSITIVE, names
from align.cli.paths import check_outputs, write_run

if TYPE_CHECKING:
    from align.calibration.thermal import ThermalCalibration, ThermalInputs, ThermalOptions


def _columns(columns: str | None, gyro_columns: str | None, accel_columns: str | None,
             sensors: tuple[str, ...]) -> tuple[str | None, str | None]:
    """The gyro's and the accelerometer's columns: ``--columns`` (three names for one sensor, six for both, gyro
    first; a time column may lead) or ``--gyro-columns`` / ``--accel-columns``."""
    from align.errors import InputError

    if columns is None:
        return gyro_columns, accel_columns
    if gyro_columns is not None or accel_columns is not None:
        raise InputError("give the columns once: {columns}, or {gyro_columns} and {accel_columns}", "{columns}")
    given = names(columns)
    want = 3 * len(sensors)
    lead = given[:len(given) - want] if len(given) in (want, want + 1) else None
    if lead is None:
        raise InputError(f"give {want} names ({', '.join(sensors)}: x,y,z each, gyro first), or {want + 1} with the "
                         f"time column first; got {len(given)}", "{columns}")
    data = given[len(lead):]
    parts = {s: ",".join(lead + data[3 * k:3 * k + 3]) for k, s in enumerate(sensors)}
    return parts.get("gyroscope"), parts.get("accelerometer")


def thermal_options(*, log: Path, temperature_column: str | None = None, temperature_units: str | None = None,
                    columns: str | None = None, gyro_columns: str | None = None, accel_columns: str | None = None,
                    time_column: str | None = None, rate_hz: float | None = None, gyro_units: str | None = None,
                    accel_units: str | None = None, sensors: str = "gyro,accel", order: int | None = None,
                    max_order: int = 5, lag: bool | None = None, window: float = 20.0, min_branch: float = 120.0,
                    hysteresis: bool = True, reference: float | None = None, motion_factor: float = 100.0,
                    skip_rows: int = 0, comment: str | None = None, delimiter: str | None = None,
                    time_units: str | None = None, topic: str | None = None, stamps: str | None = None,
                    **_: Any) -> ThermalOptions:
    """The job's options from the command's parameters (Python names; output options and unknown keys ignored).

    Returns
    -------
    ThermalOptions
    """
    from align.calibration.thermal import ThermalOptions
    from align.errors import InputError
    from align.vocab import Sensor

    try:
        chosen = tuple(Sensor.parse(s).value for s in names(sensors))
    except ValueError:
        raise InputError(f"give gyro and/or accel, not '{sensors}'", "{sensors}") from None
    order_of = [s for s in ("gyroscope", "accelerometer") if s in chosen]
    gyro_cols, accel_cols = _columns(columns, gyro_columns, accel_columns, tuple(order_of))
    fmt = dict(skip_rows=skip_rows, comment=comment, delimiter=delimiter, time_units=time_units, topic=topic,
               stamps=stamps)
    gyro = opt.log_source(log, gyro_cols, rate_hz=rate_hz, units=gyro_units, time_column=time_column, **fmt)
    gyro = replace(gyro, temperature_column=temperature_column, temperature_units=temperature_units)
    accel = opt.log_source(log, accel_cols, rate_hz=rate_hz, units=accel_units, time_column=time_column, **fmt)
    return ThermalOptions(log=gyro, accel=accel, sensors=chosen, order=order, max_order=max_order, lag=lag,
                          window_s=window, min_branch_s=min_branch, hysteresis=hysteresis, reference=reference,
                          motion_factor=motion_factor)


def thermal_files(result: ThermalCalibration, inputs: ThermalInputs, params: dict[str, Any]
                  ) -> list[tuple[Path, bytes | str]]:
    """The autopilots' parameter files ``--ardupilot`` and ``--px4`` ask for (beside the ``--json`` result)."""
    from align.calibration.thermal import firmware

    out: list[tuple[Path, bytes | str]] = []
    models = {k: s.model for k, s in result.sensors.items()}
    source = Path(str(result.inputs.get("log", ""))).name
    instance = int(params.get("instance") or 0)
    if params.get("ardupilot") is not None:
        out.append((Path(params["ardupilot"]), firmware.ardupilot(models, instance, source)))
    if params.get("px4") is not None:
        stated = result.inputs.get("device_ids") or {}
        ids = {"gyroscope": params.get("gyro_id") or stated.get("gyroscope"),
               "accelerometer": params.get("accel_id") or stated.get("accelerometer")}
        out.append((Path(params["px4"]), firmware.px4(models, ids, instance, source)))
    return out


def thermal(
    log: opt.Arg("Static log with a temperature column (soak steps or ramps, one orientation).", "LOG"),
    temperature_column: opt.TemperatureColumn = None,
    temperature_units: opt.TemperatureUnits = None,
    columns: opt.Columns("Data columns: x,y,z of the one sensor read, or six names (gyro x,y,z then accel x,y,z); "
                         "a time column may lead.", optional=True) = None,
    gyro_columns: opt.Columns("Gyro columns x,y,z (default gyro_x,gyro_y,gyro_z, or gyr_x,... / gx,...).",
                              "--gyro-columns", optional=True) = None,
    accel_columns: opt.Columns("Accelerometer columns x,y,z (default acc_x,acc_y,acc_z, or accel_x,... / ax,...).",
                               "--accel-columns", optional=True) = None,
    time_column: opt.TimeColumn = None,
    rate_hz: opt.RateHz() = None,
    gyro_units: opt.UnitFlag("--gyro-units", "Gyro unit, e.g. deg/s or rad/s (default: the file's, else deg/s).",
                             optional=True) = None,
    accel_units: opt.UnitFlag("--accel-units", "Accelerometer unit (default: the file's, else m/s^2).",
                              optional=True) = None,
    sensors: Annotated[str, typer.Option("--sensors", metavar="LIST", help=(
        "The sensors to calibrate: gyro, accel or gyro,accel."))] = "gyro,accel",
    order: Annotated[int | None, typer.Option("--order", parser=opt.whole(0, 8, "3"), metavar="N", help=(
        "A fixed polynomial order (default: chosen per axis by blocked cross-validation)."))] = None,
    max_order: opt.Whole("--max-order", "Highest order tried (3 for the autopilots' files, which take a cubic).",
                         0, 8, "3") = 5,
    lag: Annotated[bool | None, typer.Option("--lag/--no-lag", help=(
        "The thermal-lag term in dT/dt on or off (default: chosen by cross-validation)."))] = None,
    window: opt.Quantity("--window", "time", "Window of the temperature rate (a line fitted over it).", "TIME",
                         DURATION, "'20 s'") = "20 s",
    min_branch: opt.Quantity("--min-branch", "time", "Shortest heating or cooling run that is a branch.", "TIME",
                             DURATION, "'120 s'") = "120 s",
    hysteresis: opt.Flag("--hysteresis/--no-hysteresis", "Detect heating and cooling branches and report the "
                         "hysteresis (both branches then needed).") = True,
    reference: Annotated[float | None, typer.Option("--reference", parser=opt.number(opt.ANY, "35"), metavar="DEGC",
                                                    help="Reference temperature, C (default: mid-range).")] = None,
    motion_factor: opt.Number("--motion-factor", "A window varying this many times the noise is motion (refused).",
                              POSITIVE, "100", "FACTOR") = 100.0,
    json_out: opt.JsonOut = None,
    ardupilot: opt.OptInput("--ardupilot", "ArduPilot parameter file (INS_TCALn_*; needs order <= 3).",
                            "FILE.parm") = None,
    px4: opt.OptInput("--px4", "PX4 parameter file (TC_An_*, TC_Gn_*; QGroundControl's format; needs order <= 3).",
                      "FILE.params") = None,
    instance: opt.Whole("--instance", "The IMU's instance, 0 for the first (INS_TCAL1, TC_A0).", 0, 3, "0") = 0,
    gyro_id: Annotated[int | None, typer.Option("--gyro-id", parser=opt.whole(0, 2**32 - 1, "2293768"), metavar="ID",
                                                help="The gyro's PX4 device id (default: the log's).")] = None,
    accel_id: Annotated[int | None, typer.Option("--accel-id", parser=opt.whole(0, 2**32 - 1, "2293768"),
                                                 metavar="ID", help="The accelerometer's PX4 device id (default: the "
                                                 "log's).")] = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    time_units: opt.TimeUnits = None,
    topic: opt.Topic = None,
    stamps: opt.Stamps = None,
) -> None:
    """Bias against temperature per sensor axis: order by cross-validation, thermal lag, hysteresis, firmware files."""
    params = dict(locals())
    check_outputs([log], json_out=json_out, ardupilot=ardupilot, px4=px4)
    from align.calibration.thermal import THERMAL

    result, inputs = THERMAL.run_with_inputs(thermal_options(**params))
    write_run(json_out, result, thermal_files(result, inputs, params))  # all or none
    from align.present.text import thermal_summary

    typer.echo(thermal_summary(result))
