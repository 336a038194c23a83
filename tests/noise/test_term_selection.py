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
def test_false_alarm_rate_over_100_records(name):
    fits = [f for s in range(5) for f in _fits(SCENARIOS[name], 6.0, 20, 100 + s)]
    assert _false_alarms(fits, SCENARIOS[name]) <= _allowed(len(fits), FALSE_ALARM)


@pytest.mark.slow
@pytest.mark.xfail(reason="issue 23, open: under a dominant rate random walk no ramp or bump is claimed any more "
                          "(deterministic signals are tested on points of 10 EDF and more), but a bias instability "
                          "that is not there is, in 5 of 120 records (4 allowed at the stated 1 %): Holm's correction "
                          "holds, B's own likelihood-ratio p-values do not (22 of 120 below 0.01; the Gaussian "
                          "likelihood on the skewed few-EDF points at long tau); B tested on points of 10 EDF and "
                          "more: 8 and 2 of 120 below 0.01, 2 and 1 false alarms, but B then lost in 1 of 20 2-h "
                          "white+flicker records", strict=False)
def test_false_alarm_rate_under_a_dominant_rate_random_walk():
    fits = [f for s in range(6) for f in _fits(SCENARIOS["white+rrw"], 6.0, 20, 200 + s)]
    assert _false_alarms(fits, SCENARIOS["white+rrw"]) <= _allowed(len(fits), FALSE_ALARM)


def test_a_strong_ramp_is_claimed_and_covered():
    # the ramp's cross term with the noise (align.noise.covariance, ebar_m) in the covariance: without it a
    # 10 deg/h^2 ramp over white noise came back 6-15 sigma off (the variance at the longest taus ~90x too small)
    spec = dict(white=0.3 * ARW, ramp=10 * RAMP)
    fits = _fits(spec, 6.0, 10, 3)
    for f in fits:
        assert f.identifiable[4] and f.pvalues[4] < 1e-6
        assert abs(f.params[4] - 10 * RAMP) <= 3 * f.sigma[4], (f.params[4] / RAMP, f.sigma[4] / RAMP)
        assert not f.identifiable[3] and not f.identifiable[2]


@pytest.mark.slow
@pytest.mark.xfail(reason="issue 23, open: a 10 deg/h^2 ramp under a 4 deg/h/sqrt(h) rate random walk is claimed "
                          "in 31 of 60 records only (tested on points of 10 EDF and more, tau <= 1600 s of 6 h, its "
                          "p-value there is e.g. 0.004 or 0.013 and the random walk takes its place); with all cross "
                          "terms 28 of the 31 are within 3 sigma (28 of 35 before), the 3 outside fitted K = 0 "
                          "(flicker and ramp take the random walk's place, and its cross term leaves R's sigma)",
                   strict=False)
def test_ramp_under_rate_random_walk_within_three_sigma():
    spec = dict(white=0.3 * ARW, random_walk=4 * RRW, ramp=10 * RAMP)
    fits = [f for s in range(3) for f in _fits(spec, 6.0, 20, 300 + s)]
    claimed = [f for f in fits if f.identifiable[4]]
    assert len(claimed) >= 0.9 * len(fits)
    inside = np.mean([abs(f.params[4] - 10 * RAMP) <= 3 * f.sigma[4] for f in claimed])
    assert inside >= 0.97
