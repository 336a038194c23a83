"""Numbers shown with their uncertainty: the digits a value is shown with follow its 1-sigma.

A 1-sigma is shown with at least one significant digit, never as ``0.0000``: with the column's usual
decimals when they show it, else with two significant digits and the value to the same decimal place (the
usual rule of measurement reports, e.g. the GUM's 7.2.6: an uncertainty with at most two significant
digits, the value rounded to match); beyond :data:`MAX_DECIMALS` decimals in scientific notation. A 1-sigma
of exactly zero is shown as ``0``.

A margin in units of its 1-sigma (:func:`ratio_text`) is shown with two significant digits (the relative
precision of a 1-sigma estimated from a few tens of degrees of freedom), as ``> +1000`` beyond a thousand
(far beyond any guard band; more digits would claim a precision the 1-sigma does not have), and not at all
against a zero 1-sigma (a ratio to zero says nothing): the cell says why.

Public names
------------
with_sigma, sigma_text, ratio_text, decimals_for, MAX_DECIMALS, RATIO_CAP
"""

from __future__ import annotations

import math

#: the most decimals shown in fixed notation; a 1-sigma needing more is shown in scientific notation
MAX_DECIMALS = 9
#: a margin beyond this many sigmas is shown as ``> +RATIO_CAP``
RATIO_CAP = 1000.0


def _finite(x: float | None) -> bool:
    return x is not None and math.isfinite(x)


def decimals_for(sigma: float, least: int = 4) -> int:
    """Decimals that show ``sigma`` with a significant digit: ``least`` when they do (its first digit at or before
    the ``least``-th decimal), else enough for two significant digits (a 1-sigma of 4.2e-6 needs 7: ``0.0000042``).

    Examples
    --------
    >>> decimals_for(0.0009), decimals_for(4.2e-6), decimals_for(0.0)
    (4, 7, 4)
    """
    if not _finite(sigma) or sigma <= 0:
        return least
    first = -math.floor(math.log10(sigma))  # decimal place of the first significant digit
    return least if first <= least else first + 1


def _fixed(x: float, decimals: int, sign: bool) -> str:
    x = round(float(x), decimals) + 0.0  # never -0.000
    return f"{x:+.{decimals}f}" if sign else f"{x:.{decimals}f}"


def sigma_text(sigma: float, least: int = 4) -> str:
    """A 1-sigma as :func:`with_sigma` shows it (``-`` when unknown, ``0`` when exactly zero).

    Examples
    --------
    >>> sigma_text(0.0009), sigma_text(4.2e-6), sigma_text(3.1e-12), sigma_text(0.0), sigma_text(float("nan"))
    ('0.0009', '0.0000042', '3.1e-12', '0', '-')
    """
    if not _finite(sigma):
        return "-"
    if sigma == 0:
        return "0"
    d = decimals_for(sigma, least)
    return f"{sigma:.1e}" if d > MAX_DECIMALS else _fixed(sigma, d, False)


def with_sigma(value: float, sigma: float, least: int = 4, sign: bool = False) -> tuple[str, str]:
    """``(value, 1-sigma)`` as text, the value to the decimal place the 1-sigma is shown to.

    Parameters
    ----------
    value, sigma : float
        In the unit shown (degrees, ...); ``sigma`` NaN when unknown.
    least : int
        The column's usual decimals (kept whenever they show the 1-sigma).
    sign : bool
        Whether the value is shown with its sign (``+0.0015``).

    Returns
    -------
    (str, str)
        A 1-sigma below ``10**-MAX_DECIMALS`` in scientific notation (``3.1e-12``), the value then to
        :data:`MAX_DECIMALS` decimals.

    Examples
    --------
    >>> with_sigma(0.15594, 0.00039)
    ('0.1559', '0.0004')
    >>> with_sigma(0.0014523, 4.2e-6, sign=True)
    ('+0.0014523', '0.0000042')
    >>> with_sigma(0.5, 0.0)
    ('0.5000', '0')
    """
    if not _finite(value):
        return "-", sigma_text(sigma, least)
    return _fixed(value, min(decimals_for(sigma, least), MAX_DECIMALS), sign), sigma_text(sigma, least)


def ratio_text(margin: float, sigma: float) -> str:
    """``margin / sigma`` for a table: two significant digits, ``> +1000`` beyond :data:`RATIO_CAP`; ``-`` for an
    unconstrained margin or an unknown 1-sigma; ``- (sigma 0)`` against a zero 1-sigma (no ratio to show).

    Examples
    --------
    >>> ratio_text(0.8441, 0.00042), ratio_text(0.0042, 0.0021), ratio_text(0.9985, 4.0e-6), ratio_text(0.5, 0.0)
    ('> +1000', '+2.0', '> +1000', '- (sigma 0)')
    >>> ratio_text(-0.03, 0.002)
    '-15'
    """
    if not _finite(margin) or not _finite(sigma) or sigma < 0:
        return "-"
    if sigma == 0:
        return "- (sigma 0)"
    x = margin / sigma
    if abs(x) > RATIO_CAP:
        return f"> +{RATIO_CAP:.0f}" if x > 0 else f"< -{RATIO_CAP:.0f}"
    if x == 0:
        return "0"
    decimals = max(0, 1 - math.floor(math.log10(abs(x))))
    return _fixed(round(x, 1 - math.floor(math.log10(abs(x)))), decimals, True)
