"""``imu-align verify`` (issue 27): a correction replayed on a session it was not fitted to gives PASS when it works
and FAIL with the residual when it does not.

Truth: two simulated sessions of one gyro (the same M, bias and noise level, other noise draws, simulated by
align.alignment.simulate, whose sessions the alignment tests check against their truth); the deliberate errors are
set here (0.5 deg about z, a log read in rad/s).
"""

from __future__ import annotations

import json
import math

import numpy as np
from support import write_session

from align.alignment.plan import Plan
from align.alignment.simulate import SessionSpec, random_model, simulate_run
from align.results import load_result, save_result

PLAN = Plan.from_dict({"step": [{"axis": a, "rate": f"{s}100 deg/s"} for a in "xyz" for s in "+-"]})


def _sessions(tmp_path):
    rng = np.random.default_rng(11)
    truth = random_model(rng, 0.5 * math.pi / 180)
    out = []
    for name in ("fit", "check"):
        folder = tmp_path / name
        folder.mkdir()
        run = simulate_run(PLAN, truth, SessionSpec(fs=200.0, dwell_s=8.0, static_s=2.0), rng)
        out.append(write_session(folder, run.t, run.g, PLAN))
    return out


def test_a_correction_passes_on_another_session_and_a_wrong_one_fails_with_its_residual(tmp_path, run_cli):
    (log_a, plan_a), (log_b, plan_b) = _sessions(tmp_path)
    result = tmp_path / "r.json"
    assert run_cli("matrix", log_a, "--plan", plan_a, "--json", result).code == 0
    out = tmp_path / "v.json"
    res = run_cli("verify", result, log_b, "--plan", plan_b, "--json", out)
    assert res.code == 0 and "verdict: PASS: 9 figures within their limits" in res.out, res.out
    figs = json.loads(out.read_text())["figures_of_merit"]
    z = [f["value"] / f["sigma"] for f in figs]
    assert max(abs(v) for v in z) < 4.5, z                               # the residual is the noise's
    # the same M turned by 0.5 deg about z: the residual misalignment says so, exit 4, the file written
    good = load_result(result)
    c, s = math.cos(math.radians(0.5)), math.sin(math.radians(0.5))
    wrong = good.replace(M=good.M @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]),
                         A=np.linalg.inv(good.M @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])))
    save_result(tmp_path / "wrong.json", wrong)
    out.unlink()
    res = run_cli("verify", tmp_path / "wrong.json", log_b, "--plan", plan_b, "--json", out)
    assert res.code == 4 and out.exists() and "figures of merit fail" in res.err
    got = {f["name"]: f for f in json.loads(out.read_text())["figures_of_merit"]}
    assert got["residual_phi_xy"]["status"] == "FAIL" and got["residual_phi_yx"]["status"] == "FAIL"
    assert abs(abs(math.degrees(got["residual_phi_xy"]["value"])) - 0.5) < 0.01
    assert got["residual_phi_xz"]["status"] == "PASS"


def test_a_log_read_in_another_unit_does_not_pass(tmp_path, run_cli):
    (log_a, plan_a), (log_b, plan_b) = _sessions(tmp_path)
    result = tmp_path / "r.json"
    assert run_cli("matrix", log_a, "--plan", plan_a, "--json", result).code == 0
    res = run_cli("verify", result, log_b, "--plan", plan_b, "--gyro-units", "rad/s")
    assert res.code != 0 and "PASS" not in res.out.splitlines()[-1:]
    assert len(res.err.strip().splitlines()) == 1 and "Traceback" not in res.err


def test_the_session_the_result_was_fitted_on_is_refused(tmp_path, run_cli):
    """A PASS on the fitting session itself says nothing (a new user's try): one line naming the session."""
    (log_a, plan_a), _ = _sessions(tmp_path)
    result = tmp_path / "r.json"
    assert run_cli("matrix", log_a, "--plan", plan_a, "--json", result).code == 0
    res = run_cli("verify", result, log_a, "--plan", plan_a, "--json", tmp_path / "v.json")
    assert res.code == 2 and len(res.err.strip().splitlines()) == 1 and "fitted on" in res.err
    assert str(log_a.name) in res.err and not (tmp_path / "v.json").exists()

