"""``imu-align inspect``: what a log holds before any job (:func:`align.inspection.inspect_log`).

Public names
------------
inspect_log_command, COMMANDS
"""

from __future__ import annotations

from typing import Annotated

import typer

from align.cli import options as opt
from align.cli.paths import check_outputs, write_run


def inspect_log_command(
    log: opt.Arg("A log of any format imu-align reads (CSV, NPY, Parquet, a ROS bag, a ULog, a DataFlash log), or a "
                 "log folder (a ROS 2 bag, an EuRoC dataset).", "LOG"),
    topic: opt.Topic = None,
    stamps: opt.Stamps = None,
    time_column: Annotated[str | None, typer.Option("--time-column", metavar="NAME", help=(
        "Name of the time column of a file of one stream (default: time); a stream's is its time stamps."))] = None,
    json_out: opt.JsonOut = None,
    skip_rows: opt.SkipRows = 0,
    comment: opt.Comment = None,
    delimiter: opt.Delimiter = None,
    time_units: opt.TimeUnits = None,
) -> None:
    """What a log holds: its streams (topics, instances, counts) and, for each IMU stream (or the file's columns),
    its samples, rates, duration, gaps and dropped samples, time out of order, temperature range, clipped samples
    and the units it states."""
    check_outputs([log], json_out=json_out)
    from align.inspection import inspect_log

    found = inspect_log(log, opt.log_format(skip_rows=skip_rows, comment=comment, delimiter=delimiter,
                                            time_units=time_units, topic=topic, stamps=stamps), time_column)
    write_run(json_out, found.to_dict())
    typer.echo("\n".join(found.lines()))


COMMANDS = {"inspect": inspect_log_command}
