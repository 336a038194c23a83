"""Per-tau noise identification, Greenhall EDF and confidence intervals against truth from outside the code.

* Stable32's published results (AllanTools' test data, tests/data/stable32/SOURCE.txt): its noise type at every
  tau, its deviations to the printed digits, its Min/Max sigma bounds.
* Records of known power-law noise from an FFT generator written here (not align.noise.sim).
* AllanTools' implementation of Greenhall's EDF, and exact counts where the EDF is known in closed form.
* Coverage: the 68 % interval holds the true deviation about 68 % of the time.
"""

import gzip
from pathlib import Path

import numpy as np
import pytest

from align.noise.allan import allan
from align.noise.identify import alpha_from_b1, alpha_from_lag1, b1_theory, edf_greenhall, noise_type_name

DATA = Path(__file__).resolve().parents[1] / "data" / "stable32"


def _read_s32(name):
    """Stable32 table rows: AF, tau, n, alpha, min sigma, sigma, max sigma."""
    rows = [line.split() for line in (DATA / name).read_text().splitlines() if line.strip() and line[0] != "#"]
    return np.array(rows, dtype=float)


def _rates(record):
    with gzip.open(DATA / f"{record}.txt.gz", "rt") as fh:
        v = np.array([float(line) for line in fh if line.strip() and line[0] != "#"])
    if record == "ocxo_frequency":  # Hz -> fractional frequency
        return (v - 1e7) / 1e7
    return np.diff(v) if record == "tic_phase" else v  # phase (s) -> frequency


CASES = [("pink_frequency", "pink_frequency_oadev_octave.txt", False, True),
         ("ocxo_frequency", "ocxo_oadev_octave.txt", False, False),
         ("ocxo_frequency", "ocxo_mdev_octave.txt", True, False),
         ("tic_phase", "tic_oadev.txt", False, True),
         ("tic_phase", "tic_mdev.txt", True, True)]


@pytest.mark.parametrize("record,table,modified,exact", CASES, ids=[c[1] for c in CASES])
def test_noise_type_deviation_and_bounds_equal_stable32(record, table, modified, exact):
    s32 = _read_s32(table)
    r = allan(_rates(record), 1.0, grid=list(s32[:, 1]), modified=modified)
    assert np.array_equal(r.m, s32[:, 0].astype(int))
    dev = r.mdev[0] if modified else r.adev[0]
    # the noise type Stable32 identified, at every tau (lag-1 ACF, B1 ratio with R(n), nearest)
    assert r.alpha[0].tolist() == s32[:, 3].astype(int).tolist()
    if exact:  # the deviation to Stable32's printed digits
        assert [f"{d:.4e}" for d in dev] == [f"{d:.4e}" for d in s32[:, 5]]
    else:  # Stable32 ran on a differently rounded copy of this record (SOURCE.txt)
        assert np.max(np.abs(dev / s32[:, 5] - 1)) < 2e-3
    lo, hi = r.interval(modified=modified)
    # half-widths as Stable32's, within 10 % (Greenhall's EDF: within 3 % here, the printed digits' precision)
    assert np.max(np.abs((dev - lo[0]) / (s32[:, 5] - s32[:, 4]) - 1)) < 0.10
    assert np.max(np.abs((hi[0] - dev) / (s32[:, 6] - s32[:, 5]) - 1)) < 0.10


def _power_law(alpha, n, rng):
    """Rate samples with PSD ~ f^alpha (FFT shaping of white noise, twice as long, first half kept)."""
    w = np.fft.rfft(rng.standard_normal(2 * n))
    f = np.fft.rfftfreq(2 * n)
    f[0] = 1.0
    gain = f ** (alpha / 2.0)
    gain[0] = 0.0
    return np.fft.irfft(w * gain, 2 * n)[:n]


@pytest.mark.parametrize("alpha", [2, 0, -1, -2])
def test_simulated_power_law_noise_is_identified_at_mid_taus(alpha):
    # (flicker PM is left out: block means of flicker phase alias toward white PM as m grows, for Stable32 too)
    n = 1 << 17
    y = np.column_stack([_power_law(alpha, n, np.random.default_rng(100 * seed + alpha + 7)) for seed in range(4)])
    r = allan(y, 100.0, grid="octave")
    mid = (r.m >= 4) & (n // r.m >= 1000)  # >= 1000 blocks: the lag-1 estimate of alpha has sd < 0.3
    assert mid.sum() == 6
    found = r.alpha[:, mid]
    assert np.mean(found == alpha) >= 0.9 and np.all(np.abs(found - alpha) <= 1), (found, noise_type_name(alpha))


def test_lag1_and_b1_rules():
    # Riley & Greenhall: p = -2 (delta + d) at the first stationary d; for frequency data alpha = p
    assert alpha_from_lag1(np.array([-0.5, 0.0, 0.0])) == pytest.approx(2.0)  # white PM: r1 = -1/2, delta = -1
    assert alpha_from_lag1(np.array([0.0, -0.5, 0.0])) == pytest.approx(0.0)  # white FM
    assert alpha_from_lag1(np.array([0.99, 0.0, -0.5])) == pytest.approx(-2.0)  # random walk FM: one difference
    # the B1 ratio at its theoretical value gives back its type; R(n) splits white and flicker PM
    for n in (8, 12, 29):
        for mu, a in ((-1, 0), (0, -1), (1, -2)):
            assert alpha_from_b1(b1_theory(n, mu), n, None, 1000) == a
        assert alpha_from_b1(b1_theory(n, -2), n, 1 / 1000, 1000) == 2
        assert alpha_from_b1(b1_theory(n, -2), n, 0.12, 1000) == 1
    assert [noise_type_name(a) for a in (2, 1, 0, -1, -2)] == ["white PM", "flicker PM", "white FM", "flicker FM",
                                                                "random walk FM"]
    assert noise_type_name(-1, imu=True) == "bias instability"
    with pytest.raises(ValueError):
        noise_type_name(3)


@pytest.mark.slow
def test_greenhall_edf_matches_allantools_and_exact_counts():
    import allantools as at

    for n_phase in (1001, 100_001):
        for m in (1, 2, 3, 10, 33, 34, 64, 200, 300):
            for alpha in (2, 1, 0, -1, -2):
                for modified in (False, True):
                    try:
                        theirs = at.edf_greenhall(alpha=alpha, d=2, m=m, N=n_phase, overlapping=True,
                                                  modified=modified)
                    except NotImplementedError:  # white PM with M <= 2m: not in allantools; checked below
                        continue
                    assert edf_greenhall(alpha, m, n_phase, modified) == pytest.approx(theirs, rel=1e-9)
    # white PM, overlapping, m >= the number M of second differences: no two share a phase point, EDF = M
    for n_phase, m in ((1001, 400), (1001, 333), (5000, 2000)):
        big_m = n_phase - 2 * m
        if big_m <= m:
            assert edf_greenhall(2, m, n_phase) == pytest.approx(big_m)


@pytest.mark.slow
def test_result_interface_and_coverage_of_the_68_percent_interval():
    rng = np.random.default_rng(5)
    y = rng.standard_normal((20_000, 2))
    r = allan(y, 10.0, modified=True)
    assert r.alpha.shape == r.adev.shape and r.alpha.dtype.kind == "i" and set(np.unique(r.alpha)) <= {2, 1, 0, -1, -2}
    assert np.all(np.isfinite(r.edf)) and np.all(r.edf > 0) and np.all(np.isfinite(r.edf_mdev) == np.isfinite(r.mdev))
    lo, hi = r.interval()
    from scipy.stats import chi2  # independent of the code's gammaincinv: dev sqrt(edf / chi2_q(edf)) (SP 1065 5.3.3)

    q = 0.682689492137086
    assert np.allclose(lo, r.adev * np.sqrt(r.edf / chi2.ppf(0.5 + q / 2, r.edf)), rtol=1e-9)
    assert np.allclose(hi, r.adev * np.sqrt(r.edf / chi2.ppf(0.5 - q / 2, r.edf)), rtol=1e-9)
    s = r.scaled(3.0)
    assert np.array_equal(s.alpha, r.alpha) and np.allclose(s.interval()[1], 3 * hi)
    assert allan(y, 10.0, deviations=False).alpha is None
    with pytest.raises(ValueError, match="no adev EDF"):
        allan(y, 10.0, deviations=False).interval()
    # coverage: white FM (AVAR = s^2 / m) and white PM (y = diff of white phase: AVAR = 3 s^2 / m^2), 300 records
    # of 1024 blocks (with fewer blocks the lag-1 estimate of white PM often says flicker PM: wider intervals)
    m = 16
    for kind, truth in (("white FM", 1 / 4.0), ("white PM", np.sqrt(3) / m)):
        w = rng.standard_normal((m * 1024 + 1, 300))
        data = w[1:] if kind == "white FM" else np.diff(w, axis=0)
        res = allan(data, 1.0, grid=[m], modified=True)
        lo, hi = res.interval()
        assert 0.60 < np.mean((lo[:, 0] <= truth) & (truth <= hi[:, 0])) < 0.76, kind
