"""A rehearsal of the production line: a simulated lot of units with known truth, and its manifest.

Each unit is a gyro IMU with parameters drawn around a nominal part (:class:`LotSpread`): a small
mounting rotation (each component ``~ N(0, misalignment)``), scale factors ``1 + N(0, scale)``,
axis-to-axis angles ``~ N(0, delta)`` and a turn-on bias ``~ N(0, bias)``; its session is the
six-dwell rate-table test (+/- ``rate`` about x, y, z) simulated by
:func:`align.alignment.simulate.simulate_run`. A few units are deliberately bad (:data:`BAD_KINDS`):

* ``"wrong direction"``: the table turned one step the other way than the plan says;
* ``"nan rows"``: a few rows of the log hold NaN (a logger glitch);
* ``"out of spec"``: the IMU is mounted turned by ``out_of_spec`` about one axis (two cross-axis
  angles that large), a good session of a bad part.

Written into ``folder``: ``plan.toml``, ``sessions/SERIAL.csv`` (time in s, gyro columns in
deg/s), ``manifest.csv`` (job ``matrix``) and ``truth.csv``: per unit its serial, order, slot,
kind (``good`` or the bad kind), the true ``M_ij`` and ``bias_i`` (rad/s) and the figures of ``M``
(:mod:`align.production.keyfigures`, SI). ``truth.csv``'s first line is a comment (``#``) stating its
format, version, the imu-align version, the convention and every column's unit (:data:`TRUTH_HEADER`);
:func:`read_truth` reads it back and checks it.

Public names
------------
LotSpread, LotTruth, simulate_lot, lot_plan, read_truth, BAD_KINDS, TRUTH_FORMAT, TRUTH_UNITS
"""

from __future__ import annotations

import csv
import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from align.alignment.plan import Plan, Step
from align.alignment.simulate import SessionSpec, simulate_run
from align.errors import InputError
from align.io.files import write_csv, write_text
from align.model import SensorModel
from align.production.keyfigures import matrix_figures
from align.units import DEG, DEG_S, to_unit

#: the kinds of deliberately bad units, in the order :func:`simulate_lot` hands them out
BAD_KINDS = ("out of spec", "wrong direction", "nan rows")
_COLUMNS = ("time", "gyro_x", "gyro_y", "gyro_z")


@dataclass(frozen=True)
class LotSpread:
    """How the units of a lot differ from the nominal part (1-sigma, SI).

    Attributes
    ----------
    misalignment : float
        Each component of the small mounting rotation vector, rad.
    scale : float
        Each scale factor about 1.
    delta : float
        Each axis-to-axis (non-orthogonality) angle, rad.
    bias : float
        Each turn-on bias, rad/s.
    """

    misalignment: float = 0.03 * DEG
    scale: float = 1e-3
    delta: float = 0.01 * DEG
    bias: float = 0.2 * DEG_S

    def __post_init__(self) -> None:
        for name, field in (("misalignment", "spread"), ("scale", "scale_spread"), ("delta", "delta_spread"),
                            ("bias", "bias_spread")):
            x = getattr(self, name)
            if not (np.isfinite(x) and x >= 0):
                raise InputError(f"must be finite and >= 0 (got {float(x):g})", "{" + field + "}")


@dataclass(frozen=True)
class LotTruth:
    """What :func:`simulate_lot` wrote: the folder's files and each unit's truth (rows of ``truth.csv``)."""

    folder: Path
    manifest: Path
    plan: Path
    truth: Path
    units: tuple

    def serials(self, kind: str | None = None) -> list[str]:
        """The serials of the units of ``kind`` (``"good"`` or a bad kind); all when None."""
        return [u["serial"] for u in self.units if kind is None or u["kind"] == kind]


def lot_plan(rate: float = 100 * DEG_S) -> Plan:
    """The six-dwell plan: +/- ``rate`` (rad/s) about x, y, z on a table spinning about up."""
    return Plan(tuple(Step(a, 1, rate=s) for a in range(3) for s in (rate, -rate)))


def _draw(rng: np.random.Generator, spread: LotSpread) -> SensorModel:
    from scipy.spatial.transform import Rotation

    return SensorModel.from_rotation(Rotation.from_rotvec(rng.normal(0.0, spread.misalignment, 3)),
                                     scale=1 + rng.normal(0.0, spread.scale, 3), delta=rng.normal(0.0, spread.delta, 3),
                                     bias=rng.normal(0.0, spread.bias, 3))


def _bad_kinds(n: int, bad: int | dict, rng: np.random.Generator) -> list[str]:
    """Each unit's kind: ``bad`` units (a count, handed out over :data:`BAD_KINDS` in turn, or kind -> count) at
    random places, the rest good."""
    counts = dict(bad) if isinstance(bad, dict) else {k: len(range(i, int(bad), len(BAD_KINDS)))
                                                      for i, k in enumerate(BAD_KINDS)}
    unknown = [k for k in counts if k not in BAD_KINDS]
    if unknown:
        raise InputError(f"unknown kind of bad unit '{unknown[0]}'; the kinds are {', '.join(BAD_KINDS)}", "{bad}")
    total = sum(int(c) for c in counts.values())
    if any(int(c) < 0 for c in counts.values()) or total > n:
        raise InputError(f"{total} bad units in a lot of {n}: give 0 to {n}", "{bad}")
    kinds = ["good"] * n
    places = rng.permutation(n)[:total]
    flat = [k for k in BAD_KINDS for _ in range(int(counts.get(k, 0)))]
    for p, k in zip(places, flat):
        kinds[int(p)] = k
    return kinds


def simulate_lot(folder: str | Path, n: int, spread: LotSpread = LotSpread(), session: SessionSpec = SessionSpec(),
                 bad: int | dict = 5, seed: int = 0, rate: float = 100 * DEG_S, out_of_spec: float = 0.3 * DEG,
                 slots: int = 4, prefix: str = "SN") -> LotTruth:
    """Write a simulated lot of ``n`` units (module docstring) into ``folder`` (created).

    Parameters
    ----------
    folder : str or Path
    n : int
        Units, >= 1.
    spread : LotSpread
    session : SessionSpec
        The table and gyro behaviour of every session (sample rate, dwell, gaps, noise).
    bad : int or dict
        Deliberately bad units: a count handed out over :data:`BAD_KINDS` in turn, or kind -> count.
    seed : int
        Each unit draws from its own stream of ``numpy.random.SeedSequence(seed)``: the lot is the same
        whatever order it is written in.
    rate : float
        Table rate of the dwells, rad/s.
    out_of_spec : float
        The extra mounting rotation of an out-of-spec unit, rad.
    slots : int
        Fixture slots, handed out in turn (1 to ``slots``).
    prefix : str
        Serials are ``prefix`` and a 4-digit number from 1.

    Returns
    -------
    LotTruth
    """
    if not 1 <= int(n) <= 1_000_000:
        raise InputError(f"a lot holds 1 to 1000000 units (got {n})", "{lot}")
    root = Path(folder)
    (root / "sessions").mkdir(parents=True, exist_ok=True)
    plan = lot_plan(rate)
    write_text(root / "plan.toml", plan.to_toml())
    streams = np.random.SeedSequence(seed).spawn(int(n) + 1)
    kinds = _bad_kinds(int(n), bad, np.random.default_rng(streams[-1]))
    units, manifest = [], []
    for k in range(int(n)):
        serial, slot = f"{prefix}{k + 1:04d}", str(k % max(1, slots) + 1)
        rng = np.random.default_rng(streams[k])
        model, run_plan = _draw(rng, spread), plan
        if kinds[k] == "out of spec":
            model = _turned(model, out_of_spec, int(rng.integers(3)))
        elif kinds[k] == "wrong direction":
            step = int(rng.integers(len(plan.steps)))
            steps = list(plan.steps)
            turn = steps[step].rate
            assert turn is not None  # the lot's plan turns at rates
            steps[step] = dataclasses.replace(steps[step], rate=-turn)
            run_plan = dataclasses.replace(plan, steps=tuple(steps))
        run = simulate_run(run_plan, model, session, rng)
        g = to_unit(run.g, "deg/s")
        if kinds[k] == "nan rows":
            g = g.copy()
            g[rng.choice(len(g), size=3, replace=False)] = np.nan
        log = root / "sessions" / f"{serial}.csv"
        write_csv(log, list(_COLUMNS), np.column_stack([run.t, g]))
        manifest.append({"serial": serial, "job": "matrix", "log": f"sessions/{serial}.csv", "plan": "plan.toml",
                         "options": "", "slot": slot})
        units.append({"serial": serial, "order": k, "slot": slot, "kind": kinds[k],
                      **{f"M_{a}{b}": float(model.M[i, j]) for i, a in enumerate("xyz") for j, b in enumerate("xyz")},
                      **{f"bias_{a}": float(v) for a, v in zip("xyz", model.bias)},
                      **{k2: v for k2, v in matrix_figures(model.M, None).items() if not k2.startswith("M_")}})
    _write_rows(root / "manifest.csv", manifest)
    _write_rows(root / "truth.csv", units, _truth_comment())
    return LotTruth(root, root / "manifest.csv", root / "plan.toml", root / "truth.csv", tuple(units))


def _turned(model: SensorModel, angle: float, axis: int) -> SensorModel:
    """The model of the IMU turned further by ``angle`` about system axis ``axis`` (``M R^T``)."""
    c, s = np.cos(angle), np.sin(angle)
    i, j = [a for a in range(3) if a != axis]
    r = np.eye(3)
    r[i, i] = r[j, j] = c
    r[i, j], r[j, i] = -s, s
    return SensorModel(model.M @ r.T, model.bias)


#: the format named in truth.csv's comment line
TRUTH_FORMAT = "imu-align.lot-truth"
#: truth.csv's units per column prefix (everything SI)
TRUTH_UNITS = {"M_": "1", "bias_": "rad/s", "scale_": "1", "phi_": "rad", "delta_": "rad", "rotation_": "rad"}


def _truth_comment() -> str:
    from align import __version__

    units = " ".join(f"{k}*={v}" for k, v in TRUTH_UNITS.items())
    return (f"# format={TRUTH_FORMAT} version=1 generator=imu-align {__version__}; convention: g = M w + bias, "
            f"rows of M are sensor axes; units: {units}")


def read_truth(path: str | Path) -> tuple[dict, list[dict]]:
    """Read a ``truth.csv`` back: ``(header, rows)``; ``header`` the comment line's ``key=value`` items
    (``format``, ``version``, ``generator``) and ``units`` (column prefix -> unit); rows as strings.

    Raises
    ------
    InputError
        The file does not start with the comment line of :data:`TRUTH_FORMAT`.
    """
    import io

    from align.io.files import read_text

    text = read_text(path)
    first, _, rest = text.partition("\n")
    if not first.startswith(f"# format={TRUTH_FORMAT} "):
        raise InputError(f"not a lot truth file (its first line is not '# format={TRUTH_FORMAT} ...')", str(path))
    head, _, units = first[2:].partition("; units: ")
    meta: dict[str, Any] = dict(item.split("=", 1) for item in head.split(";")[0].split() if "=" in item)
    meta["generator"] = head.split("generator=", 1)[1].split(";")[0]
    meta["convention"] = head.split("convention: ", 1)[1] if "convention: " in head else ""
    meta["units"] = {k.rstrip("*"): v for k, v in (u.split("=", 1) for u in units.split())}
    return meta, list(csv.DictReader(io.StringIO(rest)))


def _write_rows(path: Path, rows: list[dict], comment: str = "") -> None:
    import io

    buf = io.StringIO()
    if comment:
        buf.write(comment + "\n")
    writer = csv.DictWriter(buf, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    write_text(path, buf.getvalue())
