"""The checks of a log's rows and time stamps, the same for every reader.

A reading must be finite and a plausible number (not a corrupt 1e300); time must
increase, and where an estimator needs uniform samples (the Allan deviation) it
must have no gaps or jitter. Each refusal names the first bad data row.

Public names
------------
check_finite, check_readings, check_repeats, check_time, check_log, MAX_READING
"""

from __future__ import annotations

import numpy as np

from align.errors import InputError

#: the largest magnitude a reading may have in its file's unit (a 32-bit ADC's counts reach 4.3e9): beyond it a
#: value is a corrupt sample, not a measurement (a single 1e300 would swamp every mean and deviation)
MAX_READING = 1e12


def _rows(n: int) -> str:
    return "1 row" if n == 1 else f"{n} rows"


def check_finite(x: np.ndarray, where: str, t: np.ndarray | None = None, first_row: int = 1) -> None:
    """Reject rows of ``x`` (n, k) (or times ``t``) that are NaN or infinite, naming the first by its data row
    (``first_row``: the number of the first row of ``x``)."""
    bad = ~np.isfinite(x).all(axis=1)
    if t is not None:
        bad |= ~np.isfinite(t)
    if bad.any():
        rows = np.flatnonzero(bad)
        raise InputError(f"{_rows(len(rows))} with NaN or inf (first at data row {rows[0] + first_row}); remove or "
                         "repair them", where)


def check_readings(x: np.ndarray, where: str, t: np.ndarray | None = None, first_row: int = 1) -> None:
    """Reject rows of ``x`` (n, k) that are not readings: NaN or infinite (:func:`check_finite`), or with a
    value beyond :data:`MAX_READING` in magnitude (a corrupt sample); the first is named by its data row."""
    x = np.asarray(x)
    x = x[:, None] if x.ndim == 1 else x
    if x.size and (t is None or np.isfinite(t).all()):  # the usual case in two passes without temporaries:
        lo, hi = float(x.min()), float(x.max())         # NaN propagates into both, inf shows in one of them
        if -MAX_READING <= lo and hi <= MAX_READING:
            return
    check_finite(x, where, t, first_row)
    big = (np.abs(x) > MAX_READING).any(axis=1)
    if big.any():
        rows = np.flatnonzero(big)
        value = float(x[rows[0]][np.abs(x[rows[0]]) > MAX_READING][0])
        raise InputError(f"{_rows(len(rows))} with a value beyond +/-{MAX_READING:.0e} (first at data row "
                         f"{rows[0] + first_row}: {value:.3g}): not a sensor reading; remove or repair them", where)


def check_repeats(t: np.ndarray, where: str) -> None:
    """Refuse time stamps that repeat on more than a tenth of the steps (and never go back): a logger clock coarser
    than the sample interval (integer milliseconds at 2 kHz), to be read at its sample rate instead."""
    dt = np.diff(t)
    repeats = int(np.sum(dt == 0))
    if repeats > 0.1 * len(dt) and not np.any(dt < 0):
        k = int(np.argmax(dt == 0))
        raise InputError(f"time stamps repeat on {repeats} of {len(dt)} steps (first at data row {k + 2}, t={t[k]:.9g}): "
                         "the clock is coarser than the sample interval; read the log without its time column at its "
                         "sample rate ({rate_hz})", where)


def check_time(t: np.ndarray, where: str, gap: float | None = None, jitter: bool = False) -> None:
    """Time must increase; with ``gap``, no step may exceed ``gap`` times the median step
    (and, with ``jitter``, none may fall below ``2 - gap`` times it: uniform sampling)."""
    dt = np.diff(t)
    if np.any(dt <= 0):
        k = int(np.argmax(dt <= 0))
        check_repeats(t, where)
        raise InputError(f"time does not increase at data row {k + 2} (t={t[k + 1]:.9g} s after {t[k]:.9g} s); "
                         "sort the log or fix the time column", where)
    if gap is None or len(dt) == 0:
        return
    med = float(np.median(dt))
    off = (dt > gap * med) | ((dt < (2 - gap) * med) if jitter else False)
    if off.any():
        k = int(np.argmax(off))
        raise InputError(f"{int(off.sum())} time gaps{' or jitter' if jitter else ''} beyond {100 * (gap - 1):g} % of the "
                         f"{med:.4g} s median step: gap in the time series at t={t[k]:.6g} s (step {dt[k]:.4g} s); "
                         "resample or split the file", where)


def check_log(t: np.ndarray, g: np.ndarray, where: str, min_rows: int = 10) -> None:
    """Reject NaN or infinite rows, non-increasing time and logs that are too short."""
    if len(t) < min_rows:
        raise InputError(f"only {len(t)} rows; at least {min_rows} are needed", where)
    check_readings(g, where, t)
    check_time(t, where)
