"""Commands of the alignment family: ``matrix`` (:mod:`align.cli.matrix`), ``apply`` (:mod:`align.cli.apply`);
``simulate`` is in :mod:`align.cli.simulate`.

Public names
------------
matrix, apply, GYRO_COLUMNS, SENSOR_COLUMNS, SENSOR_DIMENSIONS, COMMANDS
"""

from align.cli.apply import SENSOR_COLUMNS, SENSOR_DIMENSIONS, apply
from align.cli.matrix import GYRO_COLUMNS, matrix

__all__ = ["matrix", "apply", "GYRO_COLUMNS", "SENSOR_COLUMNS", "SENSOR_DIMENSIONS", "COMMANDS"]

COMMANDS = {"matrix": matrix, "apply": apply}
