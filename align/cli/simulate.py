"""The ``simulate`` command: rate-table sessions with known truth, to rehearse an alignment; and (``--kind poses``)
multi-position sessions without a rate table, to rehearse ``calibrate gyro``.

Besides the textbook session it makes the sessions real benches produce: an IMU mounted turned in the
system (``--mounting``), the table's spin axis horizontal (``--table-axis``), Earth's rate
(``--latitude``), the fixture's re-orientation moves left in the log (``--reorient``), a log that starts
moving at once (``--head "0 s"``), bias flicker (``--flicker``) and a time column in ms, us or ns
(``--time-units``).

Public names
------------
simulate, parse_mounting_option, MountingOption, COMMANDS
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Annotated

import typer

from align.cli import options as opt
from align.cli.alignment import GYRO_COLUMNS
from align.cli.options import DIP, DURATION, NONNEGATIVE, NONZERO, PAUSE, POSITIVE, value
from align.cli.paths import check_outputs, outputs

#: the written time column's unit -> units in one second
TIME_UNITS = {"s": 1.0, "ms": 1e3, "us": 1e6, "ns": 1e9}
#: ``--turn-axes`` of a poses session (:data:`align.calibration.posesim.TURN_AXES`, not imported: the CLI starts light)
TURN_AXES = ("any", "x", "y", "z", "xy", "xz", "yz", "xyz")
#: table-axis directions (``[test] table_axis``)
TABLE_AXES = ("up", "down", "north", "south", "east", "west")

_MOUNTING_ADVICE = ("give the system axis of gyros x, y, z, e.g. '+y,-x,+z', or a rotation, e.g. '30 deg about +z' "
                    "or '30 deg about 1,1,0'")
_SIGNED_AXIS = re.compile(r"^[+-]?[xyz]$")


@dataclass(frozen=True)
class MountingOption:
    """A parsed ``--mounting``: the nominal mounting ``N`` (rows: each gyro's axis in the system frame).

    Attributes
    ----------
    rows : tuple of 3 tuples of 3 float
    text : str
        As typed.
    """

    rows: tuple[tuple[float, float, float], ...]
    text: str


def _unit_axis(text: str) -> tuple[float, float, float]:
    """``'+z'`` or ``'1,1,0'`` (commas or spaces) -> a unit vector; ValueError otherwise."""
    t = text.strip().lower()
    if _SIGNED_AXIS.match(t):
        v = [0.0, 0.0, 0.0]
        v["xyz".index(t[-1])] = -1.0 if t.startswith("-") else 1.0
        return v[0], v[1], v[2]
    parts = [p for p in re.split(r"[\s,]+", t.strip("()[] ")) if p]
    try:
        v = [float(p) for p in parts]
    except ValueError:
        raise ValueError(_MOUNTING_ADVICE) from None
    norm = math.sqrt(sum(x * x for x in v)) if len(v) == 3 else 0.0
    if not (math.isfinite(norm) and norm > 0):
        raise ValueError(f"the axis must be +x ... -z or three numbers not all 0; {_MOUNTING_ADVICE}")
    return v[0] / norm, v[1] / norm, v[2] / norm


def _rotation_rows(angle: float, axis: tuple[float, float, float]) -> tuple[tuple[float, float, float], ...]:
    """``N = Rot(axis, angle)^T`` (:func:`align.alignment.simulate.mounting_from_rotation`) as rows."""
    from align.alignment.simulate import mounting_from_rotation

    return tuple(tuple(float(v) for v in row) for row in mounting_from_rotation(angle, axis))


def parse_mounting_option(text: str) -> MountingOption:
    """``'+y,-x,+z'`` (the system axis of gyros x, y, z) or ``'<angle> about <axis>'`` (``'30 deg about +z'``,
    ``'30 deg about 1,1,0'``: the IMU turned by the angle about the axis) -> :class:`MountingOption`."""
    if isinstance(text, MountingOption):
        return text
    raw = str(text).strip()
    head, about, tail = raw.partition(" about ")
    if about:
        from align.errors import AlignError
        from align.units import parse_quantity

        try:
            angle = parse_quantity(head, "angle")
        except AlignError:
            raise ValueError(f"'{head.strip()}' is not an angle; {_MOUNTING_ADVICE}") from None
        if not math.isfinite(angle):
            raise ValueError(_MOUNTING_ADVICE)
        return MountingOption(_rotation_rows(angle, _unit_axis(tail)), raw)
    parts = [p for p in re.split(r"[\s,]+", raw.strip("()[] ")) if p]
    if len(parts) != 3 or not all(_SIGNED_AXIS.match(p.lower()) for p in parts):
        raise ValueError(_MOUNTING_ADVICE)
    rows = tuple(_unit_axis(p) for p in parts)
    if sorted(p.lower().lstrip("+-") for p in parts) != ["x", "y", "z"]:
        raise ValueError(f"'{raw}': two gyros along one system axis; each gyro needs its own axis")
    det = (rows[0][0] * (rows[1][1] * rows[2][2] - rows[1][2] * rows[2][1])
           - rows[0][1] * (rows[1][0] * rows[2][2] - rows[1][2] * rows[2][0])
           + rows[0][2] * (rows[1][0] * rows[2][1] - rows[1][1] * rows[2][0]))
    if det < 0:
        raise ValueError(f"'{raw}' is a mirrored (left-handed) set: a mounting turns the gyros, it cannot mirror "
                         "them; check the signs")
    return MountingOption(rows, raw)


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


def _choice(text: str, values: tuple[str, ...], what: str) -> str:
    t = str(text).strip().lower()
    if t not in values:
        raise ValueError(f"give {what}: one of {', '.join(values)}")
    return t


def simulate(
    out_dir: opt.Arg("Folder for session.csv, plan.toml and truth.json (created if missing).", "OUT_DIR"),
    plan: opt.OptInput("--plan", "Plan to run ([[step]] tables); default the six-dwell +/- rate plan.", "PLAN.toml") = None,
    kind: opt.Choice("--kind", ("rate", "angle", "poses"), "The default plan's kind, or 'poses': a multi-position "
                     "session without a rate table (static poses reached by free rotations; accelerometer and gyro; "
                     "for calibrate gyro).") = "rate",
    rate: opt.Quantity("--rate", "angular_rate", "Table rate of the default rate plan.", "RATE", POSITIVE,
                       "'100 deg/s'") = "100 deg/s",
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
    rate_hz: opt.RateHz("Sample rate.") = "200 Hz",
    dwell: opt.Quantity("--dwell", "time", "Constant-rate part of each rate step.", "TIME", DURATION, "'10 s'") = "10 s",
    gap: opt.Quantity("--gap", "time", "Static gap between steps.", "TIME", PAUSE, "'3 s'") = "3 s",
    head: opt.OptQuantity("--head", "time", "Static time before the first step (default: --gap; '0 s': the log starts "
                          "moving).", "TIME", PAUSE, "'0 s'") = None,
    noise: opt.Quantity("--noise", "angle_random_walk", "Angle random walk (white rate noise).", "ARW", NONNEGATIVE,
                        "'0.3 deg/sqrt(h)'") = "0.3 deg/sqrt(h)",
    bias_walk: opt.Quantity("--bias-walk", "rate_random_walk", "Rate random walk of the bias.", "RRW", NONNEGATIVE,
                            "'3 deg/h/sqrt(h)'") = "0 deg/h/sqrt(h)",
    flicker: opt.Quantity("--flicker", "angular_rate", "Bias instability coefficient B of each gyro (flicker; Allan "
                          "floor 0.664 B).", "RATE", NONNEGATIVE, "'0.005 deg/s'") = "0 deg/s",
    misalignment: opt.Quantity("--misalignment", "angle", "Size of the random mounting rotation.", "ANGLE", NONNEGATIVE,
                               "'0.5 deg'") = "0.5 deg",
    seed: opt.Seed = 0,
    gyro_units: opt.GyroUnits("Unit of the written gyro columns.") = "deg/s",
    time_units: opt.Choice("--time-units", tuple(TIME_UNITS), "Unit of the written time column (named time).") = "s",
    poses: opt.Whole("--poses", "With --kind poses: static poses, the initial one included.", 2, 10000, "20") = 20,
    pose_time: opt.Quantity("--pose-time", "time", "With --kind poses: length of each pose after the first.", "TIME",
                            DURATION, "'4 s'") = "4 s",
    turn_time: opt.Quantity("--turn-time", "time", "With --kind poses: length of each rotation.", "TIME", DURATION,
                            "'2.5 s'") = "2.5 s",
    turn_axes: opt.Choice("--turn-axes", TURN_AXES, "With --kind poses: 'any' (each rotation about two random axes at "
                          "once), or the body axes to turn about in turn ('xy' never turns about z: a weakly determined "
                          "column).") = "any",
    wobble: opt.Number("--wobble", "With --kind poses and --turn-axes other than any: tilt of each rotation axis (a "
                       "hand's imprecision, radians; 0: exact axes).", NONNEGATIVE, "0.03", "SIZE") = 0.03,
    accel_noise: opt.Quantity("--accel-noise", "velocity_random_walk", "With --kind poses: accelerometer white noise.",
                              "VRW", NONNEGATIVE, "'0.002 m/s^2/sqrt(Hz)'") = "0.002 m/s^2/sqrt(Hz)",
    lot: Annotated[int | None, typer.Option("--lot", parser=opt.whole(1, 1_000_000, "200"), metavar="N", help=(
        "A lot of N units instead of one session, for imu-align batch: OUT_DIR/manifest.csv, plan.toml, "
        "sessions/SERIAL.csv and truth.csv; each unit's parameters drawn around the nominal part "
        "(--spread, --scale-spread, --bias-spread), --bad of them deliberately bad."))] = None,
    spread: opt.Quantity("--spread", "angle", "Lot: 1-sigma of each component of a unit's mounting rotation.",
                         "ANGLE", NONNEGATIVE, "'0.03 deg'") = "0.03 deg",
    scale_spread: opt.Quantity("--scale-spread", "dimensionless", "Lot: 1-sigma of each scale factor about 1.",
                               "RATIO", NONNEGATIVE, "'0.1 %'") = "0.1 %",
    bias_spread: opt.Quantity("--bias-spread", "angular_rate", "Lot: 1-sigma of each turn-on bias.", "RATE",
                              NONNEGATIVE, "'0.2 deg/s'") = "0.2 deg/s",
    bad: opt.Whole("--bad", "Lot: units made deliberately bad, in turn out of spec (mounted 0.3 deg off), wrong "
                   "direction (a step turned the other way), NaN rows.", 0, 1_000_000, "5") = 5,
) -> None:
    """Simulate a rate-table session with known M, (--kind poses) a multi-position session, or (--lot) a lot of
    units for imu-align batch (for rehearsals)."""
    if lot is not None:
        from align.cli.batch import simulate_lot_command
        from align.errors import InputError

        if plan is not None or mounting is not None or latitude is not None or reorient or value(kind) != "rate":
            raise InputError("goes with one session; a lot runs the six-dwell rate plan (--rate, --dwell, --gap, "
                             "--rate-hz, --noise, --seed)", "{lot}")
        return simulate_lot_command(out_dir, lot, spread, scale_spread, bias_spread, bad, seed, rate, dwell, gap,
                                    rate_hz, noise)
    if value(kind) == "poses":
        return _simulate_poses(out_dir, rate_hz, head, noise, accel_noise, misalignment, seed, gyro_units, time_units,
                               poses, pose_time, turn_time, value(turn_axes), wobble,
                               {"--plan": plan is not None, "--mounting": mounting is not None,
                                "--latitude": latitude is not None, "--table-axis": table_axis is not None,
                                "--reorient": reorient, "--flicker": flicker > 0, "--bias-walk": bias_walk > 0})
    names = ("session.csv", "plan.toml", "truth.json")
    check_outputs([plan], folder=("out_dir", out_dir, names))
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
        if table_axis is not None:
            raise InputError("goes with the default plan; the plan file states its table_axis ([test] or [[step]])",
                             "{table_axis}")
        the_plan = Plan.from_dict(fileio.read_toml(plan), str(plan))
    else:
        the_plan = _default_plan(value(kind), rate, angle, table_axis or "up", latitude)
    declared = the_plan.nominal
    nominal = declared if mounting is None else np.array(mounting.rows, float)
    if declared is not None and mounting is not None and np.abs(declared - nominal).max() > 1e-9:
        raise InputError(f"differs from the plan's [mounting]; give one, or the same ({mounting.text})", "{mounting}")
    if nominal is not None:
        written = declared is not None or declare_mounting or not is_signed_permutation(nominal, 1e-9)
        the_plan = dataclasses.replace(the_plan, mounting=tuple(tuple(float(v) for v in row) for row in nominal)
                                       if written else None)
    rng = np.random.default_rng(seed)
    truth = random_model(rng, misalignment, mounting=nominal)
    spec = SessionSpec(fs=rate_hz, dwell_s=dwell, static_s=gap, noise_density=noise, bias_walk=bias_walk,
                       latitude=latitude if plan is not None else None, head_s=head, reorient=reorient,
                       move_rate=move_rate, flicker=flicker)
    run = simulate_run(the_plan, truth, spec, rng)
    unit = value(time_units)
    with outputs() as out:  # all or none (a folder it creates is removed again on a failure)
        out.folder(out_dir)
        out.write_csv(out_dir / names[0], GYRO_COLUMNS.split(","),
                      np.column_stack([np.arange(len(run.t)) * (TIME_UNITS[unit] / run.fs), to_unit(run.g, gyro_units)]))
        out.write_text(out_dir / names[1], the_plan.to_toml())
        out.write_json(out_dir / names[2], SimulationTruth(truth, gyro_units, seed, {"time_units": unit}, nominal,
                                                           run.moves, run.bias.mean(axis=0)))
    moves = f", {len(run.moves)} re-orientation moves" if run.moves else ""
    typer.echo(f"wrote {out_dir}/session.csv ({len(run.t)} rows, {run.t[-1]:.1f} s{moves}), plan.toml and truth.json")


def _simulate_poses(out_dir, rate_hz: float, head: float | None, noise: float, accel_noise: float, misalignment: float,
                    seed: int, gyro_units: str, time_units, poses: int, pose_time: float, turn_time: float,
                    turn_axes: str, wobble: float, given: dict) -> None:
    """``--kind poses``: session.csv (time, acc_x..z in m/s^2, gyr_x..z) and truth.json, a calibration file of the
    true accelerometer and gyro in the accelerometer frame (the frame ``calibrate gyro`` reports), the body-frame
    truth in its inputs."""
    from align.errors import InputError

    for flag, on in given.items():
        if on:
            raise InputError(f"{flag} belongs to a rate-table session, not to --kind poses; leave it out", "{kind}")
    names = ("session.csv", "truth.json")
    check_outputs([], folder=("out_dir", out_dir, names))
    import numpy as np

    from align.calibration import Calibration, CalibrationSet
    from align.calibration.posesim import PoseSessionSpec, accel_frame_truth, random_sensors, simulate_poses
    from align.units import parse_unit, to_unit

    parse_unit(gyro_units, "angular_rate", "{gyro_units}")
    rng = np.random.default_rng(seed)
    m_a, b_a, m_g, b_g = random_sensors(rng, misalignment)
    spec = PoseSessionSpec(fs=rate_hz, poses=poses, init_s=30.0 if head is None else head, pose_s=pose_time,
                           turn_s=turn_time, axes=turn_axes, wobble=wobble, gyro_noise=noise, accel_noise=accel_noise)
    run = simulate_poses(spec, m_a, b_a, m_g, b_g, rng)
    t_acc, g_acc, q = accel_frame_truth(m_a, m_g)
    zero = np.zeros((3, 3))
    method = "simulation truth (accelerometer frame: x along the accelerometer's x axis, y in its x-y plane)"
    truth = CalibrationSet(
        {"accelerometer": Calibration("accelerometer", t_acc, b_a, zero, np.zeros(3), "m/s^2", method),
         "gyroscope": Calibration("gyroscope", g_acc, b_g, zero, np.zeros(3), gyro_units, method)},
        {"seed": seed, "kind": "poses", "rate_hz": rate_hz, "turn_axes": turn_axes, "poses": [list(p) for p in run.poses],
         "body_frame": {"accelerometer_M": m_a.tolist(), "gyroscope_M": m_g.tolist(), "Q": q.tolist(),
                        "note": "M_accel_frame = M_body Q^T (gyro), M_a = T Q (RQ decomposition)"},
         "time_units": value(time_units)})
    unit = value(time_units)
    with outputs() as out:
        out.folder(out_dir)
        out.write_csv(out_dir / names[0], ["time", "acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z"],
                      np.column_stack([run.t * TIME_UNITS[unit], run.acc, to_unit(run.gyr, gyro_units)]))
        out.write_json(out_dir / names[1], truth)
    typer.echo(f"wrote {out_dir}/session.csv ({len(run.t)} rows, {run.t[-1]:.1f} s, {poses} poses) and truth.json")


def _default_plan(kind: str, rate: float, angle: float, table_axis: str, latitude: float | None):
    """The six-step +/- plan about x, y, z on a table spinning about ``table_axis``."""
    from align.alignment.plan import Plan, Step, check_turn

    size = check_turn(rate if kind == "rate" else angle, kind, "{" + kind + "}")
    steps = tuple(Step(a, 1, table_axis=table_axis, **{kind: s}) for a in range(3) for s in (size, -size))
    return Plan(steps, latitude, table_axis=table_axis)


COMMANDS = {"simulate": simulate}
