"""No ramp, bump or bias instability claimed where a rate random walk dominates and there is none (issue 23).

Records from a generator written here (independent of align.noise.sim): white rate noise N = 0.3 deg/sqrt(h)
and a rate random walk K = 10 deg/h/sqrt(h) (IEEE Std 952 definitions), 2 h at 25 Hz; no flicker, no ramp, no
periodic part. The Allan variances of the long taus have few degrees of freedom, where the Gaussian likelihood
of the fit misstates chi-square tails: deterministic signals are tested on points of at least SIGNAL_EDF EDF
(before: false ramps and bumps in 7 % of such records, against the 1 % the fit states).
"""

import numpy as np
import pytest

from align.noise.allan import allan
from align.noise.fit import fit_noise
from align.noise.gls import FALSE_ALARM
from align.units import parse_quantity as q

N = q("0.3 deg/sqrt(h)", "angle_random_walk")
K = q("10 deg/h/sqrt(h)", "rate_random_walk")
FS, HOURS, RECORDS = 25.0, 2.0, 40


@pytest.mark.slow
def test_absent_terms_are_claimed_at_the_stated_rate_at_most():
    n = int(HOURS * 3600 * FS)
    claims = {"flicker": 0, "ramp": 0, "periodic": 0}
    for seed in range(RECORDS):
        rng = np.random.default_rng(300 + seed)
        y = rng.standard_normal(n) * N * np.sqrt(FS) + np.cumsum(rng.standard_normal(n)) * K / np.sqrt(FS)
        fit = fit_noise(allan(y, FS), 0)
        claims["flicker"] += bool(fit.identifiable[2])
        claims["ramp"] += bool(fit.identifiable[4])
        claims["periodic"] += bool(np.isfinite(fit.periodic[0]))
    # 3 x 40 chances at a stated 1 % family-wise: 1.2 expected at most; 4 or more has a 3 % chance at that rate
    assert sum(claims.values()) <= 3 and FALSE_ALARM == 0.01, claims
