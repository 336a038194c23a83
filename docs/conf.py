"""Sphinx configuration of the imu-align API reference (``python -m sphinx -W --keep-going -b html docs OUT``).

Why Sphinx + numpydoc: the docstrings are already written in the numpydoc format that numpy, scipy and
scikit-learn use (Parameters / Returns with shapes and units), which numpydoc renders as it is, and Sphinx's
autodoc reads them from the code, so the reference cannot drift from the library; MkDocs + mkdocstrings would
need the docstrings re-read by another parser for the same result.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the checkout's align/ and mechanics/, installed or not

import align  # noqa: E402

project = "imu-align"
author = "imu-align developers"
copyright = "imu-align developers"  # noqa: A001
version = release = align.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "numpydoc",
]

# autodoc: members in source order, type hints in the signature only (numpydoc's Parameters hold the prose)
autodoc_member_order = "bysource"
autodoc_typehints = "signature"
# a class a package re-exports is documented twice; its annotations name the defining module's
autodoc_type_aliases = {"ThermalModel": "align.calibration.thermal.model.ThermalModel"}
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": False}
autosummary_generate = False  # the pages list their objects; no generated stub pages

# numpydoc: no autosummary table of every class member (each member is documented where it is defined)
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

exclude_patterns = ["_build", "README.md"]
html_theme = "alabaster"
html_title = f"imu-align {release}"
html_theme_options = {"description": "MEMS IMU mounting-misalignment analysis", "page_width": "1100px"}
html_static_path: list[str] = []


def _documented_class(frame) -> type | None:
    """The class whose members autodoc is filtering, found up the stack (the event does not pass it): Sphinx 9
    keeps it as ``props._obj``, older releases as a documenter's ``object``."""
    while frame is not None:
        for holder, attr in ((frame.f_locals.get("props"), "_obj"), (frame.f_locals.get("self"), "object")):
            if getattr(holder, "obj_type", getattr(holder, "objtype", None)) in ("class", "exception"):
                cls = getattr(holder, attr, None)
                if isinstance(cls, type):
                    return cls
        frame = frame.f_back
    return None


def _skip_dataclass_fields(app, what, name, obj, skip, options):
    """A dataclass's fields are its numpydoc Attributes section (with their units): not listed twice."""
    if what not in ("class", "exception"):
        return None
    import dataclasses
    import inspect

    cls = _documented_class(inspect.currentframe())
    if cls is not None and dataclasses.is_dataclass(cls) and name in {f.name for f in dataclasses.fields(cls)}:
        return True
    return None


def setup(app):
    app.connect("autodoc-skip-member", _skip_dataclass_fields)
