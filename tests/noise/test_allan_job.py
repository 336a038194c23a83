"""The Allan job (align.noise.job) on real ADIS16405 recordings through the CLI; AllanJob's JSON form."""

import json

import numpy as np
import pytest
from support import SHARED

ADIS = SHARED / "data" / "static" / "adis16405_smac"


@pytest.mark.slow
def test_allan_cli_on_real_adis16405_and_plan_from_it(tmp_path, run_cli):
    """Two 2.78 h static runs of an ADIS16405: each run's curve and fit, the pooled curve, repeatability, plot, plan."""
    out, png = tmp_path / "allan.json", tmp_path / "allan.png"
    runs = [ADIS / "adis_16405_imu1.csv.gz", ADIS / "adis_16405_imu2.csv.gz"]
    res = run_cli("allan", *runs, "--columns", "gyro_x_dps,gyro_y_dps,gyro_z_dps", "--rate-hz", "100",
                  "--json", out, "--plot", png, "--rate", "100 deg/s", "--accuracy", "0.1 deg")
    assert res.code == 0, res.err
    d = json.loads(out.read_text())
    for key in ("tau", "adev", "ci_low", "ci_high", "fit", "units"):
        assert key in d
    assert d["units"]["adev"] == "deg/s" and d["runs"] == 2
    assert png.read_bytes()[:4] == b"\x89PNG"
    for name, fit in d["fit"].items():
        n_fit = fit["terms"]["angle_random_walk"]["value"]
        n_read = fit["ieee_point_readouts"]["N_at_tau_1s"]
        assert 1.5 < n_fit < 3.0  # deg/sqrt(h): the white-noise level of this part's class
        assert n_fit == pytest.approx(n_read, rel=0.15)  # the fit and the IEEE readout agree
        lo, hi, a = (np.array(d[k][name]) for k in ("ci_low", "ci_high", "adev"))
        assert np.all(lo <= a) and np.all(a <= hi)
        # the pooled curve is the mean Allan variance of the two runs' (equal runs: equal EDF weights)
        runs_avar = np.array([np.array(p["adev"][name]) ** 2 for p in d["per_run"]])
        assert np.allclose(a**2, runs_avar.mean(axis=0), rtol=1e-9)
        # the curve floor (taus up to a tenth of the record, where the interval is tight) against
        # the datasheet's in-run bias stability, 0.007 deg/s = 25.2 deg/h
        reliable = np.array(d["tau"]) <= 1000.0
        assert 15 < a[reliable].min() * 3600 < 50
    # the floor readout is taken in the flat region (not at the last, wide tau): 26-30 deg/h for x (issue 13)
    ro = d["fit"]["gyro_x_dps"]["ieee_point_readouts"]
    assert 26 < 0.664 * ro["B_floor_over_0.664"] < 30 and ro["B_floor_tau_s"] < 0.3 * d["tau"][-1]
    assert ro["B_floor_over_0.664_low"] < ro["B_floor_over_0.664"] < ro["B_floor_over_0.664_high"]
    # repeatability of two runs is |b1 - b2| / sqrt(2): check against the per-run means
    import pandas as pd

    b = [pd.read_csv(p, usecols=["gyro_x_dps"])["gyro_x_dps"].mean() for p in runs]
    assert d["repeatability"]["gyro_x_dps"] == pytest.approx(abs(b[0] - b[1]) / np.sqrt(2), rel=1e-9)
    assert [p["input"] for p in d["per_run"]] == [str(r) for r in runs] and "pooled" in d["adev_of"]
    assert "pooled over 2 runs" in res.out and "run adis_16405_imu2.csv.gz" in res.out
    plan_out = tmp_path / "plan.json"
    res = run_cli("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--allan", out, "--json", plan_out)
    assert res.code == 0, res.err
    p = json.loads(plan_out.read_text())
    assert p["noise_target_deg_h"] == pytest.approx(62.83, abs=0.005)
    worst = np.max([np.interp(np.log(p["averaging_time_s"]), np.log(d["tau"]), np.array(d["adev"][n]) * 3600)
                    for n in d["adev"]])
    assert worst == pytest.approx(62.83, rel=0.02)  # the chosen tau sits on the target


def test_allan_cli_bad_input(tmp_path, run_cli):
    csv = tmp_path / "s.csv"
    t = np.arange(1000) * 0.01
    t[500:] += 0.5
    csv.write_text("time,gyro_x,gyro_y,gyro_z\n" + "\n".join(f"{a},0.1,0.2,0.3" for a in t) + "\n")
    res = run_cli("allan", csv, "--json", tmp_path / "never.json")
    assert res.code == 2 and "time gaps" in res.err and "t=4.99" in res.err
    assert not (tmp_path / "never.json").exists()
    res = run_cli("allan", csv, "--units", "mm")
    assert res.code == 2 and "--units" in res.err


#: every key an Allan file had before AllanJob became a registered result (a contract: add, never rename; the
#: term names inside ``fit`` changed with version 2, and version 1 files still read)
ALLAN_KEYS = {"format", "version", "generator", "units", "sensor", "fs_hz", "samples", "runs", "tau", "adev",
              "ci_low", "ci_high", "fit", "figures", "inputs", "adev_of", "mdev", "repeatability"}
FIT_KEYS = {"method", "terms", "notes", "ieee_point_readouts", "continuous"}


def _job(units="deg/s", runs=2, modified=True, n=20_000, fs=100.0):
    from align.noise.job import run_allan
    from align.noise.sim import NoiseSpec, simulate_noise
    from align.units import parse_quantity as q
    from align.units import to_unit

    spec = NoiseSpec(bias=1e-3, turn_on=1e-4, white=q("0.3 deg/sqrt(h)", "angle_random_walk"),
                     flicker=q("5 deg/h", "angular_rate"))
    data = [to_unit(simulate_noise(n, fs, spec, 3, seed), units) for seed in range(runs)]
    return run_allan(data, fs, ["x", "y", "z"], units, modified=modified, periods=(1.0, 10.0, 2.5))


def test_allan_job_round_trips_through_the_loader(tmp_path):
    from align.noise.job import AllanJob
    from align.noise.planner import PlanResult, make_plan
    from align.results import load_result, save_result
    from align.units import parse_quantity as q
    from align.values import approx_equal

    job = _job()
    r = job.result
    plan = make_plan(q("100 deg/s", "angular_rate"), q("0.1 deg", "angle"), 10, "measured curve (worst channel)",
                     tau=r.tau, adev=r.adev.max(axis=0))
    job = job.replace(inputs=["a.csv", "b.csv"], plan=plan)
    assert np.isnan(r.mdev).any()  # the modified deviation stops short of the longest taus: written as null
    d = job.to_dict()
    assert ALLAN_KEYS | {"convention", "plan"} <= set(d)
    assert list(d)[:5] == ["format", "version", "generator", "convention", "units"]
    assert all(FIT_KEYS <= set(f) for f in d["fit"].values())
    assert d["adev_of"].startswith("pooled curve of 2 runs") and d["plan"]["format"] == "imu-align.plan"
    assert d["version"] == 2 and [p["input"] for p in d["per_run"]] == ["a.csv", "b.csv"]
    assert approx_equal(AllanJob.from_dict(d), job, rtol=1e-12)
    path = tmp_path / "allan.json"
    save_result(path, job)
    back = load_result(path)
    assert type(back) is AllanJob and type(back.plan) is PlanResult
    assert approx_equal(back, job, rtol=1e-12)
    assert back.inputs == ("a.csv", "b.csv") and back.runs == 2 and back.result.names == ("x", "y", "z")
    assert np.array_equal(back.result.m, r.m)
    assert set(back.figures[0]["stability"]) == {1.0, 10.0, 2.5}


def test_accelerometer_job_round_trips_and_reads_older_files():
    """An acceleration in g, one run; a file written before the added keys reads too."""
    from align.noise.job import AllanJob
    from align.values import approx_equal

    job = _job("g", runs=1, modified=False)
    d = job.to_dict()
    assert d["sensor"] == "accelerometer" and "mdev" not in d and "repeatability" not in d
    assert d["units"]["terms"]["bias_instability"] == "ug"
    assert set(d["fit"]["x"]["terms"]) == {"quantization", "velocity_random_walk", "bias_instability",
                                           "acceleration_random_walk", "acceleration_ramp"}
    assert approx_equal(AllanJob.from_dict(d), job, rtol=1e-12)
    for key in ("convention", "m", "periods_s", "adev_run_figures"):
        del d[key]
    for f in d["fit"].values():
        del f["dominant"], f["edf"]
    old = AllanJob.from_dict(d)
    assert np.array_equal(old.result.m, job.result.m)
    assert approx_equal(old.result, job.result, rtol=1e-12)
    assert approx_equal(old.figures, job.figures, rtol=1e-12)
    for a, b in zip(old.fits, job.fits):
        assert approx_equal(a.params, b.params, rtol=1e-12) and np.all(a.edf >= 1)


def test_malformed_allan_file_is_refused_in_one_line():
    from align.errors import InputError
    from align.noise.job import AllanJob

    d = _job(runs=1, n=5_000).to_dict()
    del d["ci_low"]
    with pytest.raises(InputError, match="malformed imu-align.allan result") as err:
        AllanJob.from_dict(d, "allan.json")
    assert str(err.value).startswith("allan.json: ")


def test_allan_plot_lives_in_present():
    from align.present.plots import allan_plot_png

    job = _job(runs=1, n=5_000)
    png = allan_plot_png(job, 1e-4, 0.5)
    assert png[:4] == b"\x89PNG"
    assert allan_plot_png(_job("g", runs=1, n=5_000))[:4] == b"\x89PNG"


def test_plan_from_allan_uses_the_worst_channel_and_needs_a_gyro():
    from align.errors import InputError
    from align.noise.job import plan_from_allan
    from align.noise.planner import make_plan
    from align.units import parse_quantity as q

    job = _job(runs=1, n=20_000)
    w, a = q("100 deg/s", "angular_rate"), q("0.1 deg", "angle")
    plan = plan_from_allan(job, w, a, 10, steps=4)
    r = job.result
    assert plan == make_plan(w, a, 10, "measured curve (worst of x, y, z)", tau=r.tau, adev=r.adev.max(axis=0), steps=4)
    with pytest.raises(InputError, match="accelerometer data") as err:
        plan_from_allan(_job("g", runs=1, n=5_000), w, a, where="acc.json")
    assert str(err.value).startswith("acc.json: ")


def test_read_runs_needs_one_sample_rate(tmp_path):
    from align.errors import InputError
    from align.noise.job import read_runs

    for name, dt in (("a.csv", 0.01), ("b.csv", 0.01), ("c.csv", 0.02)):
        t = np.arange(200) * dt
        (tmp_path / name).write_text("time,gx\n" + "\n".join(f"{v:.6f},0.1" for v in t) + "\n")
    runs, fs = read_runs([tmp_path / "a.csv", tmp_path / "b.csv"], ["gx"])
    assert len(runs) == 2 and fs == pytest.approx(100.0)
    with pytest.raises(InputError, match="differs from the first run's") as err:
        read_runs([tmp_path / "a.csv", tmp_path / "c.csv"], ["gx"])
    assert "c.csv" in str(err.value)


def test_an_unidentified_random_walk_is_stated_as_its_upper_bound_in_json_and_kalibr(tmp_path):
    """One number for a random walk a short record cannot identify: the JSON's Kalibr-style block and the Kalibr
    export both give the fit's 95 % upper bound, and say so (not the fit's 0)."""
    import yaml

    from align.cli import run
    from align.noise.sim import NoiseSpec, simulate_noise
    from align.units import parse_quantity, to_unit

    fs = 100.0
    white = parse_quantity("0.3 deg/sqrt(h)", "angle_random_walk")
    x = simulate_noise(int(0.03 * 3600 * fs), fs, NoiseSpec(white=white), 3, seed=4)
    np.save(tmp_path / "s.npy", to_unit(x, "deg/s"))
    out, yml = tmp_path / "a.json", tmp_path / "imu.yaml"
    assert run(["allan", str(tmp_path / "s.npy"), "--rate-hz", "100", "--json", str(out)]) == 0
    d = json.loads(out.read_text())
    fits = d["fit"] if isinstance(d["fit"], list) else list(d["fit"].values())
    bounds = []
    for fit in fits:
        rw = fit["terms"]["rate_random_walk"]
        assert not rw["identifiable"] and rw["upper_bound"] > 0
        c = fit["continuous"]
        assert c["gyroscope_random_walk_is"].startswith("95 % upper bound")
        si = parse_quantity(f"{rw['upper_bound']} {rw['unit']}", "rate_random_walk")
        assert c["gyroscope_random_walk"] == pytest.approx(si, rel=1e-9)
        bounds.append(c["gyroscope_random_walk"])
    acc = simulate_noise(int(0.03 * 3600 * fs), fs, NoiseSpec(white=6e-4), 3, seed=5) + np.array([0.1, 0.2, 9.8])
    np.save(tmp_path / "acc.npy", acc)
    assert run(["allan", str(tmp_path / "acc.npy"), "--rate-hz", "100", "--units", "m/s^2", "--columns",
                "acc_x,acc_y,acc_z", "--json", str(tmp_path / "acc.json")]) == 0
    assert run(["export", str(out), str(tmp_path / "acc.json"), "--to", "kalibr", "--out", str(yml)]) == 0
    assert yaml.safe_load(yml.read_text())["gyroscope_random_walk"] == pytest.approx(max(bounds), rel=1e-6)
