"""``imu-align calibrate``: Ferraris sessions, accelerometer positions, magnetometer ellipsoid, gyro without a rate
table. One module per command (``align.cli.calibrate_ferraris``, ``_accel``, ``_mag``, ``_gyro``); each is the
library job of :mod:`align.calibration.jobs` with its parse and write.

Public names
------------
app, ferraris, accel, mag, gyro, thermal, thermal_matrix, positions, COMMANDS
"""

from collections.abc import Callable
from typing import Any

import typer

from align.cli.calibrate_accel import accel
from align.cli.calibrate_ferraris import ferraris
from align.cli.calibrate_gyro import gyro
from align.cli.calibrate_mag import mag
from align.cli.calibrate_positions import positions
from align.cli.calibrate_thermal import thermal
from align.cli.calibrate_thermal_matrix import thermal_matrix

__all__ = ["app", "ferraris", "accel", "mag", "gyro", "thermal", "thermal_matrix", "positions", "COMMANDS"]

COMMANDS: dict[str, Callable[..., Any]] = {"ferraris": ferraris, "accel": accel, "mag": mag, "gyro": gyro,
                                           "thermal": thermal, "positions": positions,
                                           "thermal-matrix": thermal_matrix}

app = typer.Typer(help="Sensor calibration: Ferraris sessions, accelerometer positions, magnetometer ellipsoid, gyro "
                       "without a rate table, bias against temperature, indexed positions with Earth rate, scale and "
                       "misalignment against temperature.",
                  add_completion=False, rich_markup_mode=None, pretty_exceptions_enable=False)
for _name, _command in COMMANDS.items():
    app.command(_name)(_command)
