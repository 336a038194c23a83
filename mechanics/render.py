"""Pictures of a mount: the Monte Carlo histogram, and the assembly with its tilt exaggerated.

PNG pictures are drawn with matplotlib (Agg, no display needed); the 3-D
assembly is exported as GLB with trimesh (its own image export needs OpenGL).

Public names
------------
histogram_png, assembly_png, assembly_glb, resting_pose
"""

from __future__ import annotations

import io

import numpy as np

from align.errors import InputError
from align.units import DEG
from mechanics.budget import Budget
from mechanics.mount import Mount
from mechanics.rest import rest_plane_hull


def resting_pose(m: Mount, heights: np.ndarray, skew: float) -> tuple[float, float, float, float]:
    """``(a, b, c, skew)`` of the package resting on ledges of the given heights (hull rest model)."""
    a, b, c = rest_plane_hull(m.pads, heights)
    return a, b, c, skew


def _worst_heights(m: Mount) -> np.ndarray:
    """A telling configuration for pictures: the +y ledges high (Eq 2's case)."""
    return m.pad_heights + np.array([1.0, 1.0, 0.0, 0.0])[: len(m.pads)] * m.height_tolerance


def _figure_bytes(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    import matplotlib.pyplot as plt

    plt.close(fig)
    return buf.getvalue()


def histogram_png(b: Budget) -> bytes:
    """PNG of the Monte Carlo per-axis misalignment histograms with the budget lines."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    mc = b.monte_carlo
    if mc is None:
        raise ValueError("the budget has no Monte Carlo result")
    centres = (mc.hist_edges[:-1] + mc.hist_edges[1:]) / 2 / DEG
    width = np.diff(mc.hist_edges)[0] / DEG
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    for j, (label, colour) in enumerate(zip(("x gyro", "y gyro", "z gyro"), ("tab:red", "tab:green", "tab:blue"))):
        ax.step(centres, mc.hist_counts[j] / mc.n / width, where="mid", color=colour, label=label)
    p = mc.percentiles["99.73"] / DEG
    for j, colour in enumerate(("tab:red", "tab:green", "tab:blue")):
        ax.axvline(p[j], color=colour, ls=":", lw=1)
    ax.axvline(b.total / DEG, color="k", ls="--", lw=1.2, label=f"source RSS {b.total / DEG:.3f} deg")
    ax.axvline(b.worst_case / DEG, color="k", ls="-", lw=1.2, label=f"worst case {b.worst_case / DEG:.3f} deg")
    ax.set_xlabel("misalignment of gyro axis from system axis [deg]")
    ax.set_ylabel("probability density [1/deg]")
    ax.set_title(f"Monte Carlo, {mc.n:,} assemblies (dotted: 99.73th percentiles)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return _figure_bytes(fig)


def _box_corners(size: np.ndarray) -> np.ndarray:
    sx, sy, sz = size / 2
    return np.array([[x, y, z] for z in (0, 2 * sz) for y in (-sy, sy) for x in (-sx, sx)])


_EDGES = [(0, 1), (1, 3), (3, 2), (2, 0), (4, 5), (5, 7), (7, 6), (6, 4), (0, 4), (1, 5), (2, 6), (3, 7)]


def _check_exaggerate(exaggerate: float) -> None:
    """An exaggeration is a finite factor > 0 (at most 1e4: beyond it a picture shows nothing of the mount)."""
    if not (np.isfinite(exaggerate) and 0 < exaggerate <= 1e4):
        raise InputError(f"the angle exaggeration must be a factor > 0 and <= 10000, not {float(exaggerate):g}",
                         "{exaggerate}")


def _pose_matrix(a: float, b: float, c: float, skew: float, exaggerate: float) -> np.ndarray:
    """4x4 transform of the package (bottom centre at the origin) for an exaggerated pose."""
    from scipy.spatial.transform import Rotation

    n = np.array([-a * exaggerate, -b * exaggerate, 1.0])
    n /= np.linalg.norm(n)
    axis = np.cross([0.0, 0.0, 1.0], n)
    s = np.linalg.norm(axis)
    tilt = Rotation.from_rotvec(axis / s * np.arctan2(s, n[2])) if s > 0 else Rotation.identity()
    rot = tilt * Rotation.from_rotvec([0.0, 0.0, skew * exaggerate])
    t = np.eye(4)
    t[:3, :3] = rot.as_matrix()
    t[:3, 3] = [0.0, 0.0, c * exaggerate]
    return t


def assembly_png(m: Mount, exaggerate: float = 30.0, skew: float | None = None) -> bytes:
    """PNG: ledges, the nominal package (grey) and the resting package (red), tilt exaggerated.

    Raises
    ------
    InputError
        ``exaggerate`` not a finite factor in (0, 1e4].
    """
    _check_exaggerate(exaggerate)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    heights = _worst_heights(m)
    skew = 0.0 if skew is None else skew
    a, b, c, _ = resting_pose(m, heights, skew)
    pose = _pose_matrix(a, b, c, skew, exaggerate)
    corners = _box_corners(m.package) * 1e3
    moved = (pose[:3, :3] @ (corners / 1e3).T).T * 1e3 + pose[:3, 3] * 1e3
    fig = plt.figure(figsize=(7.5, 5.5))
    ax = fig.add_subplot(projection="3d")
    for i, j in _EDGES:
        ax.plot(*zip(corners[i], corners[j]), color="0.6", lw=1)
        ax.plot(*zip(moved[i], moved[j]), color="tab:red", lw=1.6)
    for pad, h in zip(m.pads, heights):
        ring = np.vstack([pad, pad[:1]]) * 1e3
        ax.plot(ring[:, 0], ring[:, 1], np.full(len(ring), h * exaggerate * 1e3), color="k", lw=2)
    # the package's axes, turned with it, from the centre of its top face; each labelled at its tip
    origin = pose[:3, :3] @ np.array([0.0, 0.0, m.package[2]]) * 1e3 + pose[:3, 3] * 1e3
    length = 0.3 * m.package.max() * 1e3
    for i, colour in enumerate(("tab:red", "tab:green", "tab:blue")):
        tip = pose[:3, :3] @ np.eye(3)[i] * length
        ax.quiver(*origin, *tip, color=colour, arrow_length_ratio=0.12, lw=1.6)
        ax.text(*(origin + 1.18 * tip), f"{'xyz'[i]}", color=colour, fontsize=10, fontweight="bold",
                ha="center", va="center")
    from matplotlib.ticker import MaxNLocator

    ax.zaxis.set_major_locator(MaxNLocator(3))  # the z range is short: a few ticks that do not overlap
    ax.tick_params(axis="z", labelsize=8, pad=2)
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_zlabel("z [mm]", labelpad=4)
    tx, ty = np.degrees(np.arctan(b)), np.degrees(-np.arctan(a))
    ax.set_title(f"resting on ledges, +y ledges {m.height_tolerance * 1e3:g} mm high: tilt x {tx:.3f} deg, y {ty:.3f} deg\n"
                 f"(grey nominal, red actual; angles exaggerated x{exaggerate:g}; arrows: the package's x, y, z axes)",
                 fontsize=9)
    top = max(m.package[2] + length / 1e3, 0.45 * m.package[0])
    ax.set_zlim(0, top * 1e3)
    ax.set_box_aspect((m.package[0], m.package[1], top))
    return _figure_bytes(fig)


def assembly_glb(m: Mount, exaggerate: float = 30.0, skew: float = 0.0) -> bytes:
    """GLB of the ledges and the resting package (tilt and skew exaggerated), metres (``exaggerate`` as in
    :func:`assembly_png`)."""
    _check_exaggerate(exaggerate)
    import trimesh

    heights = _worst_heights(m)
    a, b, c, _ = resting_pose(m, heights, skew)
    scene = trimesh.Scene()
    for k, (pad, h) in enumerate(zip(m.pads, heights)):
        lo, hi = pad.min(axis=0), pad.max(axis=0)
        top = h * exaggerate
        depth = 0.003
        box = trimesh.creation.box(extents=[hi[0] - lo[0], hi[1] - lo[1], depth + top])
        box.apply_translation([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (top - depth) / 2])
        box.visual.face_colors = [90, 90, 90, 255]
        scene.add_geometry(box, node_name=f"ledge_{k}")
    package = trimesh.creation.box(extents=m.package)
    package.apply_translation([0.0, 0.0, m.package[2] / 2])
    package.apply_transform(_pose_matrix(a, b, c, skew, exaggerate))
    package.visual.face_colors = [200, 60, 60, 200]
    scene.add_geometry(package, node_name="package")
    return scene.export(file_type="glb")
