"""Commands of the noise family: ``allan`` (:mod:`align.cli.allan`) and ``plan`` (:mod:`align.cli.plan`).

One command-line module per command; this module gathers the family's commands for the command line
and keeps the old import path (``from align.cli.noise import allan, grid_value``).

Public names
------------
allan, plan, allan_options, plan_options, grid_value, GRIDS, COMMANDS
"""

from align.cli.allan import GRIDS, allan, allan_files, allan_options, grid_value
from align.cli.plan import plan, plan_options

__all__ = ["allan", "plan", "allan_options", "allan_files", "plan_options", "grid_value", "GRIDS", "COMMANDS"]

COMMANDS = {"allan": allan, "plan": plan}
