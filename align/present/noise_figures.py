"""Noise figures for the consumers (``imu-align export --to kalibr|openvins|vins|px4|ardupilot``): from Allan
results and a part's datasheet to the files :mod:`align.io.noise_consumers` writes.

One rule for every consumer: a figure is the largest over the sensor's axes of the fitted ``N`` or ``K``; where
the record does not identify a term, its one-sided 95 % upper bound stands in, marked ``UPPER BOUND`` in the file
and on the terminal (never zero: a filter told "no random walk" trusts its bias forever); a term with neither a
value nor a bound is refused, naming it. A datasheet gives ``N`` (``arw`` or ``noise_density``) and the bias
instability ``B``, not ``K``: with the averaging time ``tau`` of the datasheet's Allan floor, ``K <= B sqrt(3 /
tau)`` bounds it (a rate random walk's Allan deviation ``K sqrt(tau/3)`` cannot exceed the curve there, and ``B``
is at least the floor whether the datasheet quotes the floor or the floor / 0.664), written as an upper bound.

Public names
------------
Figures, Exported, gather, select, consumer_rate, noise_export, noise_summary
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from align.errors import InputError, literal
from align.io.noise_consumers import CONSUMERS, Consumer, Entry, NoiseTerm, entries, header_lines, noise_yaml, params_text
from align.noise.analysis import AllanAnalysis
from align.parts import Part
from align.units import STANDARD_GRAVITY, parse_unit

_TERM = {1: "white", 3: "random_walk"}
_WORD = {"white": "N", "random_walk": "K"}


@dataclass(frozen=True)
class Figures:
    """What the inputs give: a figure, or why there is none, per (sensor, term); the record's rate; gravity.

    Attributes
    ----------
    terms : dict
        ``(sensor, term) -> NoiseTerm`` for the figures there are, ``-> str`` (why not, one line, and the file)
        for a sensor given whose term has neither a value nor a bound.
    where : dict
        ``sensor -> file`` the figures of each sensor come from (``"{part}"`` for a datasheet).
    rates : dict
        ``file -> sample rate (Hz)`` of each Allan record.
    g_norm : float or None
        The magnitude of the accelerometer's mean over its record (m/s^2), when it reads gravity.
    sources : tuple of str
        The inputs, for the file's statement.
    """

    terms: dict = field(default_factory=dict)
    where: dict = field(default_factory=dict)
    rates: dict = field(default_factory=dict)
    g_norm: float | None = None
    sources: tuple = ()

    def figures(self) -> list[NoiseTerm]:
        """The figures there are."""
        return [t for t in self.terms.values() if isinstance(t, NoiseTerm)]


@dataclass(frozen=True)
class Exported:
    """An export: the file's text and the lines the terminal shows (each key, its value and conversion)."""

    text: str
    summary: tuple[str, ...] = ()


def _sensor(job: AllanAnalysis, where: str) -> str:
    """The sensor of an Allan result, refusing data that is neither a rate nor an acceleration."""
    dim = parse_unit(job.units).dim
    if dim == parse_unit("rad/s").dim:
        return "gyroscope"
    if dim == parse_unit("m/s^2").dim:
        return "accelerometer"
    raise InputError(f"holds an Allan result of data in {literal(job.units)}, neither a rate nor an acceleration: "
                     "noise figures for a navigation filter come from gyroscope and accelerometer records", where)


def _mean_norm(job: AllanAnalysis) -> float | None:
    """|mean| of a three-axis record (SI), or None."""
    means = [fig.get("bias") for fig in job.figures]
    if len(means) != 3 or not all(m is not None and np.isfinite(m) for m in means):
        return None
    return float(np.linalg.norm(np.asarray(means, dtype=float)))


def _allan_terms(job: AllanAnalysis, sensor: str, where: str) -> dict:
    """The white noise and random walk of one Allan result: the largest over its channels (module docstring)."""
    name = Path(where).name
    out: dict = {}
    for k, term in _TERM.items():
        vals, bounded, none = [], [], []
        for ch, f in zip(job.result.names, job.fits):
            if f.identifiable[k] and np.isfinite(f.params[k]) and f.params[k] > 0:
                vals.append((float(f.params[k]), False, ch))
            elif np.isfinite(f.upper[k]) and f.upper[k] > 0:
                vals.append((float(f.upper[k]), True, ch))
                bounded.append(ch)
            else:
                none.append(ch)
        if none or not vals:
            out[(sensor, term)] = (f"the {sensor} {_WORD[term]} of {', '.join(none) or 'every channel'} is neither "
                                   f"identified nor bounded by the fit in {literal(name)}; record longer, or give that term "
                                   "another way")
            continue
        value, is_bound, ch = max(vals)
        if is_bound:
            how = (f"from {name}: the record does not identify it ({', '.join(bounded)}; the fit gives 0 there); "
                   f"the largest over the axes, {ch}")
        else:
            how = f"from {name}: fitted, the largest over the axes ({ch})" + (
                f"; a 95 % upper bound stands in for {', '.join(bounded)}, not identified" if bounded else "")
        out[(sensor, term)] = NoiseTerm(sensor, term, value, "upper bound" if is_bound else "fitted", how)
    return out


def _part_terms(part: Part, floor_tau: float | None) -> dict:
    """The gyroscope figures of a datasheet: N, and K bounded from B at ``floor_tau`` (module docstring)."""
    out: dict = {}
    pname = literal(part.name)
    got = [(part.si(n, "angle_random_walk"), n) for n in ("arw", "noise_density") if getattr(part, n) is not None]
    if got:
        value, name = max((v, n) for v, n in got if v is not None)
        fig = getattr(part, name)
        out[("gyroscope", "white")] = NoiseTerm(
            "gyroscope", "white", value, "datasheet", f"datasheet of {part.name}: {name} = {fig.value} ({fig.source}"
            + ("" if fig.confirmed else "; not confirmed") + ")" + ("; the larger of arw and noise_density"
                                                                    if len(got) > 1 else ""))
    else:
        out[("gyroscope", "white")] = f"the datasheet of {pname} gives no gyroscope noise (arw or noise_density)"
    b = part.bias_instability
    if b is None:
        out[("gyroscope", "random_walk")] = (f"the datasheet of {pname} gives no bias instability to bound the "
                                             "gyroscope random walk K from; give a gyroscope Allan result")
    elif floor_tau is None:
        out[("gyroscope", "random_walk")] = (
            f"the datasheet of {pname} gives the bias instability B = {literal(b.value)}, not a random walk K; give the "
            "averaging time of its Allan-curve floor ({floor_tau}) for the bound K <= B sqrt(3/tau), or a "
            "gyroscope Allan result")
    else:
        bsi = part.si("bias_instability", "angular_rate") or 0.0
        out[("gyroscope", "random_walk")] = NoiseTerm(
            "gyroscope", "random_walk", bsi * math.sqrt(3.0 / floor_tau), "datasheet bound",
            f"bound from the datasheet of {part.name}: B = {b.value} ({b.source}) at the floor's tau = "
            f"{floor_tau:g} s, K <= B sqrt(3/tau)")
    return out


def gather(allan: list[tuple[AllanAnalysis, str]], part: Part | None = None, floor_tau: float | None = None) -> Figures:
    """The figures of Allan results (at most one per sensor) and of a part's datasheet (the gyroscope's).

    Raises
    ------
    InputError
        A second result of one sensor, a gyroscope given both ways, an Allan result of data neither a rate nor an
        acceleration, or an accelerometer record in g read as m/s^2 (its mean ``|a|`` is 1 at rest).
    """
    terms: dict = {}
    where: dict = {}
    rates: dict = {}
    g_norm = None
    for job, w in allan:
        sensor = _sensor(job, w)
        if sensor in where:
            raise InputError(f"a second {sensor} Allan result (the first: {literal(where[sensor])}); give one per "
                             "sensor", w)
        where[sensor] = w
        rates[w] = float(job.result.fs)
        terms.update(_allan_terms(job, sensor, w))
        norm = _mean_norm(job) if sensor == "accelerometer" else None
        if norm is not None and 0.9 < norm < 1.1:
            raise InputError(f"the accelerometer's mean |a| is {norm:.3f} m/s^2 over the record: it reads g, not "
                             "m/s^2, and every noise figure would be 9.8 x too small; run allan again with the "
                             "accelerometer's unit", w)
        if norm is not None and 0.9 * STANDARD_GRAVITY < norm < 1.1 * STANDARD_GRAVITY:
            g_norm = norm
    if part is not None:
        if "gyroscope" in where:
            raise InputError(f"both the gyroscope Allan result {literal(where['gyroscope'])} and the datasheet of "
                             f"{literal(part.name)} "
                             "give the gyroscope's figures; give one", "{part}")
        where["gyroscope"] = "{part}"
        terms.update(_part_terms(part, floor_tau))
    sources = tuple(Path(w).name for _, w in allan) + ((f"datasheet of {part.name}",) if part is not None else ())
    return Figures(terms, where, rates, g_norm, sources)


def consumer_rate(consumer: Consumer, figs: Figures, rate_hz: float | None, first: str) -> tuple[float | None, str]:
    """The rate ``f`` of the conversion (and of ``update_rate``), and how it was chosen."""
    recorded = sorted(set(figs.rates.values()))
    if consumer.rate == "filter":
        if rate_hz is not None:
            return rate_hz, "the filter's prediction rate as given"
        return consumer.default_rate_hz, f"the filter's prediction rate, its default ({consumer.rate_source}); give yours"
    if rate_hz is not None:
        other = [r for r in recorded if not math.isclose(r, rate_hz, rel_tol=1e-9)]
        return rate_hz, "the IMU's rate as given" + (
            f" (the Allan record was at {', '.join(f'{r:g}' for r in other)} Hz: the densities hold at another rate "
            "only if the IMU low-pass filters before it decimates, Kalibr wiki)" if other else "")
    if len(recorded) > 1:
        raise InputError(f"the Allan results were sampled at different rates ({', '.join(f'{r:g}' for r in recorded)} "
                         f"Hz); {consumer.title} take one IMU rate: give it ({{rate_hz}})", first)
    if not recorded:
        return None, ""
    return recorded[0], "the Allan record's sample rate (the IMU's rate)"


def select(consumer: Consumer, figs: Figures, first: str) -> tuple[list[NoiseTerm], list[str]]:
    """The figures the consumer gets, and its keys left out (a parameter file may set some of its keys).

    Raises
    ------
    InputError
        A term of a sensor given that has neither a value nor a bound (naming it), a sensor a YAML consumer needs
        that no input gives, or nothing at all to write.
    """
    got, missing = [], []
    for key in consumer.keys:
        t = figs.terms.get((key.sensor, key.term))
        if isinstance(t, str):
            raise InputError(f"{t}; {key.name} is not exported as 0", figs.where.get(key.sensor, first))
        if t is None:
            if consumer.complete:
                raise InputError(f"no input gives the {key.sensor}'s figures ({key.name}, ...), and "
                                 f"{consumer.title.split()[0]} reads every key of its file; give an Allan result of "
                                 f"the {key.sensor} together with this one", first)
            missing.append(key.name)
        else:
            got.append(t)
    if not got:
        raise InputError(f"gives no noise figure for the {consumer.title}; give an Allan result of the gyroscope or "
                         "the accelerometer", first)
    return got, missing


def noise_summary(items: list[Entry], rate_hz: float | None, inflate: float, missing: list[str]) -> tuple[str, ...]:
    """The terminal's lines: each key = value (unit) = conversion, upper bounds marked, and the remarks."""
    out = [f"  {e.key.name} = {e.value:.6g} {e.key.unit}  ({e.conversion}"
           + {"upper bound": "; 95 % UPPER BOUND: not identified", "datasheet": "; datasheet",
              "datasheet bound": "; UPPER BOUND from the datasheet"}.get(e.figure.basis, "; fitted") + ")"
           + (f"  [{e.remark}]" if e.remark else "") for e in items]
    out.append(f"  inflation x{inflate:g}" + ("" if rate_hz is None else f"; f = {rate_hz:g} Hz")
               + ("; not written: " + ", ".join(missing) if missing else ""))
    return tuple(out)


def _matrix(name: str, m: np.ndarray) -> list[str]:
    return [f"  {name}:"] + ["    - [" + ", ".join(f"{v:.1f}" for v in row) + "]" for row in m]


def noise_export(figs: Figures, to: str, first: str, rostopic: str = "/imu0", inflate: float = 1.0,
                 rate_hz: float | None = None) -> Exported:
    """The file of one noise consumer (OpenVINS, VINS-Fusion, PX4, ArduPilot) from the figures.

    Parameters
    ----------
    figs : Figures
        :func:`gather`'s.
    to : {"openvins", "vins", "px4", "ardupilot"}
    first : str
        The first input's file, for messages.
    rostopic : str
        OpenVINS's ``rostopic``.
    inflate : float
        >= 1; every value is multiplied by it.
    rate_hz : float, optional
        The consumer's rate (the IMU's for OpenVINS and VINS-Fusion, the filter's for the autopilots); default: the
        Allan record's, or the filter's documented default.
    """
    consumer = CONSUMERS[to]
    got, missing = select(consumer, figs, first)
    f, how = consumer_rate(consumer, figs, rate_hz, first)
    items = entries(consumer, got, inflate, f)
    header = header_lines(consumer, ", ".join(figs.sources), inflate, f, how, missing)
    if to == "openvins":
        if f is None:
            raise InputError("OpenVINS's update_rate is the IMU's rate and no Allan record gives it; give it "
                             "({rate_hz})", first)
        eye = np.eye(3)
        extra = (["  # T_i_b, Tw, R_IMUtoGYRO, Ta, R_IMUtoACC identity and Tg zero: no intrinsics (OpenVINS requires "
                  "the keys); replace them with yours"]
                 + ["  T_i_b:"] + ["    - [" + ", ".join(f"{v:.1f}" for v in row) + "]" for row in np.eye(4)]
                 + _matrix("Tw", eye) + _matrix("R_IMUtoGYRO", eye) + _matrix("Ta", eye) + _matrix("R_IMUtoACC", eye)
                 + _matrix("Tg", np.zeros((3, 3))))
        scalars = [("rostopic", rostopic, ""), ("time_offset", 0.0, "s, camera-IMU offset: yours"),
                   ("update_rate", float(f), "Hz, " + how), ("model", "kalibr", "calibrated intrinsics model")]
        text = noise_yaml(header, items, scalars, nest="imu0", directive=True, extra=extra)
    elif to == "vins":
        scalars = []
        if figs.g_norm is not None:
            scalars.append(("g_norm", figs.g_norm, "m/s^2, the magnitude of the accelerometer's mean over its rest "
                            "record: its own reading of gravity (local gravity is 9.78-9.83 m/s^2)"))
        else:
            header.append("g_norm not written: no three-axis accelerometer record reading gravity (keep your config's)")
        header.insert(1, "a fragment: paste these keys into your VINS-Fusion config (an OpenCV YAML file)")
        text = noise_yaml(header, items, scalars)
    else:
        text = params_text(consumer, header, items)
    return Exported(text, noise_summary(items, f, inflate, missing))
