"""``imu-align apply``: a log corrected with an alignment or a calibration result (:data:`align.alignment.jobs.APPLY`).

Public names
------------
apply, apply_options, apply_files, SENSOR_COLUMNS, SENSOR_DIMENSIONS, COMMANDS
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from align.cli import options as opt
from align.cli.options import value
from align.cli.paths import check_outputs, write_run
from align.vocab import Sensor

#: the columns ``apply`` reads by default, per sensor, time first (:attr:`align.vocab.Sensor.columns`)
SENSOR_COLUMNS = {s.value: ",".join(("time", *s.columns)) for s in Sensor}
#: the dimension of each sensor's readings (a key of ``align.units.DIMENSIONS``; :attr:`align.vocab.Sensor.dimension`)
SENSOR_DIMENSIONS = {s.value: s.dimension for s in Sensor}


def apply_options(*, log: Path, alignment: Path, sensor: Any = None, gyro_units: str | None = None,
                  units: str | None = None, columns: str | None = None, time_column: str | None = None,
                  rate_hz: float | None = None, skip_rows: int = 0, comment: str | None = None,
                  delimiter: str | None = None, time_units: str | None = None, topic: str | None = None,
                  stamps: str | None = None, temperature_column: str | None = None,
                  temperature_units: str | None = None, **_: Any):
    """The :class:`align.alignment.jobs.ApplyOptions` of ``imu-align apply``'s parameters (output options and unknown
    keys ignored)."""
    from dataclasses import replace

    from align.alignment.jobs import ApplyOptions

    source = opt.log_source(log, columns, rate_hz=rate_hz, units=units, time_column=time_column, skip_rows=skip_rows,
                            comment=comment, delimiter=delimiter, time_units=time_units, topic=topic, stamps=stamps)
    if temperature_column is not None:
        source = replace(source, temperature_column=temperature_column, temperature_units=temperature_units)
    return ApplyOptions(log=source, alignment=alignment, sensor=None if sensor is None else value(sensor),
                        gyro_units=gyro_units)


def apply_files(result, inputs, params: dict) -> list[tuple[Path, bytes | str]]:
    """The corrected CSV ``--out`` and the picture ``--plot`` (drawn before anything is written); ``inputs``: the
    job's checked inputs (the picture shows the log before the correction)."""
    from align.io.files import csv_bytes

    names = list(result.columns)
    units = {n: result.units for n in names[-3:]} | ({names[0]: result.time_units or "s"} if len(names) > 3 else {})
    rule = next((c.split(": ", 1)[1] for c in result.CONVENTION.split("; ") if c.startswith(f"{result.sensor}:")), "")
    wrote = f"apply: {result.sensor} corrected with {Path(params['alignment']).name} ({rule})"
    out: list[tuple[Path, bytes | str]] = [(params["out"], csv_bytes(names, result.table(), units, wrote))]
    if params.get("plot") is not None:
        from align.present.calplots import apply_traces_png

        out.append((params["plot"], apply_traces_png(inputs.log.t, inputs.log.data, inputs.corrected,
                                                     inputs.log.shown)))
    return out


def apply(
    log: opt.Arg("Log to correct.", "LOG"),
    alignment: opt.Input("--alignment", "A result of 'matrix', 'calibrate ferraris', 'calibrate accel', 'calibrate mag' "
                         "or 'calibrate thermal' (with --temperature-column).", "RESULT.json"),
    out: opt.Input("--out", "Corrected CSV (same columns and units).", "OUT.csv"),
    sensor: opt.Choice("--sensor", ("accelerometer", "gyroscope", "magnetometer"),
                       "The sensor to correct, for a file holding several.") = None,
    gyro_units: opt.GyroUnits(stated=True) = None,
    units: opt.Units("Unit of the columns for an accelerometer or magnetometer result (default: the unit the file "
                     "states, else the result's).") = None,
    columns: opt.Columns("Data columns: x,y,z (with --time-column, default time), or time,x,y,z (time first); "
                         "default per sensor (gyro_x,..., acc_x,..., mag_x,...).", optional=True) = None,
    time_column: opt.TimeColumn = None,
    rate_hz: opt.RateHz() = None,
    plot: opt.OptInput("--plot", "Picture of the log before and after the correction (PNG).", "TRACES.png") = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    time_units: opt.TimeUnits = None,
    topic: opt.Topic = None,
    stamps: opt.Stamps = None,
    temperature_column: opt.TemperatureColumn = None,
    temperature_units: opt.TemperatureUnits = None,
) -> None:
    """Correct a log: gyro w = A (g - b); accelerometer M^-1 (a - b); magnetometer soft_iron (m - hard_iron); a thermal
    calibration raw - bias(T)."""
    params = dict(locals())
    check_outputs([log, alignment], out=out, plot=plot)
    from align.alignment.jobs import APPLY

    result, inputs = APPLY.run_with_inputs(apply_options(**params))
    write_run(None, result, apply_files(result, inputs, params))  # all or none: the picture drawn before anything is written
    notes = "".join(f"; {n}" for n in result.notes)
    typer.echo(f"wrote {out}: {len(result.t)} rows of {result.sensor} data corrected with {alignment} "
               f"({result.units}){notes}")


COMMANDS = {"apply": apply}
