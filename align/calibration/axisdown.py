"""Magnetometer misalignment from axis-down captures (seed 004), with its uncertainty and checks.

After the hard- and soft-iron correction the field readings lie on a sphere
centred at the origin, but the calibrated axes may still be turned from the
body's (the fixture's faces). Seed 004 finds this misalignment matrix ``[M_m]``
from captures with the x, y and z axes pointing down in turn (the paragraph
after its Eq. (16), whose images are missing from the text): "with the Z axis
vertically down, sample m times", the calibrated readings' mean
``X = [X1 X2 X3]`` gives the normalised unit vector ``R_z = X / |X|``;
"likewise ``R_x``, ``R_y`` with the X and Y axes down", and ``[M_m]`` has the
rows ``R_x, R_y, R_z`` (reference section 5: normalised mean vectors as rows;
``m_body = M_m m_cal``).

What is captured: a reading at one heading is the whole field, whose direction
depends on the heading; only its vertical component lies along the downward
axis. The seed's procedure fixes the compass in a hexahedron and records each
face down; a static record's mean would be the whole field, not the axis (it
is the axis only where the field is vertical). The mean is the axis when the
m samples are spread over headings: with face ``i`` down on a flat table the
hexahedron turns about its own axis ``i``, the horizontal field sweeps a circle
about that axis and the mean over a full turn is the vertical component along
it. So each capture here is such a turn (any number of headings spread over at
least a quarter turn) and, instead of the plain mean (which needs headings
evenly spread over the whole turn), the plane of the circle is fitted: its
normal is the same unit vector ``R_i`` (the mean's direction for a uniform full
turn) and its offset from the origin is the vertical field ``V_i``, the same in
all three captures (the seed's mean points along ``-R_i`` where the field points
up, in the southern hemisphere; the normal is oriented toward axis ``i``
instead, so the matrix stays a rotation there). The axis found is the axis of
the turn: turning on a flat surface makes it the face's normal whatever the
table's tilt; a device turned by hand about the vertical gives the vertical,
and the tilt of its axis from the vertical is an error the 1-sigma cannot hold.
With the accelerometer's readings of all three captures the lean is measured and
taken out (issue 23): each turn's axis in the accelerometer frame ``d_i``
(:func:`accel_turn_axis`, A1: the normal of the circle gravity traces in the
body frame, or, when it stands still, the down direction) is the target of the
row ``R_i`` instead of the body axis ``e_i``, and the misalignment is the
rotation taking every ``R_i`` onto its ``d_i`` (A2, Wahba's problem; with
``d_i = e_i`` the nearest rotation to the rows, as before); a lean beyond
:data:`LEAN_WARN` is warned of.

``R = [R_x; R_y; R_z]`` is a rotation up to noise (the symmetric soft iron
leaves no shear); the result is its nearest rotation (``U V^T`` of the SVD),
stored as ``misalignment`` (``m_body = misalignment m_cal``) and reported as
a rotation vector (alpha, beta, gamma about x, y, z) with its 1-sigma,
propagated from the plane fits (total least squares, normal covariance
``s^2 sum_k v_k v_k^T / S_k`` over the in-plane directions ``v_k`` with
scatter ``S_k``) and from the calibration's covariance (hard and soft iron).

Checks, each one line naming the capture: too few samples; no turn (the
readings barely move) or less than a quarter turn; not a turn about one axis
(readings off the plane); the turn axis far from the axis named (that axis
was not down); a calibrated field strength unlike the calibration's; the
captures disagreeing on the vertical field (one axis up instead of down, or
wired backwards); an accelerometer that says the axis was not down.

Public names
------------
AXES, MIN_SAMPLES, LEAN_WARN, TurnAxis, parse_axis_down, axis_down_captures, turn_axis, accel_turn_axis, with_axis_down
(LEAN_WARN and accel_turn_axis from :mod:`align.calibration.axislean`)
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from align.calibration.axislean import LEAN_WARN, accel_turn_axis, angles_onto, lean_notes, rotation_onto  # noqa: F401
from align.errors import InputError, TestError, literal
from align.units import DEG, to_unit

AXES = "xyz"
#: fewest samples in one axis-down capture
MIN_SAMPLES = 20
#: largest angle between a turn's axis and the axis named (a mounting error is a few degrees)
MAX_TILT = 20 * DEG
#: largest 1-sigma of a turn's axis (beyond it the readings barely turn: the plane is noise)
MAX_AXIS_SIGMA = 1 * DEG
#: smallest arc of headings a turn must cover
MIN_ARC = 90 * DEG
#: largest disagreement between the captures' vertical fields, as a fraction of the field
VERTICAL_TOLERANCE = 0.12
_RANGE = re.compile(r"^\s*(\d+)\s*:\s*(\d+)\s*$")


def parse_axis_down(text: str) -> dict[str, str | tuple[int, int]]:
    """``'x=FILE,y=FILE,z=FILE'`` or ``'x=100:900,y=...'`` (samples of the log, stop exclusive) -> per axis.

    Parameters
    ----------
    text : str
        Three ``AXIS=VALUE`` items separated by commas, one for each of x, y, z; a value of the form
        ``START:STOP`` (whole numbers) is a range of the log's samples (data rows counted from 0, stop
        exclusive, as a positions file's ``start``/``end``), any other value a file.

    Returns
    -------
    dict
        ``{"x": "file.csv" or (start, stop), "y": ..., "z": ...}``.

    Raises
    ------
    InputError
        An item without ``=``, an axis other than x, y, z or given twice, one missing, an empty value,
        a range of no samples.
    """
    example = "give x=FILE,y=FILE,z=FILE or samples of the log, e.g. x=100:900,y=1000:1800,z=2000:2800"
    out: dict[str, str | tuple[int, int]] = {}
    for item in (text or "").split(","):
        if not item.strip():
            continue
        axis, eq, value = item.partition("=")
        axis, value = axis.strip().lower(), value.strip()
        if not eq or axis not in AXES or not value:
            raise InputError(f"'{literal(item.strip())}' is not AXIS=FILE or AXIS=START:STOP; {example}", "{axis_down}")
        if axis in out:
            raise InputError(f"axis {axis} given twice; {example}", "{axis_down}")
        rng = _RANGE.match(value)
        if rng:
            start, stop = int(rng.group(1)), int(rng.group(2))
            if stop <= start:
                raise InputError(f"samples {start}:{stop} for {axis} are none (STOP is exclusive); {example}",
                                 "{axis_down}")
            out[axis] = (start, stop)
        else:
            out[axis] = value
    missing = [a for a in AXES if a not in out]
    if missing:
        raise InputError(f"no capture for {', '.join(missing)}: the misalignment needs x, y and z down; {example}",
                         "{axis_down}")
    return {a: out[a] for a in AXES}


def axis_down_captures(spec: dict, data: np.ndarray, log: str, read: Callable[[str], np.ndarray]
                       ) -> tuple[dict[str, tuple[np.ndarray, str]], np.ndarray]:
    """The axis-down captures :func:`parse_axis_down` names, and the log's samples left for the ellipsoid fit.

    Parameters
    ----------
    spec : dict
        ``{"x": "file" or (start, stop), ...}``.
    data : ndarray, shape (n, k)
        The log's readings (the columns a capture file must also hold).
    log : str
        The log's name, for messages.
    read : callable
        ``read(path) -> ndarray (m, k)``: reads a capture file's same columns.

    Returns
    -------
    captures : dict
        Per axis ``(readings (m, k), source)``, ``source`` the file or ``"LOG samples a:b"``.
    tumble : ndarray, shape (n', k)
        ``data`` without the samples the ranges take.

    Raises
    ------
    InputError
        A file that does not exist, a range beyond the log, two ranges that overlap.
    """
    used = np.zeros(len(data), bool)
    captures: dict[str, tuple[np.ndarray, str]] = {}
    for axis in AXES:
        value = spec[axis]
        if isinstance(value, tuple):
            start, stop = value
            if stop > len(data):
                raise InputError(f"samples {start}:{stop} for {axis} lie beyond the log's {len(data)} samples "
                                 "(counted from 0); give a range inside it", "{axis_down}")
            if used[start:stop].any():
                raise InputError(f"samples {start}:{stop} for {axis} overlap another axis's; one capture per axis",
                                 "{axis_down}")
            used[start:stop] = True
            captures[axis] = (data[start:stop], f"{log} samples {start}:{stop}")
        else:
            if not Path(value).is_file():
                raise InputError(f"the {axis}-down capture {literal(value)} is not a file; give an existing file "
                                 "or samples of the log as START:STOP", "{axis_down}")
            captures[axis] = (np.asarray(read(value), float), value)
    return captures, data[~used]


@dataclass(frozen=True)
class TurnAxis:
    """The axis of one axis-down turn, in calibrated magnetometer coordinates.

    Attributes
    ----------
    axis : ndarray, shape (3,)
        Unit normal of the circle's plane, oriented toward the axis named (seed 004's ``R_i``).
    vertical : float
        Offset of the plane from the origin along ``axis``: the vertical field (positive when it points
        down, as in the northern hemisphere), unit of the readings.
    cov : ndarray, shape (3, 3)
        Covariance of ``axis`` from the capture's noise.
    noise : float
        Scatter of the readings off the plane (1 sigma), unit of the readings.
    arc : float
        Arc of headings covered, rad (2 pi for a full turn).
    """

    axis: np.ndarray
    vertical: float
    cov: np.ndarray
    noise: float
    arc: float


def _arc(angles: np.ndarray) -> float:
    a = np.sort(np.mod(angles, 2 * np.pi))
    gaps = np.diff(np.concatenate([a, a[:1] + 2 * np.pi]))
    return float(2 * np.pi - gaps.max())


def turn_axis(m_cal: np.ndarray, axis: str, field: float, units: str, where: str) -> TurnAxis:
    """Fit the plane of the circle one axis-down turn traces (see module docstring).

    Parameters
    ----------
    m_cal : ndarray, shape (n, 3)
        Calibrated readings (``W (m - h)``), SI or counts.
    axis : {"x", "y", "z"}
        The axis that pointed down.
    field : float
        The calibration's field strength, same unit as ``m_cal``.
    units : str
        Display unit, for messages.
    where : str
        The capture (a file, or a range of rows), for messages.

    Returns
    -------
    TurnAxis

    Raises
    ------
    InputError
        Fewer than :data:`MIN_SAMPLES` samples.
    TestError
        No turn, less than :data:`MIN_ARC`, readings off the plane, a field unlike ``field``, or a turn
        axis more than :data:`MAX_TILT` from ``axis``.
    """
    n = len(m_cal)
    again = f"turn the device on a flat surface through a full turn with {axis} pointing down"
    if n < MIN_SAMPLES:
        raise InputError(f"only {n} samples in the {axis}-down capture; give at least {MIN_SAMPLES} ({again})", where)
    strength = float(np.median(np.linalg.norm(m_cal, axis=1)))
    if abs(strength / field - 1) > 0.1:
        raise TestError(f"the calibrated field in the {axis}-down capture is {to_unit(strength, units):.4g} {units}, "
                        f"not the calibration's {to_unit(field, units):.4g} {units}: captured elsewhere, near iron, or "
                        "in another unit; capture it where the tumble was captured", where)
    mu = m_cal.mean(axis=0)
    q = m_cal - mu
    _, sv, vt = np.linalg.svd(q, full_matrices=False)
    normal = vt[2] if vt[2][AXES.index(axis)] >= 0 else -vt[2]
    noise = float(sv[2] / np.sqrt(max(n - 3, 1)))
    if noise > 0.1 * field:
        raise TestError(f"the {axis}-down capture is not a turn about one axis (the readings leave the circle's plane "
                        f"by {to_unit(noise, units):.3g} {units}); {again}", where)
    if noise > MAX_AXIS_SIGMA * sv[1]:
        raise TestError(f"the {axis}-down capture turns too little for its noise to show the axis (the axis is uncertain "
                        f"by {np.degrees(noise / sv[1]):.2g} deg, limit {MAX_AXIS_SIGMA / DEG:g}); {again}", where)
    q = m_cal - (normal @ mu) * normal  # about the circle's centre, the point of the plane nearest the origin
    arc = _arc(np.arctan2(q @ vt[1], q @ vt[0]))
    if arc < MIN_ARC:
        raise TestError(f"the {axis}-down capture turns through only {arc / DEG:.0f} deg about the vertical; {again} "
                        f"(at least {MIN_ARC / DEG:.0f} deg)", where)
    tilt = float(np.arccos(np.clip(normal[AXES.index(axis)], -1, 1)))
    if tilt > MAX_TILT:
        raise TestError(f"the {axis}-down capture turns about an axis {tilt / DEG:.0f} deg from the magnetometer's "
                        f"{axis} axis: {axis} did not point down, or the device was not turned about the vertical; "
                        f"{again}", where)
    cov = noise**2 * (np.outer(vt[0], vt[0]) / sv[0] ** 2 + np.outer(vt[1], vt[1]) / sv[1] ** 2)
    return TurnAxis(normal, float(normal @ mu), cov, noise, arc)


def _check_vertical(turns: dict[str, TurnAxis], field: float, units: str, where: str) -> None:
    v = np.array([turns[a].vertical for a in AXES])
    mid = float(np.median(v))
    shown = ", ".join(f"{a} {to_unit(x, units):+.3g}" for a, x in zip(AXES, v))
    if abs(mid) > 0.15 * field:
        flipped = [a for a, x in zip(AXES, v) if np.sign(x) != np.sign(mid)]
        if flipped:
            a = flipped[0]
            raise TestError(f"the {a}-down capture reads the vertical field reversed ({shown} {units}): {a} pointed up, "
                            f"or the magnetometer's {a} axis is wired backwards; capture it with {a} pointing down", where)
    worst = int(np.argmax(np.abs(v - mid)))
    if abs(v[worst] - mid) > VERTICAL_TOLERANCE * field:
        raise TestError(f"the captures disagree on the vertical field ({shown} {units}): the {AXES[worst]}-down capture "
                        "is not axis-down, or was made elsewhere; capture all three at one place", where)


def _check_gravity(acc: np.ndarray, axis: str, where: str) -> None:
    a = np.asarray(acc, float).mean(axis=0)
    off = float(np.arccos(np.clip(-a[AXES.index(axis)] / np.linalg.norm(a), -1, 1)))
    if off > MAX_TILT:
        raise TestError(f"the accelerometer says {axis} did not point down in the {axis}-down capture ({axis} is "
                        f"{off / DEG:.0f} deg from down, limit {MAX_TILT / DEG:.0f}); capture it with {axis} pointing "
                        "down, or check the accelerometer columns", where)


def with_axis_down(cal, captures: dict, acc: dict | None = None, sources: dict | None = None,
                   where: str = "axis-down capture"):
    """``cal`` with the misalignment found from axis-down turns (seed 004; see module docstring).

    Parameters
    ----------
    cal : MagCalibration
        The hard- and soft-iron calibration (its covariance, when present, is propagated).
    captures : dict
        ``{"x": raw (n, 3), "y": ..., "z": ...}``: raw readings of each turn, SI or counts as ``cal``.
    acc : dict, optional
        Simultaneous accelerometer readings per axis (any unit), (n_i, 3) each: checked to show the axis down
        (within :data:`MAX_TILT`); with all three, each turn's axis from them is its row's target (A1-A2).
    sources : dict, optional
        Per axis, what the capture is (a file name, ``"LOG samples 100:900"``), for messages and notes.
    where : str
        What the captures came from when ``sources`` does not say.

    Returns
    -------
    MagCalibration
        ``cal`` with ``misalignment`` (the nearest rotation to seed 004's ``[R_x; R_y; R_z]``,
        ``m_body = misalignment m_cal``), ``misalignment_method = "axis-down"``,
        ``sigma_misalignment`` (1 sigma of the rotation vector, rad) and notes.

    Raises
    ------
    InputError, TestError
        See :func:`turn_axis`; also captures that disagree on the vertical field, or an accelerometer
        that shows the axis was not down.
    """
    sources = {a: (sources or {}).get(a, where) for a in AXES}
    raw = {a: np.asarray(captures[a], float) for a in AXES}
    for a in AXES:
        if raw[a].ndim != 2 or raw[a].shape[1] != 3:
            raise InputError(f"the {a}-down capture needs 3 columns, not shape {raw[a].shape}", sources[a])
        if acc is not None and acc.get(a) is not None:
            _check_gravity(acc[a], a, sources[a])
    field, units = cal.field, cal.units
    # A1: each turn's axis in the accelerometer frame, the target of its row (the body axes without all three)
    seen = {a: accel_turn_axis(acc[a]) for a in AXES} if acc is not None and all(
        acc.get(a) is not None for a in AXES) else None
    targets = None if seen is None else np.array([seen[a][0] for a in AXES])

    def fit(h, w):
        return {a: turn_axis((raw[a] - h) @ w.T, a, field, units, sources[a]) for a in AXES}

    turns = fit(cal.hard_iron, cal.soft_iron)
    _check_vertical(turns, field, units, ", ".join(dict.fromkeys(sources.values())))
    rows = np.array([turns[a].axis for a in AXES])
    # 1 sigma: the plane fits' noise (and the accelerometer's axes'), then the calibration's (h, W) covariance
    jac_rows, jac_targets = np.zeros((3, 9)), np.zeros((3, 9))
    for k in range(9):
        d = np.zeros(9)
        d[k] = 1e-7
        step = d.reshape(3, 3)
        jac_rows[:, k] = (angles_onto(rows + step, targets) - angles_onto(rows - step, targets)) / 2e-7
        if targets is not None:
            jac_targets[:, k] = (angles_onto(rows, targets + step) - angles_onto(rows, targets - step)) / 2e-7
    cov_rows, cov_targets = np.zeros((9, 9)), np.zeros((9, 9))
    for i, a in enumerate(AXES):
        cov_rows[3 * i:3 * i + 3, 3 * i:3 * i + 3] = turns[a].cov
        if seen is not None:
            cov_targets[3 * i:3 * i + 3, 3 * i:3 * i + 3] = seen[a][1]
    cov = jac_rows @ cov_rows @ jac_rows.T + jac_targets @ cov_targets @ jac_targets.T
    notes = []
    if cal.covariance is not None:
        iu = np.triu_indices(3)
        jac_cal = np.zeros((3, 9))
        base = np.concatenate([cal.hard_iron, cal.soft_iron[iu]])
        for k in range(9):
            sd = float(np.sqrt(cal.covariance[k, k]))
            if not sd > 0:
                continue
            delta = 0.1 * sd
            out = []
            for sign in (1, -1):
                p = base.copy()
                p[k] += sign * delta
                w = np.zeros((3, 3))
                w[iu] = p[3:]
                w = w + np.triu(w, 1).T
                out.append(angles_onto(np.array([t.axis for t in fit(p[:3], w).values()]), targets))
            jac_cal[:, k] = (out[0] - out[1]) / (2 * delta)
        cov = cov + jac_cal @ cal.covariance @ jac_cal.T
    else:
        notes.append("axis-down misalignment: the calibration has no covariance (an older file); its 1-sigma holds "
                     "the turns' noise only")
    notes += lean_notes(targets, acc is not None)
    sigma = np.sqrt(np.diag(cov))
    skew = max(abs(np.arcsin(np.clip(rows[i] @ rows[j], -1, 1))) for i, j in ((0, 1), (0, 2), (1, 2)))
    vert = ", ".join(f"{a} {to_unit(turns[a].vertical, units):+.4g}" for a in AXES)
    arcs = ", ".join(f"{a} {turns[a].arc / DEG:.0f}" for a in AXES)
    notes += [
        "misalignment from axis-down turns (seed 004: rows R_x, R_y, R_z, each the unit axis of the circle the "
        "calibrated field traces while that axis points down; the nearest rotation kept; its angles above)",
        "axis-down turns: " + "; ".join(f"{a} from {sources[a]}" for a in AXES)
        + f"; vertical field {vert} {units}; headings covered {arcs} deg; rows orthogonal within {skew / DEG:.3f} deg",
    ]
    return cal.replace(misalignment=rotation_onto(rows, targets), misalignment_method="axis-down", sigma_misalignment=sigma,
                       notes=tuple(cal.notes) + tuple(notes))
