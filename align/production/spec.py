"""Old name of :mod:`align.limits` (a lot's spec is a limits file: one format for every job, the report and the lot),
kept for one release."""

import sys

import align.limits as _new

sys.modules[__name__] = _new
