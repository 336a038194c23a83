"""Old name of :mod:`align.noise.analysis` (kept for one release): the Allan analysis, the result of the ``allan``
job, was called ``AllanJob`` here; the job itself is :data:`align.noise.jobs.ALLAN`.

Public names
------------
AllanJob (= AllanAnalysis), AllanAnalysis, run_allan, pool_runs, read_runs, plan_from_allan, term_units, FORMAT
"""

from align.noise.analysis import *  # noqa: F403
from align.noise.analysis import (  # noqa: F401
    CONVENTION,
    FILE_KEYS,
    FORMAT,
    MIN_SAMPLES,
    POOLING,
    AllanAnalysis,
    plan_from_allan,
    pool_runs,
    read_runs,
    run_allan,
    term_units,
)

#: the old name of :class:`~align.noise.analysis.AllanAnalysis` (the same class)
AllanJob = AllanAnalysis
