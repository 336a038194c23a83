"""Overlapping and modified Allan deviation (align.noise.allan) against allantools; grids, memory, chunks."""

import numpy as np
import pytest

from align.errors import InputError
from align.noise.allan import allan, confidence_interval, edf_overlapping, tau_grid


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


def test_grid_errors_name_the_input_not_a_flag():
    for bad in (dict(grid="weekly"), dict(grid=[1e6])):
        with pytest.raises(InputError) as err:
            tau_grid(50_000, 100.0, **bad)
        assert err.value.fields == ["grid"] and "--" not in str(err.value)
        assert err.value.render(lambda name, value: "--" + name.replace("_", "-")).startswith("--grid: ")


def test_allan_result_is_a_value():
    rng = np.random.default_rng(3)
    y = rng.normal(size=(5_000, 2))
    a, b = allan(y, 100.0), allan(y.copy(), 100.0)
    assert a == b and a is not b
    assert not a.adev.flags.writeable and not a.stability[1.0].flags.writeable
    with pytest.raises(ValueError):
        a.adev[0, 0] = 1.0
    s = a.scaled(2.0)
    assert np.array_equal(s.adev, 2 * a.adev) and np.array_equal(s.bias, 2 * a.bias) and s.names == a.names
    assert s != a and s.replace(adev=a.adev, bias=a.bias, stability=a.stability) == a
