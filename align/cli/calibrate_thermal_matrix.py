"""``imu-align calibrate thermal-matrix``: scale, misalignment and bias against temperature from calibration or
alignment results made at several temperatures; the work is the library job
:data:`align.calibration.thermal.matrix_job.THERMAL_MATRIX`.

Public names
------------
thermal_matrix, thermal_matrix_options, thermal_matrix_summary
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from align.cli import options as opt
from align.cli.paths import check_outputs, judged_outcome, write_run

if TYPE_CHECKING:
    from align.calibration.thermal.matrix_job import MatrixThermalOptions
    from align.calibration.thermal.matrix_t import MatrixThermal


def thermal_matrix_options(*, results: list[Path], temperatures: str | None = None,
                           temperature_sigma: float = 0.0, sensor: str | None = None, order: str = "1",
                           reference: float | None = None, **_: Any) -> MatrixThermalOptions:
    """The job's options from the command's parameters (Python names; output options and unknown keys ignored)."""
    from align.calibration.thermal.matrix_job import MatrixThermalOptions, parse_temperatures
    from align.errors import InputError
    from align.vocab import Sensor

    chosen = None
    if sensor is not None:
        try:
            chosen = Sensor.parse(sensor).value
        except ValueError:
            raise InputError(f"give gyroscope or accelerometer, not '{sensor}'", "{sensor}") from None
    if order not in ("1", "2", "auto"):
        raise InputError(f"give 1, 2 or auto, not '{order}'", "{order}")
    temps = None if temperatures is None else parse_temperatures(temperatures)
    return MatrixThermalOptions(results=tuple(results), temperatures=temps, temperature_sigma=temperature_sigma,
                                sensor=chosen, order=None if order == "auto" else int(order), reference=reference)


def thermal_matrix_summary(result: MatrixThermal) -> str:
    """The terminal's table: per element the slope +/- 1-sigma (ppm/K for M, the bias unit per K for b), z, order,
    and whether it changes significantly."""
    from align.units import parse_unit

    counts = result.units.strip().lower() in ("count", "counts")
    f = 1.0 if counts else parse_unit(result.units).factor
    lo, hi = result.valid_range
    at = ", ".join(f"{p.temperature:g}" for p in result.points)
    lines = [f"{result.sensor}: {len(result.points)} calibrations at {at} degC; fitted about {result.reference:g} degC,"
             f" valid {lo:g} .. {hi:g} degC"]
    for e in result.elements:
        s, ss = e.slope
        k, unit = (1e6, "ppm/K") if e.name.startswith("M_") else (1 / f, f"{result.units}/K")
        flag = "changes significantly" if e.significant else "-"
        extra = f", sigma x{e.inflation:.3g} (scatter)" if e.inflation > 1 else ""
        lines.append(f"  {e.name:<7} {s * k:+.4g} +/- {ss * k:.2g} {unit}  z = {s / ss if ss > 0 else math.inf:+.3g}"
                     f"  order {e.order}{extra}  {flag}")
    sig = result.significant()
    lines.append(f"significant (3-sigma over 12 elements, Bonferroni): {', '.join(sig) if sig else 'none'}")
    lines += [f"note: {n}" for n in result.notes]
    return "\n".join(lines)


def thermal_matrix(
    results: Annotated[list[Path], typer.Argument(metavar="RESULTS", show_default=False, help=(
        "Calibration or alignment results (JSON) of one sensor, one per temperature."))],
    temperatures: Annotated[str | None, typer.Option("--temperatures", metavar="LIST", help=(
        "Their temperatures in order, e.g. '20 degC,40 degC,60 degC' (degC, K or degF; default: the session "
        "temperature each result states)."))] = None,
    temperature_sigma: opt.Number("--temperature-sigma", "1-sigma of each given temperature, degC (>= 0).",
                                  opt.NONNEGATIVE, "0.2", "DEGC") = 0.0,
    sensor: Annotated[str | None, typer.Option("--sensor", metavar="SENSOR", help=(
        "gyroscope or accelerometer: the sensor read from results that hold both."))] = None,
    order: Annotated[str, typer.Option("--order", metavar="N", help=(
        "Polynomial order in temperature: 1, 2 (4 results or more) or auto (2 per element where a "
        "likelihood-ratio test at 1 % asks for it)."))] = "1",
    reference: Annotated[float | None, typer.Option("--reference", parser=opt.number(opt.ANY, "25"), metavar="DEGC",
                                                    help="Reference temperature, C (default: the mean).")] = None,
    json_out: opt.JsonOut = None,
) -> None:
    """Scale, misalignment and bias against temperature from calibrations at several temperatures."""
    params = dict(locals())
    check_outputs(list(results), json_out=json_out)
    from align.calibration.thermal.matrix_job import THERMAL_MATRIX

    result, _ = THERMAL_MATRIX.run_with_inputs(thermal_matrix_options(**params))
    write_run(json_out, result)
    typer.echo(thermal_matrix_summary(result))
    judged_outcome(result)
