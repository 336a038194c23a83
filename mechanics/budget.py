"""The mounting-misalignment budget three ways: the source's, worst case, Monte Carlo.

* Source (reference section 2): tilts about x and y from the full ledge-height
  band (Eq 2-3), skew about z from the screw clearance (Eq 4), mounting term the
  largest of the three, total by RSS with the datasheet axis-to-package figure (Eq 1).
* Per gyro axis: a tilt about x moves the y and z gyro axes, not the x one; the
  per-axis RSS combines only the terms that move that axis.
* Worst case: every tolerance at its extreme, composed as 3-D rotations (the
  corners of the ledge-height box through the rest model, the skew at its limit
  including screw position tolerance), plus the datasheet and extra terms added.
* Monte Carlo: each ledge height, each screw's position in its hole, the IMU's
  own axis errors and the extra terms drawn from their distributions, the
  package rested on the ledges (:mod:`mechanics.rest`), all composed in 3-D.

Public names
------------
Budget, MonteCarlo, budget, monte_carlo, FORMAT
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import product

import numpy as np

from align import CONVENTION, __version__
from align.errors import InputError
from align.units import DEG

from .formulas import rss, screw_radius, skew_from_screws, tilt_from_ledges
from .mount import Mount
from .rest import corner_geometry, plane_tilt, rest_plane_hull, rest_planes

FORMAT = "imu-align.budget"
PERCENTILES = (50.0, 95.0, 99.73)


@dataclass(frozen=True)
class MonteCarlo:
    """Monte Carlo per-axis misalignment (rad): percentiles, moments and a histogram."""

    n: int
    seed: int
    percentiles: dict          # "50" -> ndarray (4,) for x, y, z, any
    mean: np.ndarray           # (4,)
    rms: np.ndarray            # (4,)
    maximum: np.ndarray        # (4,)
    hist_edges: np.ndarray     # (bins + 1,)
    hist_counts: np.ndarray    # (4, bins)
    tilt_rms: np.ndarray       # (3,): rms tilt about x, y and skew about z


@dataclass(frozen=True)
class Budget:
    """The budget of a mount (all angles in rad)."""

    tilt_x: float
    tilt_y: float
    skew_z: float
    imu: float
    mounting: float
    total: float
    plain_sum: float
    per_axis: np.ndarray
    worst_case_per_axis: np.ndarray
    skew_worst: float
    mount: Mount
    monte_carlo: MonteCarlo | None = None

    @property
    def worst_case(self) -> float:
        return float(self.worst_case_per_axis.max())

    def elements(self, basis: str = "rss") -> dict:
        """Predicted size of each misalignment element (rad), named as in the sensitivity module.

        ``psi_i`` is the per-axis figure; ``phi_ij`` (gyro ``i`` leaning toward
        axis ``j``) combines the mounting rotation about the third axis ``k``
        (tilt x, tilt y or skew z) with the datasheet term of gyro ``i`` and the
        extras; by RSS (``basis="rss"``) or added (``"worst"``).
        """
        if basis not in ("rss", "worst"):
            raise ValueError("basis is rss or worst")
        about = {0: self.tilt_x, 1: self.tilt_y, 2: self.skew_z}
        extras = list(self.mount.extras.values())
        out = {}
        for i, a in enumerate("xyz"):
            out[f"psi_{a}"] = float(self.per_axis[i] if basis == "rss" else self.worst_case_per_axis[i])
            for j, b in enumerate("xyz"):
                if i == j:
                    continue
                terms = [about[3 - i - j], self.mount.axis_to_package[i], *extras]
                out[f"phi_{a}{b}"] = rss(*terms) if basis == "rss" else float(sum(terms))
        return out

    def to_dict(self) -> dict:
        m = self.mount
        d = {
            "format": FORMAT, "version": 1, "generator": f"imu-align {__version__}",
            "convention": CONVENTION + "; misalignment = angle between each gyro axis and its system axis",
            "units": {"angles": "deg", "lengths": "mm"},
            "tilt_x_deg": self.tilt_x / DEG, "tilt_y_deg": self.tilt_y / DEG, "skew_z_deg": self.skew_z / DEG,
            "imu_deg": self.imu / DEG, "mounting_deg": self.mounting / DEG, "total_deg": self.total / DEG,
            "sum_deg": self.plain_sum / DEG,
            "per_axis_deg": dict(zip("xyz", (self.per_axis / DEG).tolist())),
            "worst_case_deg": self.worst_case / DEG,
            "worst_case_per_axis_deg": dict(zip("xyz", (self.worst_case_per_axis / DEG).tolist())),
            "skew_worst_deg": self.skew_worst / DEG,
            "method": {
                "source": "Eq 2-3 tilts from the full height band, Eq 4 skew, mounting = max, total = RSS with axis-to-package (Eq 1)",
                "per_axis": "RSS of the terms that move each gyro axis (x: tilt_y, skew, imu_x, extras; y: tilt_x, skew, imu_y, extras; z: tilt_x, tilt_y, imu_z, extras)",
                "worst_case": "corners of the ledge-height box through the rest model and the skew limit (with screw position tolerance), composed in 3-D, plus datasheet and extra terms",
            },
            "mount": {
                "part": m.part, "axis_to_package_deg": (m.axis_to_package / DEG).tolist(),
                "package_mm": (m.package * 1e3).tolist(), "ledge_size_mm": m.ledge_size * 1e3,
                "height_tolerance_mm": m.height_tolerance * 1e3, "screw_diameter_mm": m.screw_diameter * 1e3,
                "hole_diameter_mm": m.hole_diameter * 1e3, "spacing_mm": [m.spacing_x * 1e3, m.spacing_y * 1e3],
                "screw_radius_mm": screw_radius(m.spacing_x, m.spacing_y) * 1e3,
                "position_tolerance_mm": m.position_tolerance * 1e3,
                "extras_deg": {k: v / DEG for k, v in m.extras.items()}, "distributions": m.distributions,
                "baseplate": m.baseplate,
            },
        }
        mc = self.monte_carlo
        if mc is not None:
            keys = ("x", "y", "z", "any")
            d["monte_carlo"] = {
                "draws": mc.n, "seed": mc.seed,
                "percentiles_deg": {p: dict(zip(keys, (v / DEG).tolist())) for p, v in mc.percentiles.items()},
                "mean_deg": dict(zip(keys, (mc.mean / DEG).tolist())),
                "rms_deg": dict(zip(keys, (mc.rms / DEG).tolist())),
                "max_deg": dict(zip(keys, (mc.maximum / DEG).tolist())),
                "tilt_rms_deg": dict(zip(("tilt_x", "tilt_y", "skew_z"), (mc.tilt_rms / DEG).tolist())),
                "histogram": {"edges_deg": (mc.hist_edges / DEG).tolist(), "counts": dict(zip(keys, mc.hist_counts.tolist()))},
            }
        return d


def _rotate_axes(a: np.ndarray, b: np.ndarray, skew: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """Rotate package-frame gyro axes into the system frame and return their misalignment.

    The package is turned by ``skew`` about z, then tilted by the rotation that
    takes ``e_z`` to the rest-plane normal ``n ~ (-a, -b, 1)`` (Rodrigues, axis
    ``e_z x n`` in the x-y plane).

    Parameters
    ----------
    a, b : ndarray, shape (N,)
        Rest-plane slopes.
    skew : ndarray, shape (N,)
        rad.
    axes : ndarray, shape (N, 3, 3)
        Row ``i``: gyro ``i``'s axis in the package frame (normalised here).

    Returns
    -------
    ndarray, shape (N, 3)
        Angle between each gyro axis and its system axis, rad.
    """
    vx, vy, vz = axes[:, :, 0], axes[:, :, 1], axes[:, :, 2]           # (N, 3): component of each axis
    inv = 1.0 / np.sqrt(vx * vx + vy * vy + vz * vz)
    cz, sz = np.cos(skew)[:, None], np.sin(skew)[:, None]
    x = (cz * vx - sz * vy) * inv
    y = (sz * vx + cz * vy) * inv
    z = vz * inv
    r = np.sqrt(a * a + b * b)
    c = (1.0 / np.sqrt(1.0 + r * r))[:, None]                          # cos of the tilt
    s = (r[:, None] * c)                                               # sin of the tilt
    safe = np.where(r > 0, r, 1.0)
    kx, ky = (b / safe)[:, None], (np.where(r > 0, -a, 0.0) / safe)[:, None]  # unit (e_z x n) = (b, -a, 0) / r
    kv = (kx * x + ky * y) * (1.0 - c)
    rx = x * c + ky * z * s + kx * kv                                  # v cos + (k x v) sin + k (k.v)(1 - cos)
    ry = y * c - kx * z * s + ky * kv
    rz = z * c + (kx * y - ky * x) * s
    along = np.column_stack([rx[:, 0], ry[:, 1], rz[:, 2]])
    across = np.column_stack([np.hypot(ry[:, 0], rz[:, 0]), np.hypot(rx[:, 1], rz[:, 1]), np.hypot(rx[:, 2], ry[:, 2])])
    return np.arctan2(across, along)


def _skew_limit(m: Mount) -> float:
    """Largest skew about z with each screw at the edge of its clearance and position tolerance."""
    r = screw_radius(m.spacing_x, m.spacing_y)
    return float(np.arcsin(min(1.0, (m.clearance + m.position_tolerance / 2) / r)))


def _rest(m: Mount, heights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rest-plane slopes: closed form for four corner ledges, the trimesh hull otherwise."""
    try:
        geo = corner_geometry(m.pads)
    except InputError:
        planes = np.array([rest_plane_hull(m.pads, h)[:2] for h in heights])
        return planes[:, 0], planes[:, 1]
    a, b, _ = rest_planes(geo, heights)
    return a, b


def budget(m: Mount) -> Budget:
    """The deterministic budget: source formulas, per-axis RSS and the 3-D worst case."""
    size_x, size_y = m.package[:2]
    tilt_x = tilt_from_ledges(m.height_tolerance, size_y, m.ledge_size)       # Eq 2 (span W = size_y)
    tilt_y = tilt_from_ledges(m.height_tolerance, size_x, m.ledge_size)       # Eq 3 (span L = size_x)
    skew = skew_from_screws(m.hole_diameter, m.screw_diameter, screw_radius(m.spacing_x, m.spacing_y))  # Eq 4
    imu = float(m.axis_to_package.max())
    mounting = max(tilt_x, tilt_y, skew)
    extras = list(m.extras.values())
    total = rss(imu, mounting, *extras)                                      # Eq 1
    moves = ((tilt_y, skew), (tilt_x, skew), (tilt_x, tilt_y))
    per_axis = np.array([rss(*moves[i], m.axis_to_package[i], *extras) for i in range(3)])
    # worst case: corners of the height box and the skew limits, through the rest model, in 3-D
    skew_w = _skew_limit(m)
    corners = np.array(list(product((0.0, m.height_tolerance), repeat=len(m.pads)))) + m.pad_heights[None, :]
    a, b = _rest(m, corners)
    aa, bb = np.repeat(a, 2), np.repeat(b, 2)
    ss = np.tile([-skew_w, skew_w], len(a))
    mount_angles = _rotate_axes(aa, bb, ss, np.broadcast_to(np.eye(3), (len(aa), 3, 3))).max(axis=0)
    worst = mount_angles + m.axis_to_package + sum(extras)
    return Budget(tilt_x, tilt_y, skew, imu, mounting, total, imu + mounting + sum(extras), per_axis, worst, skew_w, m)


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
    limit = _skew_limit(m)
    out = np.empty(0)
    while len(out) < n:
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
            j, l = (i + 1) % 3, (i + 2) % 3
            axes[:, i, j] += d2[:, 0]
            axes[:, i, l] += d2[:, 1]
    if "extras" in include:
        for bound in m.extras.values():
            axes += np.cross(_ball(rng, k, bound, m.distributions["extras"])[:, None, :], np.eye(3)[None])  # w x e_i
    ang = _rotate_axes(a, b, skew, axes)
    tx, ty = plane_tilt(a, b)
    return np.column_stack([ang, ang.max(axis=1)]), np.array([(tx**2).sum(), (ty**2).sum(), (skew**2).sum()])


def monte_carlo(m: Mount, n: int, seed: int = 0, chunk: int = 50_000, bins: int = 100,
                progress=None, include=("ledges", "screws", "imu", "extras"), workers: int | None = None) -> MonteCarlo:
    """Monte Carlo of the full 3-D mounting model (see module docstring).

    Parameters
    ----------
    m : Mount
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
    """
    import os
    from concurrent.futures import ThreadPoolExecutor

    if n < 1:
        raise ValueError("n must be positive")
    geo = corner_geometry(m.pads)
    sizes = [min(chunk, n - i) for i in range(0, n, chunk)]
    streams = [np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(len(sizes))]
    workers = workers or min(4, os.cpu_count() or 1)
    done = 0
    results = []
    with ThreadPoolExecutor(workers) as pool:
        for ang, tsq in pool.map(lambda job: _draw(m, geo, job[0], job[1], include), zip(sizes, streams)):
            results.append((ang, tsq))
            done += len(ang)
            if progress is not None:
                progress(done)
    ang = np.concatenate([r[0] for r in results])
    top = max(float(budget(m).worst_case_per_axis.max()) * 1.05, float(ang.max()) * 1.0001) + 1e-12
    edges = np.linspace(0.0, top, bins + 1)
    idx = np.minimum((ang / top * bins).astype(np.int64), bins - 1)
    counts = np.stack([np.bincount(idx[:, j], minlength=bins) for j in range(4)])
    pct = dict(zip((f"{p:g}" for p in PERCENTILES), np.percentile(ang, PERCENTILES, axis=0)))
    tilt_rms = np.sqrt(sum(r[1] for r in results) / n)
    return MonteCarlo(n, seed, pct, ang.mean(axis=0), np.sqrt((ang**2).mean(axis=0)), ang.max(axis=0),
                      edges, counts, tilt_rms)
