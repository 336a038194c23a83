"""The JSON form of an Allan analysis's curves and fits (engineering units, the vocabulary of :data:`TERM_TABLE`).

A curve (one run, or the pooled curve of several) is written as its deviations,
68.3 % intervals and one fit per channel; a fit as its five terms named as
engineers name them (``quantization``, ``angle_random_walk``, ``bias_instability``,
``rate_random_walk``, ``rate_ramp``; ``velocity_random_walk``,
``acceleration_random_walk``, ``acceleration_ramp`` for an accelerometer), each with
its IEEE letter. A term's ``value`` is set only when the term is identifiable;
otherwise ``upper_bound`` (when the fit gives one) and the record that would identify
it. Files of version 1 (internal names ``white``, ``flicker``, ...) read too.

Public names
------------
term_units, fit_extras, fit_dict, read_fit, curve_dict, read_curve, run_figures, note_out, note_in, figures_dict,
read_figures, periods_of, term_value, si_value, GYRO, ACCEL, READOUTS
"""

from __future__ import annotations

import dataclasses
import re
from typing import Any

import numpy as np

from align.noise.allan import AllanResult, edf_overlapping
from align.noise.fit import NoiseFit
from align.noise.model import NOISE_ALPHA, TERM_TABLE, TERMS, avar_design, term
from align.units import parse_unit, to_unit

#: display units of the five terms for gyros and accelerometers (from :data:`TERM_TABLE`)
GYRO = tuple(t.unit("gyroscope") for t in TERM_TABLE)
ACCEL = tuple(t.unit("accelerometer") for t in TERM_TABLE)
FIT_METHOD = "weighted non-negative least squares on the Allan variance (IEEE 952 five-term model)"
#: the IEEE point readouts: key in NoiseFit.readouts -> (JSON key, JSON unit key, term index)
READOUTS = {"N_tau1": ("N_at_tau_1s", "N_unit", 1), "B_floor": ("B_floor_over_0.664", "B_unit", 2),
            "K_tau3": ("K_at_tau_3s", "K_unit", 3)}
#: every readout key a fit may carry (the value, its 68.3 % bounds, the tau of the floor)
_READOUT_KEYS = tuple(k + s for k in READOUTS for s in ("", "_lo", "_hi")) + ("B_floor_tau",)
#: the NoiseFit fields this module writes by name; any other field is written as-is under ``more`` (SI)
_KNOWN = ("params", "sigma", "identifiable", "notes", "dominant", "edf", "ci_low", "ci_high", "readouts", "method",
          "upper", "needed")
#: names under which the fit may carry the upper bounds (SI, shape (5,)) and the record that identifies a term (s)
_UPPER = ("upper", "upper_bound", "upper_bounds")
_RECORD = ("needed", "record_needed", "needed_record")


def term_units(units: str) -> tuple[str, ...]:
    """Engineering units of Q, N, B, K, R for data in ``units`` (a rate or an acceleration)."""
    return GYRO if parse_unit(units).dim == parse_unit("rad/s").dim else ACCEL


def term_value(value: float, unit: str) -> float | None:
    """An SI term value in its engineering unit (None when not finite)."""
    return float(to_unit(value, unit)) if np.isfinite(value) else None


def si_value(value: float | None, factor: float) -> float:
    """A value read from a file, in SI (None is NaN)."""
    return float("nan") if value is None else float(value) * factor


def _per_term(value: Any) -> np.ndarray:
    """A per-term quantity (array of 5, or dict by internal key) as an array of 5 (NaN where absent)."""
    if value is None:
        return np.full(5, np.nan)
    if isinstance(value, dict):
        return np.array([float(value.get(k, np.nan)) if value.get(k) is not None else np.nan for k in TERMS])
    return np.asarray(value, dtype=float).reshape(5)


def fit_extras(f: NoiseFit) -> tuple[np.ndarray, np.ndarray]:
    """The upper bound of each term (SI, NaN where none) and what would identify it (record length, s;
    sample rate, Hz, for Q and N).

    Read from the fit when it carries them; NaN otherwise (an older fit: no bound is stated).
    """
    upper = next((getattr(f, n) for n in _UPPER if getattr(f, n, None) is not None), None)
    record = next((getattr(f, n) for n in _RECORD if getattr(f, n, None) is not None), None)
    return _per_term(upper), _per_term(record)


def _readout_name(key: str) -> tuple[str, str, int | None]:
    """The JSON name of a readout key, its unit key, and the term whose unit it has (None: seconds).

    ``N_tau1`` -> ``N_at_tau_1s`` (``N_unit``); the 68.3 % bounds ``N_tau1_lo``/``_hi`` -> ``N_at_tau_1s_low``/
    ``_high``; ``B_floor_tau`` -> ``B_floor_tau_s``.
    """
    for base, (name, unit_key, k) in READOUTS.items():
        if key == base:
            return name, unit_key, k
        if key == base + "_lo":
            return name + "_low", unit_key, k
        if key == base + "_hi":
            return name + "_high", unit_key, k
    if key.endswith("_tau"):
        return key + "_s", "", None
    return key, "", None


#: a note on one term as the fit writes it ("random_walk (K): ...") and as a file holds it ("K (rate random walk): ...")
_NOTE_IN = re.compile(r"^(quantization|white|flicker|random_walk|ramp) \(([QNBKR])\): ")
_NOTE_OUT = re.compile(r"^([QNBKR]) \(([a-z ]+)\): ")


def note_out(note: str, sensor: str) -> str:
    """A fit's note with its term named as in :data:`TERM_TABLE` (``K (rate random walk): ...``)."""
    return _NOTE_IN.sub(lambda mt: f"{term(mt.group(1)).label(sensor)}: ", note)


def note_in(note: str) -> str:
    """The inverse of :func:`note_out` (the fit's own wording)."""
    return _NOTE_OUT.sub(lambda mt: f"{term(mt.group(1)).key} ({mt.group(1)}): ", note)


def _plain(v: Any) -> Any:
    """A field value as JSON (arrays as lists with null for NaN; dicts and tuples element-wise)."""
    if isinstance(v, np.ndarray):
        return _plain(v.tolist())
    if isinstance(v, dict):
        return {str(k): _plain(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_plain(x) for x in v]
    if isinstance(v, (float, np.floating)):
        return None if not np.isfinite(v) else float(v)
    return v.item() if isinstance(v, np.generic) else v


def _unplain(v: Any) -> Any:
    """The inverse of :func:`_plain`: lists of numbers (nested too) become float arrays, null NaN."""
    if isinstance(v, list):
        try:
            return np.array(_nan(v), dtype=float)
        except (TypeError, ValueError):
            return tuple(v)
    if isinstance(v, dict):
        return {k: _unplain(x) for k, x in v.items()}
    return np.nan if v is None else v


def _nan(v: Any) -> Any:
    return [_nan(x) for x in v] if isinstance(v, list) else (np.nan if v is None else v)


def _needed(key: str, value: float | None) -> dict[str, float | None]:
    """What would identify a term: the sample rate (Hz) for Q and N, the record length (h) for the others."""
    if key in ("quantization", "white"):
        return {"sample_rate_to_identify_hz": value}
    return {"record_to_identify_h": None if value is None else value / 3600}


def _continuous(f: NoiseFit, upper: np.ndarray, sensor: str) -> dict[str, Any]:
    """Kalibr-style densities, SI: the fitted N and K or, where the record does not identify one, its 95 % upper
    bound (the number the Kalibr export writes), with ``<key>_is`` saying which."""
    out: dict[str, Any] = {}
    for k, key in ((1, "noise_density"), (3, "random_walk")):
        name = f"{sensor}_{key}"
        if f.identifiable[k]:
            out[name], out[f"{name}_is"] = float(f.params[k]), "fitted"
        elif np.isfinite(upper[k]):
            out[name], out[f"{name}_is"] = float(upper[k]), ("95 % upper bound: the record does not identify it "
                                                             "(the fit gives 0)")
        else:
            out[name], out[f"{name}_is"] = None, "not identified; no bound stated"
    out["units"] = "rad/s/sqrt(Hz), rad/s^2/sqrt(Hz)" if sensor == "gyroscope" else "m/s^2/sqrt(Hz), m/s^3/sqrt(Hz)"
    return out


def fit_dict(f: NoiseFit, tu: tuple[str, ...], sensor: str) -> dict[str, Any]:
    """One channel's fit in engineering units, terms named as in :data:`TERM_TABLE`."""
    upper, record = fit_extras(f)
    terms = {}
    for k, t in enumerate(TERM_TABLE):
        ok = bool(f.identifiable[k])
        terms[t.json_key(sensor)] = {
            "symbol": t.symbol, "name": t.name(sensor), "unit": tu[k], "identifiable": ok,
            "value": term_value(f.params[k], tu[k]) if ok else None,
            "sigma": term_value(f.sigma[k], tu[k]) if ok else None,
            "upper_bound": None if ok else term_value(upper[k], tu[k]),
            **_needed(t.key, None if ok or not np.isfinite(record[k]) else float(record[k])),
            "estimate": term_value(f.params[k], tu[k]), "estimate_sigma": term_value(f.sigma[k], tu[k])}
    readouts: dict[str, Any] = {}
    for key, v in f.readouts.items():
        name, unit_key, of = _readout_name(key)
        readouts[name] = term_value(v, tu[of]) if of is not None else (None if not np.isfinite(v) else float(v))
        if unit_key and of is not None:  # a unit key comes with its term (READOUTS)
            readouts[unit_key] = tu[of]
    d = {"method": getattr(f, "method", FIT_METHOD), "terms": terms, "notes": [note_out(n, sensor) for n in f.notes],
         "ieee_point_readouts": readouts,
         "continuous": _continuous(f, upper, sensor),
         "dominant": [term(k).json_key(sensor) for k in f.dominant], "edf": f.edf.tolist()}
    more = {fl.name: _plain(getattr(f, fl.name)) for fl in dataclasses.fields(f) if fl.name not in _KNOWN}
    if more:
        d["more_si"] = more
    return d


def read_fit(fd: dict[str, Any], tu: tuple[str, ...], result: AllanResult, ci_low: np.ndarray,
             ci_high: np.ndarray, channel: int = 0) -> NoiseFit:
    """A :class:`NoiseFit` from :func:`fit_dict` (or version 1); ``dominant`` and ``edf`` rebuilt when absent."""
    factors = [parse_unit(t).factor for t in tu]
    by_key = {term(name).key: t for name, t in fd["terms"].items()}
    terms = [by_key[k] for k in TERMS]
    params = np.array([si_value(t.get("estimate", t["value"]), k) for t, k in zip(terms, factors)])
    sigma = np.array([si_value(t.get("estimate_sigma", t["sigma"]), k) for t, k in zip(terms, factors)])
    got = fd["ieee_point_readouts"]
    readouts = {key: si_value(got[READOUTS[key][0]], factors[READOUTS[key][2]]) for key in READOUTS}
    for key in _READOUT_KEYS:
        name, _, k = _readout_name(key)
        if name in got:
            readouts[key] = si_value(got[name], 1.0 if k is None else factors[k])
    if "dominant" in fd:
        dominant = tuple(term(k).key for k in fd["dominant"])
    else:
        dominant = tuple(TERMS[int(k)] for k in np.argmax(avar_design(result.tau) * params**2, axis=1))
    if "edf" in fd:
        edf = np.array(fd["edf"], dtype=float)
    else:
        edf = edf_overlapping(result.n_phase, result.m, np.array([NOISE_ALPHA[t] for t in dominant]))
    kw: dict[str, Any] = dict(params=params, sigma=sigma, identifiable=tuple(bool(t["identifiable"]) for t in terms),
              notes=tuple(note_in(n) for n in fd.get("notes", ())), dominant=dominant, edf=edf, ci_low=ci_low, ci_high=ci_high,
              readouts=readouts)
    fields = {fl.name for fl in dataclasses.fields(NoiseFit)}
    if "method" in fields and "method" in fd:
        kw["method"] = fd["method"]
    if "upper" in fields:
        kw["upper"] = np.array([si_value(t.get("upper_bound"), k) for t, k in zip(terms, factors)])
    if "needed" in fields:
        kw["needed"] = np.array([_needed_in(t) for t in terms])
    kw.update({name: _unplain(v) for name, v in fd.get("more_si", {}).items() if name in fields})
    return NoiseFit(**kw)


def _needed_in(t: dict[str, Any]) -> float:
    """The inverse of :func:`_needed`: Hz, or s (NaN when none)."""
    if t.get("sample_rate_to_identify_hz") is not None:
        return float(t["sample_rate_to_identify_hz"])
    return float("nan") if t.get("record_to_identify_h") is None else float(t["record_to_identify_h"]) * 3600


def figures_dict(bias: float, stability: dict, units: str) -> dict[str, Any]:
    """Bias and bias stability (seed 002 Eq 5-8) in ``units``."""
    return {"bias": to_unit(bias, units),
            "bias_stability": {f"{p:g} s": to_unit(v, units) for p, v in stability.items()}}


def periods_of(d: dict[str, Any], names: tuple[str, ...]) -> list[float]:
    """Averaging periods of the bias stability, s: ``periods_s``, else read off the keys ("10 s")."""
    if "periods_s" in d:
        return [float(p) for p in d["periods_s"]]
    return [float(k.split()[0]) for k in d["figures"][names[0]]["bias_stability"]] if names else []


def read_figures(fig: dict[str, Any], periods: list[float], factor: float) -> dict[str, Any]:
    """The inverse of :func:`figures_dict`, SI."""
    values = list(fig["bias_stability"].values())
    if len(values) != len(periods):
        raise ValueError(f"{len(values)} bias stabilities for {len(periods)} periods")
    return {"bias": si_value(fig["bias"], factor), "stability": {p: si_value(v, factor) for p, v in zip(periods, values)}}


def _nulls(values: np.ndarray) -> list:
    return [None if not np.isfinite(v) else float(v) for v in values]


def run_figures(r: AllanResult, u: str) -> dict[str, Any]:
    """Bias and bias stability of each channel of one run, in ``u``."""
    assert r.bias is not None, "a run's figures need its bias"
    return {n: figures_dict(r.bias[j], {p: v[j] for p, v in (r.stability or {}).items()}, u)
            for j, n in enumerate(r.names)}


def curve_dict(r: AllanResult, fits, u: str, tu: tuple[str, ...], sensor: str) -> dict[str, Any]:
    """Deviations, intervals and fits of one curve (a run, or the pooled one) in ``u``."""
    d = {"adev": {n: to_unit(r.adev[j], u).tolist() for j, n in enumerate(r.names)},
         "ci_low": {n: to_unit(f.ci_low, u).tolist() for n, f in zip(r.names, fits)},
         "ci_high": {n: to_unit(f.ci_high, u).tolist() for n, f in zip(r.names, fits)},
         "fit": {n: fit_dict(f, tu, sensor) for n, f in zip(r.names, fits)}}
    if r.mdev is not None:
        d["mdev"] = {n: _nulls(to_unit(r.mdev[j], u)) for j, n in enumerate(r.names)}
    alpha = getattr(r, "alpha", None)
    if alpha is not None:
        d["noise_type_alpha"] = {n: np.asarray(alpha[j]).astype(int).tolist() for j, n in enumerate(r.names)}
    for key in ("edf", "edf_mdev"):
        edf = getattr(r, key, None)
        if edf is not None:
            d[key] = {n: _nulls(np.asarray(edf[j], dtype=float)) for j, n in enumerate(r.names)}
    return d


def read_curve(d: dict[str, Any], tau, m, n: int, fs: float, names, f: float, tu, run, periods):
    """An AllanResult and its fits from :func:`_curve_dict` (``run``: its bias figures, or None)."""
    adev = np.array([d["adev"][k] for k in names], dtype=float) * f
    mdev = np.array([[np.nan if v is None else v for v in d["mdev"][k]] for k in names], dtype=float) * f \
        if "mdev" in d else None
    bias = stability = None
    if run is not None:
        own = [read_figures(run[k], periods, f) for k in names]
        bias = np.array([g["bias"] for g in own])
        stability = {p: np.array([g["stability"][p] for g in own]) for p in periods}
    extra: dict[str, Any] = {}
    fields = {fl.name for fl in dataclasses.fields(AllanResult)}
    if "alpha" in fields and "noise_type_alpha" in d:
        extra["alpha"] = np.array([d["noise_type_alpha"][k] for k in names], dtype=int)
    for key in ("edf", "edf_mdev"):
        if key in fields and key in d:
            extra[key] = np.array([[np.nan if v is None else v for v in d[key][k]] for k in names], dtype=float)
    result = AllanResult(tau, m, adev, mdev, n, fs, names, bias, stability, **extra)
    fits = tuple(read_fit(d["fit"][k], tu, result, np.array(d["ci_low"][k], dtype=float) * f,
                             np.array(d["ci_high"][k], dtype=float) * f, j) for j, k in enumerate(names))
    return result, fits
