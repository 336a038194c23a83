"""Old name of :mod:`align.noise.analysisfile` (kept for one release): the JSON form of an Allan analysis.

Public names
------------
term_units, fit_extras, fit_dict, read_fit, curve_dict, read_curve, run_figures, note_out, note_in, figures_dict,
read_figures, periods_of, term_value, si_value, GYRO, ACCEL, READOUTS
"""

from align.noise.analysisfile import *  # noqa: F403
from align.noise.analysisfile import (  # noqa: F401
    ACCEL,
    GYRO,
    READOUTS,
    curve_dict,
    figures_dict,
    fit_dict,
    fit_extras,
    note_in,
    note_out,
    periods_of,
    read_curve,
    read_figures,
    read_fit,
    run_figures,
    si_value,
    term_units,
    term_value,
)
