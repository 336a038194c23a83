"""Readable text summaries of results (pure functions returning strings).

Public names
------------
alignment_summary, matrix_text
"""

from __future__ import annotations

import numpy as np

from .alignment import AlignmentResult
from .units import DEG, to_unit


def matrix_text(m: np.ndarray, sigma: np.ndarray | None = None, digits: int = 6, indent: str = "  ") -> str:
    """Rows of a 3x3 matrix, each element with its 1-sigma when given."""
    lines = []
    for i in range(3):
        cells = []
        for j in range(3):
            cell = f"{m[i, j]:+.{digits}f}"
            if sigma is not None:
                cell += f" ± {sigma[i, j]:.1e}"
            cells.append(cell)
        lines.append(indent + "[" + ",  ".join(cells) + "]")
    return "\n".join(lines)


def alignment_summary(r: AlignmentResult) -> str:
    """The summary ``imu-align matrix`` prints: M, A, bias, angles, segments, checks."""
    u = r.units
    ang = r.angles
    out = [f"Electronic alignment ({r.method}), convention g = M w + b, w = A (g - b)", "",
           "M (1-sigma):", matrix_text(r.M, r.sigma_M), "",
           "A = M^-1 (1-sigma):", matrix_text(r.A, r.sigma_A), "",
           "bias [" + u + "]: " + ", ".join(f"{b:+.5g} ± {s:.2g}" for b, s in zip(to_unit(r.bias, u), to_unit(r.sigma_bias, u))),
           "",
           "angles [deg]:",
           "  scale factors      " + "  ".join(f"{s:.6f}" for s in ang.scale),
           "  psi (axis-frame)   " + "  ".join(f"{k}={v / DEG:.4f}" for k, v in zip("xyz", ang.psi)),
           "  phi (cross-axis)   " + "  ".join(f"{'xyz'[i]}{'xyz'[j]}={ang.phi[i, j] / DEG:+.4f}"
                                                 for i in range(3) for j in range(3) if i != j),
           "  delta (axis-axis)  " + "  ".join(f"{p}={v / DEG:+.4f}" for p, v in zip(("xy", "xz", "yz"), ang.delta)),
           "  mounting rotation  " + ", ".join(f"{v / DEG:+.4f}" for v in ang.mounting_rotvec) + " (rotation vector)",
           "",
           f"design condition number {r.condition_number:.3g}, {r.dof} degrees of freedom per gyro",
           "", "segments (residual / noise, per gyro):"]
    for s in r.segments:
        scale = DEG if s.kind == "angle" else None
        res = np.array(s.residual) / scale if scale else to_unit(np.array(s.residual), u)
        nz = np.array(s.noise) / scale if scale else to_unit(np.array(s.noise), u)
        unit = "deg" if scale else u
        out.append(f"  {s.name:<32} {s.t_start:9.2f}-{s.t_end:9.2f} s  "
                   + " ".join(f"{a:+.2e}" for a in res) + f"  / {np.max(nz):.1e} {unit}")
    out += ["", "checks:"] + [f"  [{c.status}] {c.name}: {c.detail}" for c in r.checks]
    out += ["", "notes:"] + [f"  - {n}" for n in r.notes]
    return "\n".join(out)
