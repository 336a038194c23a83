"""A lot for people: the batch's summary, the lot's statistics as text, and its HTML report with pictures.

The report (:func:`lot_report_html`) lists the units that do not pass first, then the statistics of
every figure against its limit, which Cpk each figure shows and why (normal, or ISO 22514-2 percentile
when an Anderson-Darling test rejects normality), the control-chart run rules that fired (first unit per
rule), a histogram per figure with its limits, and an individuals control chart per figure over the lot's
order (or time) with its control limits and spec limits; pictures are matplotlib PNGs embedded as data URIs
(:func:`align.present.html.image`).

Public names
------------
batch_summary, lot_summary, lot_report_html, histograms_png, control_charts_png, relative_paths, capability_lines,
signal_lines, figure_label, thermal_lines
"""

from __future__ import annotations

import io
import math
import os
import re
from pathlib import Path

import numpy as np

from align.present.figures import pyplot
from align.present.html import Section, esc, html_report, image, table

#: the most panels in one picture
MAX_PANELS = 24


def _num(x: float, signed: bool = False, ref: float | None = None) -> str:
    """``x`` to 3 significant digits of ``ref`` (a spread: the mean of a ratio near 1 keeps its digits), else 4."""
    if x is None or not math.isfinite(x):
        return "-"
    if ref is not None and math.isfinite(ref) and ref > 0:
        d = max(0, min(12, 2 - math.floor(math.log10(ref))))
        return f"{x:+.{d}f}" if signed else f"{x:.{d}f}"
    return f"{x:+.4g}" if signed else f"{x:.4g}"


def _unit(fs) -> str:
    return "" if fs.unit == "1" else f" {fs.unit}"


def figure_label(fs) -> str:
    """A figure's standard title and its key as a short code: ``cross-axis misalignment phi_xy``
    (:data:`align.keyfigures.TITLES`)."""
    from align.keyfigures import title

    name = title(fs.figure)
    return fs.figure if name == fs.figure else f"{name} {fs.figure}"


def _unit_cell(fs) -> str:
    return "ratio" if fs.unit == "1" else fs.unit


def _per(stats) -> str:
    return "per day" if stats.trend_by == "time" else "per 100 units"


def _slope(fs, stats) -> tuple[float, float]:
    k = 1.0 if stats.trend_by == "time" else 100.0
    return fs.shown(fs.slope * k), fs.shown(fs.slope_sigma * k)


def batch_summary(run, manifest: str, where: str, table_path, seconds: float) -> str:
    """What a batch did, in a few lines: units run and skipped, the lot's counts, time, throughput, and the units
    that do not pass with their message."""
    ran = run.units()
    ok, outside = run.lot("ok"), run.lot("ok", "fail")
    failed, errors = run.lot("failed"), run.lot("error")
    units = f"{run.total} unit{'s' if run.total != 1 else ''}"
    lines = [f"batch of {manifest} on {where}: {units}; ran {len(ran)}, skipped {len(run.lot()) - len(ran)} "
             f"(done before, inputs unchanged); {len(ok)} ok" + (f" ({len(outside)} outside the spec)" if outside else "")
             + f", {len(failed)} failed, {len(errors)} errors",
             f"{seconds:.1f} s" + (f", {len(ran) / seconds:.2f} units/s (of the {len(ran)} run)" if ran and seconds > 0
                                   else "")
             + f"; results store {table_path}, results in {table_path.parent / 'units'}"]
    bad = failed + errors + outside
    if bad:
        lines.append(f"units not passing ({len(bad)}):")
        lines += [f"  {r['serial']:<12} {r['verdict']:<7} {r['message']}" for r in sorted(bad, key=lambda r: r['order'])]
    said = [r for r in run.lot("ok", "warn") if r.get("message")]
    if said:
        lines.append(f"units passing with a warning ({len(said)}):")
        lines += [f"  {r['serial']:<12} {r['message']}" for r in sorted(said, key=lambda r: r['order'])]
    return "\n".join(lines)


def _cpk_cell(fs) -> str:
    """The Cpk shown: the normal one ± its standard error, or the percentile one [its 95 % interval] marked ``pct``."""
    cap = getattr(fs, "capability", None)
    if fs.limit and cap is not None and cap.used == "percentile":
        lo, hi = cap.interval
        return f"{cap.cpk_percentile:.2f} [{lo:.2f}, {hi:.2f}] pct"
    return f"{fs.cpk:.2f} ± {fs.cpk_sigma:.2f}" if fs.limit and math.isfinite(fs.cpk_sigma) else "-"


def _name(fs) -> str:
    return f"{figure_label(fs)} ({fs.sensor}{', ' + fs.job if fs.job else ''})"


def capability_lines(stats) -> list[str]:
    """One line per figure with a limit: the Cpk shown and why; the other Cpk beside it (flagged when not applicable)."""
    out = []
    for fs in stats.figures:
        cap = getattr(fs, "capability", None)
        if fs.limit is None or cap is None:
            continue
        lo, hi = cap.interval
        pct = (f"percentile Cpk {cap.cpk_percentile:.2f} (95 % bootstrap interval {lo:.2f} to {hi:.2f})"
               if math.isfinite(cap.cpk_percentile) else "percentile Cpk -")
        normal = f"normal Cpk {cap.cpk_normal:.2f} ± {cap.cpk_normal_sigma:.2f}"
        if cap.used == "percentile":
            out.append(f"{_name(fs)}: {pct}; {cap.why}; {normal}: {cap.normal_note}")
        else:
            said = cap.normal_note and "not normal" not in cap.why  # the reason once
            out.append(f"{_name(fs)}: {normal}; {cap.why}" + (f"; {cap.normal_note}" if said else "")
                       + f"; {pct}")
    return out


def signal_lines(stats) -> list[str]:
    """One line per figure whose control chart raised a run rule: each rule's (and side's) first unit and how often it
    fired."""
    out = []
    for fs in stats.figures:
        chart = getattr(fs, "chart", None)
        if chart is None or not chart.signals:
            continue
        firsts = []
        for key in dict.fromkeys((sg.rule, sg.side) for sg in chart.signals):
            mine = [sg for sg in chart.signals if (sg.rule, sg.side) == key]
            firsts.append(mine[0].describe() + (f", {len(mine)} times" if len(mine) > 1 else ""))
        out.append(f"{_name(fs)}: " + "; ".join(firsts))
    return out


def thermal_lines(groupings) -> list[str]:
    """One line per sensor grouped by thermal profile, then one per group: its units and its curve's spread."""
    out = []
    for g in groupings:
        out.append(f"{g.sensor}: {g.count} group{'s' if g.count != 1 else ''} of {sum(len(x.members) for x in g.groups)} "
                   f"units over {g.grid[0]:.1f} to {g.grid[-1]:.1f} C ({g.criterion})")
        unit = "deg/s" if g.sensor == "gyroscope" else "m/s^2"
        for k, grp in enumerate(g.groups, 1):
            spread = np.degrees(grp.spread) if unit == "deg/s" else grp.spread
            out.append(f"  group {k} ({len(grp.members)} units; shapes about its curve rms "
                       + ", ".join(f"{v:.3g}" for v in spread) + f" {unit}): " + ", ".join(grp.members))
    return out


def _signal_note(stats) -> str:
    n = max((fs.n for fs in stats.figures), default=0)
    return ("(I-MR chart in lot order, limits from the lot's first units; Western Electric rules 1-4 (4: 8 in a row) and "
            f"the moving range beyond D4 MR. An in-control lot of {n} units raises about {n / 50:.1f} false signals "
            "per figure on these rules: a signal is a reason to look, not a verdict.)")


def _stats_rows(stats) -> list[list]:
    rows = []
    for fs in stats.figures:
        s, ss = _slope(fs, stats)
        ref = fs.shown(fs.std)
        rows.append([figure_label(fs), fs.sensor, fs.job, fs.limit.describe() if fs.limit else "", _unit_cell(fs), fs.n,
                     _num(fs.shown(fs.mean), True, ref), _num(ref, False, ref), _num(fs.shown(fs.minimum), True, ref),
                     _num(fs.shown(fs.maximum), True, ref), _cpk_cell(fs),
                     f"{100 * fs.yield_:.1f} %" if fs.limit else "-", len(fs.outliers),
                     "-" if not math.isfinite(s) else
                     f"{_num(s, True, ss)} ± {_num(ss, False, ss)}" + (" *" if abs(s) > 3 * ss else "")])
    return rows


_HEADER = ["figure", "sensor", "job", "limit", "unit", "n", "mean", "std", "min", "max", "Cpk", "yield", "outliers"]


def lot_summary(stats, source: str) -> str:
    """The lot's statistics as text: yield, a table of the figures, the units that do not pass, outliers, trends."""
    if not stats.count:
        return f"lot of {source}: no units"
    spec = (f", spec {stats.spec.path}" if stats.spec else
            " (no spec: no limits or Cpk; the yield counts the units whose jobs ran)")
    lo, hi = stats.yield_interval
    lines = [f"lot of {source}: {stats.count} units (serials; each job's latest run){spec}",
             f"yield {stats.passed} of {stats.count} = {100 * stats.yield_:.1f} % (95 % Wilson interval "
             f"{100 * lo:.1f} to {100 * hi:.1f} %; units passing every limit; units that failed, gave an error or "
             "have a limit not checked count as not passing)"]
    lines += [f"note: {n}" for n in stats.notes] + [""]
    header = _HEADER + [f"trend {_per(stats)}"]
    rows = [[str(c) for c in r] for r in _stats_rows(stats)]
    widths = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h) for i, h in enumerate(header)]
    for r in [header] + rows:
        lines.append("  ".join(c.ljust(w) if i < 5 else c.rjust(w) for i, (c, w) in enumerate(zip(r, widths))).rstrip())
    lines.append("(* a trend beyond 3 sigma; mean, std, min, max, trend in each figure's unit; populations by job, "
                 "sensor and unit: counts apart from SI; Cpk ± its standard error, or 'pct': the percentile Cpk "
                 "[95 % interval] where normality is rejected)")
    bad = [u for u in stats.units if u.verdict != "pass"]
    if bad:
        lines += ["", f"units not passing ({len(bad)}):"]
        lines += [f"  {u.serial:<12} {u.verdict:<9} {'; '.join(u.reasons)}" for u in bad]
    outliers: dict[str, list[str]] = {}
    for fs in stats.figures:
        for s in fs.outliers:
            outliers.setdefault(s, []).append(fs.figure)
    if outliers:
        lines += ["", "outliers (robust z-score beyond 3.5): "
                  + ", ".join(f"{s} ({', '.join(f)})" for s, f in outliers.items())]
    cap = capability_lines(stats)
    if cap:
        lines += ["", "capability (which Cpk is shown and why):"] + [f"  {c}" for c in cap]
    sig = signal_lines(stats)
    if sig:
        lines += ["", "control-chart signals (first unit per rule):"] + [f"  {c}" for c in sig] + [_signal_note(stats)]
    return "\n".join(lines)


def _fits(html: str) -> str:
    """A table kept within the page, on screen and printed: no scroll box (a printed page would lose what it hides);
    text cells wrap at blanks (a message's cells, class ``wrap``, anywhere), numbers do not (the page's style sheet,
    :func:`align.present.html.html_report`, styles ``table.fit``)."""
    return html.replace("<table>", '<table class="fit">', 1)


#: an absolute path in a message: POSIX (``/home/...``) or Windows (``C:\\...``), up to a blank or punctuation
_ABSOLUTE = re.compile(r"(?<![\w.~/:\\])(?:/|[A-Za-z]:\\)[^\s:;,()'\"<>]+")


def relative_paths(message: str, folder: str | Path) -> str:
    """``message`` with the absolute paths in it written relative to ``folder`` (``sessions/SN0003.csv`` for
    ``/lots/7/sessions/SN0003.csv`` and ``/lots/7``; ``../in/SN0003.csv`` beside it); other text as it is.

    Examples
    --------
    >>> relative_paths("error: /lots/7/sessions/SN3.csv: 3 rows with NaN; 100 deg/s", "/lots/7")
    'error: sessions/SN3.csv: 3 rows with NaN; 100 deg/s'
    >>> relative_paths("/data/in/SN3.csv: step 1 not found", "/lots/7")
    '../../data/in/SN3.csv: step 1 not found'
    """
    base = os.path.abspath(str(folder))

    def rel(m: re.Match) -> str:
        path = m.group(0)
        try:
            return os.path.relpath(path, base)
        except ValueError:  # another drive (Windows)
            return path

    return _ABSOLUTE.sub(rel, message.replace(base + os.sep, ""))


def _grid(n: int):
    plt = pyplot()
    cols = min(3, n)
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 2.9 * rows), squeeze=False)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    return plt, fig, list(axes.flat[:n])


def _png(plt, fig) -> bytes:
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)
    return buf.getvalue()


def _limits(ax, fs, vertical: bool) -> None:
    lim = fs.limit
    if lim is None:
        return
    for b in (lim.low, lim.high):
        if b is not None:
            (ax.axvline if vertical else ax.axhline)(fs.shown(b), color="tab:red", ls="--", lw=1.2)


def _legend(ax, fs, spec: bool, *lines) -> None:
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color=c, ls=ls, label=label) for label, c, ls in lines]
    if fs.limit is not None:
        handles.append(Line2D([], [], color="tab:red", ls="--", label="spec limits"))
    if spec:
        handles.append(Line2D([], [], color="tab:red", marker="o", ls="", label="outside the spec"))
    ax.legend(handles=handles, fontsize=6, loc="upper right", framealpha=0.8)


def histograms_png(stats, start: int = 0) -> bytes:
    """A histogram per figure (:data:`MAX_PANELS` from ``start``) with its spec limits (red dashes) and its mean."""
    figs = stats.figures[start:start + MAX_PANELS]
    plt, fig, axes = _grid(len(figs))
    for ax, fs in zip(axes, figs):
        v = np.array([fs.shown(x) for x in fs.values])
        good = np.array([fs.limit.ok(x) if fs.limit else True for x in fs.values])
        lo, hi = float(np.min(v)), float(np.max(v))
        if fs.limit is not None:
            lo = min([lo] + [fs.shown(b) for b in (fs.limit.low, fs.limit.high) if b is not None])
            hi = max([hi] + [fs.shown(b) for b in (fs.limit.low, fs.limit.high) if b is not None])
        pad = 0.05 * (hi - lo) or max(abs(lo), 1e-12) * 0.05
        bins = np.linspace(lo - pad, hi + pad, 31)
        ax.hist([v[good], v[~good]], bins=bins, stacked=True, color=["tab:blue", "tab:red"],
                label=["within", "outside"])
        _limits(ax, fs, True)
        ax.axvline(fs.shown(fs.mean), color="k", lw=0.8)
        cap = getattr(fs, "capability", None)
        shown = cap.cpk if cap is not None else fs.cpk  # the Cpk the tables show (percentile: marked)
        cpk = (f", Cpk {shown:.2f}" + (" pct" if cap is not None and cap.used == "percentile" else "")
               if fs.limit is not None and math.isfinite(shown) else "")
        ax.set_title(f"{figure_label(fs)}\n{fs.sensor}, {fs.job}{cpk}", fontsize=9)
        if ax is axes[0]:
            _legend(ax, fs, stats.spec is not None, ("mean", "k", "-"))
        ax.set_xlabel(fs.unit if fs.unit != "1" else "ratio", fontsize=8)
        ax.tick_params(labelsize=7)
    return _png(plt, fig)


def control_charts_png(stats, start: int = 0) -> bytes:
    """An individuals chart per figure: each unit over the lot's order (or days), the mean, the control limits
    (mean -/+ 3 MR/1.128, grey) and the spec limits (red dashes); units outside the spec in red
    (:data:`MAX_PANELS` figures from ``start``)."""
    figs = stats.figures[start:start + MAX_PANELS]
    plt, fig, axes = _grid(len(figs))
    for ax, fs in zip(axes, figs):
        v = np.array([fs.shown(x) for x in fs.values])
        bad = np.array([not fs.limit.ok(x) if fs.limit else False for x in fs.values])
        ax.plot(fs.x, v, "-", color="0.75", lw=0.6)
        ax.plot(fs.x[~bad], v[~bad], ".", color="tab:blue", ms=3)
        ax.plot(fs.x[bad], v[bad], "o", color="tab:red", ms=4)
        ax.axhline(fs.shown(fs.centre), color="k", lw=0.8)
        for c in (fs.lcl, fs.ucl):
            if math.isfinite(c):
                ax.axhline(fs.shown(c), color="0.4", ls=":", lw=1)
        _limits(ax, fs, False)
        chart = getattr(fs, "chart", None)
        if chart is not None and chart.signals:
            order = np.argsort(fs.x, kind="stable")
            at = order[[sg.index for sg in chart.signals]]
            ax.plot(fs.x[at], v[at], "x", color="tab:orange", ms=6)
        ax.set_title(f"{figure_label(fs)}\n{fs.sensor}, {fs.job}", fontsize=9)
        if ax is axes[0]:
            _legend(ax, fs, stats.spec is not None, ("mean", "k", "-"), ("control limits", "0.4", ":"))
        ax.set_xlabel("days since the first unit" if stats.trend_by == "time" else "unit (lot order)", fontsize=8)
        ax.set_ylabel(fs.unit if fs.unit != "1" else "ratio", fontsize=8)
        ax.tick_params(labelsize=7)
    return _png(plt, fig)


def lot_report_html(stats, source: str, thermal: tuple = ()) -> str:
    """The lot's HTML report (one self-contained page): every column visible on screen and printed (no scroll box;
    the statistics in two tables, the spread and the limits), paths in messages relative to the table's folder."""
    sections = []
    bad = [u for u in stats.units if u.verdict != "pass"]
    verdict = "pass" if not bad else "fail"
    lo, hi = stats.yield_interval
    folder = Path(source).parent
    banner = (f'<p class="banner {verdict}">yield {stats.passed} of {stats.count} = {100 * stats.yield_:.1f} % '
              f"(95 % Wilson interval {100 * lo:.1f} to {100 * hi:.1f} %): "
              + ("every unit passes" if not bad else f"{len(bad)} units do not pass") + "</p>")
    notes = "".join(f'<p class="note">{esc(n)}</p>' for n in stats.notes)
    sections.append(Section("Summary", banner + '<p class="note">Each unit (serial) judged by its jobs\' latest runs; '
                            "units that failed, gave an error or have a limit not checked count as not passing. Spec: "
                            + esc(stats.spec.path if stats.spec else "none") + ".</p>" + notes))
    if bad:
        rows = [[u.serial, u.job, (u.verdict, "fail"), (relative_paths("; ".join(u.reasons), folder), "wrap")]
                for u in bad]
        sections.append(Section(f"Units not passing ({len(bad)})",
                                _fits(table(["serial", "jobs", "verdict", "why"], rows, 4))
                                + f'<p class="note">Paths relative to the folder of the table, '
                                  f"<code>{esc(folder)}</code>.</p>"))
    if stats.figures:
        rows = _stats_rows(stats)
        spread = [r[:3] + r[4:10] for r in rows]  # figure, sensor, job, unit, n, mean, std, min, max
        limits = [r[:4] + r[10:] for r in rows]  # figure, sensor, job, limit, Cpk, yield, outliers, trend
        sections.append(Section("Statistics", _fits(table(_HEADER[:3] + _HEADER[4:10], spread, 4))
                                + _fits(table(_HEADER[:4] + _HEADER[10:] + [f"trend {_per(stats)}"], limits, 4))
                                + '<p class="note">Mean, std, min, max and trend in each figure\'s unit; Cpk &plusmn; '
                                "its standard error; outliers by the robust z-score (beyond 3.5, from 8 units on); * a "
                                "trend beyond 3 sigma. Each job, sensor and unit (counts or SI) is its own "
                                "population.</p>"))
        cap = capability_lines(stats)
        if cap:
            sections.append(Section("Capability", "<ul>" + "".join(f"<li>{esc(c)}</li>" for c in cap) + "</ul>"
                                    + '<p class="note">Cpk shown: the normal one unless an Anderson-Darling test rejects '
                                    "normality (alpha 0.05); then the percentile Cpk of ISO 22514-2 (each tail a Johnson "
                                    "fit; 95 % percentile bootstrap interval, its top raised to a far-tail reading's where "
                                    "higher).</p>"))
        sig = signal_lines(stats)
        if sig:
            sections.append(Section("Control-chart signals", "<ul>" + "".join(f"<li>{esc(c)}</li>" for c in sig)
                                    + "</ul>" + f'<p class="note">{esc(_signal_note(stats))}</p>'))
        starts = range(0, len(stats.figures), MAX_PANELS)
        sections.append(Section("Histograms", "".join(
            image(histograms_png(stats, k), "histogram of each figure with its limits") for k in starts)
            + f'<p class="note">All {len(stats.figures)} figures, {MAX_PANELS} per picture.</p>'))
        sections.append(Section("Control charts", "".join(
            image(control_charts_png(stats, k), "individuals control charts") for k in starts)
            + '<p class="note">Orange crosses: units where a run rule fired (see Control-chart signals).</p>'))
        outl = [[s, figure_label(fs), fs.sensor] for fs in stats.figures for s in fs.outliers]
        if outl:
            sections.append(Section("Outliers", table(["serial", "figure", "sensor"], outl, 3)))
    if thermal:
        sections.append(Section("Thermal groups", "<ul>" + "".join(f"<li>{esc(c)}</li>" for c in thermal_lines(thermal))
                                + "</ul>"))
    return html_report(f"Lot report: {source}", sections, {"table": source, "units": stats.count})
