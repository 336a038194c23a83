"""Closed forms of the error growth of a static, level, low-speed mission (seed 002 Eq 4), and which error dominates.

Seed 002's Eq 4 (small perturbations, low speed, Earth rate and transport rate neglected), in NED
with ``eps`` the attitude error (the computed attitude is the true one turned by ``eps``,
``C' = (I + [eps x]) C``), ``e_g`` the gyro error and ``e_a`` the accelerometer error (body frame)::

    d eps / dt = C e_g                                                                 (E1)
    d dv / dt  = eps x f^n + C e_a,   f^n = (0, 0, -g):  dv_N' = -g eps_E + (C e_a)_N,
                                                          dv_E' =  g eps_N + (C e_a)_E,
                                                          dv_D' = (C e_a)_D            (E2)
    d dp / dt  = dv                                                                    (E3)

Static and level at heading ``psi`` (``C = Rz(psi)``), the roll, pitch and heading errors are the
integrals of the x, y and z gyro errors; north and east velocity errors are ``g`` times the second
integral of the gyro errors plus the first of the accelerometer errors; positions one integral
more. Everything is linear, each error term independent and zero-mean, so the mean is zero and
each term adds its variance. With ``S_k(t)`` the standard deviation of the ``k``-th time integral
of one error process ``e(t)`` (1-sigma figures as in :mod:`align.navigation.residuals`):

=====================  ==================  ======================  ========================
term                   S1 (angle; vel.)    S2 (velocity; position)  S3 (position)
=====================  ==================  ======================  ========================
bias ``sigma_b``       ``sigma_b t``       ``sigma_b t^2 / 2``      ``sigma_b t^3 / 6``
ramp ``R``             ``R t^2 / 2``       ``R t^3 / 6``            ``R t^4 / 24``
white ``N``            ``N sqrt(t)``       ``N sqrt(t^3 / 3)``      ``N sqrt(t^5 / 20)``
random walk ``K``      ``K sqrt(t^3 / 3)`` ``K sqrt(t^5 / 20)``     ``K sqrt(t^7 / 252)``
=====================  ==================  ======================  ========================

(``n``-fold integrals of a Wiener process ``W``: ``var = t^(2n+1) / ((n!)^2 (2n + 1))``.) So a
gyro bias gives an attitude error linear in time, a velocity error quadratic and a position error
cubic (the seed's statement after Eq 4: ``dv = g sigma_b t^2 / 2``, ``dp = g sigma_b t^3 / 6``),
and the random walks grow as ``sqrt(t)``, ``t^1.5``, ``t^2.5``. Flicker noise (bias instability
``B``, one-sided PSD ``B^2 / (pi f)``) has no power law of its own: it is the sum of random
sinusoids at ``f_k = k df`` with variance ``c_k^2 = B^2 ln(1 + 1/k) / pi`` each, the PSD integrated over
``[f_k, f_k + df]`` (the lines of the Monte Carlo's synthesis, :func:`flicker_lines`: the model's cutoff
``1 / (8 T)`` for a mission of ``T``, nothing below it), and
with ``x = 2 pi f_k t``::

    S1^2 = sum c_k^2 (2 sin(x/2))^2 / w^2
    S2^2 = sum c_k^2 [(1 - cos x)^2 + (x - sin x)^2] / w^4
    S3^2 = sum c_k^2 [(x - sin x)^2 + (x^2/2 - 1 + cos x)^2] / w^6                     (E4)

A residual scale or misalignment error of a static sensor acts as a bias: the accelerometers'
``dM`` times gravity (``g sigma_M,iz``), the gyros' ``dM`` times the Earth rate (when included).
A rigid mounting rotation of the whole IMU (``ResidualErrors.mount``, 1-sigma ``s`` about body x,
y, z) is an initial attitude error ``eps = C s``: constant angles (S1 = 1), velocity ``g eps t``
(S2 = t) and position ``g eps t^2 / 2`` (S3 = t^2 / 2) through E2-E3, as a gyro term.

Public names
------------
QUANTITIES, static_sigma, term_sigmas, flicker_lines, dominance, dominance_text, SYNTHESIS_SPAN, REFINE
"""

from __future__ import annotations

import numpy as np

from align.navigation.residuals import ResidualErrors, SensorErrors, label

#: the nine error components, in the order of every (..., 9) array
QUANTITIES = ("roll", "pitch", "heading", "north velocity", "east velocity", "down velocity",
              "north position", "east position", "down position")
#: flicker is synthesised over this many mission lengths (its lowest frequency is 1 / (SPAN T))
SYNTHESIS_SPAN = 8
#: lines per cutoff frequency of the flicker synthesis (its spacing is ``1 / (REFINE SYNTHESIS_SPAN T)``)
REFINE = 2


def flicker_lines(duration: float, points: int, span: int = SYNTHESIS_SPAN) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies (Hz) and variances per unit ``B^2`` of the flicker synthesis of a mission (E4).

    The Monte Carlo synthesises flicker on a grid of ``points - 1`` intervals over the mission,
    ``REFINE span`` times as long (one-sided PSD ``B^2 / (pi f)`` for ``f >= f_c = 1 / (span T)``, zero
    below), lines ``f_k = k df``, ``df = f_c / REFINE``, ``k >= REFINE``, and keeps its first ``T``. Line
    ``k`` carries the variance of the band ``[f_k, f_k + df]``::

        c_k^2 = integral_{k df}^{(k+1) df} df' / (pi f') = ln(1 + 1 / k) / pi          (per unit B^2)

    so the lines' variances sum to the model's (``ln(K + 1) / pi`` up to line ``K``) and nothing below
    the cutoff ``f_c`` enters. (Lines of ``df / (pi f_k)``, the PSD at the line, stand for the bands
    ``[f_k - df/2, f_k + df/2]``: their sum ``(ln K + 0.577) / pi`` reaches down to about
    ``f_c / 1.8``, and the drift came out 16-21 % above the stated model at ``t = T``; lines at the
    bands' lower edges put the variance a little low in frequency, 6 % too much at ``t = T`` with
    ``df = f_c``, 3 % with ``df = f_c / 2``: :data:`REFINE`.) The cutoff is
    the model: flicker slower than that is left out (the variance of a flicker integral grows as
    ``ln(span)``).

    Returns
    -------
    f : ndarray, shape (L,)
    c2 : ndarray, shape (L,)
        ``ln(1 + 1 / k) / pi``, zero below the cutoff (``k < REFINE``), the Nyquist line halved.
    """
    n = REFINE * span * (points - 1)
    df = 1.0 / (REFINE * span * duration)
    k = np.arange(1, n // 2 + 1)
    f = k * df
    c2 = np.log1p(1.0 / k) / np.pi  # the band [f_k, f_k + df] of the PSD: integral B^2 / (pi f) df per unit B^2
    c2[k < REFINE] = 0.0  # below the cutoff 1 / (span T)
    c2[-1] *= 0.5  # the Nyquist line is real: its cosine only, twice the amplitude (flicker_fft)
    return f, c2


def _x_minus_sin(x: np.ndarray) -> np.ndarray:
    small = np.abs(x) < 0.1
    xs = np.where(small, x, 0.0)
    return np.where(small, xs**3 / 6 - xs**5 / 120 + xs**7 / 5040, x - np.sin(x))


def _half_x2_minus_1_plus_cos(x: np.ndarray) -> np.ndarray:
    small = np.abs(x) < 0.1
    xs = np.where(small, x, 0.0)
    return np.where(small, xs**4 / 24 - xs**6 / 720 + xs**8 / 40320, x * x / 2 - 2 * np.sin(x / 2) ** 2)


def _flicker_s(t: np.ndarray, lines: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """``S1, S2, S3`` (3, T) of unit flicker (E4)."""
    f, c2 = lines
    w = 2 * np.pi * f[None, :]
    out = np.empty((3, len(t)))
    block = max(1, int(2e6 // max(len(f), 1)))  # times at once: bounded memory for long flicker spans
    for i in range(0, len(t), block):
        x = w * t[i:i + block, None]
        one_minus_cos = 2 * np.sin(x / 2) ** 2
        xs = _x_minus_sin(x)
        out[0, i:i + block] = np.sum(c2 * 2 * one_minus_cos / w**2, axis=1)
        out[1, i:i + block] = np.sum(c2 * (one_minus_cos**2 + xs**2) / w**4, axis=1)
        out[2, i:i + block] = np.sum(c2 * (xs**2 + _half_x2_minus_1_plus_cos(x) ** 2) / w**6, axis=1)
    return np.sqrt(out)


def _s(term: str, t: np.ndarray, lines) -> np.ndarray:
    """``S1, S2, S3`` (3, T) of a unit figure of ``term`` (module table)."""
    if term == "mount":  # an initial attitude error
        return np.stack([np.ones_like(t), t, t**2 / 2])
    if term in ("bias", "matrix", "tilt"):
        return np.stack([t, t**2 / 2, t**3 / 6])
    if term == "ramp":
        return np.stack([t**2 / 2, t**3 / 6, t**4 / 24])
    if term == "white":
        return np.stack([np.sqrt(t), np.sqrt(t**3 / 3), np.sqrt(t**5 / 20)])
    if term == "random_walk":
        return np.stack([np.sqrt(t**3 / 3), np.sqrt(t**5 / 20), np.sqrt(t**7 / 252)])
    return _flicker_s(t, lines)


def _axis_sigma(s: SensorErrors, term: str, g: float, earth_body: np.ndarray) -> np.ndarray:
    """The 1-sigma (3,) of a term of a static sensor, per body axis; a matrix term as the bias it makes."""
    if term == "matrix":
        x = np.array([0.0, 0.0, -g]) if s.sensor == "accelerometer" else earth_body
        return np.sqrt((s.matrix**2) @ (x**2))
    if term == "tilt":  # half the squared angle on each of the other two elements of the row
        x = np.array([0.0, 0.0, -g]) if s.sensor == "accelerometer" else earth_body
        off = (np.ones((3, 3)) - np.eye(3)) * (s.tilt[:, None] ** 2 / 2)
        return np.sqrt(off @ (x**2))
    return np.asarray(getattr(s, term), float)


def term_sigmas(errors: ResidualErrors, t: np.ndarray, gravity: float, heading: float = 0.0,
                earth_body: np.ndarray | None = None, duration: float | None = None,
                points: int = 257, span: int = SYNTHESIS_SPAN) -> dict[tuple[str, str], np.ndarray]:
    """The 1-sigma of the nine error components (QUANTITIES) that each error term alone gives (E1-E4).

    Parameters
    ----------
    errors : ResidualErrors
    t : ndarray, shape (T,)
        Times from the start, s.
    gravity : float
        m/s^2.
    heading : float
        Heading of the static body, rad.
    earth_body : ndarray, shape (3,), optional
        The Earth rate in the body frame (rad/s) that a gyro scale or misalignment error multiplies.
    duration, points, span : float, int, int
        The mission length, the flicker grid and span of the Monte Carlo (:func:`flicker_lines`).

    Returns
    -------
    dict
        ``(sensor, term) -> ndarray (T, 9)`` of every non-zero term; rad, m/s, m.
    """
    t = np.asarray(t, float)
    lines = flicker_lines(duration or float(t[-1]), points, span)
    eb = np.zeros(3) if earth_body is None else np.asarray(earth_body, float)
    c2, s2 = np.cos(heading) ** 2, np.sin(heading) ** 2
    out = {}
    for sensor, term in errors.terms():
        if sensor == "imu":
            sig = np.asarray(errors.mount, float)
        else:
            sig = _axis_sigma(errors.gyro if sensor == "gyroscope" else errors.accel, term, gravity, eb)
        if not np.any(sig > 0):
            continue
        unit = _s(term, t, lines)  # (3, T)
        var = np.zeros((len(t), 9))
        if sensor != "accelerometer":  # the gyros' and the initial attitude's errors are angles
            a = (sig[:, None, None] * unit[None]) ** 2  # (axis, S_k, T)
            var[:, 0], var[:, 1], var[:, 2] = a[0, 0], a[1, 0], a[2, 0]
            var[:, 3] = gravity**2 * (s2 * a[0, 1] + c2 * a[1, 1])
            var[:, 4] = gravity**2 * (c2 * a[0, 1] + s2 * a[1, 1])
            var[:, 6] = gravity**2 * (s2 * a[0, 2] + c2 * a[1, 2])
            var[:, 7] = gravity**2 * (c2 * a[0, 2] + s2 * a[1, 2])
        else:
            a = (sig[:, None, None] * unit[None]) ** 2
            for k, col in ((0, 3), (1, 6)):  # S1: velocity, S2: position
                var[:, col] = c2 * a[0, k] + s2 * a[1, k]
                var[:, col + 1] = s2 * a[0, k] + c2 * a[1, k]
                var[:, col + 2] = a[2, k]
        out[(sensor, term)] = np.sqrt(var)
    return out


def static_sigma(terms: dict[tuple[str, str], np.ndarray], shape: tuple[int, int]) -> np.ndarray:
    """The total 1-sigma (T, 9): the root-sum-square of the terms' (independent terms' variances add)."""
    total = np.zeros(shape)
    for v in terms.values():
        total += v**2
    return np.sqrt(total)


def dominance(t: np.ndarray, terms: dict[tuple[str, str], np.ndarray]) -> list[dict]:
    """For each of the nine components, the term with the largest 1-sigma over each stretch of time.

    Returns
    -------
    list of dict
        ``{"quantity", "from_s", "to_s", "term", "share"}``: the term (its label) dominant from
        ``from_s`` to ``to_s``, ``share`` its fraction of the total variance at ``to_s``.
    """
    if not terms:
        return []
    keys = list(terms)
    stack = np.stack([terms[k] for k in keys])  # (terms, T, 9)
    var = stack**2
    total = var.sum(axis=0)
    out = []
    for q, name in enumerate(QUANTITIES):
        live = total[:, q] > 0
        if not np.any(live):
            continue
        first = int(np.argmax(live))
        best = np.argmax(var[:, :, q], axis=0)
        start = first
        for i in range(first + 1, len(t) + 1):
            if i == len(t) or best[i] != best[start]:
                k = best[start]
                end = i - 1
                out.append({"quantity": name, "from_s": float(t[start]), "to_s": float(t[end]),
                            "term": label(*keys[k]), "share": float(var[k, end, q] / total[end, q])})
                start = i
    return out


def dominance_text(rows: list[dict], quantities=("roll", "pitch", "heading", "north position", "east position",
                                                   "down position")) -> str:
    """Which error dominates when, in plain words: one line per component."""
    lines = []
    for q in quantities:
        mine = [r for r in rows if r["quantity"] == q]
        if not mine:
            continue
        parts = [f"{r['term']} up to {mine[i + 1]['from_s']:.4g} s" for i, r in enumerate(mine[:-1])]
        parts.append(f"{mine[-1]['term']} to the end ({mine[-1]['share']:.0%} of the variance)" if parts
                     else f"{mine[-1]['term']} throughout ({mine[-1]['share']:.0%} of the variance at the end)")
        lines.append(f"{q}: {', then '.join(parts)}")
    return "\n".join(lines)
