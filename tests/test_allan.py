"""Allan deviation against allantools, the noise fit against simulated truth, Example 3, real data."""

import json

import numpy as np
import pytest

from align.noise.allan import allan, confidence_interval, edf_overlapping, tau_grid
from align.errors import InputError
from align.noise.fit import fit_noise, noise_figures
from align.noise.sim import NoiseSpec, seed_method_a, seed_method_b, seed_restoring, simulate_noise
from align.noise.planner import averaging_time, model_curve, noise_target
from align.units import DEG_H, parse_quantity as q

from conftest import SHARED

ARW = q("0.3 deg/sqrt(h)", "angle_random_walk")
ADIS = SHARED / "data" / "static" / "adis16405_smac"


def test_example3_noise_target_and_white_noise_averaging_time():
    target = noise_target(q("100 deg/s", "angular_rate"), q("0.1 deg", "angle"), 10)
    assert target / DEG_H == pytest.approx(62.83, abs=0.005)
    t = averaging_time(target, sigma=model_curve(ARW)).tau
    assert t == pytest.approx(0.0821, abs=5e-5)
    assert t == pytest.approx((ARW / target) ** 2, rel=1e-9)  # sigma = N / sqrt(tau)


def test_matches_allantools_oadev_and_mdev():
    import allantools as at

    rng = np.random.default_rng(0)
    y = 3.0 + rng.normal(0, 1, 100_000) + np.cumsum(rng.normal(0, 2e-3, 100_000))
    r = allan(y, 200.0, modified=True)
    taus, ad, _, _ = at.oadev(y, rate=200.0, data_type="freq", taus=r.tau)
    assert np.allclose(taus, r.tau, rtol=0, atol=0)
    assert np.max(np.abs(ad / r.adev[0] - 1)) < 1e-10
    taus_m, md, _, _ = at.mdev(y, rate=200.0, data_type="freq", taus=r.tau)
    idx = np.searchsorted(r.tau, taus_m)
    assert np.max(np.abs(md / r.mdev[0][idx] - 1)) < 1e-10


@pytest.mark.parametrize("alpha", [2, 1, 0, -1, -2])
def test_edf_and_interval_match_allantools(alpha):
    import allantools as at

    n_phase, m = 100_001, np.array([1, 3, 10, 100, 1000, 10000])
    ours = edf_overlapping(n_phase, m, np.full(len(m), alpha))
    theirs = np.array([at.edf_simple(n_phase, int(k), alpha) for k in m])
    assert np.allclose(ours, np.maximum(theirs, 1.0), rtol=1e-12)
    lo, hi = confidence_interval(np.ones(len(m)), ours)
    for k in range(len(m)):
        a_lo, a_hi = at.confidence_interval(1.0, ours[k])
        assert lo[k] == pytest.approx(a_lo, rel=1e-12) and hi[k] == pytest.approx(a_hi, rel=1e-12)


def test_grids_and_bounded_memory_path():
    rng = np.random.default_rng(1)
    y = rng.normal(size=(50_000, 2))
    dense = tau_grid(50_000, 100.0)
    assert len(dense) >= 10 * 4 - 2 and np.all(np.diff(dense) > 0)
    assert list(tau_grid(50_000, 100.0, "octave")[:4]) == [1, 2, 4, 8]
    in_mem = allan(y, 100.0)
    on_disk = allan(y, 100.0, memory_limit=1e3)  # the phase goes to a temporary memmap file
    assert np.array_equal(in_mem.adev, on_disk.adev)
    y[123, 1] = np.nan
    with pytest.raises(InputError, match="first at sample 123"):
        allan(y, 100.0, names=["a", "b"])


def _fit(spec, seed, n=1_000_000, fs=100.0):
    e = simulate_noise(n, fs, spec, 1, seed)
    return fit_noise(allan(e, fs), 0)


def test_fit_recovers_simulated_arw_and_bias_instability_and_flags_rrw():
    b = q("5 deg/h", "angular_rate")
    fits = [_fit(NoiseSpec(white=ARW, flicker=b), seed) for seed in range(5)]
    n_ratio = np.median([f.params[1] / ARW for f in fits])
    b_ratio = np.median([f.params[2] / b for f in fits])
    assert abs(n_ratio - 1) < 0.05 and abs(b_ratio - 1) < 0.05
    for f in fits:
        assert f.identifiable[1]  # white
        assert not f.identifiable[3]  # rate random walk: not in the data, not identifiable
        assert any(note.startswith("random_walk: not identifiable") and "h of record needed" in note for note in f.notes)


def test_simulator_checks_itself_other_terms():
    k = q("30 deg/h/sqrt(h)", "rate_random_walk")
    f = _fit(NoiseSpec(white=ARW, random_walk=k), 3)
    assert f.params[3] / k == pytest.approx(1, abs=0.15) and f.identifiable[3]
    qn = 2e-5  # rad
    f = _fit(NoiseSpec(white=ARW * 0.1, quantization=qn), 4, n=200_000)
    assert f.params[0] / qn == pytest.approx(1, abs=0.05)
    gm = [_fit(NoiseSpec(white=ARW, flicker=q("5 deg/h", "angular_rate"), flicker_model="gauss-markov"), s) for s in range(3)]
    assert np.median([g.params[2] for g in gm]) / q("5 deg/h", "angular_rate") == pytest.approx(1, abs=0.1)


def test_simulator_is_seeded_and_pure():
    spec = NoiseSpec(white=ARW, flicker=1e-5, random_walk=1e-6, turn_on=1e-3)
    a, b = simulate_noise(1000, 100.0, spec, 3, 7), simulate_noise(1000, 100.0, spec, 3, 7)
    assert np.array_equal(a, b)
    truth = np.zeros(1000)
    out = seed_method_a(truth, 100.0, 0.1, 0.01, 1.0, 1e-3, 1)
    assert np.array_equal(truth, np.zeros(1000)) and out.shape == (1000,)


def test_seed_statistics_restoring_method():
    fs, period, stab, rep = 100.0, 1.0, 2e-3, 5e-3
    biases = []
    for seed in range(200):
        out = seed_restoring(np.zeros(20_000), fs, 0.1, rep, stab, period, 1e-3, seed)
        fig = noise_figures(out, fs, (period,))
        assert fig["stability"][period] == pytest.approx(stab, rel=1e-9)  # restored exactly (its Eq 18)
        biases.append(fig["bias"])
    assert np.mean(biases) == pytest.approx(0.1, abs=3 * rep / np.sqrt(200))
    assert np.std(biases, ddof=1) == pytest.approx(rep, rel=0.2)  # run-to-run (its Eq 14)
    b = seed_method_b(np.zeros(20_000), fs, 0.1, 1e-4, 1e-3, 0)
    assert b.shape == (20_000,)


def test_noise_figures_follow_seed_definitions():
    y = np.arange(1000.0)
    fig = noise_figures(y, 10.0, (1.0,))
    means = y.reshape(100, 10).mean(axis=1)
    assert fig["bias"] == pytest.approx(499.5)
    assert fig["stability"][1.0] == pytest.approx(np.std(means, ddof=1))
    # the Allan job reads the same figures off the phase: the same numbers
    rng = np.random.default_rng(5)
    z = rng.normal(0.3, 1.0, 12_345)
    r = allan(z, 100.0, periods=(1.0, 10.0))
    direct = noise_figures(z, 100.0, (1.0, 10.0))
    assert r.bias[0] == pytest.approx(direct["bias"], rel=1e-12)
    for p in (1.0, 10.0):
        assert r.stability[p][0] == pytest.approx(direct["stability"][p], rel=1e-9)


def test_npy_chunks_give_the_same_result(tmp_path):
    from align.io import NpyChunks

    rng = np.random.default_rng(8)
    y = rng.normal(size=(30_000, 2)) + 1.0
    np.save(tmp_path / "y.npy", y)
    a = allan(y, 50.0)
    b = allan(NpyChunks(tmp_path / "y.npy"), 50.0)
    assert np.allclose(a.adev, b.adev, rtol=1e-12, atol=0)
    y.astype("<f8").tofile(tmp_path / "y.bin")  # raw binary, two interleaved columns
    c = allan(NpyChunks(tmp_path / "y.bin", 2), 50.0, memory_limit=1e3)
    assert np.allclose(a.adev, c.adev, rtol=1e-12, atol=0)


def test_allan_cli_on_real_adis16405_and_plan_from_it(tmp_path, run_cli):
    """Two 2.78 h static runs of an ADIS16405: figures per run, repeatability, plot, plan."""
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
        n_fit = fit["terms"]["white"]["value"]
        n_read = fit["ieee_point_readouts"]["N_at_tau_1s"]
        assert 1.5 < n_fit < 3.0  # deg/sqrt(h): the white-noise level of this part's class
        assert n_fit == pytest.approx(n_read, rel=0.15)  # the fit and the IEEE readout agree
        lo, hi, a = (np.array(d[k][name]) for k in ("ci_low", "ci_high", "adev"))
        assert np.all(lo <= a) and np.all(a <= hi)
        # the curve floor (taus up to a tenth of the record, where the interval is tight) against
        # the datasheet's in-run bias stability, 0.007 deg/s = 25.2 deg/h
        reliable = np.array(d["tau"]) <= 1000.0
        assert 15 < a[reliable].min() * 3600 < 50
    # repeatability of two runs is |b1 - b2| / sqrt(2): check against the per-run means
    import pandas as pd

    b = [pd.read_csv(p, usecols=["gyro_x_dps"])["gyro_x_dps"].mean() for p in runs]
    assert d["repeatability"]["gyro_x_dps"] == pytest.approx(abs(b[0] - b[1]) / np.sqrt(2), rel=1e-9)
    plan_out = tmp_path / "plan.json"
    res = run_cli("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--allan", out, "--json", plan_out)
    assert res.code == 0, res.err
    p = json.loads(plan_out.read_text())
    assert p["noise_target_deg_h"] == pytest.approx(62.83, abs=0.005)
    worst = np.max([np.interp(np.log(p["averaging_time_s"]), np.log(d["tau"]), np.array(d["adev"][n]) * 3600)
                    for n in d["adev"]])
    assert worst == pytest.approx(62.83, rel=0.02)  # the chosen tau sits on the target


def test_plan_cli_example3_and_infeasible(tmp_path, run_cli):
    out = tmp_path / "p.json"
    res = run_cli("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--arw", "0.3 deg/sqrt(h)", "--json", out)
    assert res.code == 0, res.err
    d = json.loads(out.read_text())
    assert d["noise_target_deg_h"] == pytest.approx(62.83, abs=0.005)
    assert d["averaging_time_s"] == pytest.approx(0.0821, abs=5e-5)
    res = run_cli("plan", "--rate", "10 deg/s", "--accuracy", "0.01 deg", "--imu", "ADIS16470", "--json", out)
    d = json.loads(out.read_text())
    assert d["feasible"] is False and "floor" in d["reason"]
    res = run_cli("plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg")
    assert res.code == 2 and "exactly one noise source" in res.err


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
