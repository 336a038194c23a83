"""The lean of axis-down turns, from the accelerometer (issue 23, A1-A2): each turn's axis in the accelerometer
frame, and the rotation taking the magnetometer's turn axes onto them.

A turn made by hand is about the vertical, not about the axis named; the accelerometer's readings during
the turn show the axis it was made about (:func:`accel_turn_axis`, A1), and the misalignment is then the
rotation taking each turn's axis ``R_i`` onto its ``d_i`` (:func:`rotation_onto`, A2, Wahba's problem) instead
of onto the body axis ``e_i``. :func:`align.calibration.axisdown.with_axis_down` uses them; a lean beyond
:data:`LEAN_WARN` is warned of (:func:`lean_notes`).

Public names
------------
LEAN_WARN, accel_turn_axis, rotation_onto, angles_onto, lean_notes
"""

from __future__ import annotations

import numpy as np

from align.units import DEG

__all__ = ["LEAN_WARN", "accel_turn_axis", "rotation_onto", "angles_onto", "lean_notes"]

AXES = "xyz"
#: a turn's axis (from the accelerometer) further than this from the axis named: a warning (a lean, corrected)
LEAN_WARN = 0.5 * DEG


def accel_turn_axis(acc: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The axis of one axis-down turn in the accelerometer frame, from its readings during the turn (A1).

    Turning about an axis ``k`` fixed in the body, gravity in the body frame moves on a circle about ``k``:
    when the readings trace one (a turn on a tilted surface: radius ``g sin(tilt)``) its plane's normal is
    ``k``; when they stand still (a turn about the vertical, e.g. by hand, whatever the lean) ``k`` is the
    down direction ``-mean(a) / |mean(a)|``. The circle is taken as traced when its in-plane scatter exceeds
    ten times the scatter off the plane and 0.05 deg of the field's direction.

    Parameters
    ----------
    acc : ndarray, shape (n, 3)
        Accelerometer readings (specific force, any unit) during the turn.

    Returns
    -------
    axis : ndarray, shape (3,)
        Unit vector, oriented down (along ``-mean(a)``).
    cov : ndarray, shape (3, 3)
        Its covariance from the readings' scatter, dimensionless.
    """
    a = np.asarray(acc, float)
    n = len(a)
    mu = a.mean(axis=0)
    size = float(np.linalg.norm(mu))
    down = -mu / size
    q = a - mu
    _, sv, vt = np.linalg.svd(q, full_matrices=False)
    if len(sv) == 3 and sv[1] > 10 * sv[2] and sv[1] / np.sqrt(n) > np.sin(0.05 * DEG) * size:
        normal = vt[2] if vt[2] @ down >= 0 else -vt[2]
        noise = sv[2] / np.sqrt(max(n - 3, 1))
        return normal, noise**2 * (np.outer(vt[0], vt[0]) / sv[0] ** 2 + np.outer(vt[1], vt[1]) / sv[1] ** 2)
    across = np.eye(3) - np.outer(down, down)
    return down, across @ (q.T @ q / max(n - 1, 1)) @ across / (n * size**2)


def rotation_onto(rows: np.ndarray, targets: np.ndarray | None = None) -> np.ndarray:
    """The rotation ``R`` minimising ``sum_i |R n_i - d_i|^2`` (A2; Wahba's problem): the orthogonal factor of
    ``B = D^T N`` (rows ``n_i`` of ``N``, the turns' axes; rows ``d_i`` of ``D``, the same axes in the body frame,
    the identity when None, so that ``B = N``), shape (3, 3)."""
    b = rows if targets is None else targets.T @ rows
    u, _, vt = np.linalg.svd(b)
    return u @ np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt))]) @ vt


def angles_onto(rows: np.ndarray, targets: np.ndarray | None = None) -> np.ndarray:
    """The rotation vector of :func:`rotation_onto`, rad, shape (3,)."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_matrix(rotation_onto(rows, targets)).as_rotvec()


def lean_notes(targets: np.ndarray | None, acc_given: bool) -> list[str]:
    """The notes on the turns' axes from the accelerometer (rows of ``targets``, the turns' axes in the
    accelerometer frame): the lean of each, and a warning beyond :data:`LEAN_WARN`; without ``targets`` but with an
    accelerometer (``acc_given``), that the rotation is to the body axes."""
    notes: list[str] = []
    if targets is not None:
        lean = np.degrees(np.arccos(np.clip(np.diag(targets), -1.0, 1.0)))
        shown = ", ".join(f"{a} {x:.2f}" for a, x in zip(AXES, lean))
        notes.append(f"axis-down turns' axes from the accelerometer ({shown} deg from the axes): each row turned onto "
                     "its turn's axis in the accelerometer frame (the vertical for a turn by hand, the face's normal "
                     "for a turn on a surface), so the misalignment is to the accelerometer's axes (the "
                     "accelerometer's own misalignment to the fixture is not in the 1-sigma)")
        if lean.max() > LEAN_WARN / DEG:
            notes.append(f"warning: the axis-down turns were not about the axes (the accelerometer shows {shown} deg "
                         "from down: a turn made by hand leaning): corrected with the accelerometer's turn axes; "
                         "without them the lean would be in the misalignment and not in its 1-sigma")
    elif acc_given:
        notes.append("the accelerometer showed each axis down; the rotation to the accelerometer frame from gravity "
                     "is not computed: the axis-down turns give the rotation to the body (fixture) axes")
    return notes
