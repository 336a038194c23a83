"""The segmentation picture: what it shades, against the simulator's truth; the PNG; the report; a long log."""

import base64
import io
import re
import time

import numpy as np
import pytest

from align.alignment.job import align
from align.alignment.plan import Plan, Step
from align.alignment.segment import Motion, Segment
from align.alignment.simulate import SessionSpec, random_model, simulate_session
from align.errors import InputError
from align.present.plots import segmentation_plot_png, segmentation_spans
from align.units import DEG

SPEC = SessionSpec(fs=200.0, dwell_s=4.0, static_s=2.0)


def _runs(mask):
    """(start, end exclusive) of the runs of True."""
    edges = np.flatnonzero(np.diff(np.concatenate(([0], mask.astype(np.int8), [0]))))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist()))


def _session(plan, seed=0, spec=SPEC):
    rng = np.random.default_rng(seed)
    t, g, w = simulate_session(plan, random_model(rng, 0.5 * DEG), spec, rng)
    return t, g, w


@pytest.fixture(scope="module")
def rate_session():
    plan = Plan.standard_rate(100 * DEG)
    t, g, w = _session(plan)
    return t, g, w, align(t, g, plan)


@pytest.fixture(scope="module")
def angle_session():
    plan = Plan.standard_angle(360 * DEG)
    t, g, w = _session(plan, seed=1)
    return t, g, w, align(t, g, plan)


def _truth(w, peak=None):
    """From the simulator's true rate w: the runs at rest, the runs moving, and (given the plan's peak rate) the
    constant-rate dwells and the ramps (0 < |w| < peak)."""
    speed = np.linalg.norm(w, axis=1)
    truth = {"rest": _runs(speed == 0), "moving": _runs(speed > 0)}
    if peak is not None:
        truth["dwell"] = _runs(np.isclose(speed, peak, rtol=1e-12, atol=0))
        truth["ramp"] = _runs((speed > 0) & ~np.isclose(speed, peak, rtol=1e-12, atol=0))
    return truth


def _inside(span, runs, t, tol):
    return any(t[a] - tol <= span.t_start and span.t_end <= t[b - 1] + tol for a, b in runs)


@pytest.mark.slow
def test_png_is_a_picture_of_sensible_size(rate_session):
    from PIL import Image

    t, g, _, r = rate_session
    png = segmentation_plot_png(t, g, r)
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    img = Image.open(io.BytesIO(png))
    img.load()
    assert 900 < img.size[0] < 2500 and 500 < img.size[1] < 1600
    assert segmentation_plot_png(t, g, r) == png  # deterministic


def test_rate_session_spans_follow_the_simulated_table(rate_session):
    t, g, w, r = rate_session
    spans = segmentation_spans(t, g, r)
    dt = 1 / SPEC.fs
    truth = _truth(w, 100 * DEG)
    steps = [s for s in spans if s.kind == "step"]
    assert len(truth["dwell"]) == 6 and len(steps) == 6
    for k, (s, (a, b)) in enumerate(zip(steps, truth["dwell"])):
        assert t[a] - dt <= s.t_start and s.t_end <= t[b - 1] + dt      # inside the true dwell of step k
        assert s.t_end - s.t_start >= (b - a) * dt - 0.5                 # and covers nearly all of it
        assert s.label == f"{k + 1}: {['+x', '+y', '+z'][k // 2]} {'-' if k % 2 else ''}100 deg/s"
    statics = [s for s in spans if s.kind == "static"]
    assert statics and all(_inside(s, truth["rest"], t, dt) for s in statics)
    ramps = [s for s in spans if s.kind == "ramp"]
    assert ramps and all(_inside(s, truth["moving"], t, 0.1) for s in ramps)  # 0.1 s: the detector's window
    for a, b in truth["ramp"]:  # every true ramp is marked
        mid = t[(a + b) // 2]
        assert any(s.t_start <= mid <= s.t_end for s in ramps), f"ramp at {mid:.2f} s not marked"


def test_angle_session_turns_and_statics_follow_the_simulated_table(angle_session):
    t, g, w, r = angle_session
    spans = segmentation_spans(t, g, r)
    dt = 1 / SPEC.fs
    truth = _truth(w)
    steps = [s for s in spans if s.kind == "step"]
    assert len(truth["moving"]) == 6 and len(steps) == 6
    for k, (s, (a, b)) in enumerate(zip(steps, truth["moving"])):
        assert s.t_start <= t[a] + dt and t[b - 1] - dt <= s.t_end         # the whole turn, ramps included
        assert s.t_end - s.t_start <= (b - a) * dt + 2 * SPEC.static_s
        assert s.label == f"{k + 1}: {['+x', '+y', '+z'][k // 2]} {'-' if k % 2 else ''}360 deg"
    statics = [s for s in spans if s.kind == "static"]
    assert len(statics) == 7 and all(_inside(s, truth["rest"], t, dt) for s in statics)
    assert not [s for s in spans if s.kind == "ramp"]  # every moving sample is inside a turn


def _drawn(monkeypatch, t, g, r):
    """The figure as drawn: {legend label of a shaded collection: list of (t0, t1)} in the gyro-trace panel."""
    import matplotlib.figure

    figs = []
    original = matplotlib.figure.Figure.savefig
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", lambda self, *a, **k: (figs.append(self), original(self, *a, **k)))
    segmentation_plot_png(t, g, r)
    ax = figs[0].axes[1]
    out = {}
    for c in ax.collections:
        out[c.get_label()] = sorted((float(p.vertices[:, 0].min()), float(p.vertices[:, 0].max())) for p in c.get_paths())
    return out


@pytest.mark.slow
def test_the_picture_shades_one_span_per_segment_and_motion(monkeypatch):
    """A session with a 90 deg re-orientation about z between the plan's steps 2 and 3 (truth from the simulator):
    the motion is drawn hatched and labelled, each step and static period shaded once, at its times."""
    plan = Plan.standard_rate(100 * DEG)
    steps = list(plan.steps)
    full = Plan(tuple(steps[:2] + [Step(2, 1, angle=90 * DEG)] + steps[2:]))
    t, g, w = _session(full, seed=2)
    truth = _truth(w)
    trim = int(0.2 * SPEC.fs)
    speed = np.linalg.norm(w, axis=1)
    moving = truth["moving"]
    segs = []
    for k, (a, b) in enumerate(moving[:2] + moving[3:]):  # the plan's dwells, from the truth
        dwell = _runs(np.isclose(speed[a:b], 100 * DEG, rtol=1e-12, atol=0))[0]
        segs.append(Segment(f"step {k + 1} ({plan.steps[k].label})", "rate", a + dwell[0] + trim, a + dwell[1] - trim, k))
    segs += [Segment(f"static {k + 1}", "static", a + trim, b - trim) for k, (a, b) in enumerate(truth["rest"])]
    r = align(t, g, plan, segments=segs)
    a, b = moving[2]
    motion = Motion("motion 1", "turn", a, b, float(t[a]), float(t[b - 1]), np.pi / 2, (0.0, 0.0, 1.0), "+z through 90 deg")
    r = r.replace(motions=(motion,))
    spans = segmentation_spans(t, g, r)
    [m] = [s for s in spans if s.kind == "motion"]
    assert (m.t_start, m.t_end, m.label) == (t[a], t[b - 1], "ignored: about +z 90 deg")
    assert not any(s.kind == "ramp" and s.t_start < m.t_end and m.t_start < s.t_end for s in spans)
    drawn = _drawn(monkeypatch, t, g, r)
    by_label = {"plan step (dwell or turn)": "rate", "static period": "static"}
    for label, kind in by_label.items():
        want = sorted((s.t_start, s.t_end) for s in r.segments if s.kind == kind)
        assert np.allclose(drawn[label], want)
    assert np.allclose(drawn["motion that no step claimed (ignored)"], [(t[a], t[b - 1])])
    assert len(drawn["ramp (moving, not used)"]) == sum(s.kind == "ramp" for s in spans)


def test_bad_input_is_one_line(rate_session):
    t, g, _, r = rate_session
    with pytest.raises(InputError, match=r"shape .*expected \(n,\) and \(n, 3\)"):
        segmentation_plot_png(t, g[:, :2], r)
    with pytest.raises(InputError):
        segmentation_plot_png(t, g, r, units="m/s")


@pytest.mark.slow
def test_the_report_holds_the_picture_when_a_log_and_plan_are_given(tmp_path):
    from PIL import Image

    from align.present.story import build_report, demo_inputs

    inp = demo_inputs(tmp_path)
    alt = "gyro traces with the plan steps"
    page, summary, _ = build_report(inp["mount"], inp["manoeuvre"], log=inp["log"], plan=inp["plan"], monte_carlo=0)
    section = page[page.index("<h2>Electronic alignment</h2>"):]
    found = re.search(rf'<img alt="{alt}[^"]*" src="data:image/png;base64,([^"]+)"', section)
    assert found
    img = Image.open(io.BytesIO(base64.b64decode(found.group(1))))
    img.load()
    assert img.size[0] > 900
    page, _, _ = build_report(inp["mount"], inp["manoeuvre"], monte_carlo=0)
    assert alt not in page


@pytest.mark.slow
def test_a_million_samples_draw_in_under_three_seconds():
    plan = Plan.standard_rate(100 * DEG)
    t, g, _ = _session(plan, seed=3, spec=SessionSpec(fs=2000.0, dwell_s=80.0, static_s=3.0))
    assert len(t) >= 1_000_000
    r = align(t, g, plan)
    segmentation_plot_png(t[:2000], g[:2000], r.replace(segments=(), motions=()))  # matplotlib imported
    start = time.perf_counter()
    png = segmentation_plot_png(t, g, r)
    assert time.perf_counter() - start < 3.0
    assert png[:4] == b"\x89PNG"
