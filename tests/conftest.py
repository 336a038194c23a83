"""Fixtures shared by the tests: thin wrappers over the helpers of ``support.py``.

Helpers are imported from the module ``support`` (``from support import ROOT``), not from here; the names
below are re-exported only so that a test file not yet moved over keeps working.
"""

from __future__ import annotations

import pytest
from support import (  # noqa: F401  (re-exported for files that still import them from conftest)
    ROOT,
    SHARED,
    CliResult,
    coning,
    imu_align_command,
    in_chromium,
    run_in_process,
    truth_model,
    write_session,
)


@pytest.fixture
def run_cli(capsys):
    """Run ``imu-align ARGS`` in-process (the console script's ``main``); returns exit code, stdout, stderr."""
    return lambda *args: run_in_process(capsys, *args)
