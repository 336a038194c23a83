"""Inputs of the bad-input campaign: good files of every kind, and their bad and borderline variants.

:func:`build_inputs` writes everything into one folder (a session-scoped fixture calls it once):
small simulated logs (a rate-table session, a static record, a Ferraris session, an accelerometer
multi-position session, a magnetometer capture), the bundled examples (plan, mount, manoeuvres),
the result files of every kind (made by running the commands themselves), and variants of each.
Every file name is unique, so a case names its inputs by name only (see ``campaign_cases``).
"""

from __future__ import annotations

import contextlib
import gzip
import io
import json
import shutil
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
SHARED_DATA = ROOT.parent / "shared" / "data"

FS_SESSION = 50.0   # Hz, rate-table session
FS_STATIC = 100.0   # Hz, static record
FS_FERRARIS = 50.0  # Hz, Ferraris session
FS_ACCEL = 50.0     # Hz, accelerometer positions
G = 9.80665


# ---------------------------------------------------------------- writing helpers

def _csv_text(names: list[str], data: np.ndarray, fmt: str = "%.10g") -> str:
    buf = io.StringIO()
    buf.write(",".join(names) + "\n")
    np.savetxt(buf, data, delimiter=",", fmt=fmt)
    return buf.getvalue()


def write_csv(path: Path, names: list[str], data: np.ndarray) -> Path:
    path.write_text(_csv_text(names, data))
    return path


def read_csv(path: Path) -> tuple[list[str], np.ndarray]:
    lines = path.read_text().splitlines()
    names = [n.strip('"') for n in lines[0].split(",")]
    return names, np.loadtxt(lines[1:], delimiter=",", ndmin=2)


def _edit_lines(src: Path, dst: Path, edit) -> Path:
    """``dst`` = ``src`` with its lines (header first) passed through ``edit(lines) -> lines``."""
    lines = src.read_text().splitlines()
    dst.write_text("\n".join(edit(lines)) + "\n")
    return dst


def _set_cell(lines: list[str], row: int, col: int, text: str) -> list[str]:
    """Data row ``row`` (1-based, below the header), column ``col`` replaced by ``text``."""
    cells = lines[row].split(",")
    cells[col] = text
    lines[row] = ",".join(cells)
    return lines


def _variant_csv(src: Path, dst: Path, transform) -> Path:
    names, data = read_csv(src)
    return write_csv(dst, names, transform(names, data.copy()))


def _scale_cols(prefix: str, factor: float, flip: str | None = None):
    def transform(names, data):
        for j, n in enumerate(names):
            if n.startswith(prefix):
                data[:, j] *= factor
                if flip and n == flip:
                    data[:, j] *= -1
        return data
    return transform


# ---------------------------------------------------------------- simulated records

def _ferraris_session(rng: np.random.Generator, acc_scale: float = 1.0, flip_acc: int | None = None):
    """A Ferraris session (six faces, one -360 deg turn about each axis) as imucal records it.

    Returns the columns acc_x..acc_z (m/s^2), gyr_x..gyr_z (deg/s) and the section list.
    """
    fs = FS_FERRARIS
    m_a = np.eye(3) + rng.normal(0, 4e-3, (3, 3))
    b_a = np.array([0.05, -0.08, 0.1])
    m_g = np.eye(3) + rng.normal(0, 4e-3, (3, 3))
    b_g = np.radians([0.3, -0.2, 0.1])
    acc_rows, gyr_rows, sections = [], [], {}
    pos = 0

    def add(true_a, true_w, name=None):
        nonlocal pos
        n = len(true_a)
        acc_rows.append(true_a @ m_a.T + b_a + rng.normal(0, 0.01, (n, 3)))
        gyr_rows.append(true_w @ m_g.T + b_g + rng.normal(0, np.radians(0.05), (n, 3)))
        if name:
            sections[name] = {"start": pos, "end": pos + n}
        pos += n

    def tumble(a_from, a_to, n=int(fs)):
        """A short move between two faces: gravity swings, the gyro sees a smooth rate."""
        s = np.linspace(0, 1, n)[:, None]
        a = (1 - s) * a_from + s * a_to
        a = G * a / np.linalg.norm(a, axis=1, keepdims=True).clip(1e-9)
        axis = np.cross(a_from, a_to)
        axis = axis / np.linalg.norm(axis) if np.linalg.norm(axis) > 0 else np.array([1.0, 0, 0])
        w = np.outer(np.sin(np.pi * s[:, 0]) * np.pi / 2 * fs / n, axis) * (np.pi / 2)
        add(a, w)

    faces = [("x_p", 0, 1), ("x_a", 0, -1), ("y_p", 1, 1), ("y_a", 1, -1), ("z_p", 2, 1), ("z_a", 2, -1)]
    prev = None
    for name, axis, sign in faces:
        up = np.zeros(3)
        up[axis] = sign
        if prev is not None:
            tumble(G * prev, G * up)
        add(np.tile(G * up, (int(3 * fs), 1)), np.zeros((int(3 * fs), 3)), name)
        prev = up
    for axis in range(3):
        up = np.zeros(3)
        up[axis] = 1
        tumble(G * prev, G * up)
        prev = up
        n_pad, n_turn = int(fs), int(4 * fs)
        shape = np.sin(np.pi * np.arange(n_turn) / n_turn) ** 2
        rate = -2 * np.pi * shape / (shape.sum() / fs)  # integrates to -360 deg
        w = np.zeros((n_turn + 2 * n_pad, 3))
        w[n_pad:n_pad + n_turn, axis] = rate
        add(np.tile(G * up, (len(w), 1)), w, "xyz"[axis] + "_rot")
    acc = np.vstack(acc_rows) * acc_scale
    gyr = np.degrees(np.vstack(gyr_rows))
    if flip_acc is not None:
        acc[:, flip_acc] *= -1
    return acc, gyr, sections


def _accel_session(rng: np.random.Generator):
    """Twelve static attitudes (six faces and six diagonals) of 3 s, moves of 1 s: time, a (m/s^2), ups."""
    fs = FS_ACCEL
    ups = [np.array(u, float) for u in ([1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1],
                                         [1, 1, 0], [0, 1, 1], [1, 0, 1], [-1, 1, 0], [0, -1, 1], [1, 0, -1])]
    ups = [u / np.linalg.norm(u) for u in ups]
    m_a = np.eye(3) + rng.normal(0, 5e-3, (3, 3))
    b_a = np.array([0.06, -0.04, 0.09])
    rows, ranges, pos = [], [], 0
    for k, u in enumerate(ups):
        if k:
            s = np.linspace(0, 1, int(fs))[:, None]
            a = (1 - s) * ups[k - 1] + s * u
            a = a / np.linalg.norm(a, axis=1, keepdims=True).clip(1e-9)
            a = G * a + rng.normal(0, 0.8, a.shape)  # handling shakes the sensor
            rows.append(a)
            pos += len(a)
        n = int(3 * fs)
        rows.append(np.tile(G * u, (n, 1)))
        ranges.append((pos + 10, pos + n - 10))
        pos += n
    true = np.vstack(rows)
    raw = true @ m_a.T + b_a + rng.normal(0, 0.005, true.shape)
    t = np.arange(len(raw)) / fs
    return t, raw, ups, ranges


def _mag_capture(rng: np.random.Generator, n: int = 1200):
    """Raw magnetometer (uT) and accelerometer (m/s^2) over random attitudes: field 48 uT, dip 60 deg."""
    field = 48.0 * np.array([np.cos(np.radians(60)), 0, -np.sin(np.radians(60))])
    soft = np.eye(3) + 0.5 * (lambda a: a + a.T)(rng.normal(0, 0.05, (3, 3)))
    hard = np.array([12.0, -7.0, 20.0])
    rot = Rotation.random(n, random_state=int(rng.integers(1 << 30)))
    body = rot.inv().apply(field)
    acc = rot.inv().apply(np.array([0, 0, G]))
    return body @ soft.T + hard + rng.normal(0, 0.2, (n, 3)), acc + rng.normal(0, 0.02, (n, 3))


def _parquet(path: Path, names: list[str], data: np.ndarray) -> Path:
    import pyarrow as pa
    import pyarrow.parquet as pq

    pq.write_table(pa.table({n: data[:, j] for j, n in enumerate(names)}), path)
    return path


def _toml_lines(text: str, old: str, new: str) -> str:
    assert old in text, (old, text)
    return text.replace(old, new, 1)


# ---------------------------------------------------------------- running the commands

def run_cli(args: list[str]) -> tuple[int, str]:
    """``imu-align ARGS`` in-process; returns (exit status, stderr)."""
    from align.cli import run

    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        code = run([str(a) for a in args])
    return code, err.getvalue()


def _must(args: list, made: Path) -> Path:
    code, err = run_cli(args)
    if code != 0 or not made.exists():
        raise RuntimeError(f"building the campaign's inputs: imu-align {' '.join(map(str, args))} -> {code}: {err}")
    return made


# ---------------------------------------------------------------- the inputs

def build_inputs(d: Path) -> dict[str, Path]:
    """Write every input of the campaign into ``d``; returns name -> path."""
    rng = np.random.default_rng(20240611)
    d.mkdir(parents=True, exist_ok=True)
    sim = d / "_sim"
    _must(["simulate", sim, "--rate-hz", f"{FS_SESSION:g}", "--dwell", "4 s", "--gap", "2 s", "--seed", "3"],
          sim / "session.csv")
    write_csv(d / "session.csv", *read_csv(sim / "session.csv"))
    shutil.copy(sim / "plan.toml", d / "plan.toml")
    shutil.copy(sim / "truth.json", d / "truth.json")
    simang = d / "_simang"
    _must(["simulate", simang, "--kind", "angle", "--rate-hz", f"{FS_SESSION:g}", "--gap", "2 s", "--seed", "4"],
          simang / "session.csv")
    write_csv(d / "angle_session.csv", *read_csv(simang / "session.csv"))
    shutil.copy(simang / "plan.toml", d / "angle_plan.toml")
    shutil.rmtree(sim)
    shutil.rmtree(simang)
    _gyro_log_variants(d)
    _plan_variants(d)
    _segments(d)
    _static_logs(d, rng)
    _ferraris_inputs(d, rng)
    _accel_inputs(d, rng)
    _mag_inputs(d, rng)
    _mount_and_manoeuvres(d)
    _results(d)
    _misc(d)
    _logger_files(d)
    return {p.name: p for p in d.iterdir() if p.is_file()}


def _gyro_log_variants(d: Path) -> None:
    src = d / "session.csv"
    names, data = read_csv(src)
    text = src.read_text()
    (d / "session.csv.gz").write_bytes(gzip.compress(text.encode()))
    np.save(d / "session.npy", data)
    np.savetxt(d / "session.txt", data, fmt="%.10g")  # blank-separated, no header: col0..col3
    import pyarrow as pa
    import pyarrow.parquet as pq

    pq.write_table(pa.table({n: data[:, j] for j, n in enumerate(names)}), d / "session.parquet")
    pq.write_table(pa.table({"time": data[:, 0], "gyro_x": data[:, 1], "gyro_y": [f"{v:.6g}" for v in data[:, 2]],
                             "gyro_z": data[:, 3]}).cast(pa.schema([("time", pa.float64()), ("gyro_x", pa.float64()),
                                                                    ("gyro_y", pa.string()), ("gyro_z", pa.float64())])),
                   d / "session_textcell.parquet")
    tbl = pa.table({n: [f"{v:.6g}" for v in data[:, j]] for j, n in enumerate(names)})
    cells = tbl.column("gyro_y").to_pylist()
    cells[700] = "n/a?"
    tbl = tbl.set_column(2, "gyro_y", pa.array(cells))
    pq.write_table(tbl, d / "session_strcell.parquet")
    np.save(d / "session_str.npy", np.array([["a", "b", "c", "d"]] * 50))
    np.save(d / "session_3d.npy", data[:2000].reshape(500, 4, 4))
    (d / "session_bad.npy").write_bytes(b"\x93NUMPY garbage that is not an array header")
    (d / "session_bad.parquet").write_bytes(b"PAR1 this is not a parquet file")
    (d / "session_bad.csv.gz").write_bytes(b"\x1f\x8b\x08\x00 truncated gzip")
    _edit_lines(src, d / "session_nan.csv", lambda ls: _set_cell(ls, 801, 2, "nan"))
    _edit_lines(src, d / "session_emptycell.csv", lambda ls: _set_cell(ls, 801, 2, ""))
    _edit_lines(src, d / "session_inf.csv", lambda ls: _set_cell(ls, 801, 3, "inf"))
    _edit_lines(src, d / "session_textcell.csv", lambda ls: _set_cell(ls, 801, 2, "abc"))
    _edit_lines(src, d / "session_huge.csv", lambda ls: _set_cell(ls, 801, 1, "1e300"))
    (d / "session_empty.csv").write_text("")
    (d / "session_header.csv").write_text(text.splitlines()[0] + "\n")
    (d / "session_short.csv").write_text("\n".join(text.splitlines()[:6]) + "\n")
    (d / "session_latin1.csv").write_bytes(text.replace("gyro_x", "gyro_\xb5x", 1).encode("latin-1"))
    (d / "session_binary.csv").write_bytes(bytes(range(256)) * 40)
    (d / "session_semicolon.csv").write_text(text.replace(",", ";"))
    write_csv(d / "session_onecol.csv", ["time"], data[:, :1])
    write_csv(d / "session_twocols.csv", ["time", "gyro_x", "gyro_y"], data[:, :3])
    _edit_lines(src, d / "session_ragged.csv", lambda ls: ls[:900] + [ls[900] + ",1.0"] + ls[901:])

    def backwards(_n, x):
        x[1200, 0] = x[1100, 0]
        return x
    _variant_csv(src, d / "session_backwards.csv", backwards)

    def duplicate_time(_n, x):
        x[1200, 0] = x[1199, 0]
        return x
    _variant_csv(src, d / "session_duptime.csv", duplicate_time)
    # a gap: 20 samples lost inside the first static gap (borderline: must still align)
    keep = np.ones(len(data), bool)
    keep[30:50] = False
    write_csv(d / "session_gap.csv", names, data[keep])
    write_csv(d / "session_zero.csv", names, np.column_stack([data[:, 0], np.zeros((len(data), 3))]))
    write_csv(d / "session_const.csv", names, np.column_stack([data[:, 0], np.full((len(data), 3), 1.5)]))
    _variant_csv(src, d / "session_rad.csv", _scale_cols("gyro", np.pi / 180))
    _variant_csv(src, d / "session_mdps.csv", _scale_cols("gyro", 1000.0))
    _variant_csv(src, d / "session_flipy.csv", _scale_cols("gyro", 1.0, flip="gyro_y"))
    _variant_csv(src, d / "session_slow.csv", _scale_cols("gyro", 0.1))
    # borderline forms that must be read like the original
    (d / "session_crlf.csv").write_bytes(text.replace("\n", "\r\n").encode())
    (d / "session_bom.csv").write_bytes(b"\xef\xbb\xbf" + text.encode())
    write_csv(d / "session_extra.csv", names + ["temp"], np.column_stack([data, np.full(len(data), 25.0)]))
    write_csv(d / "session_reorder.csv", ["gyro_z", "time", "gyro_x", "gyro_y"], data[:, [3, 0, 1, 2]])
    write_csv(d / "session_notime.csv", names[1:], data[:, 1:])
    # angle-session variants
    write_csv(d / "angle_session_flipx.csv", *(_flip(read_csv(d / "angle_session.csv"), "gyro_x")))


def _flip(read: tuple[list[str], np.ndarray], name: str):
    names, data = read
    data = data.copy()
    data[:, names.index(name)] *= -1
    return names, data


def _in_test(plan: str, line: str) -> str:
    """``plan`` with ``line`` (``key = value``) in its ``[test]`` table, replacing the key's line there (a plan
    written by ``simulate`` has a ``[test]`` table already; TOML refuses a table or a key given twice)."""
    lines, key = plan.splitlines(), line.split("=")[0].strip()
    if "[test]" not in lines:
        return f"[test]\n{line}\n\n" + plan
    i = lines.index("[test]")
    j = i + 1
    while j < len(lines) and not lines[j].startswith("["):
        if lines[j].split("=")[0].strip() == key:
            del lines[j]
        else:
            j += 1
    lines.insert(i + 1, line)
    return "\n".join(lines) + "\n"


def _plan_variants(d: Path) -> None:
    plan = (d / "plan.toml").read_text()
    w = lambda name, text: (d / name).write_text(text)  # noqa: E731
    w("plan_latitud.toml", _in_test(plan, 'latitud = "48.1 deg"'))
    w("plan_latitude.toml", _in_test(plan, 'latitude = "48.1 deg"'))
    w("plan_tset.toml", '[tset]\nlatitude = "48.1 deg"\n\n' + plan)
    w("plan_rateacc.toml", _in_test(plan, 'rate_acuracy = "0.01 %"'))
    w("plan_rat.toml", _toml_lines(plan, 'rate = "100', 'rat = "100'))
    w("plan_axes.toml", _toml_lines(plan, 'axis = "+x"', 'axes = "+x"\naxis = "+x"'))
    w("plan_stepp.toml", plan.replace("[[step]]", "[[stepp]]"))
    w("plan_axis_w.toml", _toml_lines(plan, 'axis = "+x"', 'axis = "+w"'))
    w("plan_bare.toml", _toml_lines(plan, 'rate = "100 deg/s"', 'rate = "100"'))
    w("plan_number.toml", _toml_lines(plan, 'rate = "100 deg/s"', "rate = 100"))
    w("plan_kind.toml", _toml_lines(plan, 'rate = "100 deg/s"', 'rate = "100 deg"'))
    w("plan_nan.toml", _toml_lines(plan, 'rate = "100 deg/s"', 'rate = "nan deg/s"'))
    w("plan_inf.toml", _toml_lines(plan, 'rate = "100 deg/s"', 'rate = "inf deg/s"'))
    w("plan_huge.toml", _toml_lines(plan, 'rate = "100 deg/s"', 'rate = "1e300 deg/s"'))
    w("plan_zero.toml", _toml_lines(plan, 'rate = "100 deg/s"', 'rate = "0 deg/s"'))
    w("plan_both.toml", _toml_lines(plan, 'rate = "100 deg/s"', 'rate = "100 deg/s"\nangle = "360 deg"'))
    w("plan_lat100.toml", _in_test(plan, 'latitude = "100 deg"'))
    w("plan_latbare.toml", _in_test(plan, 'latitude = "48"'))
    w("plan_negacc.toml", _in_test(plan, 'angle_accuracy = "-1 deg"'))
    w("plan_empty.toml", "")
    w("plan_comment.toml", "# only a comment\n")
    w("plan_syntax.toml", plan + "\n[[step]\naxis = +y\n")
    (d / "plan_latin1.toml").write_bytes(("# caf\xe9 plan\n" + plan).encode("latin-1"))
    (d / "plan_nul.toml").write_bytes(plan.encode() + b"\x00\x00")
    # the steps as run, but step 3 written the wrong way, and the y and z pairs swapped
    steps = plan.split("[[step]]")
    w("plan_step3sign.toml", "[[step]]".join(steps[:3] + [steps[3].replace('"100 deg/s"', '"-100 deg/s"')] + steps[4:]))
    w("plan_swapyz.toml", "[[step]]".join([steps[0], steps[1], steps[2], steps[5], steps[6], steps[3], steps[4]]))
    w("plan_xy.toml", "[[step]]".join(steps[:5]))  # no z steps: the session has six dwells
    w("plan_1000.toml", plan.replace("100 deg/s", "1000 deg/s"))
    w("plan_4steps_xy.toml", "[[step]]".join(steps[:5]))
    w("plan_unknown_top.toml", "units = \"deg/s\"\n" + plan)
    ang = (d / "angle_plan.toml").read_text()
    w("angle_plan_angl.toml", ang.replace("angle =", "angl =", 1))


def _segments(d: Path) -> None:
    """Explicit segments of the simulated session (50 Hz, 2 s gaps, 4 s dwells) from its plan timing."""
    names, data = read_csv(d / "session.csv")
    t, g = data[:, 0], data[:, 1:]
    # dwells: where |g| is near 100 deg/s for at least 1 s
    moving = np.linalg.norm(g, axis=1) > 80
    edges = np.flatnonzero(np.diff(moving.astype(int)))
    runs = [(edges[i] + 1, edges[i + 1] + 1) for i in range(0, len(edges) - 1, 2)]
    runs = [(a + 10, b - 10) for a, b in runs if b - a > FS_SESSION]
    segs = {f"step{k + 1}": {"start": int(a), "end": int(b)} for k, (a, b) in enumerate(runs[:6])}
    (d / "segments.json").write_text(json.dumps(segs))
    bad = dict(segs)
    bad["step2"] = {"strat": segs["step2"]["start"], "end": segs["step2"]["end"]}
    (d / "segments_strat.json").write_text(json.dumps(bad))
    extra = {k: dict(v) for k, v in segs.items()}
    extra["step3"]["ends"] = 5
    (d / "segments_extrakey.json").write_text(json.dumps(extra))
    out = dict(segs)
    out["step6"] = {"start": segs["step6"]["start"], "end": len(t) + 500}
    (d / "segments_range.json").write_text(json.dumps(out))
    fl = dict(segs)
    fl["step1"] = {"start": float(segs["step1"]["start"]) + 0.5, "end": segs["step1"]["end"]}
    (d / "segments_float.json").write_text(json.dumps(fl))
    few = {k: v for k, v in segs.items() if k != "step6"}
    (d / "segments_few.json").write_text(json.dumps(few))
    rev = dict(segs)
    rev["step1"] = {"start": segs["step1"]["end"], "end": segs["step1"]["start"]}
    (d / "segments_reversed.json").write_text(json.dumps(rev))
    (d / "segments_empty.json").write_text("{}")
    (d / "segments_list.json").write_text(json.dumps(list(segs.values())))
    (d / "segments_syntax.json").write_text(json.dumps(segs)[:-5])


def _static_logs(d: Path, rng: np.random.Generator) -> None:
    """A static gyro record (deg/s): white noise with a slow bias wander, 100 Hz, 60 s."""
    n = int(60 * FS_STATIC)
    t = np.arange(n) / FS_STATIC
    white = rng.normal(0, 0.05, (n, 3))
    wander = np.cumsum(rng.normal(0, 2e-4, (n, 3)), axis=0)
    g = np.array([0.2, -0.1, 0.05]) + white + wander
    names = ["time", "gyro_x", "gyro_y", "gyro_z"]
    data = np.column_stack([t, g])
    write_csv(d / "static.csv", names, data)
    text = (d / "static.csv").read_text()
    (d / "static.csv.gz").write_bytes(gzip.compress(text.encode()))
    np.save(d / "static.npy", g)
    g.astype("<f8").tofile(d / "static.bin")
    (d / "static_odd.bin").write_bytes(g.astype("<f8").tobytes()[:-5])
    import pyarrow as pa
    import pyarrow.parquet as pq

    pq.write_table(pa.table({nm: data[:, j] for j, nm in enumerate(names)}), d / "static.parquet")
    np.savetxt(d / "static.txt", data, fmt="%.10g")
    np.save(d / "static_int16.npy", np.round(g * 1000).astype(np.int16))
    np.save(d / "static_1d.npy", g[:, 0])
    write_csv(d / "static_run2.csv", names, np.column_stack([t, g[::-1]]))
    write_csv(d / "static_200hz.csv", names, np.column_stack([t / 2, g]))
    write_csv(d / "static_zero.csv", names, np.column_stack([t, np.zeros_like(g)]))
    write_csv(d / "static_const.csv", names, np.column_stack([t, np.full_like(g, 0.25)]))
    np.save(d / "static_zero.npy", np.zeros_like(g))
    nan = g.copy()
    nan[3000, 1] = np.nan
    np.save(d / "static_nan.npy", nan)
    nan.astype("<f8").tofile(d / "static_nan.bin")
    _edit_lines(d / "static.csv", d / "static_nan.csv", lambda ls: _set_cell(ls, 3001, 2, "nan"))
    _edit_lines(d / "static.csv", d / "static_huge.csv", lambda ls: _set_cell(ls, 3001, 2, "1e300"))
    _edit_lines(d / "static.csv", d / "static_textcell.csv", lambda ls: _set_cell(ls, 3001, 1, "x"))
    gap = np.ones(n, bool)
    gap[2000:2300] = False
    write_csv(d / "static_gap.csv", names, data[gap])
    back = data.copy()
    back[4000, 0] = back[3000, 0]
    write_csv(d / "static_backwards.csv", names, back)
    (d / "static_header.csv").write_text(text.splitlines()[0] + "\n")
    (d / "static_empty.csv").write_text("")
    (d / "static_latin1.txt").write_bytes(b"# gyro \xb0/s\n" + (d / "static.txt").read_bytes())
    write_csv(d / "static_short.csv", names, data[:5])
    # an accelerometer static record (g): --units g
    write_csv(d / "static_acc.csv", ["time", "acc_x", "acc_y", "acc_z"],
              np.column_stack([t, np.array([0.01, -0.02, 1.0]) + rng.normal(0, 1e-3, (n, 3))]))


def _ferraris_inputs(d: Path, rng: np.random.Generator) -> None:
    names = ["acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z"]
    acc, gyr, sections = _ferraris_session(np.random.default_rng(5))
    write_csv(d / "ferraris.csv", names, np.column_stack([acc, gyr]))
    (d / "sections.json").write_text(json.dumps(sections))
    write_csv(d / "ferraris_g.csv", names, np.column_stack([acc / G, gyr]))              # accelerometer in g
    write_csv(d / "ferraris_flipacc.csv", names, np.column_stack([acc * [1, -1, 1], gyr]))  # a flipped accel axis
    write_csv(d / "ferraris_flipgyr.csv", names, np.column_stack([acc, gyr * [1, 1, -1]]))  # a flipped gyro axis
    write_csv(d / "ferraris_radgyr.csv", names, np.column_stack([acc, np.radians(gyr)]))   # gyro in rad/s
    write_csv(d / "ferraris_zero.csv", names, np.zeros_like(np.column_stack([acc, gyr])))
    _edit_lines(d / "ferraris.csv", d / "ferraris_nan.csv", lambda ls: _set_cell(ls, 400, 1, "nan"))
    _edit_lines(d / "ferraris.csv", d / "ferraris_textcell.csv", lambda ls: _set_cell(ls, 400, 4, "--"))
    write_csv(d / "ferraris_short.csv", names, np.column_stack([acc, gyr])[:300])
    np.save(d / "ferraris.npy", np.column_stack([acc, gyr]))
    text = (d / "ferraris.csv").read_text()
    (d / "ferraris.csv.gz").write_bytes(gzip.compress(text.encode()))
    _parquet(d / "ferraris.parquet", names, np.column_stack([acc, gyr]))
    (d / "ferraris_header.csv").write_text(text.splitlines()[0] + "\n")
    _edit_lines(d / "ferraris.csv", d / "ferraris_huge.csv", lambda ls: _set_cell(ls, 400, 2, "1e300"))
    s = lambda name, obj: (d / name).write_text(json.dumps(obj))  # noqa: E731
    sw = dict(sections)
    sw["x_p"], sw["x_a"] = sections["x_a"], sections["x_p"]
    s("sections_swapped.json", sw)
    eq = dict(sections)
    eq["x_a"] = sections["x_p"]
    s("sections_xa_eq_xp.json", eq)
    mis = {("x_pp" if k == "x_p" else k): v for k, v in sections.items()}
    s("sections_xpp.json", mis)
    extra = dict(sections)
    extra["w_rot"] = sections["z_rot"]
    s("sections_extra.json", extra)
    stat = dict(sections)
    stat["y_p"] = {"stat": sections["y_p"]["start"], "end": sections["y_p"]["end"]}
    s("sections_stat.json", stat)
    rng_ = dict(sections)
    rng_["z_rot"] = {"start": sections["z_rot"]["start"], "end": 10**6}
    s("sections_range.json", rng_)
    neg = dict(sections)
    neg["x_p"] = {"start": -5, "end": sections["x_p"]["end"]}
    s("sections_negative.json", neg)
    rev = dict(sections)
    rev["y_a"] = {"start": sections["y_a"]["end"], "end": sections["y_a"]["start"]}
    s("sections_reversed.json", rev)
    flt = dict(sections)
    flt["z_p"] = {"start": sections["z_p"]["start"] + 0.5, "end": sections["z_p"]["end"]}
    s("sections_float.json", flt)
    short = dict(sections)
    short["x_rot"] = {"start": sections["x_rot"]["start"], "end": sections["x_rot"]["start"] + 20}
    s("sections_shortrot.json", short)
    moving = dict(sections)
    moving["z_a"] = sections["y_rot"]
    s("sections_moving.json", moving)
    s("sections_empty.json", {})
    s("sections_list.json", list(sections.values()))
    (d / "sections_syntax.json").write_text(json.dumps(sections)[:-3])
    (d / "sections_latin1.json").write_bytes(json.dumps({"x_p\xe9": 1}, ensure_ascii=False).encode("latin-1"))


def _accel_inputs(d: Path, rng: np.random.Generator) -> None:
    t, a, ups, ranges = _accel_session(np.random.default_rng(6))
    names = ["time", "acc_x", "acc_y", "acc_z"]
    write_csv(d / "accel.csv", names, np.column_stack([t, a]))
    write_csv(d / "accel_g.csv", names, np.column_stack([t, a / G]))
    write_csv(d / "accel_flipy.csv", names, np.column_stack([t, a * [1, -1, 1]]))
    write_csv(d / "accel_const.csv", names, np.column_stack([t, np.tile([0.1, 0.2, 9.8], (len(t), 1))]))
    _edit_lines(d / "accel.csv", d / "accel_nan.csv", lambda ls: _set_cell(ls, 500, 3, "nan"))
    _edit_lines(d / "accel.csv", d / "accel_huge.csv", lambda ls: _set_cell(ls, 500, 3, "-1e300"))
    (d / "accel.csv.gz").write_bytes(gzip.compress((d / "accel.csv").read_bytes()))
    _parquet(d / "accel.parquet", names, np.column_stack([t, a]))
    back = np.column_stack([t, a])
    back[900, 0] = back[800, 0]
    write_csv(d / "accel_backwards.csv", names, back)

    def up_text(u):
        labels = {(1, 0, 0): "+x", (-1, 0, 0): "-x", (0, 1, 0): "+y", (0, -1, 0): "-y", (0, 0, 1): "+z", (0, 0, -1): "-z"}
        key = tuple(int(round(v)) for v in u)
        return f'"{labels[key]}"' if key in labels and abs(np.linalg.norm(u) - 1) < 1e-9 and max(abs(u)) == 1 else \
            "[" + ", ".join(f"{v:.6f}" for v in u) + "]"

    def positions(ups_, with_ranges=True, key_up="up", gravity_key="gravity", extra=""):
        out = [f'{gravity_key} = "9.80665 m/s^2"', ""]
        for k, (u, (s0, e0)) in enumerate(zip(ups_, ranges)):
            out.append("[[position]]")
            out.append(f'name = "p{k + 1}"')
            out.append(f"{key_up} = {up_text(u)}")
            if with_ranges:
                out.append(f"start = {s0}")
                out.append(f"end = {e0}")
            if k == 11:
                out.append("holdout = true" + extra)
            out.append("")
        return "\n".join(out)

    w = lambda name, text: (d / name).write_text(text)  # noqa: E731
    w("positions.toml", positions(ups))
    w("positions_auto.toml", positions(ups, with_ranges=False))
    w("positions_upp.toml", positions(ups, key_up="upp"))
    w("positions_gravty.toml", positions(ups, gravity_key="gravty"))
    w("positions_holdot.toml", positions(ups).replace("holdout = true", "holdot = true"))
    swapped = list(ups)
    swapped[0], swapped[1] = ups[1], ups[0]
    w("positions_swapped.toml", positions(swapped))
    w("positions_empty.toml", "")
    w("positions_axis_w.toml", positions(ups).replace('up = "+y"', 'up = "+w"', 1))
    w("positions_zero_up.toml", positions(ups).replace('up = "+y"', "up = [0, 0, 0]", 1))
    w("positions_gravity_mm.toml", positions(ups).replace('"9.80665 m/s^2"', '"9.81 mm"'))
    w("positions_gravity_neg.toml", positions(ups).replace('"9.80665 m/s^2"', '"-9.81 m/s^2"'))
    w("positions_gravity_zero.toml", positions(ups).replace('"9.80665 m/s^2"', '"0 m/s^2"'))
    w("positions_range.toml", positions(ups).replace(f"end = {ranges[-1][1]}", "end = 999999"))
    mixed = positions(ups).replace(f"start = {ranges[0][0]}\nend = {ranges[0][1]}\n", "")
    w("positions_mixed.toml", mixed)
    (d / "positions_latin1.toml").write_bytes(("# pos\xe9\n" + positions(ups)).encode("latin-1"))
    w("positions_syntax.toml", positions(ups) + "\n[[position]\n")


def _mag_inputs(d: Path, rng: np.random.Generator) -> None:
    m, acc = _mag_capture(np.random.default_rng(8))
    names = ["mag_x", "mag_y", "mag_z", "acc_x", "acc_y", "acc_z"]
    write_csv(d / "mag.csv", names, np.column_stack([m, acc]))
    np.savetxt(d / "mag.txt", m, fmt="%.6f")
    np.save(d / "mag.npy", m)
    _parquet(d / "mag.parquet", names, np.column_stack([m, acc]))
    write_csv(d / "mag_gauss.csv", names, np.column_stack([m / 100.0, acc]))    # gauss, read as uT
    write_csv(d / "mag_nt.csv", names, np.column_stack([m * 1000.0, acc]))      # nT, read as uT
    write_csv(d / "mag_const.csv", names, np.column_stack([np.tile([20.0, 5.0, -40.0], (len(m), 1)), acc]))
    write_csv(d / "mag_zero.csv", names, np.zeros((len(m), 6)))
    planar = m.copy()
    planar[:, 2] = 3.0
    write_csv(d / "mag_planar.csv", names, np.column_stack([planar, acc]))
    _edit_lines(d / "mag.csv", d / "mag_nan.csv", lambda ls: _set_cell(ls, 600, 1, "nan"))
    _edit_lines(d / "mag.csv", d / "mag_textcell.csv", lambda ls: _set_cell(ls, 600, 0, "12,5"))
    _edit_lines(d / "mag.csv", d / "mag_huge.csv", lambda ls: _set_cell(ls, 600, 0, "1e300"))
    (d / "mag_empty.csv").write_text("")
    (d / "mag_header.csv").write_text(",".join(names) + "\n")
    (d / "mag_latin1.txt").write_bytes(b"\xb5T readings\n" + (d / "mag.txt").read_bytes())
    write_csv(d / "mag_short.csv", names, np.column_stack([m, acc])[:8])
    write_csv(d / "mag_flipacc.csv", names, np.column_stack([m, acc * [1, 1, -1]]))
    write_csv(d / "mag_timed.csv", ["time"] + names[:3], np.column_stack([np.arange(len(m)) / 50.0, m]))
    bazhin = SHARED_DATA / "magnetometer" / "bazhin" / "mag_out.txt"
    if bazhin.is_file() and bazhin.stat().st_size < 100_000:
        shutil.copy(bazhin, d / "bazhin_mag_out.txt")


def _logger_files(d: Path) -> None:
    """Logs as data loggers write them (issue 12): time in ms or ns, a preamble, comments, ';', tabs, blanks,
    raw counts; each must read like the plain file with the options that say so."""
    names, data = read_csv(d / "session.csv")
    text = (d / "session.csv").read_text()
    ms, ns = data.copy(), data.copy()
    ms[:, 0] *= 1e3
    ns[:, 0] = np.round(ns[:, 0] * 1e9)
    write_csv(d / "session_ms.csv", names, ms)
    (d / "session_ns.csv").write_text(_csv_text(names, ns, "%.17g"))
    (d / "session_preamble.csv").write_text("Fs,50\nLogging Type,1\nsensor,sim\n" + text)
    lines = text.splitlines()
    lines = ["# logger 1.0", "# gyro in deg/s", lines[0], *lines[1:400], "# paused", *lines[400:]]
    (d / "session_comments.csv").write_text("\n".join(lines) + "\n")
    (d / "session_tab.csv").write_text(text.replace(",", "\t"))
    (d / "session_blanks.txt").write_text(text.replace(",", "   "))
    counts = np.column_stack([data[:, 0], np.round(data[:, 1:] * 131)])
    write_csv(d / "session_counts.csv", names, counts)
    names_s, static = read_csv(d / "static.csv")
    (d / "static_preamble.csv").write_text("Fs,100\nLogging Type,1\nInitialization time,-1\nWaiting time,-1\n"
                                           + (d / "static.csv").read_text())
    static_ms = static.copy()
    static_ms[:, 0] *= 1e3
    write_csv(d / "static_ms.csv", names_s, static_ms)
    names_a, accel = read_csv(d / "accel.csv")
    accel_us = accel.copy()
    accel_us[:, 0] = np.round(accel_us[:, 0] * 1e6)
    write_csv(d / "accel_us.csv", names_a, accel_us)
    (d / "mag_semicolon.csv").write_text("# HMC5883L capture\n" + (d / "mag.csv").read_text().replace(",", ";"))
    (d / "ferraris_preamble.csv").write_text("logger,2\nrate,50\n" + (d / "ferraris.csv").read_text())


def _mount_and_manoeuvres(d: Path) -> None:
    mount = (EXAMPLES / "budget" / "example1.toml").read_text()
    man = (EXAMPLES / "sensitivity" / "example2.toml").read_text()
    (d / "mount.toml").write_text(mount)
    (d / "manoeuvre.toml").write_text(man)
    shutil.copy(EXAMPLES / "sensitivity" / "sequence.toml", d / "sequence.toml")
    w = lambda name, text: (d / name).write_text(text)  # noqa: E731
    w("mount_postol.toml", mount + 'position_tolerence = "0.05 mm"\n')
    w("mount_postol_ok.toml", mount + 'position_tolerance = "0.05 mm"\n')
    w("mount_axis.toml", _toml_lines(mount, "axis_to_package", "axis_to_packag"))
    w("mount_height.toml", _toml_lines(mount, "height_tolerance", "heigth_tolerance"))
    w("mount_packge.toml", _toml_lines(mount, "[package]", "[packge]"))
    w("mount_screw.toml", _toml_lines(mount, "[screws]", "[screw]"))
    w("mount_top.toml", 'units = "mm"\n' + mount)
    w("mount_zero.toml", _toml_lines(mount, 'size_x = "47 mm"', 'size_x = "0 mm"'))
    w("mount_neg.toml", _toml_lines(mount, 'size_x = "47 mm"', 'size_x = "-47 mm"'))
    w("mount_bare.toml", _toml_lines(mount, 'size_x = "47 mm"', 'size_x = "47"'))
    w("mount_kind.toml", _toml_lines(mount, 'size_x = "47 mm"', 'size_x = "47 deg"'))
    w("mount_nan.toml", _toml_lines(mount, 'size_x = "47 mm"', 'size_x = "nan mm"'))
    w("mount_huge.toml", _toml_lines(mount, 'height_tolerance = "0.2 mm"', 'height_tolerance = "1e300 mm"'))
    w("mount_tilt_neg.toml", _toml_lines(mount, 'axis_to_package = "1 deg"', 'axis_to_package = "-1 deg"'))
    w("mount_tilt_big.toml", _toml_lines(mount, 'axis_to_package = "1 deg"', 'axis_to_package = "400 deg"'))
    w("mount_part.toml", _toml_lines(_toml_lines(mount, 'part = "ADIS16485"', 'part = "ADIS99999"'),
                                     'axis_to_package = "1 deg"\n', ""))
    w("mount_hole.toml", _toml_lines(mount, 'hole_diameter = "2.85 mm"', 'hole_diameter = "1.5 mm"'))
    w("mount_dist.toml", _toml_lines(mount, "[ledges]", '[ledges]\ndistribution = "gaussian"'))
    w("mount_noledges.toml", mount.split("[ledges]")[0] + "[screws]" + mount.split("[screws]")[1])
    w("mount_empty.toml", "")
    w("mount_syntax.toml", mount.replace('size_x = "47 mm"', "size_x = 47 mm"))
    (d / "mount_latin1.toml").write_bytes(("# support en t\xf4le\n" + mount).encode("latin-1"))
    _baseplate(d / "plate.stl")
    plate = mount.split("[ledges]")[0] + '[baseplate]\nstl = "plate.stl"\nledge_band = "1 mm"\n\n[screws]' + \
        mount.split("[screws]")[1]
    w("mount_plate.toml", plate)
    w("mount_plate_missing.toml", plate.replace('"plate.stl"', '"no_such_plate.stl"'))
    w("mount_plate_notstl.toml", plate.replace('"plate.stl"', '"notes.txt"'))
    w("mount_plate_band.toml", plate.replace("ledge_band", "ledge_bnd"))
    w("manoeuvre_axs.toml", _toml_lines(man, 'axis = "z"', 'axs = "z"'))
    w("manoeuvre_limit.toml", man.replace("[limits]", "[limit]"))
    w("manoeuvre_zz.toml", _toml_lines(man, 'z = "1 deg"', 'zz = "1 deg"'))
    w("manoeuvre_rotaton.toml", man.replace("[[rotation]]", "[[rotaton]]"))
    w("manoeuvre_angle0.toml", _toml_lines(man, 'angle = "30 deg"', 'angle = "0 deg"'))
    w("manoeuvre_bare.toml", _toml_lines(man, 'angle = "30 deg"', 'angle = "30"'))
    w("manoeuvre_kind.toml", _toml_lines(man, 'angle = "30 deg"', 'angle = "30 mm"'))
    w("manoeuvre_nan.toml", _toml_lines(man, 'angle = "30 deg"', 'angle = "nan deg"'))
    w("manoeuvre_huge.toml", _toml_lines(man, 'angle = "30 deg"', 'angle = "1e300 deg"'))
    w("manoeuvre_limneg.toml", _toml_lines(man, 'y = "1 deg"', 'y = "-1 deg"'))
    w("manoeuvre_limnan.toml", _toml_lines(man, 'y = "1 deg"', 'y = "nan deg"'))
    w("manoeuvre_axisw.toml", _toml_lines(man, 'axis = "z"', 'axis = "w"'))
    w("manoeuvre_tight.toml", _toml_lines(man, 'z = "1 deg"', 'z = "0.1 deg"').replace('y = "1 deg"', 'y = "0.1 deg"'))
    w("manoeuvre_empty.toml", "")
    (d / "manoeuvre_latin1.toml").write_bytes(("# man\u0153uvre\n" + man).encode("cp1252"))
    t = np.arange(21) / 10.0
    rates = np.column_stack([t, np.zeros(21), np.zeros(21), np.full(21, 15.0)])  # 30 deg about z in 2 s
    write_csv(d / "rates.csv", ["time", "wx", "wy", "wz"], rates)
    write_csv(d / "rates_rad.csv", ["time", "wx", "wy", "wz"], rates * [1, 1, 1, np.pi / 180])
    bad = rates.copy()
    bad[10, 3] = np.nan
    write_csv(d / "rates_nan.csv", ["time", "wx", "wy", "wz"], bad)
    series = '[series]\nfile = "{f}"\n{extra}\n[limits]\ny = "1 deg"\nz = "1 deg"\n'
    w("series.toml", series.format(f="rates.csv", extra=""))
    w("series_unit.toml", series.format(f="rates_rad.csv", extra='unit = "rad/s"'))
    w("series_units_ok.toml", series.format(f="rates_rad.csv", extra='units = "rad/s"'))
    w("series_missing.toml", series.format(f="no_such_rates.csv", extra=""))
    w("series_nan.toml", series.format(f="rates_nan.csv", extra=""))
    w("series_serie.toml", series.format(f="rates.csv", extra="").replace("[series]", "[serie]"))
    w("series_both.toml", series.format(f="rates.csv", extra="") + '\n[[rotation]]\naxis = "z"\nangle = "30 deg"\n')


def _baseplate(path: Path) -> None:
    """A baseplate STL (mm) with four 6 mm corner ledges under Example 1's 47 x 44 mm package, one 0.2 mm high."""
    import trimesh

    parts = [trimesh.creation.box(extents=[60, 60, 2])]
    parts[0].apply_translation([0, 0, -5])
    for k, (sx, sy) in enumerate([(1, 1), (-1, 1), (-1, -1), (1, -1)]):
        h = 0.2 if k == 0 else 0.0
        box = trimesh.creation.box(extents=[6, 6, 4 + h])
        box.apply_translation([sx * (47 / 2 - 3), sy * (44 / 2 - 3), (h - 4) / 2])
        parts.append(box)
    trimesh.util.concatenate(parts).export(path)


def _results(d: Path) -> None:
    """Result files of every kind, made by the commands, and their broken variants."""
    out = d / "_results"
    out.mkdir()
    _must(["matrix", d / "session.csv", "--plan", d / "plan.toml", "--json", out / "alignment.json"],
          out / "alignment.json")
    _must(["calibrate", "ferraris", d / "ferraris.csv", "--sections", d / "sections.json", "--rate-hz", f"{FS_FERRARIS:g}",
           "--json", out / "calibration.json"], out / "calibration.json")
    _must(["calibrate", "accel", d / "accel.csv", "--positions", d / "positions.toml", "--json", out / "accel_cal.json"],
          out / "accel_cal.json")
    _must(["calibrate", "mag", d / "mag.csv", "--json", out / "magnetometer.json"], out / "magnetometer.json")
    _must(["allan", d / "static.csv", "--json", out / "allan.json"], out / "allan.json")
    _must(["plan", "--rate", "100 deg/s", "--accuracy", "0.1 deg", "--arw", "0.3 deg/sqrt(h)", "--json",
           out / "plan_result.json"], out / "plan_result.json")
    _must(["budget", d / "mount.toml", "--json", out / "budget.json"], out / "budget.json")
    _must(["allowable", d / "manoeuvre.toml", "--json", out / "allowable.json"], out / "allowable.json")
    _must(["check", d / "mount.toml", d / "manoeuvre.toml", "--json", out / "check.json"], out / "check.json")
    for p in out.iterdir():
        shutil.move(p, d / p.name)
    out.rmdir()

    def variant(src: str, name: str, edit) -> None:
        data = json.loads((d / src).read_text())
        edit(data)
        (d / name).write_text(json.dumps(data, indent=1))

    def put(key, value):
        return lambda r: r.__setitem__(key, value)

    for kind, src in (("alignment", "alignment.json"), ("calibration", "calibration.json"),
                      ("magnetometer", "magnetometer.json"), ("allan", "allan.json"), ("accelcal", "accel_cal.json")):
        variant(src, f"{kind}_v99.json", put("version", 99))
        variant(src, f"{kind}_format.json", put("format", "imu-align.unheard-of"))
        variant(src, f"{kind}_noformat.json", lambda r: r.pop("format"))
        variant(src, f"{kind}_extrakey.json", put("calibraton_note", "typo'd key"))
    m = np.array(json.loads((d / "alignment.json").read_text())["M"])
    variant("alignment.json", "alignment_nullM.json", put("M", [[None] * 3] * 3))
    variant("alignment.json", "alignment_nullA.json", put("A", [[None] * 3] * 3))
    sing = m.copy()
    sing[2] = sing[0]
    variant("alignment.json", "alignment_singular.json", lambda r: r.update(M=sing.tolist(), A=np.linalg.pinv(sing).tolist()))
    neg = m * np.array([[1], [-1], [1]])
    variant("alignment.json", "alignment_det_neg.json", lambda r: r.update(M=neg.tolist(), A=np.linalg.inv(neg).tolist()))
    variant("alignment.json", "alignment_M_2x3.json", lambda r: r.update(M=m[:2].tolist()))
    variant("alignment.json", "alignment_M_text.json", lambda r: r.update(M="identity"))
    variant("alignment.json", "alignment_bais.json", lambda r: r.update(bais=r.pop("bias")))
    variant("alignment.json", "alignment_units.json", lambda r: r["units"].update(bias="furlongs"))

    def cal_edit(sensor, key, value):
        return lambda r: r[sensor].__setitem__(key, value)

    variant("calibration.json", "calibration_nullM.json", cal_edit("accelerometer", "M", [[None] * 3] * 3))
    cm = np.array(json.loads((d / "calibration.json").read_text())["accelerometer"]["M"])
    variant("calibration.json", "calibration_det_neg.json", cal_edit("accelerometer", "M", (cm * [[1], [-1], [1]]).tolist()))
    variant("calibration.json", "calibration_singular.json", cal_edit("accelerometer", "M", [[1, 0, 0], [0, 1, 0], [0, 0, 0]]))
    variant("calibration.json", "calibration_sensor.json",
            lambda r: r.__setitem__("accelerometr", r.pop("accelerometer")))
    mag = json.loads((d / "magnetometer.json").read_text())
    matrix_key = next((k for k in ("soft_iron", "W", "M") if k in mag), None)
    if matrix_key:
        variant("magnetometer.json", "magnetometer_null.json", put(matrix_key, [[None] * 3] * 3))
        variant("magnetometer.json", "magnetometer_singular.json", put(matrix_key, [[1, 0, 0], [0, 1, 0], [0, 0, 0]]))
        variant("magnetometer.json", "magnetometer_det_neg.json",
                put(matrix_key, (np.array(mag[matrix_key]) * [[1], [-1], [1]]).tolist()))
    allan = json.loads((d / "allan.json").read_text())
    drop = [k for k in allan if k not in ("format", "version", "generator", "convention", "units")]
    variant("allan.json", "allan_missing.json", lambda r: [r.pop(k) for k in drop[: max(1, len(drop) // 2)]])
    variant("allan.json", "allan_typo.json", lambda r: r.__setitem__(drop[0] + "s", r.pop(drop[0])))
    (d / "result_empty.json").write_text("")
    (d / "result_array.json").write_text("[1, 2, 3]\n")
    (d / "result_syntax.json").write_text((d / "alignment.json").read_text()[:-20])
    (d / "result_latin1.json").write_bytes(b'{"format": "imu-align.alignment", "note": "\xe9"}')
    (d / "result_foreign.json").write_text(json.dumps({"K_a": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "b_a": [0, 0, 0]}))


def _misc(d: Path) -> None:
    (d / "notes.txt").write_text("not a log\n")
    (d / "image.png").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(64))
