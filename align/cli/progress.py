"""The progress bar of long jobs (Monte Carlo, Allan deviation): on a terminal's stderr only.

Public names
------------
progress
"""

from __future__ import annotations

import sys


class progress:
    """``with progress(total, label) as tick: job(progress=tick)``; ``tick(done)`` redraws the bar.

    Silent when stderr is not a terminal (pipes, files, CI logs).
    """

    width = 30

    def __init__(self, total: int, label: str) -> None:
        self.total, self.label = max(int(total), 1), label
        self.live = sys.stderr.isatty()

    def __enter__(self):
        def tick(done: int) -> None:
            if self.live:
                filled = int(self.width * min(done, self.total) / self.total)
                sys.stderr.write(f"\r{self.label} [{'#' * filled}{'.' * (self.width - filled)}] {done:,}/{self.total:,}")
                sys.stderr.flush()

        return tick

    def __exit__(self, *exc) -> None:
        if self.live:
            sys.stderr.write("\r" + " " * (len(self.label) + self.width + 30) + "\r")
            sys.stderr.flush()
