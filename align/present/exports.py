"""Old name of :mod:`align.present.exportable` (what each result exports), kept for one release."""

import sys

import align.present.exportable as _new

sys.modules[__name__] = _new
