"""Mechanical tolerance analysis: how far the gyro axes sit from the system axes once the
IMU is screwed onto its ledges (reference section 2, Eq 1-4).

Modules
-------
formulas    the source's first-order formulas (Eq 1-4)
mount       the mount description (IMU, package, ledges or baseplate STL, screws) and its TOML reader
rest        the rigid-body rest model of a package on ledges (trimesh hull; closed form for corners)
assembly    the assembled pose: skew limit, 3-D composition of skew and tilt, the worst case
montecarlo  Monte Carlo of the assembly from the tolerances' distributions
budget      the budget result (source, per axis, worst case, Monte Carlo): ``imu-align.budget``
render      pictures: the Monte Carlo histogram, the assembly (PNG, GLB)

mechanics imports only the foundation, :mod:`align.io` and :mod:`align.results`.

Public names
------------
Mount, mount_from_dict, Budget, budget, MonteCarlo, monte_carlo, histogram_png, assembly_png, assembly_glb
"""

from mechanics.budget import Budget, budget
from mechanics.montecarlo import MonteCarlo, monte_carlo
from mechanics.mount import Mount, mount_from_dict
from mechanics.render import assembly_glb, assembly_png, histogram_png

__all__ = ["Mount", "mount_from_dict", "Budget", "budget", "MonteCarlo", "monte_carlo", "histogram_png",
           "assembly_png", "assembly_glb"]
