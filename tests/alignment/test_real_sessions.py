"""Sessions as real rate tables produce them (issue 12), each from the independent simulator.

Truth comes from the simulator (its ``M``, its bias path, its moves), never from the estimator. For
each row of the issue's table: the session is accepted, ``M`` lies within 3x the accuracy the noise
allows and inside the reported 3 sigma, the biases inside their 3 sigma; refusals say why in one line.
"""

import numpy as np
import pytest

from align.alignment.job import AlignOptions, align
from align.alignment.plan import Plan, Step
from align.alignment.simulate import (
    SessionSpec,
    mounting_from_rotation,
    random_model,
    simulate_run,
)
from align.errors import HandednessError, TestError
from align.model import SensorModel
from align.units import DEG, DEG_S

NOISE = 0.005 * DEG_S  # rad/s/sqrt(Hz)
RATE = 100 * DEG
SPEC = SessionSpec(noise_density=NOISE, dwell_s=8.0)
SEEDS = range(4)
ROT90Z = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # gyro x along +y, y along -x
UPSIDE_DOWN = np.diag([1.0, -1.0, -1.0])


def achievable(spec: SessionSpec, rate: float = RATE) -> float:
    """1-sigma of an element of M from the white noise of a +/- dwell pair (Eq 28): sigma / (sqrt(2 T) rate),
    with T the dwell less the trimmed ends (about 0.5 s)."""
    return spec.noise_density / (np.sqrt(2 * (spec.dwell_s - 0.5)) * rate)


def model_for(seed: int, mounting: np.ndarray | None = None):
    return random_model(np.random.default_rng(100 + seed), 0.5 * DEG, scale_sd=3e-3, mounting=mounting)


def judge(r, model, spec, sess, rate=RATE, bias_truth=None):
    """M within 3x the accuracy the noise allows (RMS over the nine elements, and the reported sigmas not
    inflated beyond it) and inside 3 reported sigma; bias inside 3 sigma of the truth (the mean of the true
    bias path over the session unless given)."""
    err = np.abs(r.M - model.M)
    best = achievable(spec, rate)
    assert np.sqrt(np.mean(err**2)) < 3 * best, (np.sqrt(np.mean(err**2)), best)
    assert np.median(r.sigma_M) < 3 * best
    assert np.all(err < 3 * r.sigma_M), err / r.sigma_M
    truth = sess.bias.mean(axis=0) if bias_truth is None else bias_truth
    assert np.all(np.abs(r.bias - truth) < 3 * r.sigma_bias), (r.bias - truth) / r.sigma_bias


@pytest.mark.parametrize("mounting", [ROT90Z, UPSIDE_DOWN], ids=["90deg-about-z", "upside-down"])
@pytest.mark.parametrize("seed", SEEDS)
def test_signed_permutation_mounting_is_detected(mounting, seed):
    model = model_for(seed, mounting)
    plan = Plan.standard_rate(RATE)
    sess = simulate_run(plan, model, SPEC, seed)
    r = align(sess.t, sess.g, plan)
    assert r.mounting_source == "detected" and np.array_equal(r.mounting, mounting)
    assert any("nominal mounting detected: gyro x along system" in n for n in r.notes)
    judge(r, model, SPEC, sess)
    # angles relative to the nominal mounting: the small part only (0.5 deg, scale 3e-3)
    assert np.all(np.abs(r.angles.scale - 1) < 0.02) and np.all(r.angles.psi < 1.5 * DEG)
    assert np.allclose(r.correct(sess.g[:5]), np.linalg.solve(model.M, (sess.g[:5] - r.bias).T).T, atol=2e-3)


def test_arbitrary_rotation_is_refused_undeclared_and_measured_declared(tmp_path):
    n = mounting_from_rotation(30 * DEG, [0, 0, 1])
    model = model_for(0, n)
    plan = Plan.standard_rate(RATE)
    sess = simulate_run(plan, model, SPEC, 0)
    with pytest.raises(TestError) as err:
        align(sess.t, sess.g, plan)
    line = str(err.value)
    assert "mounted at an angle" in line and "30 deg about +z" in line and "\n" not in line
    # the suggestion pasted into the plan reads back, and keeps the misalignment to measure (0.5 deg), not the
    # measured matrix (which would hide it)
    from align.io import read_toml

    f = tmp_path / "plan.toml"
    f.write_text(line.split("e.g. ", 1)[1].replace("[mounting] matrix", "[mounting]\nmatrix") + "\n" + plan.to_toml())
    declared = Plan.from_dict(read_toml(f), str(f))
    assert np.allclose(declared.nominal, n, atol=1e-4)
    r = align(sess.t, sess.g, declared)
    assert r.mounting_source == "declared" and np.allclose(r.mounting, n, atol=1e-4)
    assert 0.3 * DEG < np.max(r.angles.psi) < 1.5 * DEG
    judge(r, model, SPEC, sess)


@pytest.mark.parametrize("kind", ["rate", "angle"])
def test_fixture_reoriented_between_axes_lists_the_moves(kind):
    spec = SessionSpec(noise_density=NOISE, dwell_s=8.0, reorient=True)
    plan = Plan.standard_rate(RATE) if kind == "rate" else Plan.standard_angle(360 * DEG)
    model = model_for(1)
    sess = simulate_run(plan, model, spec, 1)
    assert len(sess.moves) == 2
    r = align(sess.t, sess.g, plan)
    assert len(r.motions) == len(sess.moves)
    for mo, truth in zip(r.motions, sess.moves):
        assert abs(mo.t_start - truth.t_start) < 1.0 and abs(mo.t_end - truth.t_end) < 1.0
        assert np.dot(mo.axis, truth.axis) > 0.999
        if kind == "angle":
            assert mo.value == pytest.approx(truth.angle, rel=0.01)
    if kind == "rate":
        judge(r, model, spec, sess)
    else:
        assert np.all(np.abs(r.M - model.M) < 3 * r.sigma_M)
    assert any("not in the plan (left out)" in n for n in r.notes)


@pytest.mark.parametrize("table_axis", ["up", "east", "north"])
@pytest.mark.parametrize("seed", SEEDS)
def test_earth_rate_with_the_table_axis_up_east_or_north(table_axis, seed):
    lat = 48.1 * DEG
    base = Plan.standard_rate(RATE)
    plan = Plan(tuple(Step(s.axis, s.sign, rate=s.rate, table_axis=table_axis) for s in base.steps), latitude=lat,
                table_axis=table_axis)
    model = model_for(seed)
    spec = SessionSpec(noise_density=0.002 * DEG_S, dwell_s=20.0)
    sess = simulate_run(plan, model, spec, seed)
    r = align(sess.t, sess.g, plan)
    judge(r, model, spec, sess, bias_truth=model.bias)
    note = next(n for n in r.notes if n.startswith("Earth rate at latitude"))
    assert "modelled the component along the spin axis" in note and "not modelled, in the uncertainty" in note


def test_east_table_axis_was_the_failing_case_and_the_vertical_guess_would_miss():
    """Before: the vertical rate was put along an east axis, biasing the bias by ~11 deg/h (6-13 sigma). The wrong
    plan's miss depends on how the fit weighs its segments: 4.4-4.6 deg/h here (4.7 sigma of the right plan; 5.1
    before issue 23, when a false bias drift was read from the right plan's static periods)."""
    lat = 48.1 * DEG
    base = Plan.standard_rate(RATE)
    plan = Plan(tuple(Step(s.axis, s.sign, rate=s.rate, table_axis="east") for s in base.steps), latitude=lat,
                table_axis="east")
    model = model_for(2)
    spec = SessionSpec(noise_density=0.002 * DEG_S, dwell_s=20.0)
    sess = simulate_run(plan, model, spec, 2)
    r = align(sess.t, sess.g, plan)
    wrong = align(sess.t, sess.g, Plan(base.steps, latitude=lat))  # the table axis left at "up"
    assert np.abs(r.bias - model.bias).max() < 3 * r.sigma_bias.max()
    assert np.abs(wrong.bias - model.bias).max() > 4 * r.sigma_bias.max()


@pytest.mark.parametrize("seed", SEEDS)
def test_angle_plan_with_latitude_models_the_static_periods(seed):
    lat = 48.1 * DEG
    plan = Plan(Plan.standard_angle(360 * DEG).steps, latitude=lat)
    model = model_for(seed)
    spec = SessionSpec(noise_density=0.002 * DEG_S, static_s=10.0)
    sess = simulate_run(plan, model, spec, seed)
    r = align(sess.t, sess.g, plan)
    assert np.all(np.abs(r.bias - model.bias) < 3 * r.sigma_bias), (r.bias - model.bias) / r.sigma_bias
    assert np.all(np.abs(r.M - model.M) < 3 * r.sigma_M)
    assert next(c for c in r.checks if c.name == "residuals").status == "pass"  # no false "bias drift" warning


def rested_session():
    """An angle plan at latitude 48.1 deg with a stated rest orientation per axis and the fixture moved between axes."""
    rests = {0: ("up", "south", "east"), 1: ("east", "up", "south"), 2: ("north", "west", "up")}
    steps = tuple(Step(s.axis, s.sign, angle=s.angle, rest=rests[s.axis]) for s in Plan.standard_angle(360 * DEG).steps)
    plan = Plan(steps, latitude=48.1 * DEG)
    model = model_for(3)
    spec = SessionSpec(noise_density=0.002 * DEG_S, static_s=10.0, reorient=True)
    return plan, model, simulate_run(plan, model, spec, 3)


def test_rest_orientation_models_the_whole_vector_in_static_periods():
    plan, model, sess = rested_session()
    r = align(sess.t, sess.g, plan)
    note = next(n for n in r.notes if n.startswith("Earth rate at latitude"))
    assert "the whole vector in" in note
    assert np.all(np.abs(r.bias - model.bias) < 3 * r.sigma_bias)


@pytest.mark.parametrize("kind", ["rate", "angle"])
def test_log_that_starts_moving_at_sample_zero(kind):
    plan = Plan.standard_rate(RATE) if kind == "rate" else Plan.standard_angle(360 * DEG)
    spec = SessionSpec(noise_density=NOISE, dwell_s=8.0, head_s=0.0)
    model = model_for(0)
    sess = simulate_run(plan, model, spec, 0)
    assert np.abs(sess.w[0]).max() > 0  # moving at the first sample
    r = align(sess.t, sess.g, plan)
    assert r.segments[0].start < int(1.0 * spec.fs)  # right after the first ramp
    assert np.all(np.abs(r.M - model.M) < 3 * r.sigma_M)


@pytest.mark.parametrize("seed", range(6))
def test_two_axis_never_turned_scale_is_assumed_and_covered(seed):
    rng = np.random.default_rng(seed)
    model = random_model(rng, 0.5 * DEG, scale_sd=4e-3)
    plan = Plan(Plan.standard_rate(RATE).steps[:4])  # x and y only: z never turned
    sess = simulate_run(plan, model, SPEC, seed)
    r = align(sess.t, sess.g, plan, AlignOptions(scale_spec=0.01))
    assert r.method == "two-axis" and r.inferred_axis == 2
    assert abs(r.M[2, 2] - model.M[2, 2]) < 3 * r.sigma_M[2, 2]
    assert r.sigma_M[2, 2] > 0.0099  # the stated scale spec (1 %) is in it
    status = {c.name: c.status for c in r.checks}
    assert status["scale z"] == "not checked" and "z" not in next(c.detail for c in r.checks if c.name == "scale")
    assert r.to_dict()["angles"]["assumed_scale"] == "z"


def test_reversed_gyro_is_still_a_handedness_error():
    model = model_for(0)
    flipped = SensorModel(np.diag([1.0, -1.0, 1.0]) @ model.M, model.bias)  # a mirror is no mounting: built by hand
    plan = Plan.standard_rate(RATE)
    sess = simulate_run(plan, flipped, SPEC, 0)
    with pytest.raises(HandednessError, match="y gyro reads backwards"):
        align(sess.t, sess.g, plan)


def test_saturation_without_a_range_is_not_checked():
    plan = Plan.standard_rate(RATE)
    sess = simulate_run(plan, model_for(0), SPEC, 0)
    r = align(sess.t, sess.g, plan)
    assert next(c for c in r.checks if c.name == "saturation").status == "not checked"


def test_step_missing_from_the_log_is_named():
    plan = Plan.standard_rate(RATE)
    run = Plan(plan.steps[:3] + plan.steps[4:])  # step 4 (-y) never run
    sess = simulate_run(run, model_for(0), SPEC, 0)
    with pytest.raises(TestError, match=r"step 4 \(\+y at -100 deg/s\) not found after step 3") as err:
        align(sess.t, sess.g, plan)
    assert "\n" not in str(err.value)


@pytest.mark.slow
def test_the_reoriented_example_is_found_and_covered(run_cli, tmp_path):
    """examples/alignment/reoriented: mounting detected, moves left out, east table axis, ms time, drifting bias."""
    import json

    from support import ROOT

    here = ROOT / "examples/alignment/reoriented"
    out = tmp_path / "out.json"
    res = run_cli("matrix", here / "session.csv", "--plan", here / "plan.toml", "--json", out, "--plot",
                  tmp_path / "seg.png")
    assert res.code == 0, res.err
    r, truth = json.loads(out.read_text()), json.loads((here / "truth.json").read_text())
    assert np.all(np.abs(np.array(r["M"]) - truth["M"]) < 3 * np.array(r["uncertainty"]["M"]))
    assert r["mounting"]["axes"] == ["+y", "-x", "+z"] and r["mounting"]["source"] == "detected"
    assert len(r["motions"]) == len(truth["moves"]) == 2
    assert r["inputs"]["time_units"] == "ms"
    assert (tmp_path / "seg.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_explicit_segments_with_rest_orientations_and_fixture_moves():
    """Explicit segments (from the simulator's own pieces): the moves between them are found, so a static period
    before a move is not modelled with the next step's rest (review of issue 12: residuals of 20 deg/h)."""
    from align.alignment.segment import Segment

    plan, model, sess = rested_session()
    segs = []
    for p in sess.pieces:
        if p.kind == "static" and p.end - p.start > 200:
            segs.append(Segment(f"static {len(segs)}", "static", p.start + 100, p.end - 100))
        elif p.kind == "step":
            segs.append(Segment(f"step {p.step + 1}", "angle", p.start - 20, p.end + 20, p.step))
    r = align(sess.t, sess.g, plan, segments=segs)
    assert len(r.motions) == len(sess.moves) == 2
    note = next(n for n in r.notes if n.startswith("Earth rate at latitude"))
    whole = int(note.split("the whole vector in ")[1].split()[0])
    assert whole == sum(1 for s in segs if s.kind == "static") - 2 - 1  # not before a move, nor the last one
    assert np.all(np.abs(r.bias - model.bias) < 3 * r.sigma_bias)
    assert np.all(np.abs(r.M - model.M) < 3 * r.sigma_M)
