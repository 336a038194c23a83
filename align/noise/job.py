"""The Allan job: logs -> Allan deviation, fits, noise figures, plan; its JSON form and plot.

Public names
------------
AllanJob, run_allan, term_units, allan_plot_png
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from align.noise.allan import AllanResult, allan
from align.noise.fit import TERMS, fit_noise, model_adev
from align.units import parse_unit, to_unit

#: display units of the five terms for gyros and accelerometers
_GYRO = ("deg", "deg/sqrt(h)", "deg/h", "deg/h/sqrt(h)", "deg/h^2")
_ACCEL = ("m/s", "m/s/sqrt(h)", "ug", "ug/sqrt(h)", "ug/h")


def term_units(units: str) -> tuple[str, ...]:
    """Engineering units of Q, N, B, K, R for data in ``units`` (a rate or an acceleration)."""
    u = parse_unit(units)
    return _GYRO if u.dim == parse_unit("rad/s").dim else _ACCEL


@dataclass(frozen=True)
class AllanJob:
    """Result of :func:`run_allan` (SI inside; ``units`` is the input unit)."""

    result: AllanResult
    fits: tuple
    figures: tuple
    repeatability: np.ndarray | None
    units: str
    runs: int
    inputs: list = field(default_factory=list)

    def to_dict(self) -> dict:
        from align import __version__

        r, u = self.result, self.units
        tu = term_units(u)
        kind = "gyroscope" if tu is _GYRO else "accelerometer"
        d = {
            "format": "imu-align.allan", "version": 1, "generator": f"imu-align {__version__}",
            "units": {"tau": "s", "adev": u, "ci": "68.3 % (1 sigma) chi-square interval",
                      "terms": dict(zip(TERMS, tu)), "bias": u},
            "sensor": kind, "fs_hz": r.fs, "samples": r.n, "runs": self.runs,
            "tau": r.tau.tolist(),
            "adev": {n: to_unit(r.adev[j], u).tolist() for j, n in enumerate(r.names)},
            "ci_low": {n: to_unit(f.ci_low, u).tolist() for n, f in zip(r.names, self.fits)},
            "ci_high": {n: to_unit(f.ci_high, u).tolist() for n, f in zip(r.names, self.fits)},
            "fit": {},
            "figures": {},
            "inputs": self.inputs,
        }
        if r.mdev is not None:
            d["mdev"] = {n: [None if not np.isfinite(v) else v for v in to_unit(r.mdev[j], u).tolist()]
                         for j, n in enumerate(r.names)}
        for name, f, fig in zip(r.names, self.fits, self.figures):
            terms = {}
            for k, t in enumerate(TERMS):
                val, sig = _term(f.params[k], k, u, tu), _term(f.sigma[k], k, u, tu)
                terms[t] = {"value": val, "sigma": sig, "unit": tu[k], "identifiable": bool(f.identifiable[k])}
            si = f.params
            d["fit"][name] = {
                "method": "weighted non-negative least squares on the Allan variance (IEEE 952 five-term model)",
                "terms": terms, "notes": list(f.notes),
                "ieee_point_readouts": {
                    "N_at_tau_1s": _term(f.readouts["N_tau1"], 1, u, tu), "N_unit": tu[1],
                    "B_floor_over_0.664": _term(f.readouts["B_floor"], 2, u, tu), "B_unit": tu[2],
                    "K_at_tau_3s": _term(f.readouts["K_tau3"], 3, u, tu), "K_unit": tu[3],
                },
                "continuous": {  # Kalibr-style densities, SI
                    f"{'gyroscope' if kind == 'gyroscope' else 'accelerometer'}_noise_density": float(si[1]),
                    f"{'gyroscope' if kind == 'gyroscope' else 'accelerometer'}_random_walk": float(si[3]),
                    "units": "rad/s/sqrt(Hz), rad/s^2/sqrt(Hz)" if kind == "gyroscope" else "m/s^2/sqrt(Hz), m/s^3/sqrt(Hz)",
                },
            }
            d["figures"][name] = {"bias": to_unit(fig["bias"], u),
                                  "bias_stability": {f"{p:g} s": to_unit(v, u) for p, v in fig["stability"].items()},
                                  "method": "seed 002 Eq 5-8: mean of each run; std (ddof 1) of consecutive P-second means, averaged over runs"}
        d["adev_of"] = self.inputs[0] if self.inputs else "first run"
        if self.repeatability is not None:
            d["repeatability"] = {n: to_unit(v, u) for n, v in zip(r.names, self.repeatability)}
        return d


def _term(value: float, k: int, units: str, tu) -> float | None:
    """An SI term value in its engineering unit (scaled by the input unit's kind)."""
    if not np.isfinite(value):
        return None
    return float(to_unit(value, tu[k]))


def run_allan(runs: list, fs: float, names: list[str], units: str, grid="dense", per_decade: int = 10,
              modified: bool = False, periods=(1.0, 10.0), progress=None, memory_limit: float = 2e9) -> AllanJob:
    """Allan deviation and fit of the first run, noise figures of every run, the repeatability.

    ``runs`` are raw arrays (n, C) or chunk sources in ``units``; everything is
    computed on the raw numbers and scaled afterwards (deviations, means and
    stabilities are linear in the unit), so no SI copy of a large record is made.
    """
    factor = parse_unit(units).factor
    # the deviations of the first run; of the others only the bias figures (no kernel pass)
    results = [allan(r, fs, names, grid, per_decade, modified, memory_limit, progress=progress if k == 0 else None,
                     periods=periods, deviations=k == 0).scaled(factor) for k, r in enumerate(runs)]
    res = results[0]
    fits = tuple(fit_noise(res, j) for j in range(len(names)))
    figures = tuple({"bias": float(np.mean([r.bias[j] for r in results])),
                     "stability": {p: float(np.mean([r.stability[p][j] for r in results])) for p in periods}}
                    for j in range(len(names)))
    rep = np.std([r.bias for r in results], axis=0, ddof=1) if len(results) > 1 else None
    return AllanJob(res, fits, figures, rep, units, len(runs))


def allan_plot_png(job: AllanJob, target: float | None = None, chosen_tau: float | None = None) -> bytes:
    """Log-log Allan deviation with its confidence band, the fitted terms, and the planning target."""
    import io

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    r, u = job.result, job.units
    tu = term_units(u)
    shown = "deg/h" if tu is _GYRO else "ug"
    fig, ax = plt.subplots(figsize=(7.5, 5))
    colours = ("tab:red", "tab:green", "tab:blue", "tab:purple", "tab:orange", "tab:brown")
    for j, (name, f) in enumerate(zip(r.names, job.fits)):
        c = colours[j % len(colours)]
        ax.loglog(r.tau, to_unit(r.adev[j], shown), color=c, lw=1.5, label=name)
        ax.fill_between(r.tau, to_unit(f.ci_low, shown), to_unit(f.ci_high, shown), color=c, alpha=0.2, lw=0)
        ax.loglog(r.tau, to_unit(model_adev(r.tau, f.params), shown), color=c, lw=0.8, ls="--")
    f0 = job.fits[0]
    for k, (t, style) in enumerate(zip(TERMS, (":", "-.", ":", "-.", ":"))):
        if f0.params[k] > 0:
            p = np.zeros(5)
            p[k] = f0.params[k]
            ax.loglog(r.tau, to_unit(model_adev(r.tau, p), shown), color="0.5", lw=0.8, ls=style)
            ax.text(r.tau[-1], float(to_unit(model_adev(r.tau[-1:], p)[0], shown)), f" {t}", fontsize=7, color="0.4")
    if target is not None:
        ax.axhline(float(to_unit(target, shown)), color="k", lw=1, ls="--", label=f"noise target {float(to_unit(target, shown)):.4g} {shown}")
    if chosen_tau is not None:
        ax.axvline(chosen_tau, color="k", lw=1, ls=":", label=f"averaging time {chosen_tau:.4g} s")
    ax.set_xlabel("averaging time tau [s]")
    ax.set_ylabel(f"Allan deviation [{shown}]")
    ax.set_title(f"Overlapping Allan deviation, {r.n:,} samples at {r.fs:g} Hz (band: 68 % CI; dashed: fit)", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()
