"""A lot of units: the manifest, per-unit runs, the results table and the lot's statistics.

A production line runs the single-unit jobs (``matrix``, ``calibrate ...``, ``allan``) on many
units and looks at them together. This package holds everything but the jobs themselves:

manifest   which units, with which job, inputs and options; the content hash of a unit's inputs
figures    the key figures of a result, one flat row per sensor (SI)
table      the lot's table: its schema and rows
store      the table's files: a folder of Parquet parts appended through a journal, read lazily
pools      where units run: a process pool, or a Dask cluster (optional extra)
batch      the batch: tasks, skipping what is done, running the rest, journaling
spec       limits per figure (TOML, units at the edge)
stats      count, mean, spread, Cpk, yield, outliers, trend, control limits; a unit's verdict
rehearsal  a simulated lot with known truth

A unit runs its library job (``align.api.job(name).run(options)``, :func:`run_job`) in a worker; the
command line (``imu-align batch``, ``imu-align lot``) builds each unit's options from its manifest row
with the command's own parser and supplies the wording of a unit's failure.

Public names
------------
Unit, Manifest, read_manifest, input_hash, result_rows, FIGURES, SCHEMA, append_rows, read_table, latest_rows,
Journal, make_pool, Task, BatchRun, plan_tasks, run_units, run_job, unit_rows, result_unit_rows, error_rows, Limit, Spec,
read_spec, lot_statistics, judge_rows, LotStats, FigureStats, LotSpread, LotTruth, simulate_lot
"""

from align.limits import Limit, Spec, read_spec
from align.production.batch import (
    TABLE,
    UNITS,
    BatchRun,
    Task,
    error_rows,
    plan_tasks,
    result_unit_rows,
    run_job,
    run_units,
    unit_rows,
)
from align.production.keyfigures import FIGURES, result_rows
from align.production.manifest import Manifest, Unit, input_hash, read_manifest
from align.production.pools import make_pool
from align.production.rehearsal import LotSpread, LotTruth, simulate_lot
from align.production.stats import FigureStats, LotStats, judge_rows, lot_statistics
from align.production.store import Journal, append_rows, read_table
from align.production.table import SCHEMA, latest_rows

__all__ = ["TABLE", "UNITS", "BatchRun", "Task", "error_rows", "plan_tasks", "run_units", "run_job", "unit_rows",
           "result_unit_rows", "FIGURES", "result_rows", "Manifest", "Unit", "input_hash", "read_manifest", "make_pool",
           "LotSpread", "LotTruth",
           "simulate_lot", "Limit", "Spec", "read_spec", "FigureStats", "LotStats", "judge_rows", "lot_statistics",
           "SCHEMA", "Journal", "append_rows", "latest_rows", "read_table"]
