"""Electronic alignment from rate-table data: ``M`` and ``A = M^-1`` with uncertainties and checks.

Modules
-------
plan      the test plan (steps about system axes, rates or angles) and its TOML form
segment   automatic segmentation of a log into dwells, turns and static periods
estimate  estimators of ``[M | b]``: Eq 28-30 (rate pairs), Eq 31 (angle pairs), weighted
          least squares
twoaxis   the two-axis shortcut (Eq 35-36): the third column inferred, with its cost
checks    checks that turn a bad test into a clear error
simulate  rate-table session simulator of known truth
job       the alignment job (:func:`align`) and its result (:class:`AlignmentResult`)

Equations are those of M. Looney, "The Basics of MEMS IMU/Gyroscope Alignment",
Analog Dialogue (reference ``alignment-basics.md``).
"""

from align.alignment.job import AlignOptions, align
from align.alignment.plan import Plan, Step
from align.alignment.result import AlignmentResult
from align.alignment.segment import Segment, SegmentOptions
from align.alignment.simulate import SessionSpec, simulate_session

__all__ = ["Plan", "Step", "Segment", "SegmentOptions", "SessionSpec", "simulate_session", "AlignmentResult",
           "AlignOptions", "align"]
