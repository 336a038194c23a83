"""Pictures a colleague can read (issue 28): no two labels of a picture overlap (the 37 rotation labels of
``calibrate gyro --plot``, the Allan plot's asymptote labels), and ``calibrate accel --plot`` draws the calibrated
|a| in m/s^2, not |a| of the raw counts. Overlap is measured here on the drawn figure: each label's extent in the
figure's pixels, as matplotlib's renderer lays it out."""

import base64

import numpy as np
import pytest

from align.units import DEG, STANDARD_GRAVITY

DOT = base64.b64decode("iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAAAAAA6fptVAAAACklEQVR4nGNgAAAAAgABSK+kcQAAAABJRU5ErkJggg==")


@pytest.fixture
def drawn(monkeypatch):
    """The figures a module hands to ``png_bytes`` (kept open to be measured), closed afterwards."""
    figs: list = []

    def capture(module):
        monkeypatch.setattr(module, "png_bytes", lambda fig, *a, **k: figs.append(fig) or DOT)
        return figs

    yield capture
    import matplotlib.pyplot as plt

    for fig in figs:
        plt.close(fig)


def _overlaps(texts) -> list[tuple[str, str]]:
    """Pairs of visible, non-empty texts whose drawn extents intersect."""
    shown = [t for t in texts if t.get_visible() and t.get_text().strip()]
    if not shown:
        return []
    renderer = shown[0].get_figure().canvas.get_renderer()
    boxes = [t.get_window_extent(renderer) for t in shown]
    return [(shown[i].get_text(), shown[j].get_text()) for i in range(len(shown)) for j in range(i + 1, len(shown))
            if boxes[i].x0 < boxes[j].x1 and boxes[j].x0 < boxes[i].x1 and boxes[i].y0 < boxes[j].y1
            and boxes[j].y0 < boxes[i].y1]


def test_the_37_rotations_of_a_gyro_session_are_labelled_without_overlap(drawn):
    """38 poses after a 200 s rest, 3 s poses and 2 s rotations (a crowded but ordinary session)."""
    import align.present.gyroplot as gyroplot

    figs = drawn(gyroplot)
    fs, head, pose, turn = 20.0, 200.0, 3.0, 2.0
    t = np.arange(0.0, head + 37 * (pose + turn) + 1.0, 1 / fs)
    poses, rows = [(0, int(head * fs))], []
    rate = np.zeros((len(t), 3))
    for k in range(37):
        t0 = head + k * (pose + turn)
        rows.append({"rotation": k + 1, "t_s": [t0, t0 + turn], "turn_deg": 60.0 + 2 * k, "axis": [0.0, 0.0, 1.0],
                     "residual_deg": 1.17 if k == 1 else 0.05 + 0.01 * (k % 7), "used": True})
        inside = (t >= t0) & (t < t0 + turn)
        rate[inside, 2] = (60.0 + 2 * k) * DEG / turn
        poses.append((int((t0 + turn) * fs), int((t0 + turn + pose) * fs)))
    acc = np.tile([0.0, 0.0, STANDARD_GRAVITY], (len(t), 1))
    gyroplot.gyro_session_png(t, acc, rate, poses, rows, STANDARD_GRAVITY)
    (fig,) = figs
    top, low, *_ = fig.axes
    assert _overlaps(low.texts) == [] and _overlaps(top.texts) == []
    numbers = sorted(int(s.get_text().split()[0]) for s in low.texts)
    assert numbers == list(range(1, 38)) or "numbered, no room for more" in low.get_title()
    assert sorted(int(s.get_text()) for s in top.texts) == list(range(1, 39))
    assert any("largest residual 1.17 deg, rotation 2" in ax.get_title() for ax in fig.axes)  # the terminal's figure


def _allan_job():
    from align.noise.job import run_allan
    from align.noise.sim import NoiseSpec, simulate_noise
    from align.units import parse_quantity as q
    from align.units import to_unit

    spec = NoiseSpec(white=q("0.3 deg/sqrt(h)", "angle_random_walk"), flicker=q("5 deg/h", "angular_rate"))
    data = [to_unit(simulate_noise(20_000, 100.0, spec, 3, 0), "deg/s")]
    return run_allan(data, 100.0, ["gyro_x", "gyro_y", "gyro_z"], "deg/s")


def test_the_allan_plot_s_asymptote_labels_do_not_overlap(drawn):
    """Three gyros of the same noise: their N and B asymptotes lie on top of each other, and so did their labels."""
    import align.present.plots as plots

    figs = drawn(plots)
    job = _allan_job()
    assert sum(f.identifiable[1] for f in job.fits) == 3  # N of every channel: three asymptotes to label
    plots.allan_plot_png(job)
    (fig,) = figs
    ax = fig.axes[0]
    assert _overlaps(ax.texts) == []
    legend = ax.get_legend().get_window_extent(fig.canvas.get_renderer())
    for text in ax.texts:
        box = text.get_window_extent(fig.canvas.get_renderer())
        assert not box.overlaps(legend)
    named = " ".join(t.get_text() for t in ax.texts)
    for f, name in zip(job.fits, ("x", "y", "z")):  # every identified term of every channel is still named
        for k, symbol in enumerate("QNBKR"):
            if f.identifiable[k] and f.params[k] > 0:
                assert any(name in t.get_text().split() and symbol in t.get_text().split() for t in ax.texts), named


def _counts_session():
    """A multi-position accelerometer session in counts of known truth (M in counts per m/s^2, bias in counts)."""
    from align.calibration.posesim import PoseSessionSpec, simulate_poses

    rng = np.random.default_rng(7)
    m_a = np.array([[1650.0, -0.8, 28.0], [1.5, 1660.0, 19.0], [-2.0, 3.0, 1671.0]])
    b_a = np.array([-193.5, -17.5, -104.4])
    spec = PoseSessionSpec(fs=50.0, poses=14, init_s=8.0, pose_s=2.5, turn_s=1.5, accel_noise=0.002 * 1660)
    return simulate_poses(spec, m_a, b_a, np.eye(3), np.zeros(3), rng)


def test_the_accelerometer_picture_draws_the_calibrated_magnitude_in_m_s2(drawn):
    import align.present.calplots as calplots
    from align.calibration.accel import session_intervals
    from align.calibration.results import Calibration

    figs = drawn(calplots)
    s = _counts_session()
    truth = Calibration("accelerometer", s.M_a, s.b_a, np.zeros((3, 3)), np.zeros(3), "counts", "truth")
    intervals = session_intervals(s.t, s.acc, None)
    calplots.accel_statics_png(s.t, s.acc, intervals, "counts", calibration=truth, gravity=STANDARD_GRAVITY)
    (fig,) = figs
    low = fig.axes[1]
    assert low.get_ylabel() == "|a| [m/s^2]"
    y = np.concatenate([line.get_ydata() for line in low.lines if line.get_label() == "|a| calibrated"])
    at_rest = np.concatenate([np.linalg.norm(s.attitude[a:b] @ [0, 0, STANDARD_GRAVITY], axis=1) for a, b in s.poses])
    assert np.median(y) == pytest.approx(np.median(at_rest), abs=0.02)  # gravity, not 16,000 counts
    assert _overlaps(fig.axes[0].texts) == []


def test_calibrate_accel_plot_draws_the_calibrated_magnitude(drawn, tmp_path, capsys):
    from support import run_in_process

    import align.present.calplots as calplots
    from align.io import write_csv

    figs = drawn(calplots)
    s = _counts_session()
    log = tmp_path / "acc.csv"
    write_csv(log, ["time", "acc_x", "acc_y", "acc_z"], np.column_stack([s.t, np.round(s.acc)]))
    res = run_in_process(capsys, "calibrate", "accel", log, "--accel-units", "counts", "--plot", tmp_path / "a.png")
    assert res.code == 0, res.err
    low = figs[0].axes[1]
    assert low.get_ylabel() == "|a| [m/s^2]"
    y = np.concatenate([line.get_ydata() for line in low.lines if line.get_label() == "|a| calibrated"])
    assert np.median(y) == pytest.approx(STANDARD_GRAVITY, abs=0.02)
