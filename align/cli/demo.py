"""``imu-align demo``: the whole story on bundled inputs (:func:`align.present.story.run_demo`).

Public names
------------
demo, DEMO_FILES, COMMANDS
"""

from pathlib import Path
from typing import Annotated

import typer

from align.cli import options as opt
from align.cli.paths import check_outputs, outputs
from align.cli.progress import progress
from align.cli.simulate import refuse_replacing

#: the files ``demo`` writes into its folder
DEMO_FILES = ("mount.toml", "manoeuvre.toml", "static.npy", "session.csv", "plan.toml", "budget.json",
              "allowable.json", "check.json", "allan.json", "plan.json", "alignment.json", "truth.json", "report.html")


def demo(
    out: opt.OptInput("--out", "Folder for the inputs, results and report (created if missing).", "FOLDER") = Path(
        "imu-align-demo"),
    force: Annotated[bool, typer.Option("--force", help="Replace the files the folder already holds.")] = False,
) -> None:
    """The whole story on bundled inputs (Examples 1-3, simulated records): summary and report."""
    check_outputs(folder=("out", out, DEMO_FILES))
    refuse_replacing("out", out, DEMO_FILES, force)
    from align.present.story import run_demo

    # all or none: the inputs are staged and read back, the results and the report staged beside them,
    # and only then are all the files (and the folder, if new) put in place
    with outputs() as staged, progress(100_000, "Monte Carlo") as tick:
        staged.folder(out)
        page, summary, results = run_demo(out, staged, progress=tick)
        for name, result in results.items():
            staged.write_json(out / f"{name}.json", result)
        staged.write_text(out / "report.html", page)
    typer.echo("imu-align demo (inputs: Examples 1-3 of Looney's 'The Basics of MEMS IMU/Gyroscope Alignment', Analog "
               "Dialogue; a simulated static record and rate-table session)\n"
               + summary + f"\nwrote {out}/report.html and the JSON results beside it")


COMMANDS = {"demo": demo}
