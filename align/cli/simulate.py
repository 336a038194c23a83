"""The ``simulate`` command: rate-table sessions with known truth, to rehearse an alignment.

Public names
------------
simulate, COMMANDS
"""


import typer

from align.cli import options as opt
from align.cli.alignment import GYRO_COLUMNS
from align.cli.options import DURATION, NONNEGATIVE, NONZERO, PAUSE, POSITIVE, value
from align.cli.paths import check_outputs, outputs


def simulate(
    out_dir: opt.Arg("Folder for session.csv, plan.toml and truth.json (created if missing).", "OUT_DIR"),
    plan: opt.OptInput("--plan", "Plan to run ([[step]] tables); default the six-dwell +/- rate plan.", "PLAN.toml") = None,
    kind: opt.Choice("--kind", ("rate", "angle"), "The default plan's kind.") = "rate",
    rate: opt.Quantity("--rate", "angular_rate", "Table rate of the default rate plan.", "RATE", POSITIVE,
                       "'100 deg/s'") = "100 deg/s",
    angle: opt.Quantity("--angle", "angle", "Turn of the default angle plan.", "ANGLE", NONZERO, "'360 deg'") = "360 deg",
    rate_hz: opt.RateHz("Sample rate.") = "200 Hz",
    dwell: opt.Quantity("--dwell", "time", "Constant-rate part of each rate step.", "TIME", DURATION, "'10 s'") = "10 s",
    gap: opt.Quantity("--gap", "time", "Static gap between steps.", "TIME", PAUSE, "'3 s'") = "3 s",
    noise: opt.Quantity("--noise", "angle_random_walk", "Angle random walk (white rate noise).", "ARW", NONNEGATIVE,
                        "'0.3 deg/sqrt(h)'") = "0.3 deg/sqrt(h)",
    bias_walk: opt.Quantity("--bias-walk", "rate_random_walk", "Rate random walk of the bias.", "RRW", NONNEGATIVE,
                            "'3 deg/h/sqrt(h)'") = "0 deg/h/sqrt(h)",
    misalignment: opt.Quantity("--misalignment", "angle", "Size of the random mounting rotation.", "ANGLE", NONNEGATIVE,
                               "'0.5 deg'") = "0.5 deg",
    seed: opt.Seed = 0,
    gyro_units: opt.GyroUnits("Unit of the written gyro columns.") = "deg/s",
) -> None:
    """Simulate a rate-table session with known M (for rehearsals and examples)."""
    names = ("session.csv", "plan.toml", "truth.json")
    check_outputs([plan], folder=("out_dir", out_dir, names))
    import numpy as np

    import align.io as fileio
    from align.alignment.plan import Plan
    from align.alignment.simulate import SessionSpec, SimulationTruth, random_model, simulate_session
    from align.units import parse_unit, to_unit

    parse_unit(gyro_units, "angular_rate", "{gyro_units}")
    if plan is not None:
        the_plan = Plan.from_dict(fileio.read_toml(plan), str(plan))
    else:
        the_plan = Plan.standard_rate(rate) if value(kind) == "rate" else Plan.standard_angle(angle)
    rng = np.random.default_rng(seed)
    truth = random_model(rng, misalignment)
    spec = SessionSpec(fs=rate_hz, dwell_s=dwell, static_s=gap, noise_density=noise, bias_walk=bias_walk)
    t, g, _ = simulate_session(the_plan, truth, spec, rng)
    with outputs() as out:  # all or none (a folder it creates is removed again on a failure)
        out.folder(out_dir)
        out.write_csv(out_dir / names[0], GYRO_COLUMNS.split(","), np.column_stack([t, to_unit(g, gyro_units)]))
        out.write_text(out_dir / names[1], the_plan.to_toml())
        out.write_json(out_dir / names[2], SimulationTruth(truth, gyro_units, seed))
    typer.echo(f"wrote {out_dir}/session.csv ({len(t)} rows, {t[-1]:.1f} s), plan.toml and truth.json")


COMMANDS = {"simulate": simulate}
