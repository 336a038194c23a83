"""Monte Carlo of the navigation error: many runs of the strapdown integrator with drawn residual errors.

Each run draws the residual errors of :mod:`align.navigation.residuals` (R1), adds them to the
mission's true increments and navigates (N4-N6, the compiled :func:`~align.navigation.strapdown.nav_step`,
runs in parallel); its error is its solution minus the error-free solution of the same integrator
(so the integration error of the truth cancels). Over a navigation step ``[t_k, t_k + h]`` the
error increments are, to first order in the errors (body frame at the step's start)::

    dtheta_err = b_g(t_k + h/2) h + dM_g dtheta_k + N_g sqrt(h) xi                    (M1)
    dv_err     = b_a(t_k + h/2) h + dM_a dv_k     + N_a sqrt(h) zeta                  (M2)
               + dtheta_err x dv_k / 2                                                 (M3)

with ``xi, zeta ~ N(0, I)``: the white noise of the ``m`` samples of a step summed (its exact
distribution: the sample rate does not enter), ``dtheta_k, dv_k`` the true increments, M3 the
rotation compensation (Savage's ``alpha x nu / 2``) of the turn error within the step (first order:
``dv_k`` holds ``g h``; without it the tilt error would reach the velocity one step late), and the
slow part ``b(t)`` (turn-on bias, ramp, bias instability, rate random walk) drawn on a grid of
at most 128 intervals over the mission and linearly interpolated: flicker by spectral synthesis
of PSD ``B^2 / (pi f)`` above the cutoff ``1 / (SYNTHESIS_SPAN T)`` (the lines of
:func:`~align.navigation.closed.flicker_lines`, each the variance of its band, on a grid
``REFINE SYNTHESIS_SPAN`` mission lengths long), the random walk ``b_j = b_j-1 + K sqrt(hc) w``. The terms
left out of (M1-M3) are second order (an error times the rotation within one step). The mean and
the standard deviation over the runs are kept at up to ``points`` times (Chan's pairwise update
over chunks of runs; no run is stored), and the percentiles of :data:`PERCENTILES` of the down
velocity and position over the first :data:`KEEP` runs (their second-order part ``g eps^2 / 2`` of a
tilt error ``eps`` is one-signed: mean +/- k sigma is no bound there).

A rigid mounting rotation of the whole IMU (``ResidualErrors.mount``) is an initial attitude error:
each run starts from ``q0 (x) exp(r)`` with ``r ~ N(0, diag(mount^2))`` (body frame) while the
truth starts from ``q0``; the sensors' readings are the IMU's own, unchanged.

Public names
------------
MonteCarlo, monte_carlo, term_monte_carlo, navigation_step, slow_grid
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from align.attitude import qexp, quat_from_rotvec, quat_multiply
from align.errors import InputError
from align.navigation.closed import REFINE, SYNTHESIS_SPAN, flicker_lines
from align.navigation.mission import Mission
from align.navigation.residuals import ResidualErrors, SensorErrors
from align.navigation.strapdown import _navigate, earth_rate_ned, euler_from_quat, nav_step, step_increments
from align.values import Value

#: the slow part of the errors is drawn on at most this many intervals over the mission
SLOW_INTERVALS = 128
#: memory for the white noise of one chunk of runs, bytes
CHUNK_BYTES = 48e6
#: the default navigation rate, Hz (the sensor's rate when slower)
NAV_RATE = 10.0
#: percentiles kept of the down channels (the central 68.27 % and 99.73 %, and the median)
PERCENTILES = (0.135, 15.865, 50.0, 84.135, 99.865)
#: runs whose down channels are kept for the percentiles
KEEP = 2000
#: the columns of the down velocity and position (closed.QUANTITIES)
DOWN = (5, 8)


@dataclass(frozen=True, eq=False)
class MonteCarlo(Value):
    """Mean and standard deviation over the runs of the nine error components (closed.QUANTITIES).

    Attributes
    ----------
    t : ndarray, shape (P,)
        s.
    mean, sigma : ndarray, shape (P, 9)
        rad (roll, pitch, heading), m/s (north, east, down), m (north, east, down); ``sigma`` ddof 1.
    runs : int
    nav_rate : float
        Navigation update rate, Hz.
    seed : int
    down_percentiles : ndarray, shape (len(PERCENTILES), P, 2)
        Percentiles of the down velocity and position over the first ``min(runs, KEEP)`` runs.
    """

    t: np.ndarray
    mean: np.ndarray
    sigma: np.ndarray
    runs: int
    nav_rate: float
    seed: int
    down_percentiles: np.ndarray | None = None


def navigation_step(fs: float, nav_rate: float | None) -> int:
    """Samples per navigation step: ``round(fs / nav_rate)``, at least 1 (default rate :data:`NAV_RATE`)."""
    rate = NAV_RATE if nav_rate is None else nav_rate
    if not (np.isfinite(rate) and rate > 0):
        raise InputError("the navigation rate must be > 0", "{nav_rate}")
    return max(1, int(round(fs / rate)))


@njit(cache=True)
def _wrap(a: float) -> float:
    return (a + np.pi) % (2 * np.pi) - np.pi


@njit(cache=True)
def _record(q, v, p, te, tv, tp, out):
    w, x, y, z = q[0], q[1], q[2], q[3]
    roll = np.arctan2(2 * (y * z + w * x), 1 - 2 * (x * x + y * y))
    s = 2 * (x * z - w * y)
    pitch = -np.arcsin(min(1.0, max(-1.0, s)))
    heading = np.arctan2(2 * (x * y + w * z), 1 - 2 * (y * y + z * z))
    out[0], out[1], out[2] = _wrap(roll - te[0]), _wrap(pitch - te[1]), _wrap(heading - te[2])
    for j in range(3):
        out[3 + j] = v[j] - tv[j]
        out[6 + j] = p[j] - tp[j]


@njit(parallel=True, cache=True)
def _runs(dth, dv, h, q0s, g, wie, mg, ma, slow_g, slow_a, hc, white_g, white_a, wsd, out_idx, te, tv, tp, err):
    runs, steps, slots = mg.shape[0], dth.shape[0], slow_g.shape[1]
    qe = qexp(-wie * h)
    wide_g, wide_a = white_g.shape[1] > 1, white_a.shape[1] > 1
    for r in prange(runs):
        q, v, p = q0s[r].copy(), np.zeros(3), np.zeros(3)
        th, du = np.empty(3), np.empty(3)
        o = 0
        if out_idx[0] == 0:
            _record(q, v, p, te[0], tv[0], tp[0], err[r, 0])
            o = 1
        for k in range(steps):
            pos = (k + 0.5) * h / hc
            j = min(int(pos), slots - 2)
            a = pos - j
            kg, ka = k if wide_g else 0, k if wide_a else 0
            for c in range(3):
                bg = slow_g[r, j, c] * (1 - a) + slow_g[r, j + 1, c] * a
                ba = slow_a[r, j, c] * (1 - a) + slow_a[r, j + 1, c] * a
                th[c] = (dth[k, c] + bg * h + mg[r, c, 0] * dth[k, 0] + mg[r, c, 1] * dth[k, 1] + mg[r, c, 2] * dth[k, 2]
                         + white_g[r, kg, c] * wsd[c])
                du[c] = (dv[k, c] + ba * h + ma[r, c, 0] * dv[k, 0] + ma[r, c, 1] * dv[k, 1] + ma[r, c, 2] * dv[k, 2]
                         + white_a[r, ka, c] * wsd[3 + c])
            e0, e1, e2 = th[0] - dth[k, 0], th[1] - dth[k, 1], th[2] - dth[k, 2]  # the step's turn error (M3)
            du[0] += 0.5 * (e1 * dv[k, 2] - e2 * dv[k, 1])
            du[1] += 0.5 * (e2 * dv[k, 0] - e0 * dv[k, 2])
            du[2] += 0.5 * (e0 * dv[k, 1] - e1 * dv[k, 0])
            nav_step(q, v, p, th, du, h, g, wie, qe)
            if o < out_idx.shape[0] and k + 1 == out_idx[o]:
                _record(q, v, p, te[o], tv[o], tp[o], err[r, o])
                o += 1


def _flicker(rng: np.random.Generator, runs: int, points: int, hc: float, b: np.ndarray,
             span: int = SYNTHESIS_SPAN) -> np.ndarray:
    """Flicker of PSD ``B^2 / (pi f)`` at ``points`` grid times (runs, points, 3) (closed.flicker_lines)."""
    n = REFINE * span * (points - 1)
    f, c2 = flicker_lines((points - 1) * hc, points, span)
    amp = np.sqrt(c2) * n / 2.0  # irfft: a line X_k = A (u + i v) gives (2 A / n) (u cos - v sin)
    amp[-1] = np.sqrt(c2[-1]) * n  # the Nyquist line appears once, real
    series = np.empty((points, runs * 3))
    group = max(1, int(CHUNK_BYTES // (16 * (n // 2 + 1))))  # columns synthesised at once: bounded memory
    for c in range(0, runs * 3, group):
        cols = min(group, runs * 3 - c)
        spec = np.zeros((n // 2 + 1, cols), complex)
        spec[1:] = amp[:, None] * (rng.standard_normal((len(f), cols)) + 1j * rng.standard_normal((len(f), cols)))
        spec[-1] = spec[-1].real
        series[:, c:c + cols] = np.fft.irfft(spec, n, axis=0)[:points]
    return series.reshape(points, runs, 3).transpose(1, 0, 2) * b


def _slow(rng, s: SensorErrors, runs: int, points: int, hc: float, span: int = SYNTHESIS_SPAN) -> np.ndarray:
    """Turn-on bias, ramp, flicker and random walk of one sensor on the grid (runs, points, 3)."""
    t = np.arange(points) * hc
    out = np.zeros((runs, points, 3))
    if np.any(s.bias > 0):
        out += (rng.standard_normal((runs, 3)) * s.bias)[:, None, :]
    if np.any(s.ramp > 0):
        out += (rng.standard_normal((runs, 3)) * s.ramp)[:, None, :] * t[None, :, None]
    if np.any(s.flicker > 0):
        out += _flicker(rng, runs, points, hc, s.flicker, span)
    if np.any(s.random_walk > 0):
        steps = rng.standard_normal((runs, points - 1, 3)) * s.random_walk * np.sqrt(hc)
        out[:, 1:] += np.cumsum(steps, axis=1)
    return out


def _matrix(rng, s: SensorErrors, runs: int) -> np.ndarray:
    """``dM`` of each run (runs, 3, 3): element sigmas and a random-direction tilt of each axis (rms ``tilt_i``:
    ``N(0, tilt_i^2 / 2)`` on each of the row's two other elements)."""
    out = np.zeros((runs, 3, 3))
    if np.any(s.matrix > 0):
        out += rng.standard_normal((runs, 3, 3)) * s.matrix
    if np.any(s.tilt > 0):
        lean = rng.standard_normal((runs, 3, 2)) * (s.tilt / np.sqrt(2))[None, :, None]
        for i in range(3):
            out[:, i, (i + 1) % 3] += lean[:, i, 0]
            out[:, i, (i + 2) % 3] += lean[:, i, 1]
    return out


def _starts(rng, q0: np.ndarray, mount: np.ndarray, runs: int) -> np.ndarray:
    """The initial attitude of each run (runs, 4): ``q0 (x) exp(r)``, ``r ~ N(0, diag(mount^2))`` (body frame)."""
    if not np.any(mount > 0):
        return np.tile(q0, (runs, 1))
    return quat_multiply(q0[None, :], quat_from_rotvec(rng.standard_normal((runs, 3)) * mount))


def slow_grid(steps: int) -> int:
    """Points of the grid the slow errors are drawn on for a mission of ``steps`` navigation steps."""
    return min(steps, SLOW_INTERVALS) + 1


def _outputs(steps: int, points: int) -> np.ndarray:
    every = max(1, int(np.ceil(steps / max(points - 1, 1))))
    idx = np.arange(0, steps + 1, every)
    return idx if idx[-1] == steps else np.append(idx, steps)


def monte_carlo(mission: Mission, errors: ResidualErrors, runs: int, seed: int = 0, nav_rate: float | None = None,
                points: int = 601, progress=None, flicker_span: int = SYNTHESIS_SPAN) -> MonteCarlo:
    """Mean and 1-sigma of the navigation error over ``runs`` runs (module docstring).

    Parameters
    ----------
    mission : Mission
    errors : ResidualErrors
    runs : int
        At least 2.
    seed : int
    nav_rate : float, optional
        Navigation update rate, Hz (:func:`navigation_step`).
    points : int
        Times kept (evenly spaced navigation steps, the last included).
    progress : callable, optional
        Called with the number of runs done so far.
    flicker_span : int
        Flicker is synthesised over this many mission lengths: its lowest frequency is
        ``1 / (flicker_span T)`` (:func:`~align.navigation.closed.flicker_lines`).

    Returns
    -------
    MonteCarlo
    """
    if runs < 2:
        raise InputError("the Monte Carlo needs at least 2 runs", "{runs}")
    m = navigation_step(mission.fs, nav_rate)
    dt = 1.0 / mission.fs
    dth, dv = step_increments(mission.w, mission.f, dt, m)
    steps, h = len(dth), m * dt
    wie = earth_rate_ned(mission.latitude) if mission.earth_rate else np.zeros(3)
    g = np.array([0.0, 0.0, mission.gravity])
    tq, tv, tp = _navigate(dth, dv, h, mission.q0.copy(), np.zeros(3), np.zeros(3), g, wie)
    idx = _outputs(steps, points)
    te = np.ascontiguousarray(euler_from_quat(tq[idx]))
    tv, tp = np.ascontiguousarray(tv[idx]), np.ascontiguousarray(tp[idx])
    slots = slow_grid(steps)
    hc = steps * h / (slots - 1)
    gy, ac = errors.gyro, errors.accel
    wsd = np.concatenate([gy.white, ac.white]) * np.sqrt(h)
    noisy = (bool(np.any(gy.white > 0)), bool(np.any(ac.white > 0)))  # only a sensor with white noise draws it
    rng = np.random.default_rng(seed)
    chunk = int(max(2, min(256, CHUNK_BYTES // (steps * 3 * 4 * sum(noisy))))) if any(noisy) else 256
    count, mean, m2 = 0, np.zeros((len(idx), 9)), np.zeros((len(idx), 9))
    kept = []
    while count < runs:
        r = min(chunk, runs - count)
        white = [rng.standard_normal((r, steps, 3), np.float32) if on else np.zeros((r, 1, 3), np.float32)
                 for on in noisy]
        err = np.zeros((r, len(idx), 9))
        _runs(dth, dv, h, _starts(rng, mission.q0, errors.mount, r), g, wie, _matrix(rng, gy, r), _matrix(rng, ac, r),
              _slow(rng, gy, r, slots, hc, flicker_span), _slow(rng, ac, r, slots, hc, flicker_span), hc, white[0],
              white[1], wsd, idx, te, tv, tp, err)
        if count < KEEP:
            kept.append(err[: KEEP - count][:, :, DOWN])
        cm = err.mean(axis=0)
        cm2 = ((err - cm) ** 2).sum(axis=0)
        delta = cm - mean
        total = count + r
        mean = mean + delta * r / total
        m2 = m2 + cm2 + delta**2 * count * r / total
        count = total
        if progress is not None:
            progress(count)
    down = np.percentile(np.concatenate(kept), PERCENTILES, axis=0)
    return MonteCarlo(idx * h, mean, np.sqrt(m2 / (runs - 1)), runs, mission.fs / m, seed, down)


def term_monte_carlo(mission: Mission, errors: ResidualErrors, runs: int, seed: int = 0,
                     nav_rate: float | None = None, points: int = 601,
                     flicker_span: int = SYNTHESIS_SPAN) -> dict[tuple[str, str], np.ndarray]:
    """The 1-sigma (P, 9) each error term alone gives: a Monte Carlo of ``runs`` runs per term."""
    return {(s, k): monte_carlo(mission, errors.only(s, k), runs, seed + 1 + i, nav_rate, points,
                                flicker_span=flicker_span).sigma
            for i, (s, k) in enumerate(errors.terms())}
