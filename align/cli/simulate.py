"""The ``simulate`` commands: ``simulate session`` (a rate-table session with known truth, to rehearse an
alignment), ``simulate poses`` (a multi-position session without a rate table, to rehearse ``calibrate gyro``)
and ``simulate lot`` (a lot of units for ``imu-align batch``).

Today's spelling stays: ``simulate DIR`` is ``simulate session DIR``, ``simulate DIR --kind poses`` is
``simulate poses DIR`` and ``simulate DIR --lot N`` is ``simulate lot DIR --lot N``
(:func:`old_spelling` rewrites the words before they are parsed). A session or poses run refuses to replace
files its folder already holds unless ``--force`` is given.

Besides the textbook session it makes the sessions real benches produce: an IMU mounted turned in the
system (``--mounting``), the table's spin axis horizontal (``--table-axis``), Earth's rate
(``--latitude``), the fixture's re-orientation moves left in the log (``--reorient``), a log that starts
moving at once (``--head "0 s"``), bias flicker (``--flicker``) and a time column in ms, us or ns
(``--time-units``).

Public names
------------
app, session, poses, lot, old_spelling, refuse_replacing, parse_mounting_option, MountingOption, COMMANDS, SUBCOMMANDS
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from align.cli import options as opt
from align.cli.alignment import GYRO_COLUMNS
from align.cli.bias import simulate_turn_ons, simulate_warmup
from align.cli.calibrate_positions import simulate_positions
from align.cli.mounting import MountingOption, parse_mounting_option  # noqa: F401  (re-exported)
from align.cli.options import DIP, DURATION, NONNEGATIVE, NONZERO, PAUSE, POSITIVE, value
from align.cli.paths import check_outputs, outputs

#: the written time column's unit -> units in one second
TIME_UNITS = {"s": 1.0, "ms": 1e3, "us": 1e6, "ns": 1e9}
#: ``--turn-axes`` of a poses session (:data:`align.calibration.posesim.TURN_AXES`, not imported: the CLI starts light)
TURN_AXES = ("any", "x", "y", "z", "xy", "xz", "yz", "xyz")
#: table-axis directions (``[test] table_axis``)
TABLE_AXES = ("up", "down", "north", "south", "east", "west")

def _choice(text: str, values: tuple[str, ...], what: str) -> str:
    t = str(text).strip().lower()
    if t not in values:
        raise ValueError(f"give {what}: one of {', '.join(values)}")
    return t


#: ``--mounting``: the IMU's nominal mounting in the system
Mounting = Annotated[MountingOption | None, typer.Option(
    "--mounting", parser=parse_mounting_option, metavar="MOUNTING",
    help="Nominal mounting of the IMU: the system axis of gyros x, y, z ('+y,-x,+z'), or a rotation "
         "('30 deg about +z', '30 deg about 1,1,0'). Default: the plan's, else none.")]
#: ``--table-axis``: the default plan's table spin axis
TableAxis = Annotated[str | None, typer.Option(
    "--table-axis", metavar="|".join(TABLE_AXES),
    parser=lambda text: _choice(text, TABLE_AXES, "a direction"),
    help="Direction of the table's spin axis for the default plan (default up).")]




def refuse_replacing(field: str, folder: Path, names: tuple[str, ...], force: bool) -> None:
    """Refuse, before any work, to replace files ``folder`` already holds (unless ``force``): one line naming them
    and ``{force}`` (exit 2)."""
    if force:
        return
    from align.errors import InputError

    held = [name for name in names if (Path(folder) / name).exists()]
    if held:
        raise InputError(f"{folder} already holds {', '.join(held)}; give {{force}} to replace "
                         f"{'it' if len(held) == 1 else 'them'}, or another folder", "{" + field + "}")


OutDir = opt.Arg("Folder for the files (created if missing).", "OUT_DIR")
Force = Annotated[bool, typer.Option("--force", help="Replace the files the folder already holds.")]
RateHz = opt.RateHz("Sample rate.")
Head = opt.OptQuantity("--head", "time", "Static time before the first step (default: --gap; '0 s': the log starts "
                       "moving).", "TIME", PAUSE, "'0 s'")
Noise = opt.Quantity("--noise", "angle_random_walk", "Angle random walk (white rate noise).", "ARW", NONNEGATIVE,
                     "'0.3 deg/sqrt(h)'")
Misalignment = opt.Quantity("--misalignment", "angle", "Size of the random mounting rotation.", "ANGLE", NONNEGATIVE,
                            "'0.5 deg'")
GyroUnitsOut = opt.GyroUnits("Unit of the written gyro columns.")
TimeUnitsOut = opt.Choice("--time-units", tuple(TIME_UNITS), "Unit of the written time column (named time).")
Rate = opt.Quantity("--rate", "angular_rate", "Table rate of the default rate plan.", "RATE", POSITIVE, "'100 deg/s'")
Dwell = opt.Quantity("--dwell", "time", "Constant-rate part of each rate step.", "TIME", DURATION, "'10 s'")
Gap = opt.Quantity("--gap", "time", "Static gap between steps.", "TIME", PAUSE, "'3 s'")


def _Session(flag: str):
    """A rate-table session's option, hidden on ``simulate poses``: refused there in words, not as unknown."""
    return Annotated[str | None, typer.Option(flag, hidden=True)]


def session(
    out_dir: opt.Arg("Folder for session.csv, plan.toml and truth.json (created if missing).", "OUT_DIR"),
    plan: opt.OptInput("--plan", "Plan to run ([[step]] tables); default the six-dwell +/- rate plan.", "PLAN.toml") = None,
    kind: opt.Choice("--kind", ("rate", "angle"), "The default plan's kind (for a multi-position session without a "
                     "rate table: imu-align simulate poses).") = "rate",
    rate: Rate = "100 deg/s",
    angle: opt.Quantity("--angle", "angle", "Turn of the default angle plan.", "ANGLE", NONZERO, "'360 deg'") = "360 deg",
    table_axis: TableAxis = None,
    latitude: opt.OptQuantity("--latitude", "angle", "Test-site latitude: adds Earth's rate (and goes in the default "
                              "plan).", "ANGLE", DIP, "'45 deg'") = None,
    mounting: Mounting = None,
    declare_mounting: opt.Flag("--declare-mounting/--no-declare-mounting",
                               "Write a signed-permutation mounting in plan.toml too (an arbitrary rotation always "
                               "is).") = False,
    reorient: opt.Flag("--reorient/--no-reorient", "Leave the fixture's re-orientation moves between steps in the "
                       "log.") = False,
    move_rate: opt.Quantity("--move-rate", "angular_rate", "Rate of the re-orientation moves.", "RATE", POSITIVE,
                            "'20 deg/s'") = "20 deg/s",
    rate_hz: RateHz = "200 Hz",
    dwell: Dwell = "10 s",
    gap: Gap = "3 s",
    head: Head = None,
    noise: Noise = "0.3 deg/sqrt(h)",
    bias_walk: opt.Quantity("--bias-walk", "rate_random_walk", "Rate random walk of the bias.", "RRW", NONNEGATIVE,
                            "'3 deg/h/sqrt(h)'") = "0 deg/h/sqrt(h)",
    flicker: opt.Quantity("--flicker", "angular_rate", "Bias instability coefficient B of each gyro (flicker; Allan "
                          "floor 0.664 B).", "RATE", NONNEGATIVE, "'0.005 deg/s'") = "0 deg/s",
    misalignment: Misalignment = "0.5 deg",
    rates: Annotated[str | None, typer.Option("--rates", metavar="RATES", help=(
        "Several table rates for the default plan: a cyclic +/- sequence about each axis (scale factor across the "
        "range), e.g. '10,30,100,300 deg/s'."))] = None,
    asymmetry: opt.Quantity("--asymmetry", "dimensionless", "Scale-factor asymmetry (K+ - K-)/K of each gyro.", "RATIO",
                            opt.ANY, "'500 ppm'") = "0 ppm",
    quadratic: opt.Quantity("--quadratic", "dimensionless", "Quadratic scale-factor term, of full-scale output at full "
                            "scale.", "RATIO", opt.ANY, "'200 ppm'") = "0 ppm",
    nonlinearity: opt.Quantity("--nonlinearity", "dimensionless", "Cubic scale-factor term, of full-scale output at "
                               "full scale.", "RATIO", opt.ANY, "'300 ppm'") = "0 ppm",
    seed: opt.Seed = 0,
    gyro_units: GyroUnitsOut = "deg/s",
    time_units: TimeUnitsOut = "s",
    force: Force = False,
) -> None:
    """Simulate a rate-table session with known M (session.csv, plan.toml, truth.json), for rehearsals."""
    names = ("session.csv", "plan.toml", "truth.json")
    check_outputs([plan], folder=("out_dir", out_dir, names))
    refuse_replacing("out_dir", out_dir, names, force)
    import dataclasses

    import numpy as np

    import align.io as fileio
    from align.alignment.geometry import is_signed_permutation
    from align.alignment.plan import Plan
    from align.alignment.simulate import SessionSpec, SimulationTruth, random_model, simulate_run
    from align.errors import InputError
    from align.units import parse_unit, to_unit

    parse_unit(gyro_units, "angular_rate", "{gyro_units}")
    if plan is not None:
        if table_axis is not None or rates is not None:
            raise InputError("goes with the default plan; the plan file states its steps and table_axis",
                             "{table_axis}" if table_axis is not None else "{rates}")
        the_plan = Plan.from_dict(fileio.read_toml(plan), str(plan))
    elif rates is not None:
        from align.alignment.linearity import linearity_plan
        from align.cli.parsers import rate_list

        if table_axis is not None:
            raise InputError("the plan across the range turns about each axis pointed up; leave {table_axis} out",
                             "{rates}")
        the_plan = linearity_plan(rate_list(rates), latitude=latitude)
    else:
        the_plan = _default_plan(value(kind), rate, angle, table_axis or "up", latitude)
    declared = the_plan.nominal
    nominal = declared if mounting is None else np.array(mounting.rows, float)
    if declared is not None and mounting is not None and np.abs(declared - nominal).max() > 1e-9:
        raise InputError(f"differs from the plan's [mounting]; give one, or the same ({mounting.text})", "{mounting}")
    if nominal is not None:
        written = declared is not None or declare_mounting or not is_signed_permutation(nominal, 1e-9)
        the_plan = dataclasses.replace(the_plan, mounting=tuple((float(r[0]), float(r[1]), float(r[2])) for r in nominal)
                                       if written else None)
    rng = np.random.default_rng(seed)
    truth = random_model(rng, misalignment, mounting=nominal)
    from align.alignment.linearity import ScaleErrors, expected_linearity

    full_scale = max((abs(s.rate) for s in the_plan.steps if s.rate is not None), default=0.0)
    errors = (ScaleErrors.from_full_scale(full_scale, asymmetry, quadratic, nonlinearity)
              if full_scale and (asymmetry or quadratic or nonlinearity) else None)
    spec = SessionSpec(fs=rate_hz, dwell_s=dwell, static_s=gap, noise_density=noise, bias_walk=bias_walk,
                       latitude=latitude if plan is not None else None, head_s=head, reorient=reorient,
                       move_rate=move_rate, flicker=flicker, scale_errors=errors)
    run = simulate_run(the_plan, truth, spec, rng)
    inputs: dict = {"time_units": value(time_units)}
    if errors is not None and (lin := expected_linearity(the_plan, truth.M, errors, nominal)) is not None:
        inputs["linearity"] = lin.to_dict(parse_unit(gyro_units).factor)  # truth.json: the rehearsal's figures
    unit = value(time_units)
    with outputs() as out:  # all or none (a folder it creates is removed again on a failure)
        out.folder(out_dir)
        out.write_csv(out_dir / names[0], GYRO_COLUMNS.split(","),
                      np.column_stack([np.arange(len(run.t)) * (TIME_UNITS[unit] / run.fs), to_unit(run.g, gyro_units)]))
        out.write_text(out_dir / names[1], the_plan.to_toml())
        out.write_json(out_dir / names[2], SimulationTruth(truth, gyro_units, seed, inputs, nominal,
                                                           run.moves, run.bias.mean(axis=0)))
    moves = f", {len(run.moves)} re-orientation moves" if run.moves else ""
    typer.echo(f"wrote {out_dir}/session.csv ({len(run.t)} rows, {run.t[-1]:.1f} s{moves}), plan.toml and truth.json")


def poses(
    out_dir: opt.Arg("Folder for session.csv and truth.json (created if missing).", "OUT_DIR"),
    rate_hz: RateHz = "200 Hz",
    head: opt.OptQuantity("--head", "time", "Static time before the first rotation (default 30 s).", "TIME", PAUSE,
                          "'30 s'") = None,
    noise: Noise = "0.3 deg/sqrt(h)",
    accel_noise: opt.Quantity("--accel-noise", "velocity_random_walk", "Accelerometer white noise.",
                              "VRW", NONNEGATIVE, "'0.002 m/s^2/sqrt(Hz)'") = "0.002 m/s^2/sqrt(Hz)",
    misalignment: Misalignment = "0.5 deg",
    seed: opt.Seed = 0,
    gyro_units: GyroUnitsOut = "deg/s",
    time_units: TimeUnitsOut = "s",
    poses: opt.Whole("--poses", "Static poses, the initial one included.", 2, 10000, "20") = 20,
    pose_time: opt.Quantity("--pose-time", "time", "Length of each pose after the first.", "TIME",
                            DURATION, "'4 s'") = "4 s",
    turn_time: opt.Quantity("--turn-time", "time", "Length of each rotation.", "TIME", DURATION,
                            "'2.5 s'") = "2.5 s",
    turn_axes: opt.Choice("--turn-axes", TURN_AXES, "'any' (each rotation about two random axes at once), or the "
                          "body axes to turn about in turn ('xy' never turns about z: a weakly determined "
                          "column).") = "any",
    wobble: opt.Number("--wobble", "With --turn-axes other than any: tilt of each rotation axis (a hand's "
                       "imprecision, radians; 0: exact axes).", NONNEGATIVE, "0.03", "SIZE") = 0.03,
    force: Force = False,
    plan: _Session("--plan") = None,
    mounting: _Session("--mounting") = None,
    latitude: _Session("--latitude") = None,
    table_axis: _Session("--table-axis") = None,
    flicker: _Session("--flicker") = None,
    bias_walk: _Session("--bias-walk") = None,
    reorient: Annotated[bool, typer.Option("--reorient", hidden=True)] = False,
) -> None:
    """Simulate a multi-position session without a rate table (static poses reached by free rotations;
    accelerometer and gyro; for calibrate gyro): session.csv and truth.json."""
    from align.errors import InputError

    given = {"--plan": plan, "--mounting": mounting, "--latitude": latitude, "--table-axis": table_axis,
             "--reorient": reorient or None, "--flicker": flicker, "--bias-walk": bias_walk}
    for flag, on in given.items():
        if on is not None:  # today's `simulate DIR --kind poses --latitude ...`: said as before, not as unknown
            raise InputError(f"{flag} belongs to a rate-table session (imu-align simulate session), not to a poses "
                             "session; leave it out")
    names = ("session.csv", "truth.json")
    check_outputs([], folder=("out_dir", out_dir, names))
    refuse_replacing("out_dir", out_dir, names, force)
    import numpy as np

    from align.calibration import Calibration, CalibrationSet
    from align.calibration.posesim import PoseSessionSpec, accel_frame_truth, random_sensors, simulate_poses
    from align.units import parse_unit, to_unit

    parse_unit(gyro_units, "angular_rate", "{gyro_units}")
    rng = np.random.default_rng(seed)
    m_a, b_a, m_g, b_g = random_sensors(rng, misalignment)
    spec = PoseSessionSpec(fs=rate_hz, poses=poses, init_s=30.0 if head is None else head, pose_s=pose_time,
                           turn_s=turn_time, axes=value(turn_axes), wobble=wobble, gyro_noise=noise,
                           accel_noise=accel_noise)
    run = simulate_poses(spec, m_a, b_a, m_g, b_g, rng)
    t_acc, g_acc, q = accel_frame_truth(m_a, m_g)
    zero = np.zeros((3, 3))
    method = "simulation truth (accelerometer frame: x along the accelerometer's x axis, y in its x-y plane)"
    unit = value(time_units)
    truth = CalibrationSet(
        {"accelerometer": Calibration("accelerometer", t_acc, b_a, zero, np.zeros(3), "m/s^2", method),
         "gyroscope": Calibration("gyroscope", g_acc, b_g, zero, np.zeros(3), gyro_units, method)},
        {"seed": seed, "kind": "poses", "rate_hz": rate_hz, "turn_axes": value(turn_axes),
         "poses": [list(p) for p in run.poses],
         "body_frame": {"accelerometer_M": m_a.tolist(), "gyroscope_M": m_g.tolist(), "Q": q.tolist(),
                        "note": "M_accel_frame = M_body Q^T (gyro), M_a = T Q (RQ decomposition)"},
         "time_units": unit})
    with outputs() as out:
        out.folder(out_dir)
        out.write_csv(out_dir / names[0], ["time", "acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z"],
                      np.column_stack([run.t * TIME_UNITS[unit], run.acc, to_unit(run.gyr, gyro_units)]))
        out.write_json(out_dir / names[1], truth)
    typer.echo(f"wrote {out_dir}/session.csv ({len(run.t)} rows, {run.t[-1]:.1f} s, {poses} poses) and truth.json")


def lot(
    out_dir: opt.Arg("Folder for manifest.csv, plan.toml, sessions/SERIAL.csv and truth.csv (created if missing; "
                     "it must not hold them yet).", "OUT_DIR"),
    lot: Annotated[int, typer.Option("--lot", parser=opt.whole(1, 1_000_000, "200"), metavar="N", help=(
        "Units in the lot, each unit's parameters drawn around the nominal part (--spread, --scale-spread, "
        "--bias-spread), --bad of them deliberately bad."))] = 200,
    spread: opt.Quantity("--spread", "angle", "1-sigma of each component of a unit's mounting rotation.",
                         "ANGLE", NONNEGATIVE, "'0.03 deg'") = "0.03 deg",
    scale_spread: opt.Quantity("--scale-spread", "dimensionless", "1-sigma of each scale factor about 1.",
                               "RATIO", NONNEGATIVE, "'0.1 %'") = "0.1 %",
    bias_spread: opt.Quantity("--bias-spread", "angular_rate", "1-sigma of each turn-on bias.", "RATE",
                              NONNEGATIVE, "'0.2 deg/s'") = "0.2 deg/s",
    bad: opt.Whole("--bad", "Units made deliberately bad, in turn out of spec (mounted 0.3 deg off), wrong "
                   "direction (a step turned the other way), NaN rows.", 0, 1_000_000, "5") = 5,
    seed: opt.Seed = 0,
    rate: Rate = "100 deg/s",
    dwell: Dwell = "10 s",
    gap: Gap = "3 s",
    rate_hz: RateHz = "200 Hz",
    noise: Noise = "0.3 deg/sqrt(h)",
) -> None:
    """Simulate a lot of units for imu-align batch (six-dwell rate sessions, a manifest and the truth)."""
    from align.cli.batch import simulate_lot_command

    return simulate_lot_command(out_dir, lot, spread, scale_spread, bias_spread, bad, seed, rate, dwell, gap,
                                rate_hz, noise)


def thermal(
    out_dir: opt.Arg("Folder for thermal.csv and truth.json (created if missing).", "OUT_DIR"),
    rate_hz: opt.RateHz("Sample rate.") = "20 Hz",
    low: opt.Number("--low", "Lowest chamber temperature, C.", opt.ANY, "-10", "DEGC") = -10.0,
    high: opt.Number("--high", "Highest chamber temperature, C.", opt.ANY, "60", "DEGC") = 60.0,
    ramp: opt.Number("--ramp", "Heating rate, C/min.", POSITIVE, "4", "C_PER_MIN") = 4.0,
    ramp_down: opt.Number("--ramp-down", "Cooling rate, C/min.", POSITIVE, "6", "C_PER_MIN") = 6.0,
    soak: opt.Quantity("--soak", "time", "Soak at each end.", "TIME", PAUSE, "'60 s'") = "60 s",
    cycles: opt.Number("--cycles", "Up and down cycles (1.5: up, down, up).", POSITIVE, "1.5", "N") = 1.5,
    resolution: opt.Number("--resolution", "Step of the temperature reading, C (0: continuous).", NONNEGATIVE,
                           "1", "DEGC") = 0.0,
    seed: opt.Seed = 0,
    force: Force = False,
) -> None:
    """Simulate a static IMU in a thermal chamber with known bias cubic, lag and hysteresis (for calibrate thermal):
    thermal.csv (time, gyro deg/s, accel m/s^2, temperature C) and truth.json."""
    names = ("thermal.csv", "truth.json")
    check_outputs([], folder=("out_dir", out_dir, names))
    refuse_replacing("out_dir", out_dir, names, force)
    from align.calibration.thermal.simulate import Profile, chamber_log
    from align.errors import InputError

    if not high > low:
        raise InputError("give a highest temperature above the lowest", "{high}")
    columns, table, truth = chamber_log(Profile(low, high, ramp / 60, ramp_down / 60, soak, cycles), rate_hz, seed,
                                        resolution)
    with outputs() as out:
        out.folder(out_dir)
        out.write_csv(out_dir / names[0], columns, table)
        out.write_json(out_dir / names[1], truth)
    typer.echo(f"wrote {out_dir}/thermal.csv ({len(table)} rows, {table[-1, 0]:.0f} s) and truth.json")


#: ``simulate``'s subcommands
COMMANDS = {"session": session, "poses": poses, "lot": lot, "thermal": thermal, "positions": simulate_positions,
            "warmup": simulate_warmup, "turn-ons": simulate_turn_ons}
SUBCOMMANDS = tuple(COMMANDS)

app = typer.Typer(help="Simulated inputs with known truth, for rehearsals: a rate-table session, a multi-position "
                       "session, a lot of units.", no_args_is_help=True)
for _name, _command in COMMANDS.items():
    app.command(_name)(_command)  # type: ignore[type-var]  # typer's TypeVar is bound to its own callable alias

#: options of simulate that take no value (the others take one: the next word, or after '=')
_SWITCHES = frozenset({"--reorient", "--no-reorient", "--declare-mounting", "--no-declare-mounting", "--force",
                       "--help"})


def old_spelling(args: list[str]) -> list[str]:
    """``args`` with today's spelling of ``simulate`` put in words of its subcommands: ``simulate DIR ...`` ->
    ``simulate session DIR ...``; ``simulate DIR --kind poses ...`` -> ``simulate poses DIR ...``;
    ``simulate DIR --lot N ...`` -> ``simulate lot DIR --lot N ...``. Other commands' words are returned as given.

    A first word that names a subcommand is one (``simulate lot DIR``; ``simulate lot`` alone misses its folder),
    unless no folder follows it and the old spelling's ``--lot``/``--kind`` does (``simulate lot --lot 200``: a
    folder named ``lot``).
    """
    first = next((i for i, a in enumerate(args) if not a.startswith("-")), None)
    if first is None or args[first] != "simulate":
        return args
    rest = args[first + 1:]
    if "--help" in rest[:1] or not rest:
        return args
    positional: list[int] = []
    i = 0
    while i < len(rest):
        word = rest[i]
        if word == "--":
            positional += list(range(i + 1, len(rest)))
            break
        if word.startswith("-") and len(word) > 1:
            i += 1 if ("=" in word or word in _SWITCHES) else 2
            continue
        positional.append(i)
        i += 1
    old_words = any(w.split("=")[0] in ("--lot", "--kind") for w in rest)
    if positional and rest[positional[0]] in SUBCOMMANDS and (len(positional) > 1 or "--help" in rest or not old_words):
        return args  # a subcommand (without its folder: the usage error says so)
    if not positional:
        return args
    words = list(rest)
    sub = "session"
    if any(w == "--lot" or w.startswith("--lot=") for w in words):
        sub = "lot"
    else:
        for k, w in enumerate(words):
            if w in ("--kind=poses",):
                sub, words = "poses", words[:k] + words[k + 1:]
                break
            if w == "--kind" and k + 1 < len(words) and words[k + 1] == "poses":
                sub, words = "poses", words[:k] + words[k + 2:]
                break
    return args[:first + 1] + [sub] + words


def _default_plan(kind: str, rate: float, angle: float, table_axis: str, latitude: float | None):
    """The six-step +/- plan about x, y, z on a table spinning about ``table_axis``."""
    from align.alignment.plan import Plan, Step, check_turn

    size = check_turn(rate if kind == "rate" else angle, kind, "{" + kind + "}")
    steps = tuple(Step(a, 1, rate=s if kind == "rate" else None, angle=s if kind != "rate" else None,
                       table_axis=table_axis) for a in range(3) for s in (size, -size))
    return Plan(steps, latitude, table_axis=table_axis)

