"""Issue 24: the Allan deviation of a long record in bounded memory, one group of channels' phase at a time.

The truth is an independent overlapping (and modified) Allan deviation written here from the definitions
(IEEE Std 1139; Riley, NIST SP 1065 Eq 14 and 15) in extended precision numpy, on a simulated record read
through the streaming chunk source (:class:`align.io.streamchunks.StreamChunks`, small blocks) with a memory
limit so small that every channel's phase goes its own way (a temporary file).
"""

from __future__ import annotations

import gc
import importlib
import os
import tempfile
from pathlib import Path

import numpy as np
import pytest

from align.errors import InputError
from align.io.formats import LogFormat
from align.io.readers import Columns
from align.io.streamchunks import StreamChunks

allan_module = importlib.import_module("align.noise.allan")  # the module (align.noise.allan is also the function)
allan = allan_module.allan

FS, N = 100.0, 60_000
OFFSETS = np.array([0.02, -1.5, 9.80665])  # a gyro bias, an accelerometer near gravity: the mean is removed first


def _record(n: int = N, seed: int = 7) -> np.ndarray:
    """(n, 3): white noise plus a random walk plus an offset per channel, in a rate unit."""
    rng = np.random.default_rng(seed)
    return rng.normal(0, 1e-2, (n, 3)) + np.cumsum(rng.normal(0, 1e-4, (n, 3)), axis=0) + OFFSETS


class _Small:
    """A chunk source that hands out another's rows in small blocks (the running sums must carry across them)."""

    def __init__(self, source, rows: int) -> None:
        self.source, self.rows, self.shape, self.passes = source, rows, source.shape, 0

    def chunks(self, rows: int = 1 << 20, columns=None):
        self.passes += 1
        return self.source.chunks(rows=self.rows, columns=columns)


def _streamed(y: np.ndarray, rows: int = 7_001) -> _Small:
    """``y`` as a ULog-like stream read by :class:`StreamChunks` (time column first, 4999-row blocks)."""
    t = np.arange(len(y)) / FS

    def blocks(path, fmt, names, block_rows):
        for s in range(0, len(y), block_rows):
            yield Columns(names, np.column_stack([t[s : s + block_rows], y[s : s + block_rows]]),
                          {"time": "s", **{n: "rad/s" for n in names[1:]}})

    return _Small(StreamChunks(Path("long.ulg"), ["gyro_x", "gyro_y", "gyro_z"], LogFormat(), blocks, rows=4_999),
                  rows)


def _reference(y: np.ndarray, fs: float, m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Overlapping and modified Allan deviations of one channel straight from the definitions (long double):
    ``x = cumsum(y) / fs`` with ``x[0] = 0``; AVAR = sum (x[i+2m] - 2x[i+m] + x[i])^2 / (2 tau^2 (N - 2m));
    MVAR = sum_j (sum_{i=j}^{j+m-1} (...))^2 / (2 m^2 tau^2 (N - 3m + 1)). NaN where 3m > N."""
    yl = np.asarray(y, dtype=np.longdouble)
    x = np.concatenate([[np.longdouble(0)], np.cumsum(yl - yl.mean())]) / fs
    big_n = len(x)
    adev, mdev = np.empty(len(m)), np.full(len(m), np.nan)
    for k, mm in enumerate(int(v) for v in m):
        tau = mm / fs
        d = x[2 * mm :] - 2 * x[mm : big_n - mm] + x[: big_n - 2 * mm]
        adev[k] = float(np.sqrt(np.sum(d * d) / (2 * tau**2 * (big_n - 2 * mm))))
        if 3 * mm <= big_n:
            s = np.concatenate([[np.longdouble(0)], np.cumsum(d)])
            inner = s[mm : mm + big_n - 3 * mm + 1] - s[: big_n - 3 * mm + 1]
            mdev[k] = float(np.sqrt(np.sum(inner * inner) / (2 * mm**2 * tau**2 * (big_n - 3 * mm + 1))))
    return adev, mdev


@pytest.fixture(scope="module")
def record():
    return _record()


@pytest.fixture(scope="module")
def whole(record):
    """Today's path: the whole record in memory, every channel in one pass."""
    return allan(record, FS, modified=True)


def test_streamed_in_tiny_memory_matches_the_definition(record, whole, tmp_path, monkeypatch):
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))  # the temporary files go here: none may stay
    held = []
    phases = allan_module._phases

    def spy(source, fs, memory_limit, columns, *args):
        x, means = phases(source, fs, memory_limit, columns, *args)
        held.append((list(columns), isinstance(x, np.memmap), x.nbytes))
        return x, means

    monkeypatch.setattr(allan_module, "_phases", spy)
    calls = []
    source = _streamed(record)
    res = allan(source, FS, modified=True, memory_limit=1e3, progress=calls.append)
    assert held == [([0], True, 8 * (N + 1)), ([1], True, 8 * (N + 1)), ([2], True, 8 * (N + 1))]
    assert source.passes == 3  # the record is read once per group
    for j in range(3):
        adev, mdev = _reference(record[:, j], FS, res.m)
        np.testing.assert_allclose(res.adev[j], adev, rtol=1e-12, atol=0)
        np.testing.assert_allclose(res.mdev[j], mdev, rtol=1e-12, atol=0)
    np.testing.assert_allclose(res.bias, record.mean(axis=0), rtol=1e-13, atol=0)
    ten = record[: N // 1000 * 1000].reshape(-1, 1000, 3).mean(axis=1)  # seed 002 Eq 7 at 10 s: 1000 samples
    np.testing.assert_allclose(res.stability[10.0], ten.std(axis=0, ddof=1), rtol=1e-10, atol=0)
    for field in ("adev", "mdev", "alpha", "edf", "edf_mdev", "bias"):  # the rest as the one-pass path gives it
        np.testing.assert_allclose(getattr(res, field), getattr(whole, field), rtol=1e-12, atol=0, err_msg=field)
    assert np.all(np.diff(calls) >= 0) and calls[-1] == N  # one progress over the three passes
    del source, res
    gc.collect()
    assert os.listdir(tmp_path) == []  # phases and the stream's spill removed


def test_channels_are_grouped_to_fit_the_limit(record, whole, monkeypatch):
    held = []
    phases = allan_module._phases

    def spy(source, fs, memory_limit, columns, *args):
        x, means = phases(source, fs, memory_limit, columns, *args)
        held.append((list(columns), isinstance(x, np.memmap)))
        return x, means

    monkeypatch.setattr(allan_module, "_phases", spy)
    res = allan(record, FS, modified=True, memory_limit=2 * 8 * (N + 1))  # two channels' phases fit, not three
    assert held == [([0, 1], False), ([2], False)]
    assert res == whole
    held.clear()
    monkeypatch.setattr(allan_module, "GROUP_BYTES", 8 * (N + 1))  # the cap holds whatever limit is given
    assert allan(record, FS, modified=True, memory_limit=2e9) == whole
    assert held == [([0], False), ([1], False), ([2], False)]


def test_a_day_at_400_hz_is_taken_one_channel_at_a_time():
    n = 24 * 3600 * 400  # one channel's phase: 8 (n + 1) bytes = 277 MB
    assert allan_module._groups(n, 6, 2e9) == [[0], [1], [2], [3], [4], [5]]
    assert allan_module._groups(n // 4, 6, 2e9) == [[0, 1, 2, 3], [4, 5]]
    assert allan_module._groups(1000, 6, 2e9) == [[0, 1, 2, 3, 4, 5]]


@pytest.mark.parametrize("streamed", [True, False])
def test_a_corrupt_sample_is_named_first_whatever_channel_is_read_first(record, streamed):
    data = record.copy()
    data[900, 0], data[123, 2] = np.nan, np.inf  # the earlier one is in the last channel's group
    with pytest.raises(InputError, match="NaN or inf.*sample 123") as info:  # streamed: refused as it is read
        allan(_streamed(data, rows=500) if streamed else allan_module.ArrayChunks(data), FS, memory_limit=1e3,
              where="long.ulg")
    assert info.value.where == "long.ulg"
