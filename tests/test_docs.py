"""The examples of the API reference run: the doctests of the modules it shows and its worked examples page.

The same as ``pytest --doctest-modules`` over :data:`MODULES` and ``--doctest-glob`` over docs/examples.rst, from
the top of the repository (the examples read the bundled inputs under ``examples/``). A module of the list that
does not exist is a failure (the reference shows it); a new family's jobs module is added here.
"""

from __future__ import annotations

import doctest
import importlib
import importlib.util

import pytest
from support import ROOT

#: modules whose docstring examples are the API reference's (docs/*.rst automodule them, or the package they are in)
MODULES = [
    "align.vocab",
    "align.io.source", "align.inspection", "align.io.noise_consumers", "align.io.dataflash", "align.io.dataflash_format",
    "align.noise.periodic", "align.calibration.thermal", "align.calibration.thermal.job", "align.calibration.thermal.model",
    "align.calibration.thermal.fit", "align.calibration.thermal.branches", "align.calibration.thermal.checks",
    "align.calibration.thermal.firmware", "align.calibration.thermal.simulate", "align.calibration.thermal.result",
    "align.calibration.thermal.matrix_t", "align.calibration.thermal.matrix_job",
    "align.job",
    "align.merit", "align.keyfigures", "align.limits", "align.judge",
    "align.calibration.jobs.positions", "align.calibration.multiposition", "align.calibration.gsens",
    "align.noise.warmup", "align.noise.repeatability", "align.noise.bias_jobs",
    "align.production.capability", "align.production.control", "align.production.lotjson",
    "align.production.thermal_groups", "align.production.store", "align.alignment.jobs.verify_job",
    "align.provenance",
    "align.results",
    "align.api",
    "align.alignment.jobs",
    "align.alignment.jobs.matrix_job",
    "align.alignment.jobs.apply_job",
    "align.noise.jobs",
    "align.calibration.jobs",
    "align.calibration.jobs.ferraris_job",
    "align.calibration.jobs.accel",
    "align.calibration.jobs.mag",
    "align.calibration.jobs.gyro",
    "align.sensitivity.jobs",
    "align.navigation.jobs",
    "mechanics.jobs",
    "align.alignment.pipeline",
    "align.alignment.simulate",
    "align.calibration.accel",
    "align.calibration.ferraris",
    "align.calibration.magnetometer",
    "align.calibration.gyro",
    "mechanics.budget",
    "mechanics.montecarlo",
    "align.navigation.drift",
    "align.navigation.strapdown",
    "align.navigation.residuals",
    "align.noise.allan",
    "align.noise.fit",
    "align.noise.planner",
    "align.noise.sim",
    "align.sensitivity.allowable",
    "align.sensitivity.margins",
    "align.sensitivity.symbolic",
]
FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def _run(tests: list[doctest.DocTest]) -> tuple[int, int, str]:
    """Run ``tests``; numbers print as numpy 1.x prints them (``0.5``, not ``np.float64(0.5)``), so one example
    holds on the newest versions and on the floor's numpy 1.26 alike."""
    import io

    import numpy as np

    out = io.StringIO()
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    saved = np.get_printoptions()
    if int(np.__version__.split(".")[0]) >= 2:
        np.set_printoptions(legacy="1.25")
    try:
        for t in tests:
            runner.run(t, out=out.write)
    finally:
        np.set_printoptions(**saved)
    return runner.failures, runner.tries, out.getvalue()


@pytest.mark.parametrize("name", MODULES)
def test_module_doctests_pass(name, monkeypatch):
    assert importlib.util.find_spec(name) is not None, f"{name} does not exist: the API reference documents it"
    monkeypatch.chdir(ROOT)
    module = importlib.import_module(name)
    failures, _, report = _run(doctest.DocTestFinder().find(module, module.__name__))
    assert failures == 0, report


def test_worked_examples_page_runs(monkeypatch):
    monkeypatch.chdir(ROOT)
    page = ROOT / "docs" / "examples.rst"
    test = doctest.DocTestParser().get_doctest(page.read_text(), {}, page.name, str(page), 0)
    failures, tries, report = _run([test])
    assert tries > 0 and failures == 0, report


def test_every_documented_module_is_a_page_s():
    """Each module of :data:`MODULES` (but the registry) is automodule'd by a page of docs/, has a function
    autofunction'd by one (an estimator), or is a module of a package that is (a family's jobs package, which
    re-exports its modules' names: the page shows them)."""
    pages = "\n".join(p.read_text() for p in (ROOT / "docs").glob("*.rst")) + "\n"
    shown = [m for m in MODULES if f".. automodule:: {m}\n" in pages or f".. autofunction:: {m}." in pages]
    missing = [m for m in MODULES if m not in shown and m.rpartition(".")[0] not in shown]
    assert not missing, f"no docs/ page shows {missing}"
