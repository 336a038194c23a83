"""A noise term is claimed only when the data demand it (issue 23), at the stated false-alarm rate.

Records from the independent simulator (independent_noise.py: Gauss-Markov bank for flicker, not
align.noise.sim); truth from the simulator. A term absent from the simulation and claimed identifiable
is a false alarm; the fit states its rate (``NoiseFit.false_alarm``, over all terms tried, per record).
"""

from __future__ import annotations

import numpy as np
import pytest
from independent_noise import ARW, DEG_H, RAMP, RRW, record
from scipy.stats import binom

from align.noise.allan import allan
from align.noise.fit import fit_noise
from align.noise.gls import FALSE_ALARM, holm, term_pvalue

FS = 10.0
SCENARIOS = {
    "white": dict(white=0.3 * ARW),
    "white+flicker": dict(white=0.3 * ARW, flicker=3 * DEG_H),
    "white+flicker+rrw": dict(white=0.3 * ARW, flicker=3 * DEG_H, random_walk=4 * RRW),
    "white+rrw": dict(white=0.3 * ARW, random_walk=4 * RRW),
}
KEYS = ("quantization", "white", "flicker", "random_walk", "ramp")


def _fits(spec: dict, hours: float, channels: int, seed: int):
    y = record(int(hours * 3600 * FS), FS, channels=channels, seed=seed, **spec)
    res = allan(y, FS)
    return [fit_noise(res, j) for j in range(channels)]


def _false_alarms(fits, spec: dict) -> int:
    absent = np.array([not spec.get(k) for k in KEYS])
    return sum(bool(np.any(np.array(f.identifiable) & absent)) for f in fits)


def _allowed(records: int, rate: float) -> int:
    """Most false alarms a rate of ``rate`` gives over ``records`` in 99 % of test runs (binomial)."""
    return int(binom.ppf(0.99, records, rate))


def test_holm_and_chi_bar_square():
    assert term_pvalue(0.0) == 1.0
    assert term_pvalue(2.705543) == pytest.approx(0.05, rel=1e-4)    # 1/2 P(chi2_1 > 2.7055) = 0.05
    # Holm over 6 tried: the smallest against alpha/6, the next against alpha/5 ...
    assert list(holm(np.array([0.001, 0.0019, 0.5]), 0.01, 6)) == [True, True, False]
    assert list(holm(np.array([0.0018, 0.0019]), 0.01, 6)) == [False, False]


def test_no_term_claimed_that_is_not_there_fast():
    fits = _fits(SCENARIOS["white+flicker"], 2.0, 20, 1) + _fits(SCENARIOS["white"], 2.0, 20, 2)
    assert all(f.false_alarm == FALSE_ALARM == 0.01 for f in fits)
    wf = fits[:20]
    assert all(f.identifiable[1] and f.identifiable[2] for f in wf)
    assert _false_alarms(wf, SCENARIOS["white+flicker"]) <= _allowed(20, FALSE_ALARM)
    assert _false_alarms(fits[20:], SCENARIOS["white"]) <= _allowed(20, FALSE_ALARM)
    for f in fits:
        assert np.all(np.isfinite(f.pvalues)) and np.all((f.pvalues >= 0) & (f.pvalues <= 1))


@pytest.mark.slow
@pytest.mark.parametrize("name", ["white", "white+flicker", "white+flicker+rrw"])
def test_false_alarm_rate_over_60_records_per_case(name):
    # 60 records of 3 h per case, 180 over the three and the 120 of the dominant random walk below (0 false alarms in
    # each case over 100 records; 6 h records, twice the time in CI, gave 0 to 1)
    fits = [f for s in range(3) for f in _fits(SCENARIOS[name], 3.0, 20, 100 + s)]
    assert _false_alarms(fits, SCENARIOS[name]) <= _allowed(len(fits), FALSE_ALARM)


@pytest.mark.slow
def test_false_alarm_rate_under_a_dominant_rate_random_walk():
    # white + rate random walk, no flicker: B was claimed in 5 of 120 records (22 of its p-values below 0.01) while
    # a third of the fits whitened with the diagonal (the model's correlation matrix had eigenvalues of -1e-4, the
    # lag sums' errors); with a ridge that factorises (align.noise.gls.whitener): 3 of 120 (8 p-values below 0.01),
    # and 0 and 1 of 120 on seeds 500-505 and 600-605
    fits = [f for s in range(6) for f in _fits(SCENARIOS["white+rrw"], 6.0, 20, 200 + s)]
    assert _false_alarms(fits, SCENARIOS["white+rrw"]) <= _allowed(len(fits), FALSE_ALARM)


def test_a_strong_ramp_is_claimed_and_covered():
    # the ramp's cross term with the noise (align.noise.covariance, ebar_m) in the covariance: without it a
    # 10 deg/h^2 ramp over white noise came back 6-15 sigma off (the variance at the longest taus ~90x too small).
    # Its p-values, 1e-21 to 5e-7 while the null model's covariance fell back to independent points, are 9e-10 to
    # 5e-6 with its correlations (align.noise.gls.whitener); Holm's first step is at 1.7e-3
    spec = dict(white=0.3 * ARW, ramp=10 * RAMP)
    fits = _fits(spec, 6.0, 10, 3)
    for f in fits:
        assert f.identifiable[4] and f.pvalues[4] < 1e-4
        assert abs(f.params[4] - 10 * RAMP) <= 3 * f.sigma[4], (f.params[4] / RAMP, f.sigma[4] / RAMP)
        assert not f.identifiable[3] and not f.identifiable[2]


@pytest.fixture(scope="module")
def ramp_under_random_walk():
    """60 records of 6 h: a 10 deg/h^2 ramp under a 4 deg/h/sqrt(h) rate random walk and white noise."""
    spec = dict(white=0.3 * ARW, random_walk=4 * RRW, ramp=10 * RAMP)
    return [f for s in range(3) for f in _fits(spec, 6.0, 20, 300 + s)]


@pytest.mark.slow
def test_ramp_under_rate_random_walk_within_three_sigma(ramp_under_random_walk):
    # the bar: claimed ramps within their 3 sigma at the nominal rate. Before, 3 of 31 claimed were 3-5 sigma
    # off: K fitted as zero (flicker and the ramp in its place) took the random walk's share out of R's sigma; now R's
    # variance has the unclaimed noise terms at their upper value (align.noise.gls, GlsFit._signal_cov): 40 of 40
    # claimed within 3 sigma (rms z 0.91), and 47 of 47 on seeds 400-402
    fits = ramp_under_random_walk
    claimed = [f for f in fits if f.identifiable[4]]
    assert len(claimed) >= 0.6 * len(fits)   # 40 and 47 of 60 measured (two seed sets); the fit must claim it
    inside = np.mean([abs(f.params[4] - 10 * RAMP) <= 3 * f.sigma[4] for f in claimed])
    assert inside >= 0.97
    # a ramp not claimed is bounded: its one-sided 95 % upper bound at or above the truth (20 of 20 measured, the
    # lowest 11.3 deg/h^2)
    above = [f.upper[4] >= 10 * RAMP for f in fits if not f.identifiable[4]]
    assert np.mean(above) >= 0.9, above


@pytest.mark.slow
@pytest.mark.xfail(reason="a power target beyond issue 23's (claimed ramps within 3 sigma, the others bounded "
                          "above the truth: both hold): the ramp is claimed in 40 of 60 "
                          "records (47 of 60 on seeds 400-402); of the 20 others, 11 not significant on the points of "
                          "10 EDF and more (tau <= 1600 s of 6 h) and 9 known to 25 % only or just short of Holm's "
                          "level (R's sigma 1.8-2.7 deg/h^2 at R of 6-9.7: the Allan variance's information; the "
                          "time-domain best, b(T)/T, has 1.6). Tried: the ramp tested on all points: 42 of 60 "
                          "claimed, but 8 false periodic bumps in 120 white + random walk records; the tests on cube "
                          "roots of the Allan variances (Wilson-Hilferty; with a fixed 1e-3 ridge): 41 of 60",
                   strict=False)
def test_ramp_under_rate_random_walk_claimed(ramp_under_random_walk):
    fits = ramp_under_random_walk
    assert sum(f.identifiable[4] for f in fits) >= 0.9 * len(fits)
