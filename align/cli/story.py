"""Commands that tell the whole story: ``report`` (:mod:`align.cli.report`) and ``demo`` (:mod:`align.cli.demo`);
this module gathers them.

Public names
------------
report, demo, COMMANDS, DEMO_FILES, LazyParts
"""

from align.cli.demo import DEMO_FILES, demo
from align.cli.parts import LazyParts
from align.cli.report import report

__all__ = ["report", "demo", "COMMANDS", "DEMO_FILES", "LazyParts"]

COMMANDS = {"report": report, "demo": demo}
