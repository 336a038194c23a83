"""imu-align: MEMS IMU mounting-misalignment analysis and electronic alignment.

Conventions shared by every module (see ``docs`` in README and the reference
``alignment-basics.md``, section 1):

* measurement model ``g = M w + b``: row ``i`` of ``M`` is gyro ``i``'s sensitive
  axis in the system frame times its scale factor;
* correction ``w = A (g - b)`` with the alignment matrix ``A = M^-1``;
* time series are arrays of shape ``(n, 3)``; everything inside is SI
  (rad, rad/s, m, s). Units appear only at the edges (files, command line).

Layout (each layer imports only the layers below it; CI checks this)
--------------------------------------------------------------------
foundation   errors (user-facing exceptions naming inputs, not flags), units (unit strings to
             SI), model (``SensorModel`` and its angles), earth, parts (datasheet presets),
             values (frozen value types compared by value)
io           logs (every log reader and its row/time checks), files (TOML, JSON, atomic
             writes), export (C header, imucal)
results      the one envelope, the registry of result types, ``load_result`` / ``save_result``
alignment    plan, segment, estimate, checks, simulate, job: ``M`` and ``A`` from a rate table
noise        Allan deviation, noise model and fit, figures, simulator, planner, the Allan job
sensitivity  symbolic response, attitude, manoeuvre, allowable misalignment
calibration  accelerometer, Ferraris sessions, magnetometer, their results
present      text summaries, the HTML report, pictures, the demo and report jobs
cli          the ``imu-align`` command line (thin: options, units at the edge, output)

``mechanics`` (the mounting budget) sits beside ``align`` and imports only its foundation,
io and results. A new estimator goes in ``alignment/estimate.py`` (or a module beside it),
a new file format in ``io``, a new sensor in ``calibration``, a new command in ``cli``
with its logic in the library.
"""

__version__ = "0.2.0"
CONVENTION = "g = M w + b; w = A (g - b); A = M^-1; rows of M are gyros"
