"""The report's thermal section: per sensor of a thermal calibration (``imu-align.thermal``), its bias against
temperature and a table of what the fit found.

The picture (one column per axis): on top the readings against the temperature, heating and cooling branches
apart (each point the mean of consecutive samples: the record decimated), the fitted static curve and its
1-sigma band; below, the residual after compensation (readings less the model with its lag term) with the band
about zero. The readings come from the log the result names, read again as the result recorded it
(:mod:`align.present.reread`); when it cannot be read again, the curve and its band are drawn alone and the
section says why in one sentence.

Public names
------------
Record, read_thermal_log, thermal_png, thermal_section, thermal_job, DECIMATED
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from align.present.html import Section, esc, image, table

__all__ = ["Record", "read_thermal_log", "thermal_png", "thermal_section", "thermal_job", "DECIMATED"]

#: most points drawn per axis (block means of consecutive samples beyond it)
DECIMATED = 3000
_AXES = ("x", "y", "z")
_DIMENSION = {"gyroscope": "angular_rate", "accelerometer": "acceleration"}
_COLUMNS = {"gyroscope": "time,gyro_x,gyro_y,gyro_z", "accelerometer": "time,acc_x,acc_y,acc_z"}
#: branch label -> (name, colour)
_BRANCHES = {1: ("heating", "tab:red"), -1: ("cooling", "tab:blue"), 0: ("neither (soak, turn)", "0.6")}


@dataclass(frozen=True)
class Record:
    """One sensor's log as the calibration read it.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Time, s.
    temperature : ndarray, shape (n,)
        C.
    data : ndarray, shape (n, 3)
        Readings, SI.
    """

    t: np.ndarray
    temperature: np.ndarray
    data: np.ndarray


def read_thermal_log(result_path: str | Path, inputs: dict, sensor: str, units: str) -> tuple[Record | None, str]:
    """The log a thermal calibration names, read again for ``sensor`` as the result recorded it (its columns, time
    column or rate, temperature column and unit, format); ``(record, "")`` or ``(None, one sentence why not)``.

    Parameters
    ----------
    result_path : str or Path
        The result file (a relative log is looked for beside it first).
    inputs : dict
        The result's ``inputs``.
    sensor : str
        ``"gyroscope"`` or ``"accelerometer"``.
    units : str
        The unit the result shows the readings in (the log's unit when it states none).

    Returns
    -------
    (Record or None, str)

    Examples
    --------
    >>> read_thermal_log("r.json", {}, "gyroscope", "deg/s")
    (None, 'The readings are not drawn: the calibration names no log.')
    """
    from align.errors import AlignError, literal
    from align.io import read_sensor_log
    from align.present.reread import recorded_format, resolve_recorded, template

    log = inputs.get("log")
    if not log:
        return None, "The readings are not drawn: the calibration names no log."
    cols = [c.strip() for c in str((inputs.get("columns") or {}).get(sensor) or _COLUMNS[sensor]).split(",")]
    rate = inputs.get("rate_hz")
    time_col, cols = (cols[0], cols[1:]) if len(cols) == 4 else (None, cols[-3:])
    try:
        got = read_sensor_log(resolve_recorded(result_path, log), cols, units, time_col,
                              None if time_col else rate, expect=_DIMENSION[sensor],
                              log_format=recorded_format(inputs), temperature_column=inputs.get("temperature_column"),
                              temperature_units=inputs.get("temperature_units"))
    except AlignError as exc:
        return None, (f"The readings are not drawn: the log {literal(log)} could not be read again "
                      f"({template(exc, words=True)}); the fitted curve and its band are shown alone.")
    if got.temperature is None:
        return None, "The readings are not drawn: the calibration records no temperature column."
    return Record(got.t, got.temperature, got.data), ""


def _blocks(x: np.ndarray, m: int) -> np.ndarray:
    """Means of ``m`` consecutive rows (the last partial block dropped)."""
    k = len(x) // m
    return x[:k * m].reshape((k, m) + x.shape[1:]).mean(axis=1)


def _decimated(st, settings, rec: Record) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]:
    """Block means of the temperature (k,), readings and residual after compensation (k, 3), SI, the branch of each
    block (k,: +1, -1, 0 where the block is not wholly on one branch), and the samples per block; the residual is
    found a run of blocks at a time (bounded memory for a long record)."""
    from align.calibration.thermal.branches import branch_labels
    from align.calibration.thermal.sensor import recorded_rate

    rate = recorded_rate(rec.t, rec.temperature, settings)
    label = (branch_labels(rec.t, rate, settings.min_rate, settings.min_branch_s) if settings.hysteresis
             else np.zeros(len(rec.t), np.int8))
    m = max(1, math.ceil(len(rec.t) / DECIMATED))
    k = len(rec.t) // m
    temp, data, resid, lab = np.empty(k), np.empty((k, 3)), np.empty((k, 3)), np.empty(k)
    run = max(1, (1 << 18) // m)  # blocks per run
    for a in range(0, k, run):
        b = min(a + run, k)
        part = slice(a * m, b * m)
        temp[a:b], lab[a:b] = _blocks(rec.temperature[part], m), _blocks(label[part].astype(float), m)
        data[a:b] = _blocks(rec.data[part], m)
        resid[a:b] = _blocks(st.model.compensate(rec.data[part], rec.temperature[part], rate[part]).data, m)
    branch = np.where(np.abs(lab) == 1.0, lab, 0.0).astype(int)
    return temp, data, resid, branch, m


def thermal_png(st, settings=None, record: Record | None = None) -> bytes:
    """One sensor's bias against temperature (module docstring), one column per axis.

    Parameters
    ----------
    st : SensorThermal
        The sensor's calibration (model, units, per axis what the fit found).
    settings : Settings, optional
        How the fit was made (the branches are found again with it); needed with ``record``.
    record : Record, optional
        The log; None: the fitted curve and its band alone.

    Returns
    -------
    bytes
        The PNG file.
    """
    from align.calibration.thermal.sensor import Settings
    from align.present.figures import display_unit, png_bytes, pyplot

    plt = pyplot()
    factor, unit = display_unit(st.units, (_DIMENSION.get(st.model.sensor, "acceleration"),))
    model = st.model
    grid = np.linspace(model.tmin, model.tmax, 201)
    curve, band = model.bias(grid)[0] / factor, model.sigma(grid) / factor
    rows = 1 if record is None else 2
    fig, axes = plt.subplots(rows, 3, figsize=(11.0, 3.2 * rows + 0.6), squeeze=False, sharex=True,
                             height_ratios=[2.0, 1.2][:rows], layout="constrained")
    got = None if record is None else _decimated(st, settings or Settings(), record)
    for i, name in enumerate(_AXES):
        top = axes[0, i]
        if got is not None:
            temp, data, resid, branch, _ = got
            for code, (what, colour) in _BRANCHES.items():
                on = branch == code
                top.plot(temp[on], data[on, i] / factor, ".", ms=2.5, color=colour, label=what, zorder=1)
                axes[1, i].plot(temp[on], resid[on, i] / factor, ".", ms=2.5, color=colour, zorder=1)
            axes[1, i].fill_between(grid, -band[:, i], band[:, i], color="k", alpha=0.3, lw=0, zorder=2)
            axes[1, i].axhline(0.0, color="k", lw=0.8, zorder=3)
            axes[1, i].set_xlabel("temperature [C]")
        else:
            top.set_xlabel("temperature [C]")
        top.fill_between(grid, curve[:, i] - band[:, i], curve[:, i] + band[:, i], color="k", alpha=0.3, lw=0,
                         label="band (1-sigma)", zorder=2)
        top.plot(grid, curve[:, i], "k-", lw=1.2, label="fitted static curve", zorder=3)
        rep = st.axes[i]
        top.set_title(f"{name} axis: order {rep.order}" + (", lag term" if rep.lag else ""), fontsize=10)
        for ax in axes[:, i]:
            ax.tick_params(labelsize=8)
            ax.yaxis.get_offset_text().set_fontsize(8)
            ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel(f"{model.sensor} reading [{unit}]", fontsize=9)
    if rows == 2:
        axes[1, 0].set_ylabel(f"residual after [{unit}]", fontsize=9)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=len(labels), fontsize=8, markerscale=3,
               frameon=False)
    return png_bytes(fig)


def _value(v: float, factor: float, fmt: str = ".4g") -> str:
    return "not determined" if not math.isfinite(v) else format(v / factor, fmt)


def _axis_rows(st, factor: float) -> list[list[str]]:
    rows = []
    for i, (ax, rep) in enumerate(zip(st.model.axes, st.axes)):
        lag = "no" if ax.lag is None else f"{ax.lag / factor:+.4g} ± {ax.lag_sigma / factor:.2g}"
        h = rep.hysteresis
        hyst = "no overlap" if h is None else f"{h.value / factor:+.4g} ± {h.sigma / factor:.2g} at {h.at:.1f} C"
        rows.append([_AXES[i], str(rep.order), lag, hyst, _value(rep.rms_before, factor),
                     _value(rep.rms_after, factor), _value(rep.max_before, factor), _value(rep.max_after, factor),
                     _value(rep.band_max, factor, ".2g")])
    return rows


def thermal_section(res, sensor: str, source: str, picture: bytes | None = None, note: str = "") -> Section:
    """One sensor's thermal calibration (module docstring).

    Parameters
    ----------
    res : ThermalCalibration
    sensor : str
        A key of ``res.sensors``.
    source : str
        The result file, as shown.
    picture : bytes, optional
        :func:`thermal_png` of the sensor.
    note : str
        One sentence: why the readings are not drawn (empty when they are).

    Returns
    -------
    Section
    """
    from align.present.figures import display_unit

    st = res.sensors[sensor]
    m = st.model
    factor, unit = display_unit(st.units, (_DIMENSION.get(sensor, "acceleration"),))
    branches = ", ".join(f"{v:,} {k}" for k, v in st.branches.items()) or "no branches detected"
    body = (f"<p>From <code>{esc(source)}</code>: {esc(sensor)}, bias against temperature per axis, "
            f"<code>bias(T, dT/dt) = sum_k c_k (T - Tref)^k + lag dT/dt</code>, readings in {esc(unit)}, the lag "
            f"coefficient in {esc(unit)} per C/s. Reference temperature <b>{m.tref:.2f} C</b>, valid range "
            f"<b>{m.tmin:.2f} to {m.tmax:.2f} C</b> (clamped outside); {st.samples:,} samples ({esc(branches)}), "
            f"temperature resolution {st.resolution:.3g} C.</p>")
    head = ["axis", "order", f"lag [{unit} per C/s] ± 1-sigma", f"hysteresis [{unit}] ± 1-sigma",
            "rms before", "rms after", "largest before", "largest after", "band 1-sigma (largest)"]
    body += (f"<p>The fit of each axis; residuals in {esc(unit)}: before, with a constant bias removed; after, "
             "with the model and its lag term; hysteresis: heating minus cooling at equal temperature where "
             "largest:</p>" + table(head, _axis_rows(st, factor)))
    if picture:
        if note:
            body += f'<p class="note">{esc(note)}</p>'
        body += image(picture, f"{sensor} bias against temperature: heating and cooling branches, fitted curve with "
                               "its 1-sigma band, residual after compensation")
        if not note:
            body += ('<p class="note">Each point is the mean of consecutive samples (the record decimated to at most '
                     f"{DECIMATED:,} points per axis); red heating, blue cooling, grey neither; the grey band is the "
                     "curve's 1-sigma, drawn about zero below.</p>")
    elif note:
        body += f'<p class="note">{esc(note)}</p>'
    body += "".join(f'<p class="note">{esc(n)}</p>' for n in st.notes)
    return Section(f"Thermal calibration: {sensor} ({source})", body)


def thermal_job(rep, path: Path, res, name: str) -> None:
    """A thermal calibration in the report (:func:`align.present.jobs.calibration_job`): per sensor its section with
    the picture, the largest residual after compensation as its summary number and terminal line.

    Parameters
    ----------
    rep : Report
        The report being built (:class:`align.present.jobs.Report`).
    path : Path
        The result file, as shown.
    res : ThermalCalibration
    name : str
        The label of the result (the file's stem).
    """
    import dataclasses

    from align.calibration.thermal.sensor import Settings
    from align.present.figures import display_unit
    from align.present.verdicts import INFO, Verdict

    recorded = res.inputs.get("settings") or {}
    settings = Settings(**{f.name: recorded[f.name] for f in dataclasses.fields(Settings) if f.name in recorded})
    for sensor, st in res.sensors.items():
        record, why = read_thermal_log(path, res.inputs, sensor, st.units)
        png = thermal_png(st, settings, record)
        rep.add("calibration", thermal_section(res, sensor, str(path), png, why))  # its figures: story's section
        factor, unit = display_unit(st.units, (_DIMENSION.get(sensor, "acceleration"),))
        k = int(np.argmax([a.max_after for a in st.axes]))
        ax = st.axes[k]
        number = f"residual after {ax.max_after / factor:.4g} {unit} ({_AXES[k]}, largest)"
        rep.verdicts.append(Verdict(f"{sensor} thermal calibration ({name})", INFO, number, ax.max_after / factor,
                                    f"order {ax.order}{' + lag' if ax.lag else ''}; rms after "
                                    f"{ax.rms_after / factor:.4g} {unit}, before {ax.rms_before / factor:.4g} {unit}; "
                                    f"valid {st.model.tmin:.1f} to {st.model.tmax:.1f} C"))
        rep.lines.append(f"{sensor} thermal calibration {path}: {number}")
        if why:
            rep.lines.append(why)
