"""One batch at a time per output folder: ``OUT/.batch.lock`` names the host and process holding it.

Public names
------------
locked
"""

from __future__ import annotations

import os
import socket
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from align.errors import InputError


@contextmanager
def locked(out: Path) -> Iterator[None]:
    """Hold the output folder for one batch at a time (``OUT/.batch.lock``, naming the host and process);
    a lock whose process is gone (a killed batch on this host) is taken over."""
    path = out / ".batch.lock"
    me = f"{socket.gethostname()} {os.getpid()}"
    for _ in range(2):
        try:
            fd = os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            host, _, pid = (path.read_text(errors="replace").strip() or " ").partition(" ")
            if not host or (host == socket.gethostname() and not _alive(pid)):  # empty: killed while writing it
                path.unlink(missing_ok=True)
                continue
            raise InputError(f"another batch ({host}, process {pid}) is writing to {out}; wait for it, or give "
                             f"another {{out}} (remove {path} if no batch runs)", "{out}") from None
        with os.fdopen(fd, "w") as fh:
            fh.write(me)
        break
    try:
        yield
    finally:
        path.unlink(missing_ok=True)


def _alive(pid: str) -> bool:
    try:
        os.kill(int(pid), 0)
    except (ValueError, ProcessLookupError):
        return False
    except PermissionError:  # a process of another user
        return True
    return True
