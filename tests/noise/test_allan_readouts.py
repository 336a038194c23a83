"""What an Allan job tells an engineer: one vocabulary, values only where identified, pooled runs, no false floor.

Truth from outside the code: allantools' overlapping Allan deviation of each simulated run (the pooled
variance is their mean for runs of equal length), the IEEE Std 952 letters and names, the closed form of
the flicker floor ``sqrt(2 ln 2 / pi) B``.
"""

import copy
import json

import numpy as np
import pytest

from align.units import parse_quantity as q
from align.units import to_unit

ARW, BI = q("0.3 deg/sqrt(h)", "angle_random_walk"), q("5 deg/h", "angular_rate")


def _runs(k=2, n=20_000, fs=100.0, units="deg/s"):
    from align.noise.sim import NoiseSpec, simulate_noise

    spec = NoiseSpec(white=ARW, flicker=BI)
    return [to_unit(simulate_noise(n, fs, spec, 3, seed), units) for seed in range(k)]


def _job(k=2, units="deg/s", n=20_000):
    from align.noise.job import run_allan

    return run_allan(_runs(k, n, units=units), 100.0, ["x", "y", "z"], units).replace(
        inputs=tuple(f"run{i}.csv" for i in range(k)))


def test_one_table_names_the_five_terms_with_their_ieee_letters():
    from align.noise.model import NOISE_ALPHA, TERM_TABLE, TERMS, term

    assert [t.key for t in TERM_TABLE] == list(TERMS)
    assert [t.symbol for t in TERM_TABLE] == ["Q", "N", "B", "K", "R"]
    assert [t.name() for t in TERM_TABLE] == ["quantization", "angle random walk", "bias instability",
                                              "rate random walk", "rate ramp"]
    assert term("white").name("accelerometer") == "velocity random walk"
    assert term("random_walk").name("accelerometer") == "acceleration random walk"
    for name in ("white", "N", "angle_random_walk", "velocity_random_walk"):
        assert term(name).key == "white"
    assert term("flicker").unit() == "deg/h" and term("flicker").unit("accelerometer") == "ug"
    assert NOISE_ALPHA == {"quantization": 2, "white": 0, "flicker": -1, "random_walk": -2, "ramp": -2}


def test_pooled_curve_is_the_mean_allan_variance_with_summed_edf():
    """Two equal runs: the pooled AVAR is the mean of allantools' AVAR of each run; its EDF the sum of theirs."""
    import allantools

    from align.noise.job import AllanJob

    runs = _runs(2)
    job = _job(2)
    r = job.result
    avars = []
    for run in runs:
        _, ad, _, _ = allantools.oadev(run[:, 0], rate=100.0, data_type="freq", taus=r.tau)
        avars.append(ad**2)
    assert np.allclose(to_unit(r.adev[0], "deg/s") ** 2, np.mean(avars, axis=0), rtol=1e-9)
    assert job.pooled and len(job.run_results) == 2 and len(job.run_fits) == 2
    assert np.array_equal(job.run_results[0].m, r.m)
    assert np.allclose(r.edf, job.run_results[0].edf + job.run_results[1].edf)
    d = job.to_dict()
    assert "pooled" in d and len(d["per_run"]) == 2 and d["adev_of"].startswith("pooled curve of 2 runs")
    back = AllanJob.from_dict(json.loads(json.dumps(d)))
    assert back.pooled and np.allclose(back.run_results[1].adev, job.run_results[1].adev, rtol=1e-12)


def test_runs_of_different_lengths_share_the_shorter_grid():
    from align.noise.job import run_allan

    a, b = _runs(2, n=20_000)
    job = run_allan([a, b[:8_000]], 100.0, ["x", "y", "z"], "deg/s")
    assert job.result.tau[-1] <= (8_000 - 1) // 2 / 100.0
    assert all(np.array_equal(rr.m, job.result.m) for rr in job.run_results)


def test_version_1_files_still_read():
    """A file of version 1 (internal term names, value and sigma of every term) reads to the same fit."""
    from align.noise.job import AllanJob
    from align.noise.model import term

    job = _job(1)
    d = job.to_dict()
    old = copy.deepcopy(d)
    old["version"] = 1
    old["units"]["terms"] = {term(k).key: u for k, u in d["units"]["terms"].items()}
    for fit in old["fit"].values():
        fit["terms"] = {term(k).key: {"value": t["estimate"], "sigma": t["estimate_sigma"], "unit": t["unit"],
                                      "identifiable": t["identifiable"]} for k, t in fit["terms"].items()}
        fit["dominant"] = [term(k).key for k in fit["dominant"]]
        fit["ieee_point_readouts"] = {k: fit["ieee_point_readouts"][k] for k in (
            "N_at_tau_1s", "N_unit", "B_floor_over_0.664", "B_unit", "K_at_tau_3s", "K_unit")}
        fit.pop("more_si", None)
    for key in ("noise_type_alpha", "edf", "edf_mdev"):
        old.pop(key, None)
    back = AllanJob.from_dict(old, "old.json")
    for a, b in zip(back.fits, job.fits):
        assert np.allclose(a.params, b.params, rtol=1e-12) and a.identifiable == b.identifiable
        assert a.dominant == b.dominant


def test_summary_shows_values_only_where_identified_in_engineering_units():
    from align.present.text import allan_summary

    job = _job(2)
    text = allan_summary(job)
    assert "angle random walk" in text and "bias instability" in text and "rate random walk" in text
    assert "white" not in text and "flicker" not in text
    assert "(not identifiable)" not in text and "never more than" not in text and "(SI)" not in text
    assert "pooled curve" in text and "run run1.csv" in text
    d = job.to_dict()
    for fit in d["fit"].values():
        for t in fit["terms"].values():
            if t["identifiable"]:
                assert t["value"] is not None and f"{t['value']:.4g} ±" in text
            else:
                assert t["value"] is None and t["sigma"] is None
    lines = [ln for ln in text.splitlines() if "not identified" in ln]
    assert lines and all("±" not in ln for ln in lines)


@pytest.mark.slow
def test_plot_y_range_comes_from_the_data_not_from_unidentified_terms():
    from align.present.plots import allan_plot_png, allan_ylim

    job = _job(1, units="g")
    lo, hi = allan_ylim(job, "ug")
    ci = np.concatenate([to_unit(f.ci_low, "ug") for f in job.fits] + [to_unit(f.ci_high, "ug") for f in job.fits])
    assert lo <= ci.min() and hi >= ci.max()
    assert hi <= 1.5 * ci.max() * (1 + 1e-12) and lo >= ci.min() / 1.5 * (1 - 1e-12)
    assert allan_plot_png(job)[:4] == b"\x89PNG" and allan_plot_png(_job(2))[:4] == b"\x89PNG"


def test_planner_has_no_floor_for_white_noise_alone(run_cli, tmp_path):
    from align.noise.planner import averaging_time, model_curve

    a = averaging_time(q("1 deg/h", "angular_rate"), sigma=model_curve(ARW))
    assert a.floor is None and a.floor_tau is None
    assert a.tau == pytest.approx((ARW / q("1 deg/h", "angular_rate")) ** 2, rel=1e-9)  # sigma = N / sqrt(tau)
    b = averaging_time(q("1 deg/h", "angular_rate"), sigma=model_curve(ARW, BI))
    assert b.tau is None and b.floor == pytest.approx(np.sqrt(2 * np.log(2) / np.pi) * BI, rel=1e-12)
    out = tmp_path / "p.json"
    res = run_cli("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--arw", "0.3 deg/sqrt(h)", "--json", out)
    assert res.code == 0, res.err
    assert "curve floor         none" in res.out and "1e+07" not in res.out
    d = json.loads(out.read_text())
    assert d["floor_deg_h"] is None and d["floor_tau_s"] is None and d["version"] == 2
    res = run_cli("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--imu", "MPU-6050")
    assert res.code == 0, res.err
    assert "curve floor         none" in res.out and "states no bias instability" in res.out
    res = run_cli("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--arw", "0.3 deg/sqrt(h)",
                  "--bias-instability", "5 deg/h")
    assert "3.321 deg/h (0.664 B, approached as tau grows)" in res.out


def test_summary_names_the_noise_identified_at_each_tau():
    """White rate noise alone (generated here, not by the code under test) reads as N over the mid taus, in the
    IEEE letters and the gyro's words (issue 13: the identified noise type per tau is reported)."""
    from align.noise.job import run_allan
    from align.present.text import allan_summary

    rng = np.random.default_rng(3)
    job = run_allan([rng.standard_normal((50_000, 1)) * 0.01], 100.0, ["x"], "deg/s")
    line = next(ln for ln in allan_summary(job).splitlines() if "noise type by tau" in ln)
    spans = line.split(": ", 1)[1].split("; ")
    widest = max(spans, key=lambda p: float(p.rsplit(" ", 1)[0].split()[-1].split("-")[-1])
                 / float(p.rsplit(" ", 1)[0].split()[-1].split("-")[0]))
    assert widest.startswith("N angle random walk 0.01-")  # from the shortest tau over the widest span
    assert "white" not in line and "flicker" not in line
