"""Monte Carlo of the mounting: assemblies drawn from their tolerances, composed in 3-D.

Each ledge height, each screw's position in its hole, the IMU's own axis errors
and the extra terms are drawn from their distributions, the package is rested
on the ledges (:mod:`mechanics.rest`) and skewed (:func:`sample_skew`), and the
angle of each gyro axis from its system axis is collected into percentiles,
moments and a histogram (:class:`MonteCarlo`, the ``monte_carlo`` part of a
budget result).

Public names
------------
MonteCarlo, monte_carlo, sample_skew, PERCENTILES
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.errors import InputError
from align.units import DEG
from align.values import Value, frozen_array
from mechanics.assembly import rotate_axes, skew_limit, worst_case_per_axis
from mechanics.mount import Mount
from mechanics.rest import corner_geometry, plane_tilt, rest_planes

#: Monte Carlo percentiles reported, %
PERCENTILES = (50.0, 95.0, 99.73)
_KEYS = ("x", "y", "z", "any")
_TILTS = ("tilt_x", "tilt_y", "skew_z")


def _per_key(values: np.ndarray, keys=_KEYS) -> dict:
    """rad array -> {key: deg}."""
    return dict(zip(keys, (np.asarray(values) / DEG).tolist()))


def _from_keys(d: dict, keys=_KEYS) -> np.ndarray:
    """{key: deg} -> rad array."""
    return np.array([d[k] for k in keys], dtype=float) * DEG


@dataclass(frozen=True, eq=False)
class MonteCarlo(Value):
    """Monte Carlo per-axis misalignment: percentiles, moments and a histogram.

    Attributes
    ----------
    n : int
        Assemblies drawn.
    seed : int
    percentiles : dict
        ``"50"``, ``"95"``, ``"99.73"`` -> ndarray, shape (4,): x, y, z and any axis, rad.
    mean, rms, maximum : ndarray, shape (4,)
        rad.
    hist_edges : ndarray, shape (bins + 1,)
        rad.
    hist_counts : ndarray of int, shape (4, bins)
    tilt_rms : ndarray, shape (3,)
        rms tilt about x, y and skew about z, rad.
    """

    n: int
    seed: int
    percentiles: dict
    mean: np.ndarray
    rms: np.ndarray
    maximum: np.ndarray
    hist_edges: np.ndarray
    hist_counts: np.ndarray
    tilt_rms: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "percentiles", {str(k): frozen_array(v) for k, v in self.percentiles.items()})
        super().__post_init__()

    def to_dict(self) -> dict:
        """The ``monte_carlo`` of a budget result, deg."""
        return {
            "draws": self.n, "seed": self.seed,
            "percentiles_deg": {p: _per_key(v) for p, v in self.percentiles.items()},
            "mean_deg": _per_key(self.mean), "rms_deg": _per_key(self.rms), "max_deg": _per_key(self.maximum),
            "tilt_rms_deg": _per_key(self.tilt_rms, _TILTS),
            "histogram": {"edges_deg": (self.hist_edges / DEG).tolist(),
                          "counts": dict(zip(_KEYS, self.hist_counts.tolist()))},
        }

    @classmethod
    def from_dict(cls, d: dict) -> MonteCarlo:
        """Read the form written by :meth:`to_dict` (KeyError, TypeError, ValueError when malformed)."""
        hist = d["histogram"]
        return cls(int(d["draws"]), int(d["seed"]), {p: _from_keys(v) for p, v in d["percentiles_deg"].items()},
                   _from_keys(d["mean_deg"]), _from_keys(d["rms_deg"]), _from_keys(d["max_deg"]),
                   np.array(hist["edges_deg"], dtype=float) * DEG,
                   np.array([hist["counts"][k] for k in _KEYS], dtype=np.int64), _from_keys(d["tilt_rms_deg"], _TILTS))


def _disc(rng: np.random.Generator, n: int, radius, distribution: str) -> np.ndarray:
    """2-D offsets (n, 2): uniform in a disc of ``radius``, or normal with 3 sigma = radius."""
    if distribution == "normal":
        return rng.normal(0.0, 1.0, (n, 2)) * (np.asarray(radius) / 3.0)[..., None]
    r = np.sqrt(rng.random(n)) * radius
    phi = rng.random(n) * 2 * np.pi
    return np.stack([r * np.cos(phi), r * np.sin(phi)], axis=1)


def _ball(rng: np.random.Generator, n: int, radius: float, distribution: str) -> np.ndarray:
    """3-D rotation vectors (n, 3): uniform in a ball of ``radius``, or normal with 3 sigma = radius."""
    if distribution == "normal":
        return rng.normal(0.0, radius / 3.0, (n, 3))
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    return v * (rng.random(n) ** (1 / 3) * radius)[:, None]


def sample_skew(m: Mount, n: int, rng: np.random.Generator) -> np.ndarray:
    """Skew about z (rad) of ``n`` assemblies: poses uniform over those that fit.

    Each screw sits at its nominal position plus a positional error (uniform in
    a disc of the tolerance zone's radius); the package pose ``(theta, tx, ty)``
    is drawn uniformly among the poses that keep every screw inside its hole's
    clearance (rejection sampling).
    """
    c, r_tol = m.clearance, m.position_tolerance / 2
    screws = m.screws
    limit = skew_limit(m)
    out = np.empty(0)
    tries = 0
    while len(out) < n:
        tries += 1
        if tries > 200 and len(out) == 0:
            raise InputError("no drawn screw position fits its hole (clearance against position tolerance); check "
                             "the mount's screws and holes", "mount: [screws]")
        k = max(2 * (n - len(out)), 1024)
        theta = rng.uniform(-limit, limit, k)
        t = _disc(rng, k, c + r_tol, "uniform")  # every fitting shift lies in this disc (symmetric pattern)
        ok = np.ones(k, dtype=bool)
        cos, sin = np.cos(theta), np.sin(theta)
        for sx, sy in screws:
            ex, ey = _disc(rng, k, r_tol, "uniform").T if r_tol > 0 else (0.0, 0.0)
            hx = cos * sx - sin * sy + t[:, 0] - (sx + ex)
            hy = sin * sx + cos * sy + t[:, 1] - (sy + ey)
            ok &= hx * hx + hy * hy <= c * c
        out = np.concatenate([out, theta[ok]])
    return out[:n]


def _draw(m: Mount, geo, k: int, rng: np.random.Generator, include) -> tuple[np.ndarray, np.ndarray]:
    """One batch of ``k`` assemblies: per-axis angles (k, 4: x, y, z, any) and summed squared tilts (3,)."""
    heights = np.broadcast_to(m.pad_heights, (k, 4)).copy()
    if "ledges" in include and m.height_tolerance > 0:
        if m.distributions["ledges"] == "normal":
            heights += rng.normal(m.height_tolerance / 2, m.height_tolerance / 6, (k, 4))
        else:
            heights += rng.uniform(0.0, m.height_tolerance, (k, 4))
    a, b, _ = rest_planes(geo, heights, rng)
    skew = sample_skew(m, k, rng) if "screws" in include else np.zeros(k)
    axes = np.broadcast_to(np.eye(3), (k, 3, 3)).copy()
    if "imu" in include:
        for i in range(3):
            d2 = _disc(rng, k, m.axis_to_package[i], m.distributions["imu"])
            j, n = (i + 1) % 3, (i + 2) % 3
            axes[:, i, j] += d2[:, 0]
            axes[:, i, n] += d2[:, 1]
    if "extras" in include:
        for bound in m.extras.values():
            axes += np.cross(_ball(rng, k, bound, m.distributions["extras"])[:, None, :], np.eye(3)[None])  # w x e_i
    ang = rotate_axes(a, b, skew, axes)
    tx, ty = plane_tilt(a, b)
    return np.column_stack([ang, ang.max(axis=1)]), np.array([(tx**2).sum(), (ty**2).sum(), (skew**2).sum()])


def monte_carlo(m: Mount, n: int, seed: int = 0, chunk: int = 50_000, bins: int = 100,
                progress=None, include=("ledges", "screws", "imu", "extras"), workers: int | None = None) -> MonteCarlo:
    """Monte Carlo of the full 3-D mounting model (see module docstring).

    Parameters
    ----------
    m : Mount
        Dimensions and tolerances (as distributions), SI (m, rad).
    n : int
        Number of assemblies drawn.
    seed : int
        Batches draw from independent streams spawned from it, so the result
        does not depend on ``workers``.
    chunk : int
        Draws per batch (bounds memory).
    bins : int
        Histogram bins (shared edges for the x, y, z and any-axis histograms).
    progress : callable, optional
        Called with the number of draws done after each batch.
    include : tuple of str
        The contributors drawn (others held at nominal); for studying one term.
    workers : int, optional
        Threads (numpy releases the GIL on large arrays); default the core count, at most 4.

    Returns
    -------
    MonteCarlo
        Per-axis (x, y, z, any axis) percentiles, mean, rms and maximum, rad, and ``hist_counts`` (4, ``bins``).

    Examples
    --------
    Example 1's mount (``examples/budget/example1.toml``): no draw exceeds the 3-D worst case of :func:`budget`.

    >>> from pathlib import Path
    >>> import numpy as np
    >>> import mechanics
    >>> from align.io import read_toml
    >>> from mechanics.budget import budget
    >>> from mechanics.mount import mount_from_dict
    >>> path = Path(mechanics.__file__).parents[1] / "examples" / "budget" / "example1.toml"
    >>> m = mount_from_dict(read_toml(path), str(path), path.parent)
    >>> mc = monte_carlo(m, 2000, seed=1, workers=1)
    >>> mc.hist_counts.shape, bool(np.all(mc.maximum[:3] <= budget(m).worst_case_per_axis))
    ((4, 100), True)
    """
    import os
    from concurrent.futures import ThreadPoolExecutor

    if int(n) < 1:
        raise InputError(f"needs at least one draw (got {int(n)})", "{monte_carlo}")
    if int(seed) < 0:
        raise InputError(f"a seed is a whole number >= 0 (got {int(seed)})", "{seed}")
    geo = corner_geometry(m.pads)
    sizes = [min(chunk, n - i) for i in range(0, n, chunk)]
    streams = [np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(len(sizes))]
    workers = workers or min(4, os.cpu_count() or 1)
    done = 0
    results = []
    pool = ThreadPoolExecutor(workers)
    try:
        for ang, tsq in pool.map(lambda job: _draw(m, geo, job[0], job[1], include), zip(sizes, streams)):
            results.append((ang, tsq))
            done += len(ang)
            if progress is not None:
                progress(done)
    except BaseException:  # Ctrl-C or an error: drop the batches not started instead of waiting for them all
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown()
    ang = np.concatenate([r[0] for r in results])
    top = max(float(worst_case_per_axis(m).max()) * 1.05, float(ang.max()) * 1.0001) + 1e-12
    edges = np.linspace(0.0, top, bins + 1)
    idx = np.minimum((ang / top * bins).astype(np.int64), bins - 1)
    counts = np.stack([np.bincount(idx[:, j], minlength=bins) for j in range(4)])
    pct = dict(zip((f"{p:g}" for p in PERCENTILES), np.percentile(ang, PERCENTILES, axis=0)))
    tilt_rms = np.sqrt(sum(r[1] for r in results) / n)
    return MonteCarlo(n, seed, pct, ang.mean(axis=0), np.sqrt((ang**2).mean(axis=0)), ang.max(axis=0),
                      edges, counts, tilt_rms)
