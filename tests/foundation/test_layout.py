"""The layout's rules, checked on the source: no flag named outside the CLI, small modules, one registry."""

from __future__ import annotations

import ast
import importlib
import re

import pytest
from support import ROOT

LIBRARY = [p for p in sorted((ROOT / "align").rglob("*.py")) if "cli" not in p.relative_to(ROOT / "align").parts]
LIBRARY += sorted((ROOT / "mechanics").glob("*.py"))
FLAG = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]+")


def _strings(path):
    """Every string constant of a module but its docstrings (messages, not documentation)."""
    tree = ast.parse(path.read_text())
    docs = {id(n.body[0].value) for n in ast.walk(tree)
            if isinstance(n, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
            and n.body and isinstance(n.body[0], ast.Expr) and isinstance(n.body[0].value, ast.Constant)}
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs:
            yield node.lineno, node.value


@pytest.mark.parametrize("path", LIBRARY, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_library_string_names_a_command_line_flag(path):
    found = [(line, s) for line, s in _strings(path) if FLAG.search(s)]
    assert not found, f"{path.relative_to(ROOT)} names flags (use {{field}} placeholders): {found}"


@pytest.mark.parametrize("path", sorted((ROOT / "align").rglob("*.py")) + sorted((ROOT / "mechanics").glob("*.py")),
                         ids=lambda p: str(p.relative_to(ROOT)))
def test_no_module_over_about_400_lines(path):
    assert len(path.read_text().splitlines()) <= 420


def test_every_known_format_is_the_format_of_the_type_its_module_registers():
    from align.results import _TYPES, KNOWN

    for fmt, module in KNOWN.items():
        importlib.import_module(module)
        cls = _TYPES[fmt]
        assert cls.FORMAT == fmt and cls.__module__ == module
        assert cls.VERSION >= 1 and cls.CONVENTION
