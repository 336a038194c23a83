"""Sensitivity: what misalignment does to a manoeuvre, and how much a requirement allows.

Modules
-------
symbolic    the response ``g = M w`` in angles and its Jacobian, derived with sympy (Eq 5-13)
manoeuvre   the manoeuvre a requirement is stated for and its limits (TOML reader)
attitude    attitude propagation: the outputs' errors over a manoeuvre; the closed form (Eq 11-13)
allowable   allowable misalignment per element, binding element, cone
margins     the budget against the allowance, element by element (the ``check`` result)

Outputs a requirement can limit: ``x``, ``y``, ``z`` (each gyro's integrated
angle error) and ``azimuth``, ``elevation``, ``roll`` (Z-Y-X Euler angle errors).

Public names
------------
ELEMENTS, OUTPUTS, symbolic, symbolic_text, matrix_from_angles, response, sensitivity (from ``symbolic``);
Manoeuvre, manoeuvre_from_dict (from ``manoeuvre``); output_errors, closed_form_errors (from ``attitude``);
Allowable, allowable (from ``allowable``); Margin, margins, MarginTable, check_margins (from ``margins``)
"""

from align.sensitivity.allowable import Allowable, allowable
from align.sensitivity.manoeuvre import Manoeuvre, manoeuvre_from_dict
from align.sensitivity.margins import Margin, MarginTable, check_margins, margins
from align.sensitivity.propagation import closed_form_errors, output_errors
from align.sensitivity.symbolic import ELEMENTS, OUTPUTS, matrix_from_angles, response, sensitivity, symbolic, symbolic_text

__all__ = ["ELEMENTS", "OUTPUTS", "symbolic", "symbolic_text", "matrix_from_angles", "response", "sensitivity",
           "Manoeuvre", "manoeuvre_from_dict", "output_errors", "closed_form_errors",
           "Allowable", "allowable", "Margin", "margins", "MarginTable", "check_margins"]
