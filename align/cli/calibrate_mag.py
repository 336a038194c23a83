"""``imu-align calibrate mag``: magnetometer hard and soft iron (ellipsoid fit with coverage gates), and the
misalignment from axis-down turns; the work is the library job :data:`align.calibration.jobs.MAG`.

Public names
------------
mag, mag_options, mag_files
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, cast

import typer

from align.cli import options as opt
from align.cli.options import DIP, names, value
from align.cli.paths import check_outputs, judged_outcome, write_run

if TYPE_CHECKING:
    from align.calibration.jobs import MagInputs, MagOptions
    from align.calibration.magnetometer import MagCalibration


def mag_options(*, log: Path, columns: str | None = None, mag_units: str | None = None,
                field: str | float | None = None, model: Any = "symmetric", accel_columns: str | None = None,
                dip: float | None = None, axis_down: str | None = None, skip_rows: int = 0, comment: str | None = None,
                delimiter: str | None = None, topic: str | None = None, stamps: str | None = None,
                limits: Path | None = None, **_: Any) -> MagOptions:
    """The job's options from the command's parameters (Python names; output options and unknown keys ignored).

    Returns
    -------
    MagOptions
    """
    from align.calibration.axisdown import parse_axis_down
    from align.calibration.jobs import MagOptions
    from align.units import parse_quantity, parse_scale

    f: float | None
    if isinstance(field, str):
        shown = parse_scale(mag_units or "uT", "magnetic_field", "{mag_units}")[1]
        f = parse_quantity(field, "counts" if shown == "counts" else "magnetic_field", "{field}")
    else:
        f = field
    down = None if axis_down is None else {a: v if isinstance(v, tuple) else Path(v)
                                           for a, v in parse_axis_down(axis_down).items()}
    return MagOptions(limits=limits, log=opt.log_source(log, columns, units=mag_units, skip_rows=skip_rows, comment=comment,
                                         delimiter=delimiter, topic=topic, stamps=stamps),
                      accel_columns=None if accel_columns is None else tuple(names(accel_columns)), field=f,
                      model=cast(Any, value(model)), dip=dip, axis_down=down)


def mag_files(result: MagCalibration, inputs: MagInputs, params: dict[str, Any]) -> list[tuple[Path, bytes | str]]:
    """The picture ``--plot`` asks for (beside the ``--json`` result)."""
    plot = params.get("plot")
    if plot is None:
        return []
    from align.present.calplots import magnetometer_png

    return [(Path(plot), magnetometer_png(inputs.m, result))]


def mag(
    log: opt.Arg("Magnetometer capture while tumbling the device (CSV, blank-separated text, or a stream of a log of "
                 "several: --topic).", "LOG"),
    columns: opt.Columns("Magnetometer columns x,y,z (default mag_x,mag_y,mag_z, or mx,my,mz when the file has those; "
                         "col0,col1,... for a file without header).", optional=True) = None,
    mag_units: opt.UnitFlag("--mag-units", "Unit: uT, nT, gauss, mG, 'counts', or the size of one count, e.g. "
                            "'0.92 mG'." + opt.stated_default("uT")) = None,
    field: Annotated[str | None, typer.Option("--field", metavar="FIELD", help=(
        "Known field strength to refine to, e.g. '48.5 uT'."))] = None,
    model: opt.Choice("--model", ("sphere", "diagonal", "symmetric"), "Soft-iron model.") = "symmetric",
    accel_columns: opt.Columns("Simultaneous accelerometer columns (dip angle, alignment to gravity).", "--accel-columns",
                               optional=True) = None,
    dip: opt.OptQuantity("--dip", "angle", "Magnetic dip for the heading-error prediction when no accelerometer "
                         "(-90 to 90 deg).", "ANGLE", DIP, "'60 deg'") = None,
    axis_down: Annotated[str | None, typer.Option("--axis-down", metavar="x=FILE,y=FILE,z=FILE", help=(
        "Misalignment to the body axes from turns with each axis pointing down (seed 004): the device turned on a "
        "flat surface through a full turn with x, then y, then z down; each a file with the same columns, or samples "
        "of LOG as START:STOP (counted from 0, STOP exclusive; left out of the ellipsoid fit), e.g. "
        "'x=100:900,y=1000:1800,z=2000:2800'."))] = None,
    plot: opt.OptInput("--plot", "Picture of the capture before and after, and the heading error (PNG).",
                       "OUT.png") = None,
    json_out: opt.JsonOut = None,
    limits: opt.Limits = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    topic: opt.Topic = None,
    stamps: opt.Stamps = None,
) -> None:
    """Magnetometer hard and soft iron (ellipsoid fit with coverage gates), and the misalignment from axis-down turns."""
    params = dict(locals())
    from align.calibration.jobs import MAG

    opts = mag_options(**params)
    files = [v for v in (opts.axis_down or {}).values() if isinstance(v, Path)]
    check_outputs([log, *files, limits], json_out=json_out, plot=plot)
    from align.present.text import magnetometer_summary

    result, inputs = MAG.run_with_inputs(opts)
    write_run(json_out, result, mag_files(result, inputs, params))  # all or none
    typer.echo(magnetometer_summary(result))
    judged_outcome(result)
