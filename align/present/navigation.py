"""What the residual errors cost in navigation, shown: the drift picture, the report section, the terminal summary.

:func:`drift_plot_png` draws a :class:`~align.navigation.result.DriftResult` as nine panels (roll,
pitch, heading; north, east, down velocity; north, east, down position) against time: the Monte
Carlo mean, its 1-sigma and 3-sigma envelopes and, for a static mission, the closed forms' +/- 1
sigma and 3 sigma. The down channels' second-order part (``g eps^2 / 2`` of a tilt error) is
one-signed: there the envelopes are the runs' percentiles (central 68.27 % and 99.73 %), not
mean +/- k sigma, so that no band shows values no run reaches. :func:`navigation_section` is the
report's section; :func:`drift_summary` the terminal's.

Public names
------------
drift_plot_png, navigation_section, drift_summary, experiment_png
"""

from __future__ import annotations

import numpy as np

from align.navigation.result import GROUPS
from align.present.figures import png_bytes, pyplot
from align.present.html import Section, esc, image, table

#: JSON group -> (title, unit, components)
_ROWS = (("attitude_deg", "attitude error", "deg", ("roll", "pitch", "heading")),
         ("velocity_m_s", "velocity error", "m/s", ("north", "east", "down")),
         ("position_m", "position error", "m", ("north", "east", "down")))


def _name(group: str, name: str) -> str:
    """``roll``, ``north velocity``: how a component is named in the picture and the tables."""
    return name if group == "attitude_deg" else f"{name} {group.split('_')[0]}"


def _time_axis(t: np.ndarray) -> tuple[float, str]:
    end = float(t[-1]) if len(t) else 0.0
    if end >= 3 * 3600:
        return 3600.0, "h"
    if end >= 180:
        return 60.0, "min"
    return 1.0, "s"


def drift_plot_png(result) -> bytes:
    """Nine panels of the error growth (module docstring), PNG bytes."""
    plt = pyplot()
    scale, tunit = _time_axis(result.t)
    x = result.t / scale
    fig, axes = plt.subplots(3, 3, figsize=(12, 8.4), sharex=True)
    for row, (group, title, unit, names) in enumerate(_ROWS):
        for col, name in enumerate(names):
            ax = axes[row, col]
            mean, sigma = result.component(group, name)
            pct = None
            if name == "down" and result.down_percentiles is not None:
                pct = result.down_percentiles[:, :, 0 if group == "velocity_m_s" else 1]
            if pct is None:
                ax.fill_between(x, mean - 3 * sigma, mean + 3 * sigma, color="tab:blue", alpha=0.15, lw=0,
                                label="mean +/- 3 sigma")
                ax.fill_between(x, mean - sigma, mean + sigma, color="tab:blue", alpha=0.35, lw=0,
                                label="mean +/- 1 sigma")
            else:  # one-signed second order: the runs' percentiles
                ax.fill_between(x, pct[0], pct[-1], color="tab:orange", alpha=0.2, lw=0, label="central 99.73 % of runs")
                ax.fill_between(x, pct[1], pct[-2], color="tab:orange", alpha=0.4, lw=0, label="central 68.27 % of runs")
            ax.plot(x, mean, color="tab:blue", lw=1.2, label="Monte Carlo mean")
            if result.closed is not None:
                cf = result.closed[:, row * 3 + col] * GROUPS[group][1]
                ax.plot(x, cf, "k--", lw=0.9, label="closed form +/- 1 sigma, 3 sigma")
                ax.plot(x, -cf, "k--", lw=0.9)
                ax.plot(x, 3 * cf, "k:", lw=0.9)
                ax.plot(x, -3 * cf, "k:", lw=0.9)
            ax.set_title(_name(group, name) + (" (percentiles of the runs)" if pct is not None else ""),
                         fontsize=10)
            if pct is not None and row == 2:
                ax.legend(handles=ax.get_legend_handles_labels()[0][:2], fontsize=7, loc="upper left")
            ax.grid(alpha=0.3)
            if col == 0:
                ax.set_ylabel(f"{title} ({unit})")
            if row == 2:
                ax.set_xlabel(f"time ({tunit})")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=9, frameon=False)
    mission = result.mission
    fig.suptitle(f"Navigation error growth: {mission.get('description', '')}; "
                 f"{result.runs:,} Monte Carlo runs", fontsize=11)
    fig.tight_layout(rect=(0, 0.04, 1, 0.97))
    return png_bytes(fig)


def _final_rows(result) -> list[list]:
    rows = []
    for group, _title, unit, names in _ROWS:
        for name in names:
            mean, sigma = result.component(group, name)
            rows.append([f"{_name(group, name)} ({unit})", f"{mean[-1]:.4g}", f"{sigma[-1]:.4g}",
                         f"{3 * sigma[-1]:.4g}"])
    return rows


def _error_rows(result) -> list[list]:
    rows = []
    for terms in result.errors.to_dict().values():
        for term in terms.values():
            if not any(v > 0 for v in np.ravel(term["value"])):
                continue
            v = np.asarray(term["value"], float)
            shown = ", ".join(f"{a:.4g}" for a in (np.sqrt((v**2).sum(axis=1)) if v.ndim == 2 else v))
            what = f"{term['label']} ({'row RSS of ' if v.ndim == 2 else ''}x, y, z)"
            rows.append([what, shown, term["unit"], term["source"] or ""])
    return rows


def navigation_section(result, png: bytes | None) -> Section:
    """The report's section: the residual errors, the errors at the end, which dominates when, the picture."""
    m = result.mission
    t_end = float(result.t[-1]) if len(result.t) else 0.0
    body = [f"<p>Mission: {esc(m.get('kind', ''))}, {esc(m.get('description', ''))}, {t_end:g} s; navigation at "
            f"{result.nav_rate:g} Hz from {m.get('rate_hz', 0):g} Hz samples; latitude {m.get('latitude_deg', 0):g} deg, "
            f"Earth rate {'included' if m.get('earth_rate') else 'left out'}; {result.runs:,} Monte Carlo runs "
            f"(seed {result.seed}).</p>",
            "<p>Residual errors (1-sigma, drawn per run):</p>",
            table(["term", "value", "unit", "source"], _error_rows(result)),
            f"<p>Errors at {t_end:g} s (Monte Carlo; the envelopes are mean +/- 1 and 3 sigma, those of the one-signed "
            "down channels the runs' percentiles):</p>",
            table(["component", "mean", "1 sigma", "3 sigma"], _final_rows(result)),
            f"<p><b>Which error dominates when</b> ({esc(result.dominance_method)}):</p>",
            "<ul>" + "".join(f"<li>{esc(line)}</li>" for line in result.dominance.splitlines()) + "</ul>"]
    if png is not None:
        body.append(image(png, "navigation error growth"))
    if result.notes:
        body.append('<p class="note">' + "<br>".join(esc(n) for n in result.notes) + "</p>")
    return Section("What the residual errors cost in navigation", "".join(body))


def drift_summary(result) -> str:
    """Terminal text: the mission, the errors at the end (mean, 1 sigma, 3 sigma) and which error dominates when."""
    m = result.mission
    t_end = float(result.t[-1]) if len(result.t) else 0.0
    lines = [f"drift: {m.get('kind', '')} mission, {m.get('description', '')}, {t_end:g} s; {result.runs:,} runs, "
             f"navigation at {result.nav_rate:g} Hz",
             f"{'at the end':<26}{'mean':>12}{'1 sigma':>12}{'3 sigma':>12}"]
    for row in _final_rows(result):
        lines.append(f"{row[0]:<26}{row[1]:>12}{row[2]:>12}{row[3]:>12}")
    if result.down_percentiles is not None:
        end = result.down_percentiles[:, -1, :]
        lines.append(f"down, central 99.73 % of the runs: velocity {end[0, 0]:.4g} to {end[-1, 0]:.4g} m/s, "
                     f"position {end[0, 1]:.4g} to {end[-1, 1]:.4g} m (one-signed second order: see the notes)")
    lines.append(f"which error dominates when ({result.dominance_method}):")
    lines += ["  " + line for line in result.dominance.splitlines()] or ["  none: no error term grows on this mission"]
    lines += [f"note: {n}" for n in result.notes]
    return "\n".join(lines)


def experiment_png(exp) -> bytes:
    """Seed 002's experiment (:class:`align.navigation.experiment.Experiment`): east, north and heading drift of the
    real record and of every simulated one (top), and their differences real - simulated, its Eq 19 (bottom)."""
    from align.navigation.experiment import METHODS, OUTPUTS

    plt = pyplot()
    colours = dict(zip(METHODS, ("tab:red", "tab:green", "tab:blue")))
    scale = (1.0, 1.0, 180 / np.pi)
    units = ("m", "m", "deg")
    fig, axes = plt.subplots(2, 3, figsize=(12, 7), sharex=True)
    for k in range(3):
        top, bottom = axes[0, k], axes[1, k]
        for method in METHODS:
            for r, run in enumerate(exp.sims[method]):
                top.plot(exp.t, run[:, k] * scale[k], color=colours[method], lw=0.7, alpha=0.6,
                         label=method if r == 0 else None)
                bottom.plot(exp.t, (exp.real[:, k] - run[:, k]) * scale[k], color=colours[method], lw=0.7, alpha=0.6)
        top.plot(exp.t, exp.real[:, k] * scale[k], color="k", lw=1.6, label="real record")
        top.set_title(f"{OUTPUTS[k]} drift", fontsize=10)
        bottom.set_title(f"real - simulated {OUTPUTS[k]} (Eq 19)", fontsize=10)
        top.set_ylabel(units[k])
        bottom.set_ylabel(units[k])
        bottom.set_xlabel("time (s)")
        for ax in (top, bottom):
            ax.grid(alpha=0.3)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=9, frameon=False)
    reps = len(next(iter(exp.sims.values())))
    fig.suptitle(f"Static navigation drift: the real record and {reps} simulated records per error model "
                 "(seed 002, section 3.1)", fontsize=11)
    fig.tight_layout(rect=(0, 0.04, 1, 0.97))
    return png_bytes(fig)
