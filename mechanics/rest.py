"""Rigid-body rest model: a flat package bottom resting on ledges of unequal height.

Under gravity the package settles so that its centre (the origin of the package
frame) is as low as possible while every ledge top stays on or below its
bottom face: a linear programme whose solution is a plane ``z = a x + b y + c``
through three contact points (a facet of the upper convex hull of the ledge
tops, the one above the centre). On four ledges of two heights it is exactly
Eq 2-3 (contact on the inner edge of the high ledges and the outer edge of the
low ones).

Two implementations:

* :func:`rest_plane_hull` builds the convex hull of the ledge-top vertices with
  trimesh and picks the upper facet above the centre: exact, one configuration
  at a time (the reference, and the baseplate-STL path);
* :func:`rest_planes` solves many configurations at once (Monte Carlo) in closed
  form for four equal rectangular ledges at the corners of a rectangle (see its
  docstring); tests check it against the hull and against a linear programme.

Public names
------------
rest_plane_hull, rest_planes, corner_geometry, plane_tilt, ledges_from_stl, CORNERS
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from align.errors import InputError

_TOL = 1e-12  # m: a ledge this far above a plane still counts as touching


def rest_plane_hull(pads: np.ndarray, heights: np.ndarray) -> tuple[float, float, float]:
    """Resting plane ``(a, b, c)`` of ``z = a x + b y + c`` from the convex hull (trimesh).

    The facet of the upper convex hull of the ledge-top vertices that lies above
    the package centre: the general form of Eq 2-3 (reference section 2).

    Parameters
    ----------
    pads : ndarray, shape (P, V, 2)
        Ledge-top outlines (x, y) in the package frame, centre at the origin, m.
    heights : ndarray, shape (P,)
        Ledge-top heights, m.

    Returns
    -------
    a, b : float
        Slopes of the plane along x and y, dimensionless (:func:`plane_tilt` turns
        them into angles).
    c : float
        Height of the plane under the package centre, m.

    Raises
    ------
    InputError
        When the centre is not above the ledges (the package would tip over).
    """
    import trimesh

    pts = np.concatenate([np.column_stack([p, np.full(len(p), h)]) for p, h in zip(pads, heights)])
    if np.ptp(pts[:, 2]) < _TOL:
        return 0.0, 0.0, float(pts[0, 2])
    hull = trimesh.convex.convex_hull(pts)
    for face, normal in zip(hull.faces, hull.face_normals):
        if normal[2] <= 1e-12:
            continue
        tri = hull.vertices[face]
        if _contains(tri[:, :2], np.zeros(2)):
            a, b = -normal[0] / normal[2], -normal[1] / normal[2]
            return float(a), float(b), float(tri[0, 2] - a * tri[0, 0] - b * tri[0, 1])
    raise InputError("the package centre is not above the ledges: it would tip over", "ledges")


def _contains(tri: np.ndarray, p: np.ndarray, eps: float = 1e-12) -> bool:
    """Whether 2-D point ``p`` lies in triangle ``tri`` (edges included)."""
    d = []
    for i in range(3):
        e, f = tri[(i + 1) % 3] - tri[i], p - tri[i]
        d.append(e[0] * f[1] - e[1] * f[0])
    return bool(all(x >= -eps for x in d) or all(x <= eps for x in d))


def corner_geometry(pads: np.ndarray) -> tuple[float, float, float, float]:
    """``(X, Y, hx, hy)`` of four equal axis-aligned rectangular ledges centred at ``(+/-X, +/-Y)``.

    The layout of Eq 2-3 and Example 1, which :func:`rest_planes` solves in closed form.

    Parameters
    ----------
    pads : ndarray, shape (P, V, 2)
        Ledge-top outlines (x, y) in the package frame, centre at the origin, m.

    Returns
    -------
    X, Y : float
        Distance of the ledge centres from the package centre along x and y, m.
    hx, hy : float
        Half-size of each ledge along x and y, m.

    Raises
    ------
    InputError
        For any other layout (the closed-form rest model needs it; the hull
        model takes any layout).
    """
    lo, hi = pads.min(axis=1), pads.max(axis=1)
    rect = np.all(np.isclose(pads, lo[:, None, :], atol=1e-9) | np.isclose(pads, hi[:, None, :], atol=1e-9))
    centre, half = (lo + hi) / 2, (hi - lo) / 2
    X, Y = np.abs(centre).mean(axis=0)
    signs = {(int(np.sign(x)), int(np.sign(y))) for x, y in centre}
    ok = (len(pads) == 4 and rect and signs == {(1, 1), (-1, 1), (-1, -1), (1, -1)}
          and np.allclose(np.abs(centre), [X, Y], atol=1e-6) and np.allclose(half, half[0], atol=1e-6))
    if not ok:
        raise InputError("the Monte Carlo rest model needs four equal rectangular ledges at the corners "
                         "of a rectangle centred on the package", "ledges")
    return float(X), float(Y), float(half[0, 0]), float(half[0, 1])


#: ledge order of :func:`rest_planes`: (+x,+y), (-x,+y), (-x,-y), (+x,-y)
CORNERS = ((1, 1), (-1, 1), (-1, -1), (1, -1))


def rest_planes(
    geometry: tuple[float, float, float, float],
    heights: np.ndarray,
    rng: np.random.Generator | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Resting planes of a package on four corner ledges, closed form, vectorised (Eq 2-3 generalised).

    With ledge tops of half-size ``hx, hy`` centred at ``(+/-X, +/-Y)`` the rest
    problem ``min_{a,b} max_vertices (h - a x - b y)`` becomes, with ``u = a X``,
    ``v = b Y``, ``p = u + v``, ``q = u - v``, ``kx = hx / X``, ``ky = hy / Y``:

    ``min kx |p + q| / 2 + ky |p - q| / 2 + max(G1(p), G2(q))``,
    ``G1 = max(h++ - p, h-- + p)``, ``G2 = max(h-+ + q, h+- - q)``.

    The diagonal with the higher mean height carries the package: its V-shaped
    term fixes one of ``p, q`` at its vertex (``kx, ky < 1``), and the other may
    move (the package rocks about that diagonal) within the range where the low
    diagonal stays below, to where the ledge-size term is least: ``u = 0`` when
    ``kx > ky``, ``v = 0`` when ``ky > kx``; a tie (square layout) is drawn
    uniformly with ``rng`` (midpoint without it). Two-level ledges give Eq 2-3.

    Parameters
    ----------
    geometry : tuple
        ``(X, Y, hx, hy)`` from :func:`corner_geometry`, m.
    heights : ndarray, shape (N, 4)
        Ledge-top heights in :data:`CORNERS` order, m.
    rng : numpy.random.Generator, optional
        Draws the free slope of a square layout (a tie); the midpoint without it.

    Returns
    -------
    a, b, c : ndarray, shape (N,)
        The plane ``z = a x + b y + c``; ``c`` is the height under the package centre.
    """
    X, Y, hx, hy = geometry
    kx, ky = hx / X, hy / Y
    h = np.asarray(heights, dtype=float)
    hpp, hmp, hmm, hpm = h[:, 0], h[:, 1], h[:, 2], h[:, 3]
    p_star, m1 = (hpp - hmm) / 2, (hpp + hmm) / 2
    q_star, m2 = (hpm - hmp) / 2, (hmp + hpm) / 2
    first = m1 >= m2                      # the (++, --) diagonal is the high one
    fixed = np.where(first, p_star, q_star)
    centre = np.where(first, q_star, p_star)
    d = np.abs(m1 - m2)
    # the free variable f minimises kx |fixed + f| + ky |fixed - f| (first) or kx |f + fixed| + ky |f - fixed|:
    # both are minimised at f = -fixed when kx > ky and f = +fixed when ky > kx
    if np.isclose(kx, ky):
        lo, hi = -np.abs(fixed), np.abs(fixed)
        lo, hi = np.clip(lo, centre - d, centre + d), np.clip(hi, centre - d, centre + d)
        t = rng.random(len(h)) if rng is not None else 0.5
        free = lo + t * (hi - lo)
    else:
        target = -fixed if kx > ky else fixed
        free = np.clip(target, centre - d, centre + d)
    p = np.where(first, fixed, free)
    q = np.where(first, free, fixed)
    u, v = (p + q) / 2, (p - q) / 2
    c = kx * np.abs(u) + ky * np.abs(v) + np.maximum(np.maximum(hpp - p, hmm + p), np.maximum(hmp + q, hpm - q))
    return u / X, v / Y, c


def plane_tilt(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tilt angles of a resting plane: about x ``atan(b)``, about y ``-atan(a)`` (Eq 2-3).

    A rotation ``alpha`` about x raises the +y side (slope ``tan alpha`` along y);
    a rotation ``beta`` about y lowers the +x side (slope ``-tan beta`` along x).

    Parameters
    ----------
    a, b : ndarray, shape (N,)
        Slopes of the plane ``z = a x + b y + c`` along x and y, dimensionless.

    Returns
    -------
    alpha, beta : ndarray, shape (N,)
        Tilt about x and about y, rad.
    """
    return np.arctan(b), -np.arctan(a)


def ledges_from_stl(path: str | Path, band: float, where: str) -> tuple[np.ndarray, np.ndarray]:
    """Ledge tops of a baseplate STL: the upward-facing facets within ``band`` of the highest.

    The STL is read in metres unless its extent suggests millimetres (> 1 unit).

    Parameters
    ----------
    path : str or Path
        The STL file.
    band : float
        How far below the highest upward-facing facet a facet still counts as a
        ledge top, m.
    where : str
        Names the file in error messages.

    Returns
    -------
    pads : ndarray, shape (P, V, 2)
        Ledge-top outlines (convex hull in x-y, padded to ``V`` vertices by
        repeating the last), centred on the centroid of the ledge centres, m.
    heights : ndarray, shape (P,)
        Ledge-top heights relative to the lowest ledge, m.

    Raises
    ------
    InputError
        An unreadable STL, no upward-facing facets, or fewer than three ledge tops.
    """
    import trimesh
    from scipy.spatial import ConvexHull

    try:
        mesh = trimesh.load(str(path), force="mesh")
    except Exception as exc:  # trimesh raises many types for unreadable files
        raise InputError(f"cannot read STL ({exc})", where) from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise InputError("no triangles in the STL", where)
    scale = 1e-3 if np.max(mesh.extents) > 1.0 else 1.0
    in_facets = set(np.concatenate(mesh.facets)) if len(mesh.facets) else set()
    groups = [list(f) for f in mesh.facets] + [[i] for i in set(range(len(mesh.faces))) - in_facets]
    tops = []
    for faces in groups:
        normal = mesh.face_normals[faces[0]]
        if normal[2] < 0.999:
            continue
        verts = mesh.vertices[np.unique(mesh.faces[faces])] * scale
        tops.append((float(verts[:, 2].mean()), verts[:, :2]))
    if not tops:
        raise InputError("no upward-facing facets", where)
    top = max(h for h, _ in tops)
    tops = [(h, v) for h, v in tops if h >= top - band]
    merged: list[tuple[float, np.ndarray]] = []
    for h, v in tops:  # triangles of one ledge top that trimesh did not merge into a facet
        for i, (h2, v2) in enumerate(merged):
            if abs(h - h2) < 1e-9 and np.min(np.linalg.norm(v[:, None] - v2[None], axis=2)) < 1e-9:
                merged[i] = (h2, np.vstack([v2, v]))
                break
        else:
            merged.append((h, v))
    if len(merged) < 3:
        raise InputError(f"found {len(merged)} ledge tops within {band * 1e3:g} mm of the highest; need at least 3", where)
    outlines = []
    for _, v in merged:
        hull = ConvexHull(v)
        outlines.append(v[hull.vertices])
    origin = np.mean([o.mean(axis=0) for o in outlines], axis=0)
    width = max(len(o) for o in outlines)
    outlines = [np.vstack([o, np.repeat(o[-1:], width - len(o), axis=0)]) for o in outlines]
    pads = np.array(outlines) - origin
    heights = np.array([h for h, _ in merged])
    return pads, heights - heights.min()
