"""Old name of :mod:`align.production.keyfigures` (a unit's key figures for the lot table), kept for one release."""

import sys

import align.production.keyfigures as _new

sys.modules[__name__] = _new
