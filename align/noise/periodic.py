"""A periodic disturbance in an Allan variance curve: its signature, a scan over periods, the note that names it.

A sinusoidal rate ``Omega_0 sin(2 pi f_0 t)`` (a thermal cycle, a pump, a fan) has the Allan variance
(IEEE Std 952-1997 Annex C, Eq C.15)::

    sigma^2(tau) = Omega_0^2 (sin^2(pi f_0 tau) / (pi f_0 tau))^2

a bump that peaks near ``tau = 0.371 / f_0`` and falls as ``tau^-2`` beyond: no IEEE term has that shape,
and without a column of its own the fit takes its hump for bias instability (4 deg/h at a 500 s period
raised ``B`` by half). The fit (:func:`align.noise.fit.fit_noise`) scans :data:`PER_OCTAVE` periods per
octave over the taus it fits (:func:`scan`: the largest drop of chi-square one such column could give
beside the five terms), adds the best as a sixth column, and lets Holm's test
(:mod:`align.noise.gls`) decide with its p-value multiplied by the number of periods scanned (Bonferroni:
the look-elsewhere effect of the scan). Claimed, it stays in the model (out of ``B``) and is named in a note;
not claimed, it leaves the model.

Public names
------------
signature, periods, scan, note, PER_OCTAVE
"""

from __future__ import annotations

import numpy as np

from align.vocab import Note

__all__ = ["signature", "periods", "scan", "note", "PER_OCTAVE"]

#: periods scanned per octave (neighbouring signatures overlap: a finer grid adds look-elsewhere, not power)
PER_OCTAVE = 2


def signature(tau: np.ndarray, period: float) -> np.ndarray:
    """The Allan variance of a unit-amplitude sinusoid of ``period`` (s) at ``tau`` (T,) s (Eq C.15), shape (T,).

    Examples
    --------
    >>> import numpy as np
    >>> float(np.round(signature(np.array([0.371 * 500.0]), 500.0)[0], 3))
    0.525
    """
    x = np.pi * np.asarray(tau, dtype=float) / period
    return (np.sin(x) ** 2 / x) ** 2


def periods(tau: np.ndarray) -> np.ndarray:
    """The periods scanned for fitted taus ``tau`` (T,): the bump's peak (``0.371 P``) inside the taus, s."""
    lo, hi = tau[0] / 0.371 * 2.0, tau[-1] / 0.371 / 2.0
    if not hi > lo:
        return np.empty(0)
    count = max(1, int(np.floor(PER_OCTAVE * np.log2(hi / lo))) + 1)
    return np.geomspace(lo, hi, count)


def scan(tau: np.ndarray, residual_w: np.ndarray, wh: np.ndarray) -> tuple[float, float, int]:
    """The period whose signature best explains the whitened residual of a fit.

    Parameters
    ----------
    tau : ndarray, shape (T,)
        Fitted taus, s.
    residual_w : ndarray, shape (T,)
        Whitened residual ``W (y - A p)`` of the five-term fit.
    wh : ndarray, shape (T, T)
        The whitening ``W`` of that fit.

    Returns
    -------
    period : float
        s (NaN when no period fits in the taus).
    drop : float
        Chi-square drop a non-negative amplitude of it alone gives, ``max(0, r'c)^2 / c'c``.
    count : int
        Periods scanned (the Bonferroni factor of its test).
    """
    grid = periods(tau)
    best, where = 0.0, float("nan")
    for period in grid:
        c = wh @ signature(tau, period)
        dot = float(residual_w @ c)
        drop = dot * dot / float(c @ c) if dot > 0 else 0.0
        if drop > best:
            best, where = drop, float(period)
    return where, best, len(grid)


def note(period: float, amplitude: float) -> Note:
    """The note of a claimed periodic disturbance of ``period`` (s) and ``amplitude`` (SI: rad/s for a gyro, m/s^2
    for an accelerometer)."""
    return Note(f"periodic disturbance: a bump no noise term fits (a sinusoid's signature, IEEE Std 952 Annex C), "
                f"period about {period:.3g} s, amplitude about {amplitude:.3g} (SI: rad/s for a gyro, m/s^2 for an "
                "accelerometer); modelled apart from the terms, not read as bias instability", code="periodic")
