"""Old name of :mod:`align.alignment.biasdrift` (bias drift of a session's static periods), kept for one release."""

import sys

import align.alignment.biasdrift as _new

sys.modules[__name__] = _new
