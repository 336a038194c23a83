"""``imu-align export`` (:mod:`align.cli.export`); this module gathers it.

Public names
------------
export, COMMANDS
"""

from align.cli.export import NOT_A_RESULT, export

__all__ = ["export", "COMMANDS", "NOT_A_RESULT"]

COMMANDS: dict = {"export": export}
