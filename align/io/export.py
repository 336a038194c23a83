"""Old name of :mod:`align.io.consumers` (writers of the formats other programs load), kept for one release."""

import sys

import align.io.consumers as _new

sys.modules[__name__] = _new
