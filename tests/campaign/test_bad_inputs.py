"""The bad-input campaign (issue 11): every command, every input, every class of mistake, table-driven.

Each case of :data:`campaign_cases.CASES` runs ``imu-align`` once (in-process, a few as real
processes) in a folder of its own holding copies of its inputs, and checks what a careful user
expects:

* the exit status (2 input or usage, 3 a test that cannot be trusted, 4 a failed check, 0 a
  borderline input that must work);
* a failure prints exactly one line on stderr, no traceback, no leaked warning, naming the right
  thing (the file, the option, the key) and nothing it must not say; a success prints nothing there;
* every input is byte-identical afterwards;
* a failed run leaves nothing behind: no output, no temporary file, no folder; a successful one
  writes its outputs and nothing else.

Set ``IMU_ALIGN_CAMPAIGN_LOG=FILE`` to append one JSON line per case (the outcome, for the notes).
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import signal
import stat
import subprocess
import warnings
from pathlib import Path

import pytest
from campaign_cases import CASES, PYTHON_REPRS, Case
from campaign_inputs import build_inputs
from support import imu_align_command

#: seconds one in-process case may take before it is reported as hanging
CASE_TIMEOUT = 60
#: warnings a user would not see (Python hides them outside __main__)
HIDDEN_WARNINGS = (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning)


@pytest.fixture(scope="session")
def campaign_inputs(tmp_path_factory) -> dict[str, Path]:
    """Every input of the campaign, built once: name -> path."""
    return build_inputs(tmp_path_factory.mktemp("campaign-inputs"))


class CaseTimeout(BaseException):
    """Raised by the alarm: not an Exception, so the CLI's catch-all cannot swallow it."""


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _tree(folder: Path) -> set[str]:
    """Every file, folder and link under ``folder`` (hidden ones too), relative."""
    out = set()
    for root, dirs, files in os.walk(folder):
        for name in dirs + files:
            out.add(os.path.relpath(os.path.join(root, name), folder))
    return out


class CaseFolder:
    """A case's folder: input copies (hashed), setup, token substitution."""

    def __init__(self, root: Path, library: dict[str, Path]) -> None:
        self.root, self.library = root, library
        self.inputs: dict[Path, str] = {}

    def copy_in(self, name: str, rel: str | None = None) -> Path:
        if name not in self.library:
            raise KeyError(f"campaign input {name!r} was not built")
        dst = self.root / (rel or name)
        if dst not in self.inputs:
            dst.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(self.library[name], dst)
            self.inputs[dst] = _digest(dst)
        return dst

    def setup(self, steps) -> None:
        for step in steps:
            op, rel = step[0], step[1]
            if op == "input":
                self.copy_in(rel, step[2])
                continue
            p = self.root / rel
            p.parent.mkdir(parents=True, exist_ok=True)
            if op == "mkdir":
                p.mkdir(exist_ok=True)
            elif op == "file":
                p.write_text(step[2])
            elif op == "symlink":
                target = self.copy_in(step[2])
                p.symlink_to(target)
            elif op == "readonly":
                p.mkdir(exist_ok=True)
                p.chmod(0o555)
                try:
                    (p / ".probe").write_text("x")
                except OSError:
                    continue
                (p / ".probe").unlink()
                p.chmod(0o755)
                pytest.skip("the test runs as root: a chmod 555 folder is writable (see the /proc and /sys cases)")
            else:
                raise ValueError(op)

    def resolve(self, arg: str) -> str:
        arg = re.sub(r"IN:([\w.\-]+)", lambda m: str(self.copy_in(m.group(1))), arg)
        arg = re.sub(r"REL:([\w.\-]+)", lambda m: self.copy_in(m.group(1)).name, arg)
        return re.sub(r"CASE:([\w.\-/]+)", lambda m: str(self.root / m.group(1)), arg)

    def unlock(self) -> None:
        for root, dirs, _ in os.walk(self.root):
            for d in dirs:
                p = os.path.join(root, d)
                if not os.path.islink(p):
                    os.chmod(p, os.stat(p).st_mode | stat.S_IWUSR | stat.S_IXUSR | stat.S_IRUSR)


def _in_process(args: list[str], capsys) -> tuple[int, str, list[str]]:
    """Run ``imu-align ARGS`` in this process: exit status, stderr, warnings a user would see."""
    from align.cli import main

    def alarm(*_):
        raise CaseTimeout(f"no answer within {CASE_TIMEOUT} s")

    capsys.readouterr()
    previous = signal.signal(signal.SIGALRM, alarm)
    signal.alarm(CASE_TIMEOUT)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            for category in HIDDEN_WARNINGS:
                warnings.simplefilter("ignore", category)
            try:
                main(args)
                code = 0
            except SystemExit as exc:
                code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    err = capsys.readouterr().err
    return code, err, [f"{w.category.__name__}: {w.message}" for w in caught]


def _subprocess(args: list[str], cwd: Path) -> tuple[int, str, list[str]]:
    env = {k: v for k, v in os.environ.items() if k != "IMU_ALIGN_DEBUG"}
    proc = subprocess.run(imu_align_command() + args, cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=120)
    return proc.returncode, proc.stderr, []


def _named(err: str, want: str) -> bool:
    low = err.lower()
    return any(alt.lower() in low for alt in want.split("|"))


def check_case(case: Case, folder: CaseFolder, before: set[str], code: int, err: str, leaked: list[str]) -> list[str]:
    """What went wrong in a finished case (empty: as expected)."""
    problems = []
    lines = err.splitlines()
    if code != case.code:
        problems.append(f"exit {code}, expected {case.code}")
    if "Traceback" in err:
        problems.append("a traceback on stderr")
    if leaked:
        problems.append(f"warnings leak to stderr: {'; '.join(leaked)[:300]}")
    if case.code != 0:
        if len(lines) != 1:
            problems.append(f"stderr has {len(lines)} lines, expected exactly one")
        missing = [w for w in case.names if not _named(err, w)]
        if missing and code != 0:
            problems.append(f"stderr does not name {', '.join(repr(w) for w in missing)}")
        said = [f for f in case.forbid if f.lower() in err.lower()] + [f for f in PYTHON_REPRS if f in err]
        if said:
            problems.append(f"stderr says {', '.join(repr(f) for f in said)} (misleading)")
    elif err.strip():
        problems.append("stderr is not empty on success")
    changed = [p.name for p, digest in folder.inputs.items() if not p.is_file() or _digest(p) != digest]
    if changed:
        problems.append(f"inputs changed: {', '.join(changed)}")
    new = _tree(folder.root) - before
    allowed = set()
    if code == 0 or code == 4:
        for out in case.outputs:
            parts = Path(out).parts
            allowed |= {str(Path(*parts[: i + 1])) for i in range(len(parts))}
    left = sorted(p for p in new if p not in allowed)
    if left:
        what = "left behind after a failure" if code not in (0, 4) else "written besides the outputs"
        problems.append(f"{what}: {', '.join(left[:8])}")
    if code == case.code == 0:
        absent = [o for o in case.outputs if not (folder.root / o).is_file()]
        if absent:
            problems.append(f"outputs not written: {', '.join(absent)}")
    return problems


# the borderline inputs (full runs that must work) and the real processes but one are the slow lane's
@pytest.mark.parametrize("case", [pytest.param(c, marks=pytest.mark.slow) if c.kind == "borderline" or (
    c.process and c.command != "top") else c for c in CASES], ids=[c.id for c in CASES])
def test_bad_input(case: Case, campaign_inputs, tmp_path, capsys, monkeypatch):
    monkeypatch.delenv("IMU_ALIGN_DEBUG", raising=False)
    root = tmp_path / "case"
    root.mkdir()
    folder = CaseFolder(root, campaign_inputs)
    try:
        folder.setup(case.setup)
        for name in case.extra:
            folder.copy_in(name)
        args = [folder.resolve(a) for a in case.args]
        before = _tree(root)
        monkeypatch.chdir(root)
        if case.process:
            code, err, leaked = _subprocess(args, root)
        else:
            code, err, leaked = _in_process(args, capsys)
        problems = check_case(case, folder, before, code, err, leaked)
    finally:
        folder.unlock()
    log = os.environ.get("IMU_ALIGN_CAMPAIGN_LOG")
    if log:
        with open(log, "a") as fh:
            fh.write(json.dumps({"id": case.id, "command": case.command, "kind": case.kind, "expected": case.code,
                                 "code": code, "stderr": err.strip()[:600], "problems": problems,
                                 "args": case.args}) + "\n")
    assert not problems, f"imu-align {' '.join(case.args)}\n  " + "\n  ".join(problems) + f"\n  stderr: {err.strip()[:800]}"


def test_campaign_breadth():
    """At least 300 cases, every command and every class of the issue."""
    assert len(CASES) >= 300
    commands = {c.command for c in CASES}
    for name in ("matrix", "apply", "simulate", "budget", "allowable", "check", "allan", "plan", "report", "demo",
                 "calibrate ferraris", "calibrate accel", "calibrate mag"):
        assert name in commands, name
    kinds = {c.kind for c in CASES}
    for kind in ("usage", "malformed", "borderline", "domain", "units", "handedness", "keys", "results", "outputs",
                 "partial"):
        assert kind in kinds, kind
