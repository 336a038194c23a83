"""``imu-align drift`` (:mod:`align.cli.drift`); this module gathers the navigation commands.

Public names
------------
drift, COMMANDS
"""

from align.cli.drift import drift

__all__ = ["drift", "COMMANDS"]

COMMANDS = {"drift": drift}
