"""Old name of :mod:`align.sensitivity.propagation` (attitude propagation over a manoeuvre), kept for one release."""

import sys

import align.sensitivity.propagation as _new

sys.modules[__name__] = _new
