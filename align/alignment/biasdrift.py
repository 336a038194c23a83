"""Bias drift between segments: a random walk plus flicker, measured from the static periods.

Model (per gyro, Eq D1): ``b(t) = b_0 + K W(t) + F(t)``: ``W`` a Wiener process (rate random walk ``K``,
rad/s/sqrt(s), one-sided PSD ``K^2 / (2 pi f)^2``, as :func:`~align.alignment.simulate.simulate_session`
makes it) and ``F`` flicker of coefficient ``B`` (rad/s, one-sided PSD ``B^2 / (pi f)``, Allan floor
``0.664 B``, as :func:`align.flicker.flicker_fft`). Neither has a variance of its own, but every
combination ``sum_k c_k bbar_k`` of the segments' mean biases with ``sum_k c_k = 0`` has (Eq D2)::

    var = sum_kl c_k c_l G_kl,   G_kl = -(K^2 / 2) <|s - t|>_kl - (B^2 / pi) <ln|s - t|>_kl

with ``<.>_kl`` the mean over ``s`` in segment ``k`` and ``t`` in segment ``l`` (the generalised covariances of
Brownian motion and of 1/f noise; closed forms in :func:`interval_means`). Two adjacent means over ``tau``
differ by ``2 K^2 tau / 3`` and ``(4 ln 2 / pi) B^2``: twice the Allan variances. :func:`estimate_drift`
measures ``K`` and ``B`` from the scatter of the static periods' means (Eq D4; one value shared by the three
gyros unless a gyro's own is significantly better, Eq D5); :func:`with_drift` attaches the model to the
observations and adds to each its mean bias' deviation from the session bias (Eq D3). Without a latitude the
static periods also hold the Earth rate, constant but different between orientations (Eq O1-O3 of
:mod:`align.alignment.observe`): its covariance is part of the samples' noise, so it is not read as a drift.

The estimators' own error follows exactly from Eq D2 (:mod:`align.alignment.estimate`): a ``+/-`` pair's
difference carries the bias change between its two segments, a turn its mean bias change times ``T``. The
bias a fit reports is the session bias: the mean of ``b(t)`` over the samples of the segments it used.

Public names
------------
Drift, DriftObservation, interval_means, estimate_drift, with_drift
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.alignment.observe import Observation
from align.units import to_unit
from align.values import Value


@dataclass(frozen=True, eq=False)
class Drift(Value):
    """The bias drift of the three gyros (Eq D1) and where it was measured.

    Attributes
    ----------
    walk : ndarray, shape (3,)
        Rate random walk ``K`` of each gyro, rad/s/sqrt(s).
    flicker : ndarray, shape (3,)
        Flicker coefficient ``B`` of each gyro, rad/s.
    source : str
        ``"static periods"``, ``"pairwise biases"`` or ``"none"``.
    probes : int
        Bias samples the estimate rests on (static periods or +/- pairs).
    note : str
        One line for the result's notes.
    """

    walk: np.ndarray
    flicker: np.ndarray
    source: str
    probes: int
    note: str

    def covariance(self, spans: np.ndarray) -> np.ndarray:
        """Generalised covariance ``G`` (Eq D2) of the mean biases over the time spans ``(k, 2)`` (s).

        Returns
        -------
        ndarray, shape (3, k, k)
            (rad/s)^2 per gyro; meaningful only in combinations whose coefficients sum to zero.
        """
        m_abs, m_log = interval_means(spans)
        return -(self.walk[:, None, None] ** 2 / 2) * m_abs - (self.flicker[:, None, None] ** 2 / np.pi) * m_log


@dataclass(frozen=True, eq=False)
class DriftObservation(Observation):
    """An :class:`Observation` whose ``var`` also holds the bias drift (Eq D3), made by :func:`with_drift`.

    Attributes
    ----------
    noise_var : ndarray, shape (3,)
        The variance of ``y`` from the noise inside the segment alone (the original ``var``).
    span : tuple of float
        Start and end of the segment, s (from the log's first sample).
    drift : Drift
        The model the estimators propagate exactly (Eq D2).
    """

    noise_var: np.ndarray
    span: tuple[float, float]
    drift: Drift


def _f2_abs(u: np.ndarray) -> np.ndarray:
    return np.abs(u) ** 3 / 6.0


def _f2_log(u: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore"):
        out = u**2 / 2.0 * np.log(np.abs(u)) - 0.75 * u**2
    return np.where(u == 0.0, 0.0, out)


def interval_means(spans: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Means of ``|t - s|`` and ``ln|t - s|`` over ``s`` in span ``k`` and ``t`` in span ``l``.

    By the second antiderivative ``F`` of the kernel: ``(F(b1 - a0) - F(b1 - a1) - F(b0 - a0) + F(b0 - a1))
    / ((a1 - a0)(b1 - b0))`` with ``F(u) = |u|^3 / 6`` and ``u^2 ln|u| / 2 - 3 u^2 / 4``.

    Parameters
    ----------
    spans : ndarray, shape (k, 2)
        Start and end of each span, s (end > start).

    Returns
    -------
    tuple of ndarray, shapes (k, k)
        s and ln(s).
    """
    spans = np.asarray(spans, float).reshape(-1, 2)
    a0, a1 = spans[:, :1], spans[:, 1:]
    b0, b1 = a0.T, a1.T
    area = (a1 - a0) * (b1 - b0)
    out = []
    for f2 in (_f2_abs, _f2_log):
        out.append((f2(b1 - a0) - f2(b1 - a1) - f2(b0 - a0) + f2(b0 - a1)) / area)
    return out[0], out[1]


def _span(o: Observation, t: np.ndarray) -> tuple[float, float]:
    start = float(t[o.segment.start] - t[0])
    return start, start + float(o.duration)


def _earth(o: Observation) -> np.ndarray:
    """The observation's shared, unmodelled Earth term (3, 3) (zeros when none; see :mod:`~align.alignment.observe`)."""
    return np.zeros((3, 3)) if o.earth is None else np.asarray(o.earth, float)


def _probes(observations: list[Observation], t: np.ndarray, sigma: np.ndarray | None, m: np.ndarray):
    """Bias samples (value (3,), noise variance (3,), spans (j, 2), weights (j,), shared Earth term (3, 3)) and
    their source."""
    statics = sorted((o for o in observations if o.segment.kind == "static"), key=lambda o: o.segment.start)
    if len(statics) >= 2:
        out = []
        for o in statics:  # var: the noise inside, and the Earth rate observe could not model
            v = o.var if sigma is None else np.maximum(o.var, sigma**2 / o.segment.n)
            out.append((o.y - m @ o.phi[:3], np.asarray(v, float), np.array([_span(o, t)]), np.ones(1), _earth(o)))
        return out, "static periods"
    moving = sorted((o for o in observations if o.segment.kind != "static"), key=lambda o: o.segment.start)
    taken: set[int] = set()
    out = []
    for i, p in enumerate(moving):
        if i in taken:
            continue
        for j in range(i + 1, len(moving)):
            n = moving[j]
            size = np.linalg.norm(p.phi[:3])
            if j not in taken and n.segment.kind == p.segment.kind and size > 0 and \
                    np.linalg.norm(p.phi[:3] + n.phi[:3]) < 1e-3 * size:
                total = p.phi[3] + n.phi[3]
                value = (p.y + n.y - m @ (p.phi[:3] + n.phi[:3])) / total
                out.append((value, (p.var + n.var) / total**2, np.array([_span(p, t), _span(n, t)]),
                            np.array([p.phi[3], n.phi[3]]) / total, (_earth(p) + _earth(n)) / total))
                taken.update((i, j))
                break
    return out, "pairwise biases"


#: the grids of Eq D4: the flicker share of the drift and its size relative to the increments' scatter
_SHARES = np.linspace(0.0, 1.0, 21)
_SIZES = np.concatenate([[0.0], np.geomspace(1e-6, 1e6, 241)])


def _walk_flicker(incs: list[np.ndarray], noises: list[np.ndarray], basis: list[np.ndarray]
                  ) -> tuple[np.ndarray, np.ndarray]:
    """``(K^2, B^2) >= 0`` maximising the Gaussian likelihood of the increments ``d`` (Eq D4), shape (2, 4):
    for each gyro alone (columns 0-2) and for the three sharing them (column 3); and each gyro's gain in
    ``-2 log L`` (3,) from its own values over the shared ones (Eq D5).

    ``cov = V + s ((1 - r) A_W / a_W + r A_F / a_F)`` over a grid of shares ``r`` and sizes ``s`` (``a`` scales
    each to the mean square increment); for each ``r`` the generalised eigenvectors of ``(A_r, V)`` make
    ``-2 log L = sum_j ln(1 + s l_j) + z_j^2 / (1 + s l_j)`` + const.
    """
    from scipy.linalg import eigh

    ss = float(np.mean([d @ d for d in incs]))
    out = np.zeros((2, 4))
    if not ss > 0:
        return out, np.zeros(3)
    scale = np.array([ss / max(float(np.trace(b)), 1e-300) for b in basis])
    nll = np.zeros((len(_SHARES), 3, len(_SIZES)))
    for j, r in enumerate(_SHARES):
        a = (1 - r) * scale[0] * basis[0] + r * scale[1] * basis[1]
        for i, (d, v) in enumerate(zip(incs, noises)):
            v = v + np.eye(len(d)) * 1e-12 * max(float(np.trace(v)), ss)
            lam, u = eigh(a, v)
            den = 1.0 + _SIZES[:, None] * np.maximum(lam, 0.0)[None, :]
            nll[j, i] = np.sum(np.log(den) + (u.T @ d) ** 2 / den, axis=1)
    best = []
    for i, curve in enumerate([nll[:, 0], nll[:, 1], nll[:, 2], nll.sum(axis=1)]):
        j, k = (int(v) for v in np.unravel_index(np.argmin(curve), curve.shape))
        out[:, i] = _SIZES[k] * np.array([1 - _SHARES[j], _SHARES[j]]) * scale
        best.append((j, k))
    j, k = best[3]
    gain = np.array([nll[j, i, k] - nll[best[i][0], i, best[i][1]] for i in range(3)])
    return out, gain


#: Eq D5: a gyro's own drift replaces the shared one only beyond this gain in ``-2 log L`` (two more parameters,
#: chi^2 with 2 degrees of freedom at 5 % over the three gyros tried: 1 - 0.05 / 3)
OWN_DRIFT_GAIN = 8.19


def _fit_walk_flicker(probes) -> tuple[np.ndarray, np.ndarray]:
    """``K^2`` and ``B^2`` (each shape (3,)) from the probes' consecutive differences (Eq D4): the shared estimate,
    or, where a gyro's own fits its increments significantly better (Eq D5), the larger of the two term by term."""
    spans = np.vstack([p[2] for p in probes])
    m_abs, m_log = interval_means(spans)
    sizes = np.cumsum([0] + [len(p[3]) for p in probes])
    diff = np.zeros((len(probes) - 1, len(spans)))  # consecutive differences of the probes, on the spans
    for j in range(len(probes) - 1):
        diff[j, sizes[j]:sizes[j + 1]] = probes[j][3]
        diff[j, sizes[j + 1]:sizes[j + 2]] = -probes[j + 1][3]
    basis = [diff @ (-0.5 * m_abs) @ diff.T, diff @ (-m_log / np.pi) @ diff.T]
    step = np.eye(len(probes))[:-1] - np.eye(len(probes), k=1)[:-1]
    values, noise = np.array([p[0] for p in probes]), np.array([p[1] for p in probes])
    earth = np.array([p[4] for p in probes])  # (j, 3, 3): the Earth rate shared between probes is not a drift
    incs = [step @ values[:, i] for i in range(3)]
    noises = [step @ (np.diag(noise[:, i]) + earth[:, i] @ earth[:, i].T) @ step.T for i in range(3)]
    both, gain = _walk_flicker(incs, noises, basis)
    out = np.where(gain[None, :] > OWN_DRIFT_GAIN, np.maximum(both[:, :3], both[:, 3:]), both[:, 3:])
    return out[0], out[1]


def estimate_drift(observations: list[Observation], t: np.ndarray, sigma: np.ndarray | None = None,
                   m: np.ndarray | None = None) -> Drift:
    """Measure the bias drift (Eq D1) from the scatter of the bias between segments (Eq D4).

    The bias samples are the static periods' means ``y - M phi`` (at least two); without them, the pairwise biases
    of ``+/-`` pairs (two dwells or turns with opposite ``phi``: ``(y+ + y-) / (T+ + T-)``, each the mean over its
    two segments). Their consecutive differences ``d`` (free of the turn-on bias) are Gaussian with the covariance
    ``V + K^2 A_W + B^2 A_F`` (``V`` the samples' noise and, without a latitude, the covariance of the Earth rate
    they share, Eq O3 of :mod:`~align.alignment.observe`: a constant, not a drift; ``A`` Eq D2 for unit ``K``,
    ``B``); ``K^2, B^2 >= 0`` maximise its likelihood (Eq D4, restricted maximum likelihood), for each gyro and for
    the three together (sharing ``K``, ``B``). The gyros share the joint value unless one's own fits its increments
    better by more than chance allows (Eq D5: ``-2 log L`` lower by more than :data:`OWN_DRIFT_GAIN`, the 5 % level
    of chi^2 with 2 degrees of freedom over the three gyros tried): that gyro keeps the larger of its own and the
    shared value, term by term, since a handful of static periods measures the drift only to tens of percent and an
    underestimate would make the uncertainties claim too much. (Taking the larger one always claims a drift on a
    drift-free gyro in about half the sessions of a few static periods, and a false drift spends what the dwells
    hold.) With neither source the drift is zero and the note says it was not measured.

    Parameters
    ----------
    observations : list of Observation
        All segments of the session (statics included), from :func:`~align.alignment.observe.observe`.
    t : ndarray, shape (n,)
        Time of the log, s.
    sigma : ndarray, shape (3,), optional
        Per-sample white noise, rad/s: the noise of a static mean is its ``var`` (what observe put there: the
        noise inside and the Earth rate it could not model), at least ``sigma^2 / n``.
    m : ndarray, shape (3, 3), optional
        ``M`` (or the nominal mounting) to remove the modelled rate ``M phi`` from the bias samples
        (the Earth rate of static periods, the unequal Earth terms of a pair); identity by default.

    Returns
    -------
    Drift
    """
    m = np.eye(3) if m is None else np.asarray(m, float)
    probes, source = _probes(observations, t, sigma, m)
    if len(probes) < 2:
        note = ("bias drift not measured (no static periods or +/- pairs): the uncertainties hold the noise "
                "inside the segments and the scatter between them only")
        return Drift(np.zeros(3), np.zeros(3), "none", len(probes), note)
    walk2, flick2 = _fit_walk_flicker(probes)
    walk, flick = np.sqrt(walk2), np.sqrt(flick2)
    where = (f"{len(probes)} static periods" if source == "static periods"
             else f"the scatter of {len(probes)} pairwise biases of +/- pairs (no static periods; a rough estimate)")
    note = (f"bias drift allowed for, estimated from {where} (a rough figure from few periods, the largest of the "
            f"gyros): random walk {to_unit(walk.max(), 'deg/h/sqrt(h)'):.3g} deg/h/sqrt(h), flicker "
            f"{to_unit(flick.max(), 'deg/h'):.3g} deg/h; the bias change between segments is in the uncertainties, "
            "and the bias is the mean over the segments used")
    return Drift(walk, flick, source, len(probes), note)


#: batches of :func:`~align.alignment.observe.observe`'s batch-means variance of a dwell or static mean
BATCHES = 10


def _within(span: tuple[float, float], drift: Drift) -> np.ndarray:
    """Expected drift part (3,) of a segment's batch-means variance: ``sum_j var(m_j - m) / (nb (nb - 1))``."""
    edges = np.linspace(span[0], span[1], BATCHES + 1)
    c = np.eye(BATCHES) - 1.0 / BATCHES
    g = drift.covariance(np.column_stack([edges[:-1], edges[1:]]))
    return np.maximum(np.einsum("kj,ijl,kl->i", c, g, c), 0.0) / (BATCHES * (BATCHES - 1))


def with_drift(observations: list[Observation], drift: Drift, t: np.ndarray,
               sigma: np.ndarray | None = None) -> list[DriftObservation]:
    """The observations with the bias drift added to their variance (Eq D3) and the model attached.

    ``var_k = noise_k + phi_k3^2 var(bbar_k - bbar)`` (Eq D2 with ``c = e_k - tau``): the variance of the
    segment's mean bias about the session bias ``bbar = sum_j tau_j bbar_j`` (``tau_j = T_j / sum T``), times
    ``T_k^2`` for a turn. The estimators use it as weights and propagate the whole model (Eq D2). With
    ``sigma``, the drift that a dwell's or static period's own batch-means variance already holds (what
    Eq D2 predicts for its ten batches) is taken out of ``noise_k``, down to the white ``sigma^2 / n``, so that
    it is not counted twice.

    Parameters
    ----------
    observations : list of Observation
        The segments one fit will use (not yet drift-aware).
    drift : Drift
        From :func:`estimate_drift`.
    t : ndarray, shape (n,)
        Time of the log, s.
    sigma : ndarray, shape (3,), optional
        Per-sample white noise, rad/s (:func:`~align.alignment.segment.noise_sigma`).

    Returns
    -------
    list of DriftObservation
        Same order; ``var`` (3,) in (rad/s)^2 or rad^2.
    """
    if not observations:
        return []
    spans = np.array([_span(o, t) for o in observations])
    durations = spans[:, 1] - spans[:, 0]
    tau = durations / durations.sum()
    c = np.eye(len(observations)) - tau[None, :]
    g = drift.covariance(spans)
    dev = np.maximum(np.einsum("kj,ijl,kl->ki", c, g, c), 0.0)  # (k, 3): var(bbar_k - bbar) per gyro
    out = []
    for o, s, d in zip(observations, spans, dev):
        span = (float(s[0]), float(s[1]))
        noise = o.noise_var if isinstance(o, DriftObservation) else o.var
        if sigma is not None and o.segment.kind != "angle":
            noise = np.maximum(noise - _within(span, drift), np.minimum(noise, sigma**2 / o.segment.n))
        out.append(DriftObservation(o.segment, o.y, o.phi, noise + o.phi[3] ** 2 * d, o.duration, noise, span, drift,
                                    earth=o.earth))
    return out
