"""The ``imu-align`` command line: a thin layer over the library.

Each command parses its options (units at this edge), calls the library,
prints a summary and writes its files only after everything succeeded. A
user-facing problem is one line on stderr and a non-zero exit status
(2: bad input, 3: the test does not support a result); set
``IMU_ALIGN_DEBUG=1`` to see the traceback of an unexpected failure.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Optional

import typer

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="MEMS IMU mounting-misalignment analysis and electronic alignment.\n\n"
    "Convention everywhere: g = M w + b, w = A (g - b), A = M^-1; rows of M are gyros.",
)

DEFAULT_COLUMNS = "time,gyro_x,gyro_y,gyro_z"


def _columns(text: str, rate_hz: Optional[float]) -> tuple[Optional[str], list[str]]:
    names = [c.strip() for c in text.split(",") if c.strip()]
    if rate_hz is None:
        if len(names) != 4:
            from align.errors import InputError

            raise InputError("give four names: time,x,y,z (or three with --rate-hz)", "--columns")
        return names[0], names[1:]
    return None, names[-3:]


@app.command()
def matrix(
    log: Path = typer.Argument(..., help="Gyro log: .csv, .csv.gz, .npy or .parquet."),
    plan: Path = typer.Option(..., "--plan", help="Test plan TOML: [[step]] axis, rate or angle."),
    method: str = typer.Option("auto", help="auto | rate | angle | lsq | two-axis."),
    gyro_units: str = typer.Option("deg/s", help="Unit of the gyro columns, e.g. deg/s, rad/s, mdps."),
    columns: str = typer.Option(DEFAULT_COLUMNS, help="Column names: time,x,y,z (x,y,z with --rate-hz)."),
    rate_hz: Optional[float] = typer.Option(None, help="Sample rate for a log without a time column."),
    segments: Optional[Path] = typer.Option(None, help="Explicit segments JSON {name: {start, end}} instead of automatic."),
    json_out: Optional[Path] = typer.Option(None, "--json", help="Write the versioned JSON result here."),
    c_header: Optional[Path] = typer.Option(None, "--c-header", help="Write A and the bias as a C header here."),
    gyro_range: Optional[str] = typer.Option(None, help="Gyro full scale, e.g. '2000 deg/s': flags saturation."),
    min_dwell: str = typer.Option("1 s", help="Shortest acceptable step."),
    window: str = typer.Option("0.1 s", help="Moving-mean window of the segmentation."),
    margin: str = typer.Option("0.1 s", help="Trimmed from each end of a dwell beyond the ramp."),
    static_threshold: str = typer.Option("1 deg/s", help="Static periods lie within this of the quietest one (angle plans)."),
    rate_tolerance: str = typer.Option("10 %", help="Largest difference of a measured turn from the plan."),
    scale_tolerance: str = typer.Option("5 %", help="Scale factors must lie within 1 +/- this."),
    axis_to_axis: str = typer.Option("0.05 deg", help="Axis-to-axis spec for the two-axis shortcut's error."),
    two_axis_variant: str = typer.Option("procrustes", help="procrustes | cross (the source's Eq 36)."),
    earth: bool = typer.Option(True, help="Correct the vertical Earth rate when the plan gives a latitude."),
) -> None:
    """Alignment matrix M and A = M^-1 from rate-table data."""
    import align.io as fileio
    from align.alignment.job import AlignOptions, align
    from align.alignment.plan import Plan
    from align.alignment.segment import SegmentOptions, segments_from_ranges
    from align.present.text import alignment_summary
    from align.units import parse_quantity as q

    if two_axis_variant not in ("procrustes", "cross"):
        from align.errors import InputError

        raise InputError("choose procrustes or cross", "--two-axis-variant")
    time_col, cols = _columns(columns, rate_hz)
    the_plan = Plan.from_dict(fileio.read_toml(plan), str(plan))
    t, g = fileio.read_log(log, cols, gyro_units, time_col, rate_hz)
    opts = AlignOptions(
        method=method,
        two_axis_variant=two_axis_variant,
        axis_to_axis=q(axis_to_axis, "angle", "--axis-to-axis"),
        segmentation=SegmentOptions(
            window_s=q(window, "time", "--window"),
            margin_s=q(margin, "time", "--margin"),
            static_threshold=q(static_threshold, "angular_rate", "--static-threshold"),
        ),
        min_dwell=q(min_dwell, "time", "--min-dwell"),
        rate_tolerance=q(rate_tolerance, "dimensionless", "--rate-tolerance"),
        scale_tolerance=q(scale_tolerance, "dimensionless", "--scale-tolerance"),
        gyro_range=None if gyro_range is None else q(gyro_range, "angular_rate", "--gyro-range"),
        earth_correction=earth,
    )
    segs = None
    if segments is not None:
        segs = segments_from_ranges(fileio.read_json(segments), the_plan, len(t), str(segments))
    result = align(t, g, the_plan, opts, segs, gyro_units, str(log))
    inputs = {"log": str(log), "plan": str(plan), "gyro_units": gyro_units, "columns": columns,
              "segments": None if segments is None else str(segments)}
    result = type(result)(**{**result.__dict__, "inputs": inputs})
    typer.echo(alignment_summary(result))
    if json_out is not None:
        fileio.write_json(json_out, result.to_dict())
    if c_header is not None:
        from align import CONVENTION
        from align.units import to_unit

        text = fileio.c_header("IMU_ALIGN", result.A, to_unit(result.bias, gyro_units), gyro_units,
                               f"imu-align alignment from {log.name}\n{CONVENTION}")
        fileio.write_text(c_header, text)


@app.command()
def apply(
    log: Path = typer.Argument(..., help="Log to correct."),
    alignment: Path = typer.Option(..., "--alignment", help="A result of 'matrix', 'calibrate ferraris/accel' or 'calibrate mag'."),
    out: Path = typer.Option(..., "--out", help="Corrected CSV (same columns and units)."),
    sensor: Optional[str] = typer.Option(None, help="accelerometer | gyroscope, for a file holding both."),
    gyro_units: str = typer.Option("deg/s", help="Unit of the gyro columns."),
    units: Optional[str] = typer.Option(None, help="Unit of the columns for an accelerometer or magnetometer result."),
    columns: Optional[str] = typer.Option(None, help="Column names: time,x,y,z (x,y,z with --rate-hz); default per sensor."),
    rate_hz: Optional[float] = typer.Option(None, help="Sample rate for a log without a time column."),
) -> None:
    """Correct a log: gyro w = A (g - b); accelerometer M^-1 (a - b); magnetometer soft_iron (m - hard_iron)."""
    import numpy as np

    import align.io as fileio
    from align.alignment.job import FORMAT as ALIGN_FORMAT
    from align.alignment.job import AlignmentResult
    from align.calibration.accel import Calibration
    from align.errors import InputError
    from align.calibration.magnetometer import MagCalibration
    from align.model import SensorModel
    from align.units import parse_unit, to_unit

    d = fileio.read_json(alignment)
    fmt = d.get("format")
    defaults = {"gyroscope": "time,gyro_x,gyro_y,gyro_z", "accelerometer": "time,acc_x,acc_y,acc_z",
                "magnetometer": "time,mag_x,mag_y,mag_z"}
    if fmt == ALIGN_FORMAT:
        kind, u = "gyroscope", gyro_units
        model = AlignmentResult.from_dict(d, str(alignment))
        correct = SensorModel(model.M, model.bias).correct
    elif fmt == "imu-align.calibration":
        present = [k for k in ("accelerometer", "gyroscope") if k in d]
        kind = sensor or (present[0] if len(present) == 1 else None)
        if kind not in present:
            raise InputError(f"this file holds {', '.join(present)}: choose one with --sensor", "--sensor")
        cal = Calibration.from_dict(d[kind], f"{alignment}: {kind}")
        u = units or (gyro_units if kind == "gyroscope" else cal.units)
        correct = cal.correct
    elif fmt == "imu-align.magnetometer":
        kind = "magnetometer"
        cal = MagCalibration.from_dict(d, str(alignment))
        u = units or cal.units
        correct = cal.correct
    else:
        raise InputError(f"not an imu-align result (format {fmt!r})", str(alignment))
    expect = {"gyroscope": "angular_rate", "accelerometer": None, "magnetometer": None}[kind]
    parse_unit(u, expect, "--units")
    time_col, cols = _columns(columns or defaults[kind], rate_hz)
    t, raw = fileio.read_log(log, cols, u, time_col, rate_hz, expect=expect or _kind_of(u))
    w = correct(raw)
    names = ([time_col] if time_col else []) + cols
    data = np.column_stack(([t] if time_col else []) + [to_unit(w, u)])
    fileio.write_csv(out, names, data)
    typer.echo(f"wrote {out}: {len(t)} rows of {kind} data corrected with {alignment} ({u})")


def _kind_of(unit: str) -> str:
    from align.units import DIMENSIONS, parse_unit

    dim = parse_unit(unit).dim
    for name in ("acceleration", "magnetic_field", "counts", "angular_rate"):
        if DIMENSIONS[name][0].dim == dim:
            return name
    return "dimensionless"


@app.command()
def simulate(
    out_dir: Path = typer.Argument(..., help="Folder for session.csv, plan.toml and truth.json."),
    plan: Optional[Path] = typer.Option(None, "--plan", help="Plan to run; default the six-dwell +/- rate plan."),
    kind: str = typer.Option("rate", help="rate | angle: the default plan's kind."),
    rate: str = typer.Option("100 deg/s", help="Table rate of the default rate plan."),
    angle: str = typer.Option("360 deg", help="Turn of the default angle plan."),
    fs: str = typer.Option("200 Hz", help="Sample rate."),
    dwell: str = typer.Option("10 s", help="Constant-rate part of each rate step."),
    gap: str = typer.Option("3 s", help="Static gap between steps."),
    noise: str = typer.Option("0.3 deg/sqrt(h)", help="Angle random walk (white rate noise)."),
    bias_walk: str = typer.Option("0 deg/h/sqrt(h)", help="Rate random walk of the bias."),
    misalignment: str = typer.Option("0.5 deg", help="Size of the random mounting rotation."),
    seed: int = typer.Option(0, help="Random seed."),
    gyro_units: str = typer.Option("deg/s", help="Unit of the written gyro columns."),
) -> None:
    """Simulate a rate-table session with known M (for rehearsals and examples)."""
    import numpy as np
    from scipy.spatial.transform import Rotation

    from align import CONVENTION

    import align.io as fileio
    from align.errors import InputError
    from align.model import SensorModel
    from align.alignment.plan import Plan
    from align.alignment.simulate import SessionSpec, simulate_session
    from align.units import DEG, to_unit
    from align.units import parse_quantity as q

    if not out_dir.is_dir():
        raise InputError("output folder does not exist", str(out_dir))
    if plan is not None:
        the_plan = Plan.from_dict(fileio.read_toml(plan), str(plan))
    elif kind == "rate":
        the_plan = Plan.standard_rate(q(rate, "angular_rate", "--rate"))
    elif kind == "angle":
        the_plan = Plan.standard_angle(q(angle, "angle", "--angle"))
    else:
        raise InputError("choose rate or angle", "--kind")
    rng = np.random.default_rng(seed)
    size = q(misalignment, "angle", "--misalignment")
    rotvec = rng.normal(size=3)
    rotvec *= size / np.linalg.norm(rotvec)
    truth = SensorModel.from_rotation(
        Rotation.from_rotvec(rotvec), scale=1 + rng.normal(0, 2e-3, 3), delta=rng.normal(0, 0.05 * DEG, 3),
        bias=rng.normal(0, 0.2 * DEG, 3),
    )
    spec = SessionSpec(fs=q(fs, "frequency", "--fs"), dwell_s=q(dwell, "time", "--dwell"), static_s=q(gap, "time", "--gap"),
                       noise_density=q(noise, "angle_random_walk", "--noise"),
                       bias_walk=q(bias_walk, "rate_random_walk", "--bias-walk"))
    t, g, _ = simulate_session(the_plan, truth, spec, rng)
    fileio.write_csv(out_dir / "session.csv", DEFAULT_COLUMNS.split(","), np.column_stack([t, to_unit(g, gyro_units)]))
    fileio.write_text(out_dir / "plan.toml", the_plan.to_toml())
    fileio.write_json(out_dir / "truth.json", {
        "format": "imu-align.truth", "version": 1, "convention": CONVENTION,
        "units": {"M": "1", "bias": gyro_units}, "M": truth.M, "A": truth.alignment(),
        "bias": to_unit(truth.bias, gyro_units), "seed": seed,
    })
    typer.echo(f"wrote {out_dir}/session.csv ({len(t)} rows, {t[-1]:.1f} s), plan.toml and truth.json")


@app.command()
def budget(
    mount: Path = typer.Argument(..., help="Mount description TOML ([imu], [package], [ledges] or [baseplate], [screws])."),
    monte_carlo: int = typer.Option(0, "--monte-carlo", help="Monte Carlo draws (0: none)."),
    seed: int = typer.Option(0, help="Random seed of the Monte Carlo."),
    json_out: Optional[Path] = typer.Option(None, "--json", help="Write the versioned JSON result here."),
    plot: Optional[Path] = typer.Option(None, "--plot", help="PNG histogram of the Monte Carlo."),
    picture: Optional[Path] = typer.Option(None, "--picture", help="PNG of the assembly, tilt exaggerated."),
    glb: Optional[Path] = typer.Option(None, "--glb", help="GLB of the assembly, tilt exaggerated."),
    exaggerate: float = typer.Option(30.0, help="Angle exaggeration of --picture and --glb."),
) -> None:
    """Mounting-misalignment budget: source formulas, worst case and Monte Carlo."""
    import align.io as fileio
    from align.errors import InputError
    from align.present.text import budget_summary
    from mechanics.budget import budget as make_budget
    from mechanics.budget import monte_carlo as run_mc
    from mechanics.mount import mount_from_dict

    if monte_carlo < 0:
        raise InputError("must be 0 or more", "--monte-carlo")
    if plot is not None and monte_carlo == 0:
        raise InputError("the histogram needs --monte-carlo N", "--plot")
    m = mount_from_dict(fileio.read_toml(mount), str(mount), mount.parent)
    result = make_budget(m)
    if monte_carlo:
        with _progress(monte_carlo, "Monte Carlo") as tick:
            mc = run_mc(m, monte_carlo, seed, progress=tick)
        result = type(result)(**{**result.__dict__, "monte_carlo": mc})
    outputs = []
    if plot is not None:
        from mechanics.render import histogram_png

        outputs.append((plot, histogram_png(result)))
    if picture is not None:
        from mechanics.render import assembly_png

        outputs.append((picture, assembly_png(m, exaggerate)))
    if glb is not None:
        from mechanics.render import assembly_glb

        outputs.append((glb, assembly_glb(m, exaggerate)))
    typer.echo(budget_summary(result))
    if json_out is not None:
        fileio.write_json(json_out, result.to_dict())
    for path, data in outputs:
        fileio.write_bytes(path, data)


@app.command()
def allowable(
    manoeuvre: Path = typer.Argument(..., help="Manoeuvre TOML: [[rotation]] axis/angle (or [series]) and [limits]."),
    json_out: Optional[Path] = typer.Option(None, "--json", help="Write the versioned JSON result here."),
    symbolic: Optional[str] = typer.Option(None, help="Also print the sympy response and sensitivity: pretty | latex."),
) -> None:
    """Allowable misalignment per element for a manoeuvre, the binding element and the cone."""
    import align.io as fileio
    from align.sensitivity.allowable import allowable as compute, manoeuvre_from_dict, symbolic_text
    from align.present.text import allowable_summary

    man = manoeuvre_from_dict(fileio.read_toml(manoeuvre), str(manoeuvre), manoeuvre.parent)
    if symbolic is not None:
        typer.echo(symbolic_text(symbolic) + "\n")
    result = compute(man)
    typer.echo(allowable_summary(result))
    if json_out is not None:
        fileio.write_json(json_out, result.to_dict())


@app.command()
def check(
    mount: Path = typer.Argument(..., help="Mount TOML (see 'budget')."),
    manoeuvre: Path = typer.Argument(..., help="Manoeuvre TOML (see 'allowable')."),
    basis: str = typer.Option("rss", help="Budget figure to compare: rss (the source's method) or worst."),
    json_out: Optional[Path] = typer.Option(None, "--json", help="Write the element table as JSON."),
) -> None:
    """The mounting budget against the allowance; exit status 4 when an element fails."""
    from align import CONVENTION
    import align.io as fileio
    from align.errors import InputError
    from align.sensitivity.allowable import allowable as compute, manoeuvre_from_dict, margins
    from align.present.text import margin_summary
    from mechanics.budget import budget as make_budget
    from mechanics.mount import mount_from_dict

    if basis not in ("rss", "worst"):
        raise InputError("choose rss or worst", "--basis")
    b = make_budget(mount_from_dict(fileio.read_toml(mount), str(mount), mount.parent))
    allow = compute(manoeuvre_from_dict(fileio.read_toml(manoeuvre), str(manoeuvre), manoeuvre.parent))
    rows = margins(b.elements(basis), allow)
    typer.echo(margin_summary(rows, basis))
    if json_out is not None:
        import math

        fileio.write_json(json_out, {
            "format": "imu-align.check", "version": 1, "convention": CONVENTION, "units": {"angles": "deg"},
            "basis": basis, "pass": all(r.ok for r in rows),
            "elements": [{"element": r.element, "predicted_deg": math.degrees(r.predicted),
                          "allowed_deg": None if math.isinf(r.allowed) else math.degrees(r.allowed),
                          "margin_deg": None if math.isinf(r.allowed) else math.degrees(r.margin),
                          "pass": r.ok} for r in rows],
        })
    if not all(r.ok for r in rows):
        raise typer.Exit(4)


@app.command()
def allan(
    logs: list[Path] = typer.Argument(..., help="Static recordings: .csv, .csv.gz, .npy or raw float64 .bin; several runs give the bias repeatability."),
    columns: str = typer.Option("gyro_x,gyro_y,gyro_z", help="Data columns (a CSV's time column is 'time' unless --rate-hz)."),
    rate_hz: Optional[float] = typer.Option(None, help="Sample rate for files without a time column (.npy always)."),
    gyro_units: str = typer.Option("deg/s", help="Unit of the data columns (an angular rate)."),
    units: Optional[str] = typer.Option(None, help="Any rate or acceleration unit instead of --gyro-units (e.g. g)."),
    grid: str = typer.Option("dense", help="dense | octave | decade | explicit taus '0.01,0.1,1' (s)."),
    per_decade: int = typer.Option(10, help="Points per decade of the dense grid."),
    modified: bool = typer.Option(False, help="Also the modified Allan deviation."),
    json_out: Optional[Path] = typer.Option(None, "--json", help="Write the versioned JSON result here."),
    plot: Optional[Path] = typer.Option(None, "--plot", help="Log-log plot with confidence band and fit (PNG)."),
    rate: Optional[str] = typer.Option(None, help="Table rate, to plan: draws the target and the averaging time."),
    accuracy: Optional[str] = typer.Option(None, help="Alignment goal, to plan (with --rate)."),
    noise_ratio: float = typer.Option(10.0, help="Noise this many times below the goal, to plan."),
    memory_limit_mb: float = typer.Option(2000.0, help="Phase kept in memory up to this size; beyond it, a temporary file."),
) -> None:
    """Allan deviation, noise-model fit and noise figures of static recordings."""

    import align.io as fileio
    from align.errors import InputError
    from align.noise.job import allan_plot_png, run_allan
    from align.present.text import allan_summary
    from align.units import parse_quantity as q
    from align.units import parse_unit

    unit = units or gyro_units
    parse_unit(unit, None if units else "angular_rate", "--units" if units else "--gyro-units")
    if units and parse_unit(units).dim not in (parse_unit("rad/s").dim, parse_unit("m/s^2").dim):
        raise InputError(f"'{units}' is neither an angular rate nor an acceleration", "--units")
    names = [c.strip() for c in columns.split(",") if c.strip()]
    grid_value = grid if grid in ("dense", "octave", "decade") else _taus(grid)
    runs, fs = [], None
    for log in logs:
        data, f = fileio.read_static(log, names, rate_hz)
        if fs is not None and abs(f - fs) > 1e-9 * fs:
            raise InputError(f"sample rate {f:g} Hz differs from the first run's {fs:g} Hz", str(log))
        runs.append(data)
        fs = f
    rows = runs[0].shape[0]
    with _progress(rows, "Allan deviation (samples read)") as tick:
        job = run_allan(runs, fs, names, unit, grid_value, per_decade, modified, progress=tick,
                        memory_limit=memory_limit_mb * 1e6)
    job = type(job)(**{**job.__dict__, "inputs": [str(p) for p in logs]})
    d = job.to_dict()
    target = chosen = None
    if (rate is None) != (accuracy is None):
        raise InputError("give both --rate and --accuracy to plan", "--rate")
    if rate is not None:
        from align.noise.planner import make_plan

        r = job.result
        worst = r.adev.max(axis=0)
        pl = make_plan(q(rate, "angular_rate", "--rate"), q(accuracy, "angle", "--accuracy"), noise_ratio,
                       "measured curve (worst channel)", tau=r.tau, adev=worst)
        target, chosen = pl.noise_target, pl.averaging.tau
        d["plan"] = pl.to_dict()
    typer.echo(allan_summary(d))
    if "plan" in d:
        from align.present.text import plan_summary

        typer.echo("\n" + plan_summary(d["plan"]))
    png = allan_plot_png(job, target, chosen) if plot is not None else None
    if json_out is not None:
        fileio.write_json(json_out, d)
    if png is not None:
        fileio.write_bytes(plot, png)


def _taus(text: str) -> list[float]:
    from align.errors import InputError

    try:
        taus = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise InputError(f"'{text}' is not dense, octave, decade or a comma list of taus in seconds", "--grid") from None
    if not taus or min(taus) <= 0:
        raise InputError("taus must be positive seconds", "--grid")
    return taus


@app.command()
def plan(
    rate: str = typer.Option(..., "--rate", help="Table rate, e.g. '100 deg/s'."),
    accuracy: str = typer.Option(..., "--accuracy", help="Alignment goal, e.g. '0.1 deg'."),
    noise_ratio: float = typer.Option(10.0, help="Noise this many times below the goal."),
    arw: Optional[str] = typer.Option(None, help="Angle random walk, e.g. '0.3 deg/sqrt(h)'."),
    bias_instability: Optional[str] = typer.Option(None, help="Bias instability, e.g. '6 deg/h' (with --arw)."),
    rate_random_walk: Optional[str] = typer.Option(None, help="Rate random walk, e.g. '3 deg/h/sqrt(h)' (with --arw)."),
    imu: Optional[str] = typer.Option(None, help="A datasheet preset (see 'budget'), e.g. ADIS16485."),
    allan_json: Optional[Path] = typer.Option(None, "--allan", help="A result of 'imu-align allan --json'."),
    turn_angle: str = typer.Option("360 deg", help="Turn of the angle method."),
    settle: str = typer.Option("2 s", help="Settling time added to each step."),
    steps: int = typer.Option(6, help="Table steps (6: +/- about three axes)."),
    json_out: Optional[Path] = typer.Option(None, "--json", help="Write the versioned JSON result here."),
) -> None:
    """Averaging time per table step for an alignment goal (Example 3), and the whole plan."""
    import numpy as np

    import align.io as fileio
    from align.errors import InputError
    from align.noise.planner import make_plan, model_curve
    from align.present.text import plan_summary
    from align.units import parse_quantity as q
    from align.units import parse_unit

    given = [x is not None for x in (arw, imu, allan_json)]
    if sum(given) != 1:
        raise InputError("give exactly one noise source: --arw X [--bias-instability Y], --imu PART or --allan RESULT.json", "plan")
    if arw is None and (bias_instability or rate_random_walk):
        raise InputError("goes with --arw", "--bias-instability" if bias_instability else "--rate-random-walk")
    w, a = q(rate, "angular_rate", "--rate"), q(accuracy, "angle", "--accuracy")
    if w <= 0 or a <= 0 or noise_ratio <= 0:
        raise InputError("rate, accuracy and noise ratio must be positive", "--rate")
    common = dict(turn_angle=q(turn_angle, "angle", "--turn-angle"), steps=steps, settle=q(settle, "time", "--settle"))
    if arw is not None:
        n = q(arw, "angle_random_walk", "--arw")
        b = q(bias_instability, "angular_rate", "--bias-instability") if bias_instability else 0.0
        k = q(rate_random_walk, "rate_random_walk", "--rate-random-walk") if rate_random_walk else 0.0
        label = f"model: ARW {arw}" + (f", bias instability {bias_instability}" if b else "") + (f", RRW {rate_random_walk}" if k else "")
        result = make_plan(w, a, noise_ratio, label, sigma=model_curve(n, b, k), **common)
    elif imu is not None:
        from align.parts import get_part

        part = get_part(imu, "--imu")
        n = part.si("arw", "angle_random_walk") or part.si("noise_density", "angle_random_walk")
        if n is None:
            raise InputError(f"{part.name} has no angle random walk or noise density in the preset table", "--imu")
        b = part.si("bias_instability", "angular_rate") or 0.0
        result = make_plan(w, a, noise_ratio, f"datasheet preset {part.name}", sigma=model_curve(n, b), **common)
    else:
        d = fileio.read_json(allan_json)
        if d.get("format") != "imu-align.allan":
            raise InputError("not a result of 'imu-align allan --json'", str(allan_json))
        factor = parse_unit(d["units"]["adev"], "angular_rate", f"{allan_json}: units.adev").factor
        curves = np.array(list(d["adev"].values()), dtype=float) * factor
        result = make_plan(w, a, noise_ratio, f"measured curve (worst of {', '.join(d['adev'])})",
                           tau=np.array(d["tau"]), adev=curves.max(axis=0), **common)
    out = result.to_dict()
    typer.echo(plan_summary(out))
    if json_out is not None:
        fileio.write_json(json_out, out)


@app.command()
def report(
    mount: Path = typer.Option(..., "--mount", help="Mount TOML (see 'budget')."),
    manoeuvre: Path = typer.Option(..., "--manoeuvre", help="Manoeuvre TOML (see 'allowable')."),
    out: Path = typer.Option(..., "--out", help="The HTML report to write."),
    log: Optional[Path] = typer.Option(None, "--log", help="Rate-table log for the alignment (with --plan)."),
    plan: Optional[Path] = typer.Option(None, "--plan", help="Its test plan TOML."),
    allan_log: Optional[Path] = typer.Option(None, "--allan", help="Static recording for the Allan deviation and plan."),
    allan_columns: str = typer.Option("gyro_x,gyro_y,gyro_z", help="Columns of the static recording."),
    allan_rate_hz: Optional[float] = typer.Option(None, help="Its sample rate when it has no time column."),
    allan_units: str = typer.Option("deg/s", help="Its unit."),
    gyro_units: str = typer.Option("deg/s", help="Unit of the rate-table log."),
    rate: str = typer.Option("100 deg/s", help="Table rate for the plan."),
    accuracy: str = typer.Option("0.1 deg", help="Alignment goal for the plan."),
    monte_carlo: int = typer.Option(100_000, "--monte-carlo", help="Monte Carlo draws of the budget."),
    seed: int = typer.Option(0, help="Monte Carlo seed."),
) -> None:
    """One self-contained HTML report: budget, allowance, noise plan and alignment."""
    import align.io as fileio
    from align.errors import InputError
    from align.present.story import build_report

    if (log is None) != (plan is None):
        raise InputError("give --log and --plan together", "--log" if log is None else "--plan")
    with _progress(monte_carlo, "Monte Carlo") as tick:
        page, summary, _ = build_report(mount, manoeuvre, log, plan, allan_log, allan_columns, allan_rate_hz, allan_units,
                                        gyro_units, rate, accuracy, 10.0, monte_carlo, seed, progress=tick)
    fileio.write_text(out, page)
    typer.echo(summary + f"\nreport: {out}")


@app.command()
def demo(
    out: Path = typer.Option(Path("imu-align-demo"), "--out", help="Folder for the inputs, results and report."),
) -> None:
    """The whole story on bundled inputs (Examples 1-3, simulated records): summary and report."""

    import align.io as fileio
    from align.present.story import build_report, demo_inputs

    out.mkdir(parents=True, exist_ok=True)
    inp = demo_inputs(out)
    with _progress(100_000, "Monte Carlo") as tick:
        page, summary, results = build_report(inp["mount"], inp["manoeuvre"], inp["log"], inp["plan"], inp["allan"],
                                              inp["allan_columns"], inp["allan_rate_hz"], progress=tick,
                                              title="imu-align demo: ADIS16485 on a vehicle antenna platform")
    err = abs(__import__("numpy").array(results["alignment"]["M"]) - inp["truth_M"]).max()
    for name, data in results.items():
        if name != "check":
            fileio.write_json(out / f"{name}.json", data)
    fileio.write_text(out / "report.html", page)
    typer.echo("imu-align demo (inputs: the reference's Examples 1-3, a simulated static record and rate-table session)\n"
               + summary + f"\nalignment error against the simulation's truth: {err:.1e} (largest element of M)"
               + f"\nwrote {out}/report.html and the JSON results beside it")


calibrate_app = typer.Typer(help="Sensor calibration: Ferraris sessions, accelerometer positions, magnetometer ellipsoid.",
                            no_args_is_help=True)
app.add_typer(calibrate_app, name="calibrate")


def _calibration_file(sensors: dict, inputs: dict) -> dict:
    from align import __version__
    from align.calibration.accel import CONVENTION

    d = {"format": "imu-align.calibration", "version": 1, "generator": f"imu-align {__version__}",
         "convention": CONVENTION, "inputs": inputs}
    d.update({k: v.to_dict() for k, v in sensors.items()})
    return d


@calibrate_app.command("ferraris")
def calibrate_ferraris(
    log: Path = typer.Argument(..., help="Session log (CSV) with accelerometer and gyro columns."),
    sections: Path = typer.Option(..., "--sections", help="imucal section list JSON: x_p ... z_a, x_rot, y_rot, z_rot."),
    rate_hz: float = typer.Option(..., "--rate-hz", help="Sample rate."),
    turn_angle: str = typer.Option("-360 deg", help="Signed angle of each turn about the axis pointing up."),
    gravity: str = typer.Option("9.80665 m/s^2", help="Local gravity."),
    acc_columns: str = typer.Option("acc_x,acc_y,acc_z", help="Accelerometer columns."),
    gyr_columns: str = typer.Option("gyr_x,gyr_y,gyr_z", help="Gyro columns."),
    acc_units: str = typer.Option("m/s^2", help="Accelerometer unit."),
    gyr_units: str = typer.Option("deg/s", help="Gyro unit."),
    bias: str = typer.Option("pairwise", help="Accelerometer bias: pairwise (Ferraris, tilt-robust) or lsq."),
    g_sensitivity: bool = typer.Option(True, help="Estimate the gyro's g-sensitivity from the static faces."),
    json_out: Optional[Path] = typer.Option(None, "--json", help="Write the versioned JSON result here."),
    imucal_json: Optional[Path] = typer.Option(None, "--imucal-json", help="Also write the result as imucal's JSON."),
) -> None:
    """A Ferraris session (six static faces and a turn about each axis), as imucal records it."""

    import align.io as fileio
    from align.calibration.accel import ferraris, imucal_dict
    from align.errors import InputError
    from align.present.text import calibration_summary
    from align.units import parse_quantity as q

    if bias not in ("pairwise", "lsq"):
        raise InputError("choose pairwise or lsq", "--bias")
    acc_names = [c.strip() for c in acc_columns.split(",")]
    gyr_names = [c.strip() for c in gyr_columns.split(",")]
    _, acc = fileio.read_log(log, acc_names, acc_units, None, rate_hz, expect="acceleration")
    _, gyr = fileio.read_log(log, gyr_names, gyr_units, None, rate_hz)
    raw = fileio.read_json(sections)
    try:
        secs = {k: (int(v["start"]), int(v["end"])) for k, v in raw.items()}
    except (KeyError, TypeError, ValueError):
        raise InputError("each section needs integer start and end", str(sections)) from None
    acc_cal, gyr_cal = ferraris(acc, gyr, rate_hz, secs, q(turn_angle, "angle", "--turn-angle"),
                                q(gravity, "acceleration", "--gravity"), acc_units, gyr_units,
                                pairwise_bias=bias == "pairwise", g_sensitivity=g_sensitivity)
    typer.echo(calibration_summary({"accelerometer": acc_cal, "gyroscope": gyr_cal}))
    if json_out is not None:
        fileio.write_json(json_out, _calibration_file({"accelerometer": acc_cal, "gyroscope": gyr_cal},
                                                      {"log": str(log), "sections": str(sections)}))
    if imucal_json is not None:
        fileio.write_json(imucal_json, imucal_dict(acc_cal, gyr_cal))


@calibrate_app.command("accel")
def calibrate_accel_cmd(
    log: Path = typer.Argument(..., help="Accelerometer log: static positions separated by moves."),
    positions: Optional[Path] = typer.Option(None, "--positions", help="Positions TOML ([[position]] up, start/end, holdout); "
                                             "without it the orientations are unknown and |a| = g is fitted."),
    columns: str = typer.Option("time,acc_x,acc_y,acc_z", help="Columns: time,x,y,z (x,y,z with --rate-hz)."),
    rate_hz: Optional[float] = typer.Option(None, help="Sample rate for a log without a time column."),
    units: str = typer.Option("m/s^2", help="Unit of the readings (an acceleration, or 'counts')."),
    gravity: Optional[str] = typer.Option(None, help="Local gravity (default 9.80665 m/s^2, or the positions file's)."),
    window: str = typer.Option("1 s", help="Variance window of the static detector."),
    factor: float = typer.Option(6.0, help="Static threshold: this many times the quiet variance."),
    init_static: Optional[str] = typer.Option(None, help="Initial static period for the threshold (imu_tk), e.g. '50 s'."),
    min_static: str = typer.Option("1 s", help="Shortest static interval."),
    json_out: Optional[Path] = typer.Option(None, "--json", help="Write the versioned JSON result here."),
) -> None:
    """Accelerometer multi-position calibration (known orientations, or |a| = g over many attitudes)."""
    import numpy as np

    import align.io as fileio
    from align.calibration.accel import accel_session
    from align.io import check_log
    from align.alignment.segment import static_intervals
    from align.present.text import calibration_summary
    from align.units import parse_unit
    from align.units import parse_quantity as q

    time_col, cols = _columns(columns, rate_hz)
    counts = parse_unit(units).dim == parse_unit("counts").dim
    t, a = fileio.read_log(log, cols, units, time_col, rate_hz, expect="counts" if counts else "acceleration")
    check_log(t, a, str(log))
    fs = 1.0 / float(np.median(np.diff(t)))
    spec = fileio.read_toml(positions) if positions is not None else {}
    g = q(gravity or spec.get("gravity", "9.80665 m/s^2"), "acceleration", "--gravity" if gravity else f"{positions}: gravity")
    intervals = static_intervals(a, fs, q(window, "time", "--window"), factor,
                                 q(init_static, "time", "--init-static") if init_static else None, q(min_static, "time", "--min-static"))
    cal = accel_session(t, a, intervals, spec.get("position"), g, units, str(log), str(positions))
    typer.echo(calibration_summary({"accelerometer": cal}))
    if json_out is not None:
        fileio.write_json(json_out, _calibration_file({"accelerometer": cal}, {"log": str(log),
                                                                              "positions": None if positions is None else str(positions)}))


@calibrate_app.command("mag")
def calibrate_mag(
    log: Path = typer.Argument(..., help="Magnetometer capture while tumbling the device (CSV or blank-separated text)."),
    columns: str = typer.Option("mag_x,mag_y,mag_z", help="Magnetometer columns (col0,col1,... for a file without header)."),
    mag_units: str = typer.Option("uT", help="Unit: uT, nT, gauss, mG, 'counts', or the size of one count, e.g. '0.92 mG'."),
    field: Optional[str] = typer.Option(None, help="Known field strength to refine to, e.g. '48.5 uT'."),
    model: str = typer.Option("symmetric", help="sphere | diagonal | symmetric soft iron."),
    accel_columns: Optional[str] = typer.Option(None, help="Simultaneous accelerometer columns (dip angle, alignment to gravity)."),
    dip: Optional[str] = typer.Option(None, help="Magnetic dip for the heading-error prediction when no accelerometer."),
    json_out: Optional[Path] = typer.Option(None, "--json", help="Write the versioned JSON result here."),
) -> None:
    """Magnetometer hard and soft iron (ellipsoid fit with coverage gates)."""
    import numpy as np

    import align.io as fileio
    from align.errors import InputError
    from align.calibration.magnetometer import alignment_to_gravity, calibrate_magnetometer
    from align.present.text import magnetometer_summary
    from align.units import parse_quantity, parse_unit

    names = [c.strip() for c in columns.split(",")]
    if mag_units[:1].isdigit() or mag_units[:1] == ".":
        factor, shown = parse_quantity(mag_units, "magnetic_field", "--mag-units"), "uT"
    else:
        unit = parse_unit(mag_units, where="--mag-units")
        if unit.dim not in (parse_unit("T").dim, parse_unit("counts").dim):
            raise InputError(f"'{mag_units}' is not a magnetic field unit or 'counts'", "--mag-units")
        factor, shown = unit.factor, mag_units
    wanted = names + ([c.strip() for c in accel_columns.split(",")] if accel_columns else [])
    _, data = fileio.read_columns(log, wanted)
    m = data[:, :3] * factor
    acc = data[:, 3:6] if accel_columns else None
    f = None
    if field is not None:
        f = parse_quantity(field, "magnetic_field", "--field") if shown != "counts" else parse_quantity(field, "counts", "--field")
    d = parse_quantity(dip, "angle", "--dip") if dip else None
    cal = calibrate_magnetometer(m, shown, f, model, acc, d)
    if acc is not None:
        rot, dip_fit, scatter = alignment_to_gravity(cal.correct(m), acc)
        cal = type(cal)(**{**cal.__dict__, "misalignment": rot,
                           "notes": cal.notes + (f"rotation to the accelerometer frame from gravity: dip {np.degrees(dip_fit):.2f} deg, "
                                                 f"scatter {np.degrees(scatter):.2f} deg after alignment",)})
    typer.echo(magnetometer_summary(cal))
    if json_out is not None:
        out = cal.to_dict()
        out["inputs"] = {"log": str(log), "columns": columns, "mag_units": mag_units}
        fileio.write_json(json_out, out)


class _progress:
    """A progress bar on a terminal's stderr; silent when stderr is not a terminal."""

    def __init__(self, total: int, label: str) -> None:
        self.total, self.label = total, label
        self.live = sys.stderr.isatty()

    def __enter__(self):
        def tick(done: int) -> None:
            if self.live:
                width = 30
                filled = int(width * done / self.total)
                sys.stderr.write(f"\r{self.label} [{'#' * filled}{'.' * (width - filled)}] {done:,}/{self.total:,}")
                sys.stderr.flush()

        return tick

    def __exit__(self, *exc) -> None:
        if self.live:
            sys.stderr.write("\r" + " " * 70 + "\r")
            sys.stderr.flush()


def main() -> None:
    """Entry point: run the app, turning user-facing errors into one line and an exit code."""
    from align.errors import AlignError

    try:
        code = app(standalone_mode=False)  # a typer.Exit(code) comes back as the return value here
    except AlignError as exc:
        typer.echo(f"imu-align: error: {exc}", err=True)
        sys.exit(exc.exit_code)
    except Exception as exc:  # click's usage errors and unexpected failures
        import click

        if isinstance(exc, click.exceptions.ClickException):
            exc.show()
            sys.exit(exc.exit_code)
        if isinstance(exc, click.exceptions.Abort):
            sys.exit(130)
        if os.environ.get("IMU_ALIGN_DEBUG"):
            raise
        typer.echo(f"imu-align: internal error: {type(exc).__name__}: {exc} (set IMU_ALIGN_DEBUG=1 for details)", err=True)
        sys.exit(1)
    if isinstance(code, int) and code:
        sys.exit(code)

