"""Each job's command-line builders: the function that makes its options from the command's parameters,
and the one that makes the extra files its output options ask for.

The command itself, the batch (a manifest row's options parsed by the same command) and any other
caller of the command line build a job's options with the same function, so a unit in a batch runs
exactly the single command's job by construction.

``BUILDERS[job] = ("module:options_function", "module:files_function or None")``:

* ``options_function(**params) -> Options``: ``params`` are the command's parameters by their Python
  names, as typer (click) parses them; output options and unknown keys are ignored.
* ``files_function(result, inputs, params) -> list[(Path, bytes | str)]``: the files the output options
  (``plot``, ``c_header``, ...) ask for, beside the JSON result.

Public names
------------
BUILDERS, options_builder, files_builder
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any

BUILDERS: dict[str, tuple[str, str | None]] = {
    # each family adds its lines here
    "allan": ("align.cli.allan:allan_options", "align.cli.allan:allan_files"),
    "plan": ("align.cli.plan:plan_options", None),
    "matrix": ("align.cli.matrix:matrix_options", "align.cli.matrix:matrix_files"),
    "apply": ("align.cli.apply:apply_options", "align.cli.apply:apply_files"),
    "verify": ("align.cli.verify:verify_options", None),
    "calibrate ferraris": ("align.cli.calibrate_ferraris:ferraris_options",
                           "align.cli.calibrate_ferraris:ferraris_files"),
    "calibrate accel": ("align.cli.calibrate_accel:accel_options", "align.cli.calibrate_accel:accel_files"),
    "calibrate mag": ("align.cli.calibrate_mag:mag_options", "align.cli.calibrate_mag:mag_files"),
    "calibrate gyro": ("align.cli.calibrate_gyro:gyro_options", "align.cli.calibrate_gyro:gyro_files"),
    "calibrate thermal": ("align.cli.calibrate_thermal:thermal_options", "align.cli.calibrate_thermal:thermal_files"),
    "budget": ("align.cli.budget:budget_options", "align.cli.budget:budget_files"),
    "allowable": ("align.cli.allowable:allowable_options", None),
    "check": ("align.cli.check:check_options", None),
    "drift": ("align.cli.drift:drift_options", "align.cli.drift:drift_files"),
}


def _load(target: str) -> Callable[..., Any]:
    module, _, name = target.partition(":")
    return getattr(importlib.import_module(module), name)


def options_builder(job: str) -> Callable[..., Any]:
    """The function that makes ``job``'s options from its command's parameters."""
    return _load(BUILDERS[job][0])


def files_builder(job: str) -> Callable[..., Any] | None:
    """The function that makes ``job``'s extra output files (None: the job writes none but its JSON)."""
    target = BUILDERS[job][1]
    return None if target is None else _load(target)
