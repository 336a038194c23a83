"""Old name of :mod:`align.alignment.pipeline` (the estimator pipeline ``align``), kept for one release.

The command's job (options, reading, checks, provenance) is :mod:`align.alignment.jobs`.
"""

from align.alignment.pipeline import *  # noqa: F401,F403
from align.alignment.pipeline import METHODS, AlignOptions, align

__all__ = ["AlignOptions", "align", "METHODS"]
