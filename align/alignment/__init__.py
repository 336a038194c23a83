"""Electronic alignment from rate-table data: ``M`` and ``A = M^-1`` with uncertainties and checks.

Modules
-------
geometry  frames: the local level frame, table axis, rest orientations, the nominal mounting
plan      the test plan (mounting, table geometry, steps about system axes) and its TOML form
segment   plateaus, static periods and the motions of a log
match     the plan's steps found in order among the motions, with the nominal mounting
observe   segments as linear observations, with the Earth rate the geometry allows
estimate  estimators of ``[M | b]``: Eq 28-30 (rate pairs), Eq 31 (angle pairs), weighted
          least squares
drift     the bias change between segments, in the observations' variances
twoaxis   the two-axis shortcut (Eq 35-36): the third column inferred, with its cost
checks    checks that turn a bad test into a clear error
kinematics, timeline, simulate
          rate-table session simulator of known truth (orientation, moves, Earth rate)
pipeline  the alignment pipeline (:func:`align`: segmentation, checks, estimator)
jobs      the commands' jobs: `matrix` (log + plan -> result) and `apply` (result + log -> corrected log)
result    its result (:class:`AlignmentResult`) and file

Equations are those of M. Looney, "The Basics of MEMS IMU/Gyroscope Alignment",
Analog Dialogue (reference ``alignment-basics.md``).
"""

from align.alignment.pipeline import AlignOptions, align
from align.alignment.plan import Plan, Step
from align.alignment.result import AlignmentResult
from align.alignment.segment import Segment, SegmentOptions
from align.alignment.simulate import SessionSpec, simulate_run, simulate_session

__all__ = ["Plan", "Step", "Segment", "SegmentOptions", "SessionSpec", "simulate_run", "simulate_session",
           "AlignmentResult", "AlignOptions", "align"]
