"""Checks of a multi-position gyro session: enough poses, each long and static, rotations within the gyro's range.

Each refusal is one line naming the pose or rotation (poses are numbered from 1, the initial static
period being pose 1; rotation ``k`` goes from pose ``k`` to pose ``k + 1``) and what to do.

Public names
------------
MIN_POSES, RECOMMENDED_POSES, parse_intervals, check_poses, check_static, saturated_samples, check_saturation,
rotation_spans
"""

from __future__ import annotations

import re

import numpy as np

from align.errors import InputError, TestError, literal
from align.units import to_unit

#: fewest poses the two fits need: the accelerometer's 9 parameters plus one degree of freedom for its 1-sigma
#: (the gyro's 9 need 5 rotations, 6 poses)
MIN_POSES = 10
#: imu_tk's minimum number of static intervals
RECOMMENDED_POSES = 12
#: a static pose varies by at most this fraction of |a| (1 sigma, any axis)
MAX_SPREAD = 0.02


def parse_intervals(text: str | list, n: int, where: str = "{intervals}") -> list[tuple[int, int]]:
    """Static intervals given explicitly: ``"150:3613, 4297:4299"`` (sample ranges, end exclusive) or pairs.

    Parameters
    ----------
    text : str or list of (int, int)
        The ranges, increasing and not overlapping; the first is the initial static period.
    n : int
        Samples in the log.

    Raises
    ------
    InputError
        A range that is not ``start:end`` with ``0 <= start < end <= n``, or ranges out of order.
    """
    if isinstance(text, str):
        parts = [p for p in re.split(r"[,;\s]+", text.strip()) if p]
        pairs = []
        for p in parts:
            m = re.fullmatch(r"(\d+)(?::|-|\.\.)(\d+)", p)
            if not m:
                raise InputError(f"'{literal(p)}' is not a sample range start:end (e.g. 150:3613)", where)
            pairs.append((int(m.group(1)), int(m.group(2))))
    else:
        pairs = [(int(a), int(b)) for a, b in text]
    out: list[tuple[int, int]] = []
    for k, (a, b) in enumerate(pairs, start=1):
        if not 0 <= a < b <= n:
            raise InputError(f"pose {k}: samples {a}:{b} are not a range inside the log's {n} samples", where)
        if out and a < out[-1][1]:
            raise InputError(f"pose {k}: samples {a}:{b} start before pose {k - 1} ends ({out[-1][1]}); give the "
                             "poses in time order", where)
        out.append((a, b))
    return out


def check_poses(t: np.ndarray, poses: list, min_static_s: float, where: str) -> None:
    """Refuse too few poses, or a pose shorter than ``min_static_s`` (naming it)."""
    if len(poses) < MIN_POSES:
        raise TestError(f"only {len(poses)} static poses (the initial one included); the calibration needs at least "
                        f"{MIN_POSES} ({RECOMMENDED_POSES} or more recommended, as imu_tk asks): record more poses, or "
                        "adjust the static detector ({factor}, {gyro_factor}, {window_s}, {min_duration_s})", where)
    for k, (a, b) in enumerate(poses, start=1):
        length = float(t[b - 1] - t[a]) if b - a > 1 else 0.0
        if length < min_static_s * 0.999:
            raise TestError(f"pose {k} (t={t[a]:.1f} s) lasts {length:.2f} s, shorter than {min_static_s:g} s: hold each "
                            "pose longer, or leave it out of {intervals}", where)


def check_static(t: np.ndarray, acc: np.ndarray, poses: list, where: str) -> np.ndarray:
    """Mean accelerometer reading (K, 3) of every pose, refusing one that is not static.

    A pose is static when every axis varies by at most :data:`MAX_SPREAD` of the median ``|a|`` (1 sigma):
    unit-free, so raw counts work too.
    """
    scale = float(np.median(np.linalg.norm(acc[poses[0][0]:poses[0][1]], axis=1)))
    means = []
    for k, (a, b) in enumerate(poses, start=1):
        spread = float(np.std(acc[a:b], axis=0).max())
        if spread > MAX_SPREAD * scale:
            raise TestError(f"pose {k} (t={t[a]:.1f}-{t[b - 1]:.1f} s) is not static: the accelerometer varies by "
                            f"{spread / scale:.1%} of |a| (1 sigma), more than {MAX_SPREAD:.0%}; check its range", where)
        means.append(acc[a:b].mean(axis=0))
    return np.array(means)


def rotation_spans(poses: list) -> list[tuple[int, int]]:
    """Rotation ``k``: from the last sample of pose ``k`` to the first of pose ``k + 1`` (both included)."""
    return [(a_end - 1, b_start) for (_, a_end), (b_start, _) in zip(poses[:-1], poses[1:])]


#: the rails of 16-bit converters (signed and unsigned): raw counts there are clipped
RAILS = (-32768.0, 32767.0, 0.0, 65535.0)


def saturated_samples(g: np.ndarray, bias: np.ndarray, noise: np.ndarray, gyro_range: float | None,
                      counts: bool = False) -> np.ndarray:
    """Samples (n, 3) of bool at the gyro's range.

    With ``gyro_range`` (the full scale, in the readings' unit): ``|g| >= 0.999 gyro_range``. Without it,
    a reading farther than 100 static sigma from the bias is clipped when it sits on a 16-bit rail
    (:data:`RAILS`, raw counts only), or on a flat top: the axis's extreme over the record, held for two
    samples or more and entered or left by a step of at least 1 % of its distance from the bias (a smooth
    peak neither repeats its exact largest value nor turns a corner there).
    """
    g = np.asarray(g, float)
    if gyro_range is not None:
        return np.abs(g) >= 0.999 * gyro_range
    far = np.abs(g - bias) > 100.0 * np.maximum(np.asarray(noise, float), 1e-300)
    out = np.isin(g, RAILS) & far if counts else np.zeros(g.shape, bool)
    for j in range(3):
        for extreme in (g[:, j].max(), g[:, j].min()):
            at = g[:, j] == extreme
            for a, b in _runs(at):
                steps = [abs(extreme - g[k, j]) for k in (a - 1, b) if 0 <= k < len(g)]
                if b - a >= 2 and max(steps, default=0.0) >= 0.01 * abs(extreme - bias[j]):
                    out[a:b, j] |= far[a:b, j]
    return out


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    edges = np.diff(np.concatenate(([0], mask.astype(np.int8), [0])))
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist()))


def check_saturation(t: np.ndarray, g: np.ndarray, spans: list, at_range: np.ndarray, dropped: tuple,
                     units: str, where: str) -> None:
    """Refuse a rotation (not among ``dropped``) with samples at the gyro's range, naming it and the axis."""
    for k, (a, b) in enumerate(spans, start=1):
        hits = at_range[a:b + 1]
        if k in dropped or not hits.any():
            continue
        j = int(np.argmax(hits.sum(axis=0)))
        value = float(to_unit(g[a:b + 1, j][hits[:, j]][0], units))
        raise TestError(f"rotation {k} (t={t[a]:.1f}-{t[b]:.1f} s) holds {int(hits.any(axis=1).sum())} samples at the "
                        f"gyro's range ({'xyz'[j]} reads {value:+.6g} {units}): too fast, so its turn is "
                        f"lost; turn more slowly, or leave it out with {{drop_rotations={k}}}", where)
