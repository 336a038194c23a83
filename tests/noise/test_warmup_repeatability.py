"""Warm-up time and turn-on to turn-on bias repeatability (issue 26, third bullet).

Truth from outside: this module's own simulator (numpy, written here from the model, not the library's):
a gyro record from turn-on ``b(t) = b_end + d exp(-t / tau)`` plus white noise, whose settling time into a band is
``tau ln(|d| / band)`` analytically; and turn-ons whose biases are drawn with a known sigma, so that the chi-square
interval of the repeatability must cover that sigma at its stated rate (binomial band over many seeds).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.stats import binom

import align.results

align.results.KNOWN.setdefault("imu-align.warmup", "align.noise.warmup")  # the lead adds these lines to KNOWN
align.results.KNOWN.setdefault("imu-align.repeatability", "align.noise.repeatability")

from align.errors import InputError  # noqa: E402
from align.noise.bias_jobs import REPEATABILITY, RepeatabilityOptions, repeatability_job, warmup  # noqa: E402
from align.noise.repeatability import RepeatabilityResult, RunBias, record_bias, repeatability  # noqa: E402
from align.noise.warmup import WarmupResult, warmup_time  # noqa: E402

FS = 100.0
TAU = 60.0
BAND = 2e-4  # rad/s
NOISE = 5e-4  # rad/s per sample (0.17 deg/sqrt(h) at 100 Hz)
EXCURSIONS = np.array([5e-3, -4e-3, 2.5e-3])  # d per channel, rad/s


def turn_on_record(seed: int, duration: float = 1200.0, tau: float = TAU, d=EXCURSIONS, noise: float = NOISE):
    """(n, 3) rad/s: b_end + d exp(-t / tau) + white noise, with b_end drawn per channel."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(duration * FS)) / FS
    b_end = rng.uniform(-3e-3, 3e-3, 3)
    return b_end[None, :] + np.outer(np.exp(-t / tau), d) + noise * rng.standard_normal((t.size, 3))


def truth_settling(d: float, tau: float = TAU, band: float = BAND) -> float:
    return tau * math.log(abs(d) / band)


def test_warmup_time_within_10_percent_of_the_simulated_settling_over_24_seeds(tmp_path):
    """Through the job (an .npy record, rad/s): every channel's warm-up within 10 % of tau ln(|d| / band), and within
    its own 3-sigma no more often missed than the binomial allows."""
    truth = np.array([truth_settling(d) for d in EXCURSIONS])  # 193, 180, 151 s
    errors, z = [], []
    for seed in range(24):
        path = tmp_path / f"rec{seed}.npy"
        np.save(path, turn_on_record(seed))
        res = warmup(log=path, rate_hz=FS, gyro_units="rad/s", window=20.0, band=BAND)
        got = np.array([c.time for c in res.channels])
        assert all(c.settled and c.left_band for c in res.channels)
        errors.append(got / truth - 1)
        z.append((got - truth) / np.array([c.sigma for c in res.channels]))
    errors, z = np.array(errors), np.array(z)
    assert np.max(np.abs(errors)) < 0.10, np.max(np.abs(errors))
    assert np.abs(errors).mean() < 0.03
    assert np.sum(np.abs(z) > 3) <= binom.ppf(0.999, z.size, 0.0027) + 2  # the stated sigma is not optimistic


def test_warmup_result_states_its_criterion_figures_and_file(tmp_path):
    path = tmp_path / "rec.npy"
    np.save(path, turn_on_record(7))
    res = warmup(log=path, rate_hz=FS, gyro_units="rad/s", window=20.0, band="0.0114592 deg/s")  # 2e-4 rad/s
    assert res.channels[0].band == pytest.approx(BAND, rel=1e-5)
    figs = res.figures_of_merit()
    assert [f.name for f in figs] == ["warmup_x", "warmup_y", "warmup_z"]
    assert all(f.unit == "s" and f.sensor == "gyroscope" and "20 s moving mean" in f.method for f in figs)
    assert figs[0].value == pytest.approx(truth_settling(EXCURSIONS[0]), rel=0.1)
    assert [f.name for f in res.verdicts] == ["warmup_x", "warmup_y", "warmup_z"]  # stamped by the job
    out = tmp_path / "w.json"
    align.results.save_result(out, res)
    d = json.loads(out.read_text())
    assert d["format"] == "imu-align.warmup" and "criterion" in d and d["units"]["time"] == "s"
    back = align.results.load_result(out)
    assert isinstance(back, WarmupResult) and back == res


def test_a_record_without_warm_up_gives_zero_and_one_still_drifting_is_not_settled():
    rng = np.random.default_rng(3)
    flat = 1e-3 + NOISE * rng.standard_normal(int(600 * FS))
    w = warmup_time(flat, FS, window=20.0)  # default band: five sigma of the moving mean's noise
    assert w.settled and not w.left_band and w.time == 0.0 and w.band > 0
    slow = turn_on_record(4, duration=600.0, tau=1500.0)  # a record far shorter than the settling
    for j in range(3):
        got = warmup_time(slow[:, j], FS, window=20.0, band=BAND)
        assert not got.settled and math.isnan(got.time) and "not settled" in got.note


def test_not_settled_is_a_nan_figure_that_says_why(tmp_path):
    path = tmp_path / "slow.npy"
    np.save(path, turn_on_record(5, duration=600.0, tau=1500.0))
    res = warmup(log=path, rate_hz=FS, gyro_units="rad/s", window=20.0, band=BAND)
    for f in res.figures_of_merit():
        assert math.isnan(f.value) and "not settled" in f.detail


def _simulated_repeatability(seed: int, count: int, spread: float, levels=(0.95, 0.6827)):
    rng = np.random.default_rng(seed)
    biases = rng.normal(0.0, spread, (count, 3))
    runs = [record_bias(b + NOISE * rng.standard_normal((3000, 3)), FS, period=5.0) for b in biases]
    return [repeatability(runs, level) for level in levels]


def test_chi_square_interval_covers_the_true_spread_at_its_stated_rate():
    """400 seeds of 6 turn-ons (bias spread 1e-3 rad/s, each bias's own noise 1e-5): the 95 % and 68.27 % intervals
    cover the true spread at their rates within the binomial 99.9 % band, per channel (1200 trials)."""
    spread, trials = 1e-3, 400
    cover = {0.95: 0, 0.6827: 0}
    for seed in range(trials):
        for rep in _simulated_repeatability(seed, 6, spread):
            cover[rep.level] += int(np.sum((rep.low <= spread) & (spread <= rep.high)))
    for level, hits in cover.items():
        n = 3 * trials
        lo, hi = binom.ppf(0.0005, n, level), binom.ppf(0.9995, n, level)
        assert lo <= hits <= hi, (level, hits / n)


def test_repeatability_job_on_turn_on_records_with_warm_up(tmp_path):
    """Eight turn-ons, each with a warm-up: the job leaves each record's warm-up out, and the biases (mean after it)
    give the drawn spread's sample std; per-record sigma and in-run stability as white noise predicts."""
    rng = np.random.default_rng(11)
    end = rng.normal(0.0, 2e-3, (8, 3))
    paths = []
    for k, b in enumerate(end):
        t = np.arange(int(900 * FS)) / FS
        rec = b + np.outer(np.exp(-t / 30.0), [3e-3, -2e-3, 1e-3]) + NOISE * rng.standard_normal((t.size, 3))
        paths.append(tmp_path / f"on{k}.npy")
        np.save(paths[-1], rec)
    res = repeatability_job(logs=paths, rate_hz=FS, gyro_units="rad/s", window=20.0, band=BAND, period=10.0)
    skips = [r["skip_s"] for r in res.runs]
    assert all(truth_settling(1e-3, 30.0) * 0.9 < s < truth_settling(3e-3, 30.0) * 1.1 for s in skips)
    assert res.value == pytest.approx(np.std(end, axis=0, ddof=1), abs=3 * NOISE / math.sqrt(700 * FS) * 2)
    assert np.all(res.low < res.value) and np.all(res.value < res.high)
    sig = np.array([r["sigma"] for r in res.runs])
    assert np.all((0.5 < sig / (NOISE / np.sqrt(np.array([r["samples"] for r in res.runs]))[:, None])) & (sig < 2e-4))
    stab = np.array([r["stability"] for r in res.runs])  # 10-s means: white noise and the warm-up's last trace
    assert np.all((0.7 * NOISE / math.sqrt(10 * FS) < stab) & (stab < BAND))
    figs = res.figures_of_merit()
    assert [f.name for f in figs] == ["bias_repeatability_x", "bias_repeatability_y", "bias_repeatability_z"]
    assert all(f.unit == "rad/s" and f.sigma > 0 and "chi-square" in f.method for f in figs)
    out = tmp_path / "r.json"
    align.results.save_result(out, res)
    back = align.results.load_result(out)
    assert isinstance(back, RepeatabilityResult) and back == res


def test_accelerometer_records_give_m_s2(tmp_path):
    rng = np.random.default_rng(2)
    paths = []
    for k in range(3):
        paths.append(tmp_path / f"a{k}.csv")
        a = np.array([0.0, 0.0, 9.80665]) + rng.normal(0, 0.01, 3) + 0.002 * rng.standard_normal((6000, 3))
        np.savetxt(paths[-1], np.column_stack([np.arange(6000) / FS, a]), delimiter=",",
                   header="time,accel_x,accel_y,accel_z", comments="")
    res = repeatability_job(logs=paths, columns="accel_x,accel_y,accel_z", units="m/s^2", skip=0.0, period=1.0)
    assert res.sensor == "accelerometer" and res.figures_of_merit()[0].unit == "m/s^2"
    stab = np.array([r["stability"] for r in res.runs])  # 1-s means of white noise: 0.002 / sqrt(100)
    assert stab == pytest.approx(np.full((3, 3), 0.002 / math.sqrt(FS)), rel=0.3)
    assert np.mean(stab) == pytest.approx(0.002 / math.sqrt(FS), rel=0.1)


def test_garbage_gets_one_clear_input_error(tmp_path):
    text = tmp_path / "junk.csv"
    text.write_text("hello, world\nthis is, not a record\n")
    with pytest.raises(InputError):
        warmup(log=text, window=1.0)
    nan = tmp_path / "nan.npy"
    rec = turn_on_record(1, duration=120.0)
    rec[500, 1] = np.nan
    np.save(nan, rec)
    with pytest.raises(InputError, match="not a finite number"):
        warmup(log=nan, rate_hz=FS, gyro_units="rad/s", window=5.0)
    ok = tmp_path / "ok.npy"
    np.save(ok, turn_on_record(1, duration=120.0))
    with pytest.raises(InputError) as one:
        repeatability_job(logs=[ok], rate_hz=FS, gyro_units="rad/s", skip=0.0)
    assert one.value.where == "{logs}"
    with pytest.raises(InputError) as short:
        warmup(log=ok, rate_hz=FS, gyro_units="rad/s", window=60.0)
    assert short.value.where == "{window}"
    with pytest.raises(InputError) as band:
        warmup(log=ok, rate_hz=FS, gyro_units="rad/s", window=5.0, band="1e-9 rad/s")
    assert band.value.where == "{band}"
    with pytest.raises(InputError) as unit:
        warmup(log=ok, rate_hz=FS, gyro_units="rad/s", window=5.0, band="3 m")
    assert unit.value.where == "{band}"
    with pytest.raises(InputError):
        REPEATABILITY.run(RepeatabilityOptions(logs=(ok, ok), rate_hz=FS, gyro_units="rad/s", level=1.5))


def test_record_bias_and_repeatability_by_hand():
    x = np.column_stack([np.r_[np.full(100, 50.0), np.full(1000, 1.0)], np.full(1100, 2.0)])
    r = record_bias(x, 10.0, skip=10.0, period=10.0)
    assert r.samples == 1000 and r.bias.tolist() == [1.0, 2.0] and r.stability.tolist() == [0.0, 0.0]
    runs = [RunBias(np.array([b]), np.array([0.1]), np.array([np.nan]), 0.0, 10) for b in (1.0, 3.0)]
    rep = repeatability(runs, 0.95)
    assert rep.value[0] == pytest.approx(math.sqrt(2.0)) and rep.within[0] == pytest.approx(0.1)
    assert rep.low[0] < rep.value[0] < rep.high[0]


def test_cli_commands_write_the_results(tmp_path):
    import typer
    from typer.testing import CliRunner

    from align.cli.bias import COMMANDS, SIMULATE

    app = typer.Typer()
    for name, cmd in {**COMMANDS, **{f"sim-{k}": v for k, v in SIMULATE.items()}}.items():
        app.command(name)(cmd)
    runner = CliRunner()
    got = runner.invoke(app, ["sim-warmup", str(tmp_path / "w"), "--duration", "10 min", "--rate-hz", "50"])
    assert got.exit_code == 0, got.output
    truth = json.loads((tmp_path / "w" / "truth.json").read_text())
    out = tmp_path / "warm.json"
    got = runner.invoke(app, ["warmup", str(tmp_path / "w" / "warmup.csv"), "--window", "20 s", "--band",
                              "0.01 deg/s", "--json", str(out)])
    assert got.exit_code == 0, got.output
    times = [c["time"] for c in json.loads(out.read_text())["channels"].values()]
    assert np.allclose(times, truth["settling_time_s"], rtol=0.1)
    got = runner.invoke(app, ["sim-turn-ons", str(tmp_path / "t"), "--count", "4", "--duration", "60 s"])
    assert got.exit_code == 0, got.output
    out = tmp_path / "rep.json"
    logs = sorted(str(p) for p in (tmp_path / "t").glob("turn_on_*.csv"))
    got = runner.invoke(app, ["repeatability", *logs, "--skip", "0 s", "--json", str(out)])
    assert got.exit_code == 0, got.output
    truth = json.loads((tmp_path / "t" / "truth.json").read_text())
    rep = json.loads(out.read_text())["repeatability"]["value"]
    within = json.loads(out.read_text())["repeatability"]["within"]  # each bias's own noise, inside the spread
    assert np.allclose(list(rep.values()), truth["sample_std_rad_s"], rtol=0, atol=3 * max(within.values()))


@pytest.mark.parametrize("call, options", [(warmup, "WarmupOptions"), (repeatability_job, "RepeatabilityOptions")])
def test_job_calls_list_every_option_keyword_only(call, options):
    import dataclasses
    import inspect

    import align.noise.bias_jobs as bj

    params = inspect.signature(call).parameters
    assert {f.name for f in dataclasses.fields(getattr(bj, options)) if f.init} <= set(params)
    assert all(p.kind is inspect.Parameter.KEYWORD_ONLY for p in params.values())
    with pytest.raises(TypeError):
        call(log="x.npy", not_an_option=1) if call is warmup else call(logs=["x.npy"], not_an_option=1)
