"""The README's Python examples run as written.

The ```python fenced blocks run in order in one namespace, as a reader pastes them into one session, in a
folder that holds the repository's ``examples/`` (a block that reads ``imu-align-demo/`` gets the folder
``imu-align demo`` makes, as the README says, and is in the slow lane); any ``>>>`` example runs as a doctest.
The README must hold at least one Python example.
"""

from __future__ import annotations

import doctest
import re

import pytest
from support import ROOT

README = ROOT / "README.md"
_FENCE = re.compile(r"^```python[ \t]*\n(.*?)^```[ \t]*$", re.M | re.S)
_DEMO = "imu-align-demo/"


def python_blocks(text: str) -> list[tuple[int, str]]:
    """(line number, code) of each ```python fenced block of ``text``."""
    return [(text.count("\n", 0, m.start()) + 2, m.group(1)) for m in _FENCE.finditer(text)]


BLOCKS = python_blocks(README.read_text())


def _reader_folder(tmp_path, demo: bool):
    """A folder as the README's reader has it: the repository's examples/ (and the demo's output)."""
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    if demo:
        from align.cli import main

        try:
            main(["demo", "--out", str(tmp_path / "imu-align-demo")])
        except SystemExit as exc:
            assert not exc.code, f"imu-align demo exited {exc.code}"
    return tmp_path


def test_the_readme_has_python_examples():
    text = README.read_text()
    assert BLOCKS or ">>>" in text, "README.md has no Python example to test"


@pytest.mark.parametrize("k", [k if not any(_DEMO in c for _, c in BLOCKS[: k + 1]) else
                               pytest.param(k, marks=pytest.mark.slow) for k in range(len(BLOCKS))],
                         ids=[f"line{line}" for line, _ in BLOCKS])
def test_python_block_runs(k, tmp_path, monkeypatch, capsys):
    """Block ``k`` after the blocks before it, in one namespace."""
    monkeypatch.chdir(_reader_folder(tmp_path, any(_DEMO in c for _, c in BLOCKS[: k + 1])))
    namespace: dict = {"__name__": "__readme__"}
    for line, code in BLOCKS[: k + 1]:
        exec(compile(code, f"{README.name}:{line}", "exec"), namespace)


def test_doctest_examples_pass(tmp_path, monkeypatch):
    monkeypatch.chdir(_reader_folder(tmp_path, False))
    text = _FENCE.sub("", README.read_text())  # the fenced blocks run above
    test = doctest.DocTestParser().get_doctest(text, {}, README.name, str(README), 0)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    runner.run(test)
    assert runner.failures == 0
