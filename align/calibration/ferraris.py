"""Ferraris calibration: six static faces and one turn about each axis, as imucal records it.

The accelerometer comes from the six faces (:func:`~align.calibration.accel.calibrate_accel`,
by default with the pairwise bias); the gyro from the alignment family's
estimators on the static faces (bias) and the integrated turns (Eq 31), after
removing the g-sensitivity ``K_ga`` estimated from the static faces, as
Ferraris and imucal do (``raw = M w + K_ga a + bias``).

Public names
------------
ferraris, sections_from_dict, SECTIONS
"""

from __future__ import annotations

import numpy as np

from align.alignment.job import AlignOptions, align
from align.alignment.plan import Plan, Step
from align.alignment.segment import Segment
from align.calibration.accel import FACES, calibrate_accel, face_ups, norms_at_rest, static_means
from align.calibration.results import Calibration
from align.errors import InputError, literal
from align.io import check_finite
from align.io.keys import check_keys
from align.plausible import check_at_rest, check_gravity
from align.units import STANDARD_GRAVITY

#: imucal's section names: the six static faces, then the turns about x, y, z
SECTIONS = tuple(FACES) + ("x_rot", "y_rot", "z_rot")


def _check_sections(sections: dict, n: int) -> None:
    """Every section named, inside the log, and no two faces (or turns) sharing samples (a section copied)."""
    check_keys(sections, SECTIONS, "{sections}")
    missing = [k for k in SECTIONS if k not in sections]
    if missing:
        raise InputError(f"missing sections {', '.join(missing)} (imucal's names: {', '.join(SECTIONS)})", "{sections}")
    for name, (a, b) in sections.items():
        if not 0 <= a < b <= n:
            raise InputError(f"{literal(name)}: {a}..{b} is not inside the log's {n} samples", "{sections}")
    # a face inside a turn is caught as "not static"; two faces (or two turns) sharing samples are a copied section
    for group in (tuple(FACES), SECTIONS[len(FACES):]):
        _check_disjoint(sections, group)


def _check_disjoint(sections: dict, names: tuple[str, ...]) -> None:
    for i, k in enumerate(names):
        for other in names[i + 1:]:
            (a, b), (c, d) = sections[k], sections[other]
            if a < d and c < b:
                same = "the same samples as" if (a, b) == (c, d) else "samples shared with"
                raise InputError(f"{k} ({a}..{b}) has {same} {other} ({c}..{d}): each needs its own samples; "
                                 "check the section list", "{sections}")


def _readings(x: np.ndarray, sensor: str, columns: str, where: str) -> np.ndarray:
    """Readings of one sensor as an (n, 3) float array, refusing another width and NaN rows (naming the log)."""
    x = np.asarray(x, float)
    if x.ndim != 2 or x.shape[1] != 3:
        raise InputError(f"the {sensor} needs 3 columns (x, y, z), not {x.shape[-1] if x.ndim else 0}; "
                         f"give three {{{columns}}}", where)
    check_finite(x, where)
    return x


def _g_sensitivity(gyr: np.ndarray, sections: dict, gravity: float) -> np.ndarray:
    """``K_ga`` from the faces: column ``i`` is ``(g(+i up) - g(-i up)) / 2g``, (rad/s) per (m/s^2)."""
    face = {f: gyr[a:b].mean(axis=0) for f, (a, b) in sections.items() if f in FACES}
    return np.column_stack([(face[f"{a}_p"] - face[f"{a}_a"]) / (2 * gravity) for a in "xyz"])


def ferraris(acc: np.ndarray, gyr: np.ndarray, fs: float, sections: dict, turn_angle: float,
             gravity: float = STANDARD_GRAVITY, acc_units: str = "m/s^2", gyr_units: str = "deg/s",
             pairwise_bias: bool = True, g_sensitivity: bool = True, where: str = "log") -> tuple[Calibration, Calibration]:
    """A Ferraris session (six faces, one turn about each axis): accelerometer and gyro.

    Parameters
    ----------
    acc, gyr : ndarray, shape (n, 3)
        Readings, SI (m/s^2, rad/s).
    fs : float
        Sample rate, Hz.
    sections : dict of str -> (int, int)
        imucal's section list: ``x_p``, ``x_a``, ... ``z_a`` (static faces) and
        ``x_rot``, ``y_rot``, ``z_rot`` (turns), each ``(start, end)`` samples, end exclusive.
    turn_angle : float
        Signed angle of each turn about the axis pointing up, rad (imucal: -360 deg).
    gravity : float
        Local gravity, m/s^2.
    acc_units, gyr_units : str
        Units of the readings, for the results' file form.
    pairwise_bias : bool
        Accelerometer bias by Ferraris' pairwise formula (else least squares).
    g_sensitivity : bool
        Estimate and remove the gyro's ``K_ga`` from the static faces.
    where : str
        The log (its file name), for errors.

    Returns
    -------
    (Calibration, Calibration)
        The accelerometer (``a = M f + b``: the six-face least squares of reference section 5) and the
        gyroscope (``g = M w + K_ga a + b``; ``M`` from the integrated turns, Eq 31): ``M`` (3, 3),
        dimensionless, ``bias`` (3,), SI (m/s^2, rad/s), the gyro's ``g_sensitivity`` (3, 3), (rad/s) per (m/s^2).

    Examples
    --------
    A noise-free session at 100 Hz: 2 s on each face, then a -360 deg turn in 4 s about each axis
    pointing up; both sensors' ``M`` (dimensionless) and bias (SI) come back.

    >>> import numpy as np
    >>> Ma = np.array([[1.01, 0.002, -0.003], [0.001, 0.99, 0.004], [-0.002, 0.003, 1.005]])
    >>> Mg = np.array([[1.002, 0.003, -0.002], [-0.004, 0.998, 0.001], [0.002, -0.001, 1.001]])
    >>> ba, bg = np.array([0.05, -0.03, 0.02]), np.array([1e-3, -2e-3, 5e-4])
    >>> f, w, sections = [], [], {}
    >>> for name in SECTIONS:
    ...     axis, kind = name.split("_")
    ...     up = np.eye(3)["xyz".index(axis)] * (-1 if kind == "a" else 1)
    ...     k = 400 if kind == "rot" else 200
    ...     f.append(np.tile(9.80665 * up, (k, 1)))
    ...     w.append(np.tile(up * (-2 * np.pi / 4.0 if kind == "rot" else 0.0), (k, 1)))
    ...     sections[name] = (sum(map(len, f)) - k, sum(map(len, f)))
    >>> acc, gyr = np.vstack(f) @ Ma.T + ba, np.vstack(w) @ Mg.T + bg
    >>> a, g = ferraris(acc, gyr, 100.0, sections, -2 * np.pi)
    >>> bool(np.allclose(a.M, Ma, atol=1e-9)), bool(np.allclose(g.M, Mg, atol=1e-9))
    (True, True)
    >>> bool(np.allclose(a.bias, ba, atol=1e-9)), bool(np.allclose(g.bias, bg, atol=1e-9))
    (True, True)
    """
    gravity = check_gravity(gravity)
    acc, gyr = _readings(acc, "accelerometer", "acc_columns", where), _readings(gyr, "gyroscope", "gyr_columns", where)
    if len(acc) != len(gyr):
        raise InputError(f"{len(acc)} accelerometer rows but {len(gyr)} gyro rows: one row per sample", where)
    if not (np.isfinite(fs) and fs > 0):
        raise InputError(f"the sample rate must be positive, not {fs:g} Hz", "{fs}")
    if not (np.isfinite(turn_angle) and abs(turn_angle) > 0):
        raise InputError("each turn needs a non-zero angle, e.g. '-360 deg'", "{turn_angle}")
    _check_sections(sections, len(acc))
    at_rest = norms_at_rest(acc, {f: sections[f] for f in FACES})
    check_at_rest(at_rest, gravity, acc_units, "acc_units")
    means = static_means(acc, {f: sections[f] for f in FACES}, 0.05 * gravity / np.median(at_rest))
    acc_cal = calibrate_accel(means, face_ups(), gravity, acc_units, pairwise_bias=pairwise_bias, where="{sections}")
    a_true = acc_cal.correct(acc)
    t = np.arange(len(acc)) / fs
    g = np.array(gyr, float)
    kga = None
    notes = []
    if g_sensitivity:
        kga = _g_sensitivity(g, sections, gravity)
        g = g - a_true @ kga.T
        notes.append("g-sensitivity K_ga from the static faces ((g(+i up) - g(-i up)) / 2g); it also absorbs the "
                     "vertical Earth rate, which changes sign between the faces")
    plan = Plan(tuple(Step(i, 1, angle=turn_angle) for i in range(3)))
    segs = [Segment(f, "static", *sections[f]) for f in FACES]
    segs += [Segment(f"{a}_rot", "angle", sections[f"{a}_rot"][0], sections[f"{a}_rot"][1], step=i)
             for i, a in enumerate("xyz")]
    r = align(t, g, plan, AlignOptions(method="lsq", min_dwell=0.5, scale_tolerance=0.2), segs, gyr_units, "gyroscope")
    notes += ["gyro: Eq 31 on the integrated turns, bias from the static faces (weighted least squares)",
              "Earth rate not modelled: its vertical part differs between opposite faces and lands in K_ga (or, "
              "without it, in the bias); the turns integrate at most 15.04 deg/h times their duration"]
    residuals = {s.name: np.array(s.residual) for s in r.segments if s.kind == "static"}
    gyro_cal = Calibration("gyroscope", r.M, r.bias, r.sigma_M, r.sigma_bias, gyr_units, "Ferraris turns, least squares",
                           residuals, {}, tuple(notes), kga)
    return acc_cal, gyro_cal


def sections_from_dict(raw: dict, where: str = "sections") -> dict[str, tuple[int, int]]:
    """imucal's section list (``{"x_p": {"start": i, "end": j}, ...}``) as sample ranges.

    Raises
    ------
    InputError
        Not an object, a section name that is not one of :data:`SECTIONS` or a key other than
        ``start``/``end`` (the nearest valid one named), a start or end that is not a sample number.
    """
    if not isinstance(raw, dict):
        raise InputError(f"expected a JSON object of sections ({', '.join(SECTIONS)})", where)
    check_keys(raw, SECTIONS, where)
    out = {}
    for name, v in raw.items():
        at = f"{where}: {name}"
        if not isinstance(v, dict):
            raise InputError(literal('each section needs integer start and end, e.g. {"start": 540, "end": 1271}'), at)
        check_keys(v, ("start", "end"), at)
        start, end = v.get("start"), v.get("end")
        if not (isinstance(start, int) and not isinstance(start, bool) and isinstance(end, int)
                and not isinstance(end, bool)):
            raise InputError("each section needs integer start and end (samples, end exclusive)", at)
        out[str(name)] = (start, end)
    return out
