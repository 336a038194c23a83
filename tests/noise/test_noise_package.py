"""The noise family as a package: its public names, its layer, and messages that name inputs, never flags."""

import ast
import re
from pathlib import Path

import align.noise

NOISE = Path(align.noise.__file__).parent


def _tree(path):
    return ast.parse(path.read_text(), str(path))


def test_public_names_are_re_exported_and_listed():
    doc = align.noise.__doc__
    for name in ("allan", "AllanResult", "tau_grid", "fit_noise", "NoiseFit", "noise_figures", "simulate_noise",
                 "NoiseSpec", "make_plan", "PlanResult", "run_allan", "AllanJob", "NoiseModel", "model_adev",
                 "model_curve", "TERMS"):
        assert hasattr(align.noise, name) and name in align.noise.__all__ and name in doc
    for module in sorted(p.stem for p in NOISE.glob("*.py") if not p.stem.startswith("_")):
        assert re.search(rf"^{module}\s", doc, re.M), module


def test_noise_imports_neither_present_nor_plotting_nor_the_cli():
    """Layer 3: only the layers below (and numba/scipy/numpy); no sibling family."""
    banned = ("align.present", "align.cli", "align.calibration", "align.sensitivity", "matplotlib", "typer",
              "click", "rich")
    for path in NOISE.glob("*.py"):
        for node in ast.walk(_tree(path)):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                     [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            for name in names:
                assert not name.startswith(banned), f"{path.name} imports {name}"


def test_no_library_string_names_a_flag():
    flag = re.compile(r"(?<![\w-])--[a-z]")
    for path in NOISE.glob("*.py"):
        for node in ast.walk(_tree(path)):
            if isinstance(node, ast.Constant) and isinstance(node.value, str):
                assert not flag.search(node.value), f"{path.name}:{node.lineno}: {node.value!r}"
