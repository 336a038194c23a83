"""The report's thermal section (issue 25): ``imu-align report --calibration THERMAL.json`` shows per sensor the
numbers of the result file, a picture of both branches with the fitted curve and its band, and still reports (in
one sentence) when the log the result names is gone.

The log is written here from its own description (a chamber: soak, ramp up, soak, ramp down, soak; a gyro whose
bias is a known quadratic in temperature, read higher by ``H`` while heating than while cooling); the numbers
shown are compared with the result file as JSON, and the picture with the known hysteresis."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from align.calibration.thermal import calibrate_thermal
from align.io.formats import LogFormat
from align.results import save_result

RATE_HZ = 5.0
#: heating minus cooling at equal temperature, deg/s
H = 0.004
NOISE = 5e-4


def _chamber_csv(path) -> None:
    """soak 200 s at 0 C, up at 0.05 C/s to 50 C, soak 200 s, down at 0.05 C/s, soak 200 s; gyro in deg/s."""
    t = np.arange(0.0, 2600.0, 1 / RATE_HZ)
    temp = np.interp(t, [0, 200, 1200, 1400, 2400, 2600], [0, 0, 50, 50, 0, 0])
    state = np.where(t < 1300, 1.0, -1.0)  # heating until the top soak's middle, cooling after
    d = temp - 25.0
    bias = np.array([0.01, -0.02, 0.005])[None, :] + np.outer(d, [2e-4, -1e-4, 5e-5]) + np.outer(d * d, [-3e-6, 2e-6, 1e-6])
    rng = np.random.default_rng(7)
    gyro = bias + np.outer(state, [H / 2] * 3) + rng.normal(0.0, NOISE, bias.shape)
    with open(path, "w") as fh:
        fh.write("time,gyro_x,gyro_y,gyro_z,temperature\n")
        for row in np.column_stack([t, gyro, temp + rng.normal(0, 0.005, len(t))]):
            fh.write(",".join(repr(float(v)) for v in row) + "\n")


@pytest.fixture(scope="module")
def thermal(tmp_path_factory):
    folder = tmp_path_factory.mktemp("thermal")
    log = folder / "chamber.csv"
    _chamber_csv(log)
    res = calibrate_thermal(log=log, temperature_column="temperature", format=LogFormat(time_units="s"),
                            sensors=("gyroscope",), max_order=3)
    path = folder / "thermal.json"
    save_result(path, res)
    return folder, log, path


class _Drawn:
    """Keeps the figures handed to ``png_bytes`` open, to be measured (a small real PNG still returned)."""

    def __init__(self):
        self.figs: list = []

    def __call__(self, fig, *a, **k) -> bytes:
        import io

        self.figs.append(fig)
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=40)
        return buf.getvalue()

    def close(self) -> None:
        import matplotlib.pyplot as plt

        for f in self.figs:
            plt.close(f)


def _report(path):
    """``build_report`` of one calibration file: (page, terminal text, the figures drawn)."""
    import align.present.figures as figures
    from align.present.story import build_report

    drawn = _Drawn()
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(figures, "png_bytes", drawn)
        page, text, _ = build_report(calibrations=[path])
    return page, text, drawn


@pytest.fixture(scope="module")
def reported(thermal):
    page, text, drawn = _report(thermal[2])
    yield page, text, drawn.figs
    drawn.close()


def _section(page: str) -> str:
    start = page.index("Thermal calibration: gyroscope")
    end = page.find("<h2", start)
    return page[start:end if end > 0 else None]


def _rows(section: str) -> dict[str, list[str]]:
    rows = re.findall(r"<tr>(.*?)</tr>", section)
    out = {}
    for r in rows:
        cells = [re.sub(r"<[^>]+>", "", c) for c in re.findall(r"<td[^>]*>(.*?)</td>", r)]
        if cells and cells[0] in ("x", "y", "z"):
            out[cells[0]] = cells
    return out


def _number(text: str) -> float:
    return float(re.match(r"\s*([+-]?[0-9.]+(?:e[+-]?\d+)?)", text).group(1))


def _drawn_texts(fig) -> list:
    """Every text the figure draws: titles, axis labels, the tick labels inside the view, legends."""
    texts = list(fig.texts)
    for leg in fig.legends:
        texts += leg.get_texts()
    for ax in fig.axes:
        texts += [ax.title, ax.xaxis.label, ax.yaxis.label, ax.yaxis.get_offset_text(), *ax.texts]
        for axis, (lo, hi) in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
            texts += [tick.label1 for tick in axis.get_major_ticks() if min(lo, hi) <= tick.get_loc() <= max(lo, hi)]
    return [t for t in texts if t.get_visible() and t.get_text().strip()]


def _overlaps(fig) -> list:
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    texts = _drawn_texts(fig)
    boxes = [t.get_window_extent(renderer) for t in texts]
    return [(texts[i].get_text(), texts[j].get_text()) for i in range(len(texts)) for j in range(i + 1, len(texts))
            if boxes[i].overlaps(boxes[j])]


def test_the_section_shows_the_numbers_of_the_result_file(thermal, reported):
    path = thermal[2]
    page, text, _ = reported
    d = json.loads(path.read_text())["gyroscope"]
    sec = _section(page)
    assert f"{d['reference_temperature']:.2f} C" in sec
    lo, hi = d["valid_range"]
    assert f"{lo:.2f} to {hi:.2f} C" in sec
    assert f"{d['branches']['heating']:,} heating" in sec and f"{d['branches']['cooling']:,} cooling" in sec
    rows = _rows(sec)
    assert sorted(rows) == ["x", "y", "z"]
    for ax in d["axes"]:
        cells = rows[ax["axis"]]
        assert int(cells[1]) == ax["order"]
        h = ax["hysteresis"]
        value, sigma = (float(v) for v in re.findall(r"[+-]?[0-9.]+(?:e[+-]?\d+)?", cells[3])[:2])
        assert value == pytest.approx(h["value"], rel=1e-3) and sigma == pytest.approx(h["sigma"], rel=0.05)
        assert value == pytest.approx(H, abs=max(5 * sigma, 0.2 * H))  # the chamber's hysteresis, read off the page
        res = ax["residual"]
        shown = [_number(c) for c in cells[4:8]]
        want = [res["before"]["rms"], res["after"]["rms"], res["before"]["largest"], res["after"]["largest"]]
        assert shown == pytest.approx(want, rel=1e-3)
        assert ("no" if ax["lag_coefficient"] is None else f"{ax['lag_coefficient']:+.4g}") in cells[2]
    assert "<img" in sec and "gyroscope thermal calibration" in text


def test_both_branches_the_curve_and_its_band_are_drawn_without_overlapping_labels(thermal, reported):
    path = thermal[2]
    page, _, drawn = reported
    assert "heating" in _section(page) and "cooling" in _section(page)
    (fig,) = drawn
    top = [ax for ax in fig.axes if "axis: order" in ax.get_title()]
    assert len(top) == 3
    d = json.loads(path.read_text())["gyroscope"]
    for ax, model in zip(top, d["axes"]):
        lines = {ln.get_label(): ln for ln in ax.get_lines()}
        heat, cool = lines["heating"], lines["cooling"]
        assert len(heat.get_xdata()) > 100 and len(cool.get_xdata()) > 100
        curve = lines["fitted static curve"]

        def off(line, curve=curve):  # reading less the fitted curve at the point's temperature
            return np.asarray(line.get_ydata()) - np.interp(line.get_xdata(), curve.get_xdata(), curve.get_ydata())

        assert off(heat).mean() - off(cool).mean() == pytest.approx(H, rel=0.25)
        (band,) = [c for c in ax.collections if c.get_label() == "band (1-sigma)"]
        verts = band.get_paths()[0].vertices
        for where in (0.3, 0.5, 0.9):  # across the range: the band's width is twice the file's 1-sigma
            at = verts[np.argmin(np.abs(verts[:, 0] - np.interp(where, [0, 1], d["valid_range"]))), 0]
            x = (at - d["reference_temperature"]) ** np.arange(model["order"] + 1)
            cov = np.array(model["covariance"])[:len(x), :len(x)]
            sigma = float(np.sqrt(x @ cov @ x))  # the file's covariance, evaluated here
            assert np.ptp(verts[verts[:, 0] == at, 1]) == pytest.approx(2 * sigma, rel=1e-3)
    assert _overlaps(fig) == []


def test_a_result_whose_log_is_gone_still_reports_in_one_sentence(thermal, tmp_path):
    path = thermal[2]
    moved = tmp_path / "moved.json"
    d = json.loads(path.read_text())
    d["inputs"]["log"] = str(tmp_path / "gone.csv")
    moved.write_text(json.dumps(d))
    page, text, drawn = _report(moved)
    sec = _section(page)
    notes = re.findall(r'<p class="note">([^<]*could not be read again[^<]*)</p>', sec)
    assert len(notes) == 1 and notes[0].count(". ") == 0 and notes[0].endswith(".")
    assert "gone.csv" in notes[0]
    assert sorted(_rows(sec)) == ["x", "y", "z"] and "<img" in sec
    (fig,) = drawn.figs
    axes = [ax for ax in fig.axes if ax.get_title()]
    assert len(axes) == 3 and all({ln.get_label() for ln in ax.get_lines()} == {"fitted static curve"} for ax in axes)
    assert "could not be read again" in text
    drawn.close()


def test_the_figures_of_merit_of_the_file_are_shown_with_their_verdicts(thermal, tmp_path):
    """A result file carrying judged figures (as a job writes them into the envelope): each figure is a row of the
    report's figures-of-merit table of the result, with its limit and verdict, once."""
    path = thermal[2]
    d = json.loads(path.read_text())
    d["figures_of_merit"] = [
        {"name": "bias_x", "sensor": "gyroscope", "value": 1.5e-4, "sigma": 2e-6, "unit": "rad/s",
         "title": "bias at the reference temperature", "method": "thermal fit", "test": "calibrate thermal",
         "status": "WARN", "limit": "|bias_x| <= 0.01 deg/s (limits.toml)", "detail": "within the guard band"},
        {"name": "bias_y", "sensor": "accelerometer", "value": 0.01, "sigma": 1e-4, "unit": "m/s^2",
         "title": "bias", "method": "", "test": "", "status": "PASS", "limit": "", "detail": "another sensor's"}]
    judged = tmp_path / "judged.json"
    judged.write_text(json.dumps(d))
    page, _, drawn = _report(judged)
    drawn.close()
    rows = [re.sub(r"<[^>]+>", "|", r) for r in re.findall(r"<tr>(.*?)</tr>", page) if "|bias_x|" in
            re.sub(r"<[^>]+>", "|", r)]
    assert len(rows) == 1 and "|bias_x|" in rows[0] and "WARN" in rows[0] and "limits.toml" in rows[0]
    assert "0.00859" in rows[0]  # 1.5e-4 rad/s shown in deg/s
