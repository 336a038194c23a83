"""The mounting budget and the allowance, one module per command: ``budget`` (:mod:`align.cli.budget`),
``allowable`` (:mod:`align.cli.allowable`), ``check`` (:mod:`align.cli.check`); this module gathers them.

Public names
------------
budget, allowable, check, COMMANDS, MOUNT_HELP, MANOEUVRE_HELP
"""

from align.cli.allowable import MANOEUVRE_HELP, Manoeuvre, allowable
from align.cli.budget import MOUNT_HELP, Mount, budget
from align.cli.check import check

__all__ = ["budget", "allowable", "check", "COMMANDS", "MOUNT_HELP", "MANOEUVRE_HELP", "Mount", "Manoeuvre"]

COMMANDS = {"budget": budget, "allowable": allowable, "check": check}
