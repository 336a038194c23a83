"""The drift result (``imu-align.drift``): attitude, velocity and position error growth over a mission.

Its file holds ``time_s`` and, for each of ``attitude_deg`` (``roll``, ``pitch``, ``heading``),
``velocity_m_s`` and ``position_m`` (``north``, ``east``, ``down``), the ``mean`` and ``sigma`` of
the Monte Carlo over time (the 1-sigma and 3-sigma envelopes are ``mean -/+ sigma`` and
``mean -/+ 3 sigma``) and, for a static mission, the ``closed_form_sigma`` of
:mod:`align.navigation.closed`; the down velocity and position also carry ``percentiles`` (of
:data:`align.navigation.montecarlo.PERCENTILES`, over the first runs: their second-order part is
one-signed, so mean -/+ 3 sigma is no 99.7 % bound there); the residual errors used and their sources, the mission, each
term's 1-sigma at the end, and which error dominates when (``dominant``, ``dominance``).

Public names
------------
DriftResult, FORMAT, GROUPS, FILE_KEYS
"""

from __future__ import annotations

from dataclasses import field
from typing import Any

import numpy as np

from align.errors import InputError
from align.navigation.montecarlo import PERCENTILES
from align.navigation.residuals import ResidualErrors
from align.results import Result
from align.units import DEG
from align.wellformed import malformed

FORMAT = "imu-align.drift"
CONVENTION = ("navigation frame north-east-down (local level, Earth-fixed, no transport rate); body to NED "
              "quaternion; error = solution with the residual errors minus the error-free solution; "
              "attitude error = computed minus true roll, pitch, heading; envelopes mean -/+ 1 sigma and "
              "mean -/+ 3 sigma over the Monte Carlo runs")
#: JSON group -> (components, the factor from SI to the file's unit)
GROUPS = {"attitude_deg": (("roll", "pitch", "heading"), 1.0 / DEG), "velocity_m_s": (("north", "east", "down"), 1.0),
          "position_m": (("north", "east", "down"), 1.0)}
#: the keys of a drift file after its envelope
FILE_KEYS = ("mission", "errors", "runs", "seed", "nav_rate_hz", "time_s", *GROUPS, "final", "term_sigma_final",
             "dominant", "dominance", "dominance_method", "method", "inputs", "notes")
METHOD = ("Monte Carlo through the strapdown integrator (align.navigation.strapdown N1-N6; error increments "
          "M1-M2 of align.navigation.montecarlo); closed forms of seed 002 Eq 4 for a static mission "
          "(align.navigation.closed E1-E4)")


def _columns(group: str) -> range:
    start = list(GROUPS).index(group) * 3
    return range(start, start + 3)


class DriftResult(Result, format=FORMAT, convention=CONVENTION):
    """What the residual errors cost over a mission (SI inside: rad, m/s, m).

    Attributes
    ----------
    mission : dict
        The mission's settings (:meth:`align.navigation.mission.Mission.to_dict`).
    errors : ResidualErrors
    t : ndarray, shape (P,)
        s.
    mean, sigma : ndarray, shape (P, 9)
        Monte Carlo mean and 1-sigma of the nine components (:data:`align.navigation.closed.QUANTITIES`).
    closed : ndarray, shape (P, 9), or None
        Closed-form 1-sigma (a static mission).
    term_final : dict
        Term label -> 1-sigma (9,) at the end that the term alone gives.
    dominant : tuple of dict
        ``{"quantity", "from_s", "to_s", "term", "share"}`` (:func:`align.navigation.closed.dominance`).
    dominance : str
        The same in words.
    dominance_method : str
    runs, seed : int
    nav_rate : float
        Hz.
    inputs : dict
    notes : tuple of str
    down_percentiles : ndarray, shape (len(PERCENTILES), P, 2), or None
        Percentiles of the down velocity (m/s) and position (m) over the first runs.
    """

    mission: dict
    errors: ResidualErrors
    t: np.ndarray
    mean: np.ndarray
    sigma: np.ndarray
    closed: np.ndarray | None
    term_final: dict
    dominant: tuple
    dominance: str
    dominance_method: str
    runs: int
    seed: int
    nav_rate: float
    inputs: dict = field(default_factory=dict)
    notes: tuple = ()
    down_percentiles: np.ndarray | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "dominant", tuple(dict(r) for r in self.dominant))
        object.__setattr__(self, "notes", tuple(self.notes))

    def component(self, group: str, name: str) -> tuple[np.ndarray, np.ndarray]:
        """Mean and 1-sigma (P,) of one component in the file's unit, e.g. ``("attitude_deg", "heading")``."""
        names, factor = GROUPS[group]
        col = _columns(group)[names.index(name)]
        return self.mean[:, col] * factor, self.sigma[:, col] * factor

    def to_dict(self) -> dict[str, Any]:
        """The versioned JSON form (module docstring)."""
        d: dict[str, Any] = {
            **self.envelope({"time_s": "s", "attitude_deg": "deg", "velocity_m_s": "m/s", "position_m": "m"}),
            "mission": dict(self.mission), "errors": self.errors.to_dict(), "runs": self.runs, "seed": self.seed,
            "nav_rate_hz": self.nav_rate, "time_s": self.t.tolist(),
        }
        final: dict[str, Any] = {}
        for group, (names, factor) in GROUPS.items():
            d[group], final[group] = {}, {}
            for name, col in zip(names, _columns(group)):
                entry = {"mean": (self.mean[:, col] * factor).tolist(), "sigma": (self.sigma[:, col] * factor).tolist()}
                if self.closed is not None:
                    entry["closed_form_sigma"] = (self.closed[:, col] * factor).tolist()
                final[group][name] = {"mean": float(self.mean[-1, col] * factor),
                                      "sigma": float(self.sigma[-1, col] * factor),
                                      "three_sigma": float(3 * self.sigma[-1, col] * factor)}
                if name == "down" and self.down_percentiles is not None:
                    pc = self.down_percentiles[:, :, 0 if group == "velocity_m_s" else 1]
                    entry["percentiles"] = {f"{p:g}": v.tolist() for p, v in zip(PERCENTILES, pc)}
                    final[group][name]["percentiles"] = {f"{p:g}": float(v[-1]) for p, v in zip(PERCENTILES, pc)}
                d[group][name] = entry
        d["final"] = final
        d["term_sigma_final"] = {
            term: {group: {name: float(v[col] * factor) for name, col in zip(names, _columns(group))}
                   for group, (names, factor) in GROUPS.items()}
            for term, v in self.term_final.items()}
        d["dominant"] = [dict(r) for r in self.dominant]
        d["dominance"] = self.dominance
        d["dominance_method"] = self.dominance_method
        d["method"] = METHOD
        d["inputs"] = dict(self.inputs)
        d["notes"] = list(self.notes)
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any], where: str = "result") -> DriftResult:
        """Read the form written by :meth:`to_dict`."""
        cls.check_envelope(d, where, keys=FILE_KEYS)
        try:
            t = np.array(d["time_s"], float)
            mean, sigma = np.zeros((len(t), 9)), np.zeros((len(t), 9))
            closed, pct = None, None
            for group, (names, factor) in GROUPS.items():
                for name, col in zip(names, _columns(group)):
                    entry = d[group][name]
                    mean[:, col] = np.array(entry["mean"], float) / factor
                    sigma[:, col] = np.array(entry["sigma"], float) / factor
                    if "closed_form_sigma" in entry:
                        closed = np.zeros((len(t), 9)) if closed is None else closed
                        closed[:, col] = np.array(entry["closed_form_sigma"], float) / factor
                    if name == "down" and "percentiles" in entry:
                        pct = np.zeros((len(PERCENTILES), len(t), 2)) if pct is None else pct
                        for k, p in enumerate(PERCENTILES):
                            pct[k, :, 0 if group == "velocity_m_s" else 1] = np.array(entry["percentiles"][f"{p:g}"])
            term_final = {}
            for term, groups in d.get("term_sigma_final", {}).items():
                v = np.zeros(9)
                for group, (names, factor) in GROUPS.items():
                    for name, col in zip(names, _columns(group)):
                        v[col] = float(groups[group][name]) / factor
                term_final[term] = v
            return cls(dict(d["mission"]), ResidualErrors.from_dict(d["errors"]), t, mean, sigma, closed, term_final,
                       tuple(d.get("dominant", ())), str(d.get("dominance", "")), str(d.get("dominance_method", "")),
                       int(d["runs"]), int(d["seed"]), float(d["nav_rate_hz"]), dict(d.get("inputs", {})),
                       tuple(d.get("notes", ())), pct)
        except (KeyError, TypeError, ValueError, AttributeError, IndexError) as exc:
            raise InputError(f"malformed {FORMAT} result ({malformed(exc)}); regenerate it", where) from None


