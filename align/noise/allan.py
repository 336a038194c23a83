"""Overlapping and modified Allan deviation of many channels, with confidence intervals.

For rate samples ``y`` at ``fs`` the phase is ``x = [0, cumsum(y - mean(y)) / fs]``
(the mean is removed before the sum, as allantools does, to keep precision) and

    AVAR(m tau0)  = sum_i (x[i+2m] - 2 x[i+m] + x[i])^2 / (2 (m tau0)^2 (N - 2m))
    MVAR(m tau0)  = sum_j (sum_{i=j}^{j+m-1} (x[i+2m] - 2 x[i+m] + x[i]))^2 / (2 m^2 (m tau0)^2 (N - 3m + 1))

(N phase points; IEEE Std 1139 / Riley, NIST SP 1065). The sums run in a compiled kernel (numba; tiled over
blocks of the record, parallel, vectorised), with no temporaries the size of the record. The phase is built in
place for a group of channels at a time, as many as :data:`GROUP_BYTES` hold (the record read once per group):
each channel's sums are its own, so the results do not depend on the grouping, and the memory used stays that of
one group (one channel of a record longer than a day at 400 Hz); one channel's phase beyond ``memory_limit`` bytes
lives in a temporary file (``numpy.memmap``).

Every point carries the noise type identified from the data at its tau (lag-1
autocorrelation, B1 ratio; :mod:`align.noise.identify`, NIST SP 1065 section 5.6),
its equivalent degrees of freedom from that type (Greenhall & Riley 2003, as
Stable32) and so its chi-square confidence interval (SP 1065 section 5.3,
:meth:`AllanResult.interval`). Howe's simple EDF formulas (SP 1065 Table 5) stay
available as :func:`edf_overlapping`.

Public names
------------
tau_grid, AllanResult, allan, ArrayChunks, window_stability, edf_overlapping, confidence_interval,
NOISE_ALPHA (from :mod:`align.noise.model`)
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass

import numpy as np

from align.errors import InputError
from align.io.logs import check_readings
from align.noise.model import NOISE_ALPHA
from align.values import Value, frozen_array

__all__ = ["tau_grid", "AllanResult", "allan", "ArrayChunks", "window_stability", "edf_overlapping",
           "confidence_interval", "NOISE_ALPHA"]


def tau_grid(n: int, fs: float, grid: str | list = "dense", per_decade: int = 10) -> np.ndarray:
    """Averaging factors ``m`` (samples) for a record of ``n`` rate samples.

    Parameters
    ----------
    n : int
        Rate samples in the record.
    fs : float
        Sample rate, Hz.
    grid : {"dense", "octave", "decade"} or list of float
        ``dense``: log-spaced, ``per_decade`` points per decade; ``octave``:
        powers of two; ``decade``: 1, 2, 4 x 10^k; a list: explicit taus in seconds.
    per_decade : int

    Returns
    -------
    ndarray of int64, shape (T,)
        Strictly increasing, ``1 <= m <= (n - 1) // 2``.

    Raises
    ------
    InputError
        An unknown grid, or no tau of it fitting the record (``where`` is ``{grid}``).
    """
    m_max = (n - 1) // 2  # at least two second differences behind every point
    if m_max < 1:
        raise InputError(f"only {n} samples: an Allan deviation needs at least 3")
    m: np.ndarray
    if isinstance(grid, str):
        if grid == "dense":
            k = np.arange(0, int(np.floor(np.log10(m_max) * per_decade)) + 1)
            m = np.round(10.0 ** (k / per_decade))
        elif grid == "octave":
            m = 2.0 ** np.arange(0, int(np.floor(np.log2(m_max))) + 1)
        elif grid == "decade":
            m = np.array([d * 10.0**e for e in range(0, int(np.log10(m_max)) + 1) for d in (1, 2, 4)])
        else:
            raise InputError(f"unknown grid '{grid}'; use dense, octave, decade or a list of taus", "{grid}")
    else:
        m = np.round(np.asarray(grid, dtype=float) * fs)
    m = np.unique(m[(m >= 1) & (m <= m_max)]).astype(np.int64)
    if len(m) == 0:
        raise InputError(f"no tau of the grid fits the record ({n} samples at {fs:g} Hz)", "{grid}")
    return m


class ArrayChunks:
    """Row chunks of an in-memory (n, C) array, with the interface of :class:`align.io.NpyChunks`."""

    def __init__(self, data) -> None:
        arr = np.asarray(data)
        self.data = arr.reshape(-1, 1) if arr.ndim == 1 else arr
        self.shape = self.data.shape

    def chunks(self, rows: int = 1 << 20, columns: list[int] | None = None):
        cols = list(range(self.shape[1])) if columns is None else columns
        for start in range(0, self.shape[0], rows):
            yield np.asarray(self.data[start : start + rows, cols], dtype=np.float64)


#: bytes of phase held in memory at once, however large ``memory_limit``: the channels are taken in groups that fit,
#: the source read once per group (one 24-hour 400 Hz channel's phase is 277 MB); fewer cost more reads of the source
GROUP_BYTES = 320e6


def _groups(n: int, c: int, memory_limit: float) -> list[list[int]]:
    """The channels of each pass: as many as fit ``min(memory_limit, GROUP_BYTES)`` bytes of phase, at least one."""
    g = max(1, min(c, int(min(memory_limit, GROUP_BYTES) // (8 * (n + 1)))))
    return [list(range(s, min(s + g, c))) for s in range(0, c, g)]


def _phases(source, fs: float, memory_limit: float, columns: list[int], check: bool = True, progress=None,
            where: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Phases ``[0, cumsum(y - c) / fs]`` of the ``columns`` of ``source`` in one pass, shape (len(columns), n + 1).

    ``c`` is the mean of the first chunk (the whole column when it fits one chunk, as allantools does): removing
    a constant near the mean keeps the running sum small and precise, and any constant cancels exactly in the
    second differences. The running sums carry across chunks, so each row equals one ``numpy.cumsum`` over its
    column, whatever columns are read beside it. Phases larger than ``memory_limit`` bytes live in a temporary
    file (``numpy.memmap``) that is gone once released. With ``check``, every column of each chunk is checked
    (:func:`align.io.logs.check_readings`), not only those used. Returns the phases and the columns' means.
    """
    n, c_all = source.shape
    c = len(columns)
    x: np.ndarray
    if c * (n + 1) * 8 > memory_limit:
        with tempfile.TemporaryFile(prefix="imu_align_phase_", suffix=".f8") as fh:  # unlinked at once
            x = np.memmap(fh, dtype=np.float64, mode="w+", shape=(c, n + 1))  # the mapping keeps it alive
    else:
        x = np.empty((c, n + 1))
    x[:, 0] = 0.0
    pos, carry, total, const = 1, np.zeros(c), np.zeros(c), np.zeros(c)
    sub = not check and c != c_all  # the chunks hold only ``columns``
    cols = list(range(c)) if sub else list(columns)
    for chunk in source.chunks(columns=columns if sub else None):
        k = len(chunk)
        if check:
            try:
                check_readings(chunk, where or "record", first_row=pos - 1)  # samples count from 0
            except InputError as exc:  # named by sample: a chunk source has no header row
                raise InputError(exc.message.replace("data row", "sample"), exc.where) from None
        if pos == 1:
            const = np.array([np.mean(chunk[:, j]) for j in cols])
        for i, j in enumerate(cols):
            seg = x[i, pos : pos + k]
            np.subtract(chunk[:, j], const[i], out=seg)
            total[i] += np.sum(seg)
            seg[0] += carry[i]
            np.cumsum(seg, out=seg)
            carry[i] = seg[-1]
        pos += k
        if progress is not None:
            progress(pos - 1)
    x[:, 1:] *= 1.0 / fs
    return x, const + total / n


def window_stability(x: np.ndarray, fs: float, period: float) -> float:
    """Seed 002 Eq 7 from the phase: std (ddof 1) of the means of consecutive ``period``-second windows.

    A window mean is ``(x[(i+1) k] - x[i k]) fs / k`` plus the (removed) mean.
    """
    k = int(round(period * fs))
    windows = (len(x) - 1) // k if k > 0 else 0
    if windows < 2:
        return float("nan")
    edges = np.asarray(x[: windows * k + 1 : k])
    return float(np.std(np.diff(edges) * fs / k, ddof=1))


def edf_overlapping(n_phase: int, m: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """Equivalent degrees of freedom of the overlapping ADEV (Howe's simple formulas, SP 1065 Table 5).

    Parameters
    ----------
    n_phase : int
        Number of phase points ``N``.
    m : ndarray
        Averaging factors.
    alpha : ndarray
        Noise exponent at each tau (2 white PM, 1 flicker PM, 0 white FM, -1 flicker FM, -2 RW FM).
    """
    N = float(n_phase)
    m = np.asarray(m, dtype=float)
    alpha = np.broadcast_to(alpha, m.shape)
    out = np.empty_like(m)
    for k, (mm, a) in enumerate(zip(m, alpha)):
        if a == 2:
            e = (N + 1) * (N - 2 * mm) / (2 * (N - mm))
        elif a == 1:
            e = np.exp(np.sqrt(np.log((N - 1) / (2 * mm)) * np.log((2 * mm + 1) * (N - 1) / 4)))
        elif a == 0:
            e = (3 * (N - 1) / (2 * mm) - 2 * (N - 2) / N) * 4 * mm**2 / (4 * mm**2 + 5)
        elif a == -1:
            e = 2 * (N - 2) / (2.3 * N - 4.9) if mm == 1 else 5 * N**2 / (4 * mm * (N + 3 * mm))
        else:
            e = (N - 2) / mm * ((N - 1) ** 2 - 3 * mm * (N - 1) + 4 * mm**2) / (N - 3) ** 2
        out[k] = max(e, 1.0)
    return out


def confidence_interval(dev: np.ndarray, edf: np.ndarray, level: float = 0.682689492137086) -> tuple[np.ndarray, np.ndarray]:
    """Chi-square interval of a deviation: ``dev sqrt(edf / chi2_{(1 +/- level)/2}(edf))``.

    The chi-square quantile is ``2 gammaincinv(edf / 2, q)`` (scipy.special; lighter than scipy.stats).
    """
    from scipy.special import gammaincinv

    lo = dev * np.sqrt(edf / (2 * gammaincinv(edf / 2, 0.5 + level / 2)))
    hi = dev * np.sqrt(edf / (2 * gammaincinv(edf / 2, 0.5 - level / 2)))
    return lo, hi


@dataclass(frozen=True, eq=False)
class AllanResult(Value):
    """Allan deviation of several channels (in the unit of the input, e.g. rad/s).

    Attributes
    ----------
    tau : ndarray, shape (T,)
        s.
    m : ndarray, shape (T,)
        Averaging factors.
    adev : ndarray, shape (C, T)
    mdev : ndarray or None, shape (C, T)
    n : int
        Samples per channel (of each run, for a pooled curve).
    fs : float
    names : tuple of str
    bias : ndarray, shape (C,)
        Mean of each channel (seed 002 Eq 5).
    stability : dict
        Period (s) -> ndarray (C,): bias stability (seed 002 Eq 7).
    runs : int
        Independent runs averaged into this curve (a pooled curve); the covariance of its points is that of one
        run of ``n`` samples divided by ``runs``.
    alpha : ndarray of int or None, shape (C, T)
        Noise type identified at each tau: exponent of the rate PSD ``S ~ f^alpha``, 2 white PM /
        quantization, 1 flicker PM, 0 white FM / angle random walk, -1 flicker FM / bias instability,
        -2 random-walk FM / rate random walk (:func:`align.noise.identify.noise_type_name`).
    edf : ndarray or None, shape (C, T)
        Equivalent degrees of freedom of each ``adev`` point (Greenhall, from ``alpha``).
    edf_mdev : ndarray or None, shape (C, T)
        The same for ``mdev`` (NaN where ``mdev`` is).

    Arrays (also those of ``stability``) are read-only copies; ``==`` compares by value.
    """

    tau: np.ndarray
    m: np.ndarray
    adev: np.ndarray
    mdev: np.ndarray | None
    n: int
    fs: float
    names: tuple
    bias: np.ndarray | None = None
    stability: dict | None = None
    alpha: np.ndarray | None = None
    edf: np.ndarray | None = None
    edf_mdev: np.ndarray | None = None
    runs: int = 1

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "names", tuple(self.names))
        t = np.shape(self.tau)
        if len(t) != 1 or np.shape(self.m) != t or np.shape(self.adev) != (len(self.names), t[0]) or (
                self.mdev is not None and np.shape(self.mdev) != np.shape(self.adev)):
            raise ValueError(f"tau {t}, m {np.shape(self.m)}, adev {np.shape(self.adev)} do not match "
                             f"{len(self.names)} channels")
        if self.stability is not None:
            object.__setattr__(self, "stability", {float(p): frozen_array(v) for p, v in self.stability.items()})

    @property
    def n_phase(self) -> int:
        return self.n + 1

    def interval(self, level: float = 0.682689492137086, modified: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Chi-square confidence interval of every point (NIST SP 1065 section 5.3.3).

        Parameters
        ----------
        level : float
            Probability that the interval holds the true deviation (0.6827: 1 sigma).
        modified : bool
            Of ``mdev`` instead of ``adev``.

        Returns
        -------
        lo, hi : ndarray, shape (C, T)
            In the unit of the deviations.
        """
        dev, edf = (self.mdev, self.edf_mdev) if modified else (self.adev, self.edf)
        if dev is None or edf is None:
            raise ValueError(f"this result has no {'mdev' if modified else 'adev'} EDF "
                             "(made without noise identification)")
        return confidence_interval(dev, edf, level)

    def scaled(self, factor: float) -> AllanResult:
        """The same result with the data unit scaled by ``factor`` (deviations are linear in it)."""
        return self.replace(adev=self.adev * factor, mdev=None if self.mdev is None else self.mdev * factor,
                            bias=None if self.bias is None else self.bias * factor,
                            stability=None if self.stability is None else
                            {p: v * factor for p, v in self.stability.items()})


def allan(data, fs: float, names=None, grid="dense", per_decade: int = 10, modified: bool = False,
          memory_limit: float = 2e9, progress=None, periods=(1.0, 10.0), deviations: bool = True,
          where: str | None = None) -> AllanResult:
    """Overlapping (and optionally modified) Allan deviation of each column, and the seed's figures.

    Parameters
    ----------
    data : array_like, shape (n,) or (n, C), or a chunk source
        Rate samples, uniform in time; an in-memory array or an object with
        ``shape`` and ``chunks(rows, columns)`` such as :class:`align.io.NpyChunks`
        (read in chunks, once per group of channels, never whole; ``checked`` True: its readings were checked).
    fs : float
        Sample rate, Hz.
    names : sequence of str, optional
        Channel names (C,).
    grid, per_decade : see :func:`tau_grid`
    modified : bool
        Also compute the modified Allan deviation.
    memory_limit : float
        Bytes of phase kept in memory (at most :data:`GROUP_BYTES` are: the channels are taken in groups, the
        source read once per group); one channel's phase beyond it goes to a temporary file.
    progress : callable, optional
        Called with the number of samples read so far.
    periods : sequence of float
        Averaging periods (s) of the bias stability.
    deviations : bool
        False skips the deviations (left NaN) when only the bias figures are wanted.
    where : str, optional
        The recording (its file), for messages.

    Returns
    -------
    AllanResult
        ``tau`` (T,), s; ``adev`` (C, T) in the unit of ``data``; the bias (C,) (seed 002 Eq 5) and the bias
        stability per period (seed 002 Eq 7).

    Raises
    ------
    InputError
        NaN, infinite or absurdly large samples (the first one is named, with ``where``), a sample rate that is
        not finite and positive.

    Examples
    --------
    White rate noise of density ``N = 1e-3`` rad/s/sqrt(Hz): ``sigma(tau) = N / sqrt(tau)``, so 1e-3 rad/s at 1 s.

    >>> import numpy as np
    >>> from align.noise.sim import NoiseSpec, simulate_noise
    >>> r = allan(simulate_noise(20_000, 100.0, NoiseSpec(white=1e-3), channels=2, seed=1), 100.0)
    >>> i = int(np.argmin(abs(r.tau - 1.0)))
    >>> r.adev.shape[0], float(r.tau[i]), bool(np.allclose(r.adev[:, i], 1e-3, rtol=0.15))
    (2, 1.0, True)
    """
    if not (np.isfinite(fs) and fs > 0):
        raise InputError(f"the sample rate must be a finite number of Hz > 0, not {float(fs)!r}", "{fs}")
    source = data if hasattr(data, "chunks") else ArrayChunks(data)
    n, c = source.shape
    names = tuple(names) if names is not None else tuple(f"col{j}" for j in range(c))
    m = tau_grid(n, fs, grid, per_decade)
    tau = m / fs
    adev, means, stability = np.full((c, len(m)), np.nan), np.empty(c), {p: np.empty(c) for p in periods}
    mdev = np.full((c, len(m)), np.nan) if modified and deviations else None
    alpha, edf, edf_m = (np.zeros((c, len(m)), np.int64), np.empty((c, len(m))), None if mdev is None else
                         np.empty((c, len(m)))) if deviations else (None, None, None)
    groups = _groups(n, c, memory_limit)
    for g, cols in enumerate(groups):  # the source read once per group: one group's phases in memory at a time
        step = None if progress is None else (lambda k, g=g: progress((g * n + k) // len(groups)))
        x, means[cols] = _phases(source, fs, memory_limit, cols, g == 0 and not getattr(source, "checked", False),
                                 step, where)
        if deviations:
            _deviations(x, m, fs, cols, adev, mdev, alpha, edf, edf_m)
        for p in periods:
            stability[p][cols] = [window_stability(x[i], fs, p) for i in range(len(cols))]
        del x
    return AllanResult(tau, m, adev, mdev, n, fs, names, means, stability, alpha, edf, edf_m)


def _deviations(x, m, fs, cols, adev, mdev, alpha, edf, edf_m) -> None:
    """The deviations of the channels ``cols`` from their phases ``x``, the noise type of every point and the
    Greenhall EDF that follows, written into those arrays' rows ``cols``."""
    from align.noise._kernels import avar_sums, mvar_sums  # numba is imported only when needed
    from align.noise.identify import edf_of, identify_noise

    n_phase = x.shape[1]
    adev[cols] = np.sqrt(avar_sums(x, m) / (2.0 * (m / fs) ** 2 * (n_phase - 2 * m)))
    if mdev is not None:
        mm = m[3 * m <= n_phase]
        mdev[cols, : len(mm)] = np.sqrt(mvar_sums(x, mm) / (2.0 * mm.astype(float) ** 2 * (mm / fs) ** 2
                                                             * (n_phase - 3 * mm + 1)))

    def mvar_of(k: int) -> np.ndarray:  # only where the B1 ratio finds phase noise
        if mdev is not None and np.all(np.isfinite(mdev[cols, k])):
            return mdev[cols, k] ** 2
        mk = m[k : k + 1]
        return mvar_sums(x, mk)[:, 0] / (2.0 * float(mk[0]) ** 2 * (mk[0] / fs) ** 2 * (n_phase - 3 * mk[0] + 1))

    alpha[cols], _ = identify_noise(x, m, adev[cols] ** 2, mvar_of)
    edf[cols] = edf_of(alpha[cols], m, n_phase)
    if edf_m is not None:
        edf_m[cols] = np.where(np.isfinite(mdev[cols]), edf_of(alpha[cols], m, n_phase, modified=True), np.nan)
