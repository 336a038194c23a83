"""The bad-input campaign's table: every command, every input, every class of mistake (issue 11).

Each :class:`Case` is one run of ``imu-align`` and what a careful user expects of it:

* ``code``: 0 (a borderline input that must work), 2 (bad input or usage), 3 (the test or result
  cannot be trusted: a unit mix-up, a handedness error, a dead record) or 4 (a failed check);
* ``names``: what the one line on stderr must name (case-insensitive substrings; ``"a|b"`` means
  either), typically the file, the option flag or the key; ``forbid``: what it must not say;
* ``outputs``: files a successful run writes (relative to the case folder).

Arguments are one shell-like string with three kinds of token:

* ``IN:name``   a copy of the campaign input ``name`` in the case folder (hashed before and after);
* ``REL:name``  the same copy, given by its bare name (the run's working folder is the case folder);
* ``CASE:path`` a path in the case folder (outputs, folders made by ``setup``).

``setup`` prepares the case folder: ``("mkdir", rel)``, ``("file", rel, text)``, ``("symlink", rel,
target_rel)``, ``("readonly", rel)`` (a chmod 555 folder), ``("input", name, rel)`` (a hashed copy of
an input at ``rel``). ``extra`` lists inputs a file refers to (a manoeuvre's rate series).

Grow this table whenever a bug is found: one line per case.
"""

from __future__ import annotations

import shlex
from dataclasses import dataclass

from campaign_inputs import SHARED_DATA

#: the classes of the issue
KINDS = {
    "usage": "usage mistakes",
    "malformed": "malformed and borderline files",
    "borderline": "borderline inputs that must work",
    "domain": "option and field values out of domain",
    "units": "unit mix-ups",
    "handedness": "handedness",
    "keys": "misspelt or unknown keys",
    "results": "result files (format, version, M)",
    "outputs": "output paths (an input, twice, missing/read-only folder, a folder)",
    "partial": "partial outputs (all or none)",
}


@dataclass(frozen=True)
class Case:
    command: str
    kind: str
    name: str
    args: tuple[str, ...]
    code: int
    names: tuple[str, ...] = ()
    forbid: tuple[str, ...] = ()
    outputs: tuple[str, ...] = ()
    setup: tuple[tuple, ...] = ()
    extra: tuple[str, ...] = ()
    process: bool = False
    why: str = ""

    @property
    def id(self) -> str:
        return f"{self.command.replace(' ', '-')}/{self.kind}/{self.name}"


CASES: list[Case] = []


def add(command: str, kind: str, name: str, args: str, code: int, names=(), forbid=(), outputs=(), setup=(),
        extra=(), process=False, why="") -> None:
    assert kind in KINDS, kind
    as_tuple = lambda x: (x,) if isinstance(x, str) else tuple(x)  # noqa: E731
    CASES.append(Case(command, kind, name, tuple(shlex.split(args)), code, as_tuple(names), as_tuple(forbid),
                      as_tuple(outputs), tuple(setup), as_tuple(extra), process, why))


HANDED = "det|handed|backward|revers|mirror|flipped"
PROC = "/proc/imu-align-campaign"
#: what ``demo`` writes into its folder
DEMO_FILES = ("mount.toml", "manoeuvre.toml", "static.npy", "session.csv", "plan.toml", "budget.json", "allowable.json",
              "check.json", "allan.json", "plan.json", "alignment.json", "truth.json", "report.html")
#: never in a message: Python reprs and exception names
PYTHON_REPRS = ("np.float64(", "np.int64(", "Error('", 'Error("', "Error: ")
SYS = "/sys/imu-align-campaign"


def bad_values(command: str, base: str, flag: str, values: list[str], tag: str, names=None, forbid=(), setup=()):
    """One domain case per bad value of ``flag`` (values given with ``=``: a leading '-' stays a value)."""
    for v in values:
        label = v.replace(" ", "").replace("/", "per").replace("^", "") or "empty"
        add(command, "domain", f"{tag}={label}", f"{base} {shlex.quote(flag + '=' + v)}", 2, names or flag, forbid,
            setup=setup)


def output_cases(command: str, base: str, flag: str, ext: str, inputs: list[str], other: str | None = None,
                 readonly: bool = False):
    """An output flag: equal to each input, a folder, in a missing folder, unwritable, a symlink to an input
    (and, with ``readonly``, in a chmod 555 folder: skipped when the test runs as root, who may write there)."""
    short = flag.strip("-")
    for inp in inputs:
        add(command, "outputs", f"{short}-is-input-{inp}", f"{base} {flag} IN:{inp}", 2, (flag, inp))
    add(command, "outputs", f"{short}-is-folder", f"{base} {flag} CASE:outdir", 2, flag, setup=[("mkdir", "outdir")])
    add(command, "outputs", f"{short}-missing-folder", f"{base} {flag} CASE:nodir/out.{ext}", 2, (flag, "nodir"))
    add(command, "outputs", f"{short}-parent-is-file", f"{base} {flag} CASE:afile/out.{ext}", 2, flag,
        setup=[("file", "afile", "x")])
    add(command, "outputs", f"{short}-proc", f"{base} {flag} {PROC}.{ext}", 2, flag)
    if readonly:
        add(command, "outputs", f"{short}-readonly", f"{base} {flag} CASE:ro/out.{ext}", 2, flag, setup=[("readonly", "ro")])
    add(command, "outputs", f"{short}-symlink-to-input", f"{base} {flag} CASE:link.{ext}", 2, flag,
        setup=[("symlink", f"link.{ext}", inputs[0])])
    if other:
        add(command, "outputs", f"{short}-same-as-{other.strip('-')}", f"{base} {flag} CASE:same.{ext} {other} CASE:same.{ext}",
            2, f"{flag}|{other}")


# ====================================================================== top level

add("top", "usage", "no-args", "", 2, "command")
add("top", "usage", "unknown-command", "matrx", 2, "matrix")
add("top", "usage", "unknown-top-option", "--verbose", 2, "--verbose")
add("top", "borderline", "version", "--version", 0)
add("top", "borderline", "help", "--help", 0)
add("top", "borderline", "matrix-help", "matrix --help", 0)
add("top", "usage", "unknown-command-process", "bogus", 2, "bogus", process=True)

# ====================================================================== matrix

M = "matrix IN:session.csv --plan IN:plan.toml"
MN = "matrix IN:session_notime.csv --plan IN:plan.toml --columns gyro_x,gyro_y,gyro_z"
c = "matrix"
# borderline inputs that must work
add(c, "borderline", "csv-json-header", f"{M} --json CASE:r.json --c-header CASE:a.h", 0, outputs=("r.json", "a.h"))
add(c, "borderline", "csv-gz", "matrix IN:session.csv.gz --plan IN:plan.toml", 0)
add(c, "borderline", "parquet", "matrix IN:session.parquet --plan IN:plan.toml", 0)
add(c, "borderline", "npy-with-time", "matrix IN:session.npy --plan IN:plan.toml", 0)
add(c, "borderline", "blank-text", "matrix IN:session.txt --plan IN:plan.toml --columns col0,col1,col2,col3", 0)
add(c, "borderline", "crlf", "matrix IN:session_crlf.csv --plan IN:plan.toml", 0)
add(c, "borderline", "utf8-bom", "matrix IN:session_bom.csv --plan IN:plan.toml", 0,
    why="spreadsheets write a BOM before the header")
add(c, "borderline", "extra-column", "matrix IN:session_extra.csv --plan IN:plan.toml", 0)
add(c, "borderline", "reordered-columns", "matrix IN:session_reorder.csv --plan IN:plan.toml", 0)
add(c, "borderline", "gap-in-static", "matrix IN:session_gap.csv --plan IN:plan.toml", 0,
    why="20 samples lost inside a static gap do not touch any dwell")
add(c, "borderline", "no-time-rate-hz", f"{MN} --rate-hz 50", 0)
add(c, "borderline", "no-time-rate-hz-unit", f"{MN} --rate-hz '50 Hz'", 0)
add(c, "borderline", "angle-session", "matrix IN:angle_session.csv --plan IN:angle_plan.toml --json CASE:r.json", 0,
    outputs="r.json")
add(c, "borderline", "segments", f"{M} --segments IN:segments.json", 0)
add(c, "borderline", "latitude", "matrix IN:session.csv --plan IN:plan_latitude.toml", 0)
add(c, "borderline", "latitude-earth", "matrix IN:session.csv --plan IN:plan_latitude.toml --earth", 0)
add(c, "borderline", "latitude-no-earth", "matrix IN:session.csv --plan IN:plan_latitude.toml --no-earth", 0)
add(c, "borderline", "method-rate", f"{M} --method rate", 0)
add(c, "borderline", "gyro-units-dps", f"{M} --gyro-units dps", 0)
add(c, "borderline", "json-equals-form", f"{M} --json=CASE:r.json", 0, outputs="r.json")
add(c, "borderline", "relative-paths", "matrix REL:session.csv --plan REL:plan.toml --json r.json", 0, outputs="r.json")
add(c, "borderline", "gyro-range-ok", f"{M} --gyro-range '2000 deg/s'", 0)
# malformed logs
for log, extra_names in [
    ("session_nan.csv", "row"), ("session_emptycell.csv", "row"), ("session_inf.csv", "row"),
    ("session_textcell.csv", ()), ("session_huge.csv", "row"), ("session_empty.csv", ()), ("session_header.csv", ()),
    ("session_short.csv", ()), ("session_latin1.csv", ()), ("session_binary.csv", ()), ("session_semicolon.csv", ()),
    ("session_onecol.csv", "gyro_x"), ("session_twocols.csv", "gyro_z"), ("session_ragged.csv", ()),
    ("session_backwards.csv", "row"), ("session_duptime.csv", "row"), ("session_bad.npy", ()), ("session_str.npy", ()),
    ("session_3d.npy", ()), ("session_bad.parquet", ()), ("session_textcell.parquet", ()),
    ("session_strcell.parquet", ()), ("session_bad.csv.gz", ()), ("notes.txt", ()), ("image.png", ()),
]:
    names = (log,) + ((extra_names,) if isinstance(extra_names, str) else tuple(extra_names))
    add(c, "malformed", log, f"matrix IN:{log} --plan IN:plan.toml", 2, names)
add(c, "malformed", "log-missing", "matrix CASE:nope.csv --plan IN:plan.toml", 2, "nope.csv")
add(c, "malformed", "log-is-folder", "matrix CASE:logdir --plan IN:plan.toml", 2, "logdir", setup=[("mkdir", "logdir")])
add(c, "malformed", "no-time-column", "matrix IN:session_notime.csv --plan IN:plan.toml", 2,
    ("session_notime.csv", "--rate-hz"))
add(c, "malformed", "all-zero", "matrix IN:session_zero.csv --plan IN:plan.toml", 3, "session_zero.csv|step|dwell",
    why="the gyro never moved: nothing matches the plan")
add(c, "malformed", "constant", "matrix IN:session_const.csv --plan IN:plan.toml", 3, "session_const.csv|step|dwell")
add(c, "malformed", "nan-process", "matrix IN:session_nan.csv --plan IN:plan.toml", 2, ("session_nan.csv", "row"),
    process=True)
# plan files
for plan, key in [("plan_latitud.toml", "latitud"), ("plan_tset.toml", "tset"), ("plan_rateacc.toml", "rate_acuracy"),
                  ("plan_rat.toml", "rat"), ("plan_axes.toml", "axes"), ("plan_stepp.toml", "stepp"),
                  ("plan_unknown_top.toml", "units")]:
    add(c, "keys", plan, f"matrix IN:session.csv --plan IN:{plan}", 2, (plan, key))
add(c, "keys", "angle_plan_angl.toml", "matrix IN:angle_session.csv --plan IN:angle_plan_angl.toml", 2,
    ("angle_plan_angl.toml", "angl"))
for plan, what in [("plan_axis_w.toml", "axis"), ("plan_bare.toml", "rate"), ("plan_number.toml", "rate"),
                   ("plan_kind.toml", "rate"), ("plan_nan.toml", "rate"), ("plan_inf.toml", "rate"),
                   ("plan_huge.toml", "rate"), ("plan_zero.toml", "step 1"), ("plan_both.toml", "step 1"),
                   ("plan_lat100.toml", "latitude"), ("plan_latbare.toml", "latitude"),
                   ("plan_negacc.toml", "angle_accuracy")]:
    add(c, "domain", plan, f"matrix IN:session.csv --plan IN:{plan}", 2, (plan, what))
for plan in ("plan_empty.toml", "plan_comment.toml", "plan_syntax.toml", "plan_latin1.toml", "plan_nul.toml"):
    add(c, "malformed", plan, f"matrix IN:session.csv --plan IN:{plan}", 2, plan)
add(c, "malformed", "plan-missing", "matrix IN:session.csv --plan CASE:nope.toml", 2, "nope.toml")
add(c, "malformed", "plan-is-folder", "matrix IN:session.csv --plan CASE:plandir", 2, "plandir",
    setup=[("mkdir", "plandir")])
add(c, "malformed", "plan-is-the-log", "matrix IN:session.csv --plan IN:session.csv", 2, "session.csv")
# segments files
add(c, "keys", "segments_strat.json", f"{M} --segments IN:segments_strat.json", 2, ("segments_strat.json", "strat|start"))
add(c, "keys", "segments_extrakey.json", f"{M} --segments IN:segments_extrakey.json", 2, ("segments_extrakey.json", "ends"))
for seg in ("segments_range.json", "segments_float.json", "segments_few.json", "segments_reversed.json",
            "segments_empty.json", "segments_list.json", "segments_syntax.json"):
    add(c, "malformed", seg, f"{M} --segments IN:{seg}", 2, seg)
# unit mix-ups and tests that cannot be trusted
add(c, "units", "rad-read-as-deg", "matrix IN:session_rad.csv --plan IN:plan.toml", 3, "--gyro-units")
add(c, "units", "mdps-read-as-deg", "matrix IN:session_mdps.csv --plan IN:plan.toml", 3, "--gyro-units")
add(c, "units", "deg-declared-rad", f"{M} --gyro-units rad/s", 3, "--gyro-units")
add(c, "units", "deg-declared-mdps", f"{M} --gyro-units mdps", 3, "--gyro-units")
add(c, "units", "gyro-units-acceleration", f"{M} --gyro-units m/s^2", 2, "--gyro-units")
add(c, "units", "gyro-units-unknown", f"{M} --gyro-units furlong/s", 2, "--gyro-units")
add(c, "units", "gyro-units-empty", f"{M} --gyro-units=", 2, "--gyro-units")
add(c, "units", "plan-rate-10x", "matrix IN:session.csv --plan IN:plan_1000.toml", 3, "step 1|plan")
add(c, "units", "table-10x-slow", "matrix IN:session_slow.csv --plan IN:plan.toml", 3, "step 1|plan")
add(c, "handedness", "flipped-gyro-y", "matrix IN:session_flipy.csv --plan IN:plan.toml", 3, HANDED)
add(c, "handedness", "flipped-gyro-x-angle", "matrix IN:angle_session_flipx.csv --plan IN:angle_plan.toml", 3, HANDED)
add(c, "handedness", "step-3-wrong-way", "matrix IN:session.csv --plan IN:plan_step3sign.toml", 3, "step 3")
add(c, "handedness", "y-z-steps-swapped", "matrix IN:session.csv --plan IN:plan_swapyz.toml", 3, "step 3",
    forbid=("det(M)",), why="issue: a swapped plan must name the step, not claim a handedness error")
add(c, "borderline", "plan-without-z", "matrix IN:session.csv --plan IN:plan_xy.toml", 0,
    why="issue 12: the plan's steps are found among the log's motions; the z dwells are listed as left out and the "
        "two-axis shortcut states its assumptions")
add(c, "units", "saturation", f"{M} --gyro-range '50 deg/s'", 3, "satur|--gyro-range")
# option values
bad_values(c, MN, "--rate-hz", ["0", "-50", "nan", "inf", "1e300", "50 deg", "abc", "0 Hz"], "rate-hz",
           forbid=("no time column",))
bad_values(c, M, "--min-dwell", ["0 s", "-1 s", "1", "1 deg", "nan s", "inf s"], "min-dwell")
bad_values(c, M, "--window", ["0 s", "-0.1 s", "nan s", "1e300 s"], "window")
bad_values(c, M, "--margin", ["-0.1 s", "nan s", "1 deg/s"], "margin")
bad_values(c, M, "--static-threshold", ["-1 deg/s", "0 deg/s", "1 deg"], "static-threshold")
bad_values(c, M, "--rate-tolerance", ["-10 %", "nan %", "10 deg"], "rate-tolerance")
bad_values(c, M, "--scale-tolerance", ["-5 %", "nan %", "200 %"], "scale-tolerance")
bad_values(c, M, "--axis-to-axis", ["-0.05 deg", "0.05 mm", "nan deg"], "axis-to-axis")
bad_values(c, M, "--gyro-range", ["0 deg/s", "-2000 deg/s", "2000", "2000 deg"], "gyro-range")
add(c, "usage", "method-unknown", f"{M} --method bogus", 2, "--method")
add(c, "usage", "two-axis-variant-unknown", f"{M} --two-axis-variant bogus", 2, "--two-axis-variant")
add(c, "usage", "columns-two", f"{M} --columns time,gyro_x", 2, "--columns")
add(c, "usage", "columns-five", f"{M} --columns time,a,b,c,d", 2, "--columns")
add(c, "malformed", "columns-missing", f"{M} --columns time,gx,gy,gz", 2, ("session.csv", "gx"))
add(c, "usage", "no-arguments", "matrix", 2, "LOG|missing")
add(c, "usage", "no-plan", "matrix IN:session.csv", 2, "--plan")
add(c, "usage", "misspelt-option", f"{M} --plna IN:plan.toml", 2, "--plna")
add(c, "usage", "option-without-value", f"{M} --method", 2, "--method")
add(c, "usage", "json-without-value", f"{M} --json", 2, "--json")
add(c, "usage", "extra-argument", f"{M} IN:plan.toml", 2, "plan.toml|argument")
# outputs
output_cases(c, M, "--json", "json", ["plan.toml", "session.csv"], other="--c-header", readonly=True)
output_cases(c, M, "--c-header", "h", ["session.csv", "plan.toml"])
add(c, "outputs", "json-same-file-other-spelling", f"{M} --json CASE:sub/../plan.toml", 2, ("--json", "plan.toml"),
    setup=[("mkdir", "sub")])
add(c, "outputs", "json-is-segments", f"{M} --segments IN:segments.json --json IN:segments.json", 2, "--json")
add(c, "outputs", "json-sys", f"{M} --json {SYS}.json", 2, "--json")
add(c, "partial", "json-ok-header-proc", f"{M} --json CASE:r.json --c-header {PROC}.h", 2, "--c-header")
add(c, "partial", "json-ok-header-folder", f"{M} --json CASE:r.json --c-header CASE:hdir", 2, "--c-header",
    setup=[("mkdir", "hdir")])
add(c, "partial", "json-ok-header-missing-folder", f"{M} --json CASE:r.json --c-header CASE:nodir/a.h", 2, "--c-header")
add(c, "partial", "unit-mixup-writes-nothing", "matrix IN:session_rad.csv --plan IN:plan.toml --json CASE:r.json "
    "--c-header CASE:a.h", 3, "--gyro-units")
add(c, "partial", "handedness-writes-nothing", "matrix IN:session_flipy.csv --plan IN:plan.toml --json CASE:r.json "
    "--c-header CASE:a.h", 3, HANDED)

# ====================================================================== apply

A = "apply IN:session.csv --alignment IN:alignment.json"
c = "apply"
add(c, "borderline", "gyro", f"{A} --out CASE:c.csv", 0, outputs="c.csv")
add(c, "borderline", "gyro-csv-gz", "apply IN:session.csv.gz --alignment IN:alignment.json --out CASE:c.csv", 0,
    outputs="c.csv")
add(c, "borderline", "gyro-parquet", "apply IN:session.parquet --alignment IN:alignment.json --out CASE:c.csv", 0,
    outputs="c.csv")
add(c, "borderline", "gyro-no-time", "apply IN:session_notime.csv --alignment IN:alignment.json --rate-hz 50 "
    "--columns gyro_x,gyro_y,gyro_z --out CASE:c.csv", 0, outputs="c.csv")
add(c, "borderline", "ferraris-accelerometer", "apply IN:ferraris.csv --alignment IN:calibration.json --sensor "
    "accelerometer --rate-hz 50 --columns acc_x,acc_y,acc_z --out CASE:c.csv", 0, outputs="c.csv")
add(c, "borderline", "accel-calibration", "apply IN:accel.csv --alignment IN:accel_cal.json --out CASE:c.csv", 0,
    outputs="c.csv")
add(c, "borderline", "magnetometer", "apply IN:mag_timed.csv --alignment IN:magnetometer.json --out CASE:c.csv", 0,
    outputs="c.csv")
# result files
for res, extra_args, code, names in [
    ("alignment_v99.json", "", 2, "99|version"), ("alignment_format.json", "", 2, "unheard-of|format"),
    ("alignment_noformat.json", "", 2, "format"), ("alignment_nullM.json", "", 2, "M"),
    ("alignment_nullA.json", "", 2, "A"), ("alignment_singular.json", "", 3, "singular|invertible|det"),
    ("alignment_det_neg.json", "", 3, HANDED), ("alignment_M_2x3.json", "", 2, "M"),
    ("alignment_M_text.json", "", 2, "M"), ("alignment_bais.json", "", 2, "bais|bias"),
    ("alignment_extrakey.json", "", 2, "calibraton_note"), ("alignment_units.json", "", 2, "furlongs"),
    ("allan.json", "", 2, "allan"), ("budget.json", "", 2, "budget"), ("plan_result.json", "", 2, "plan"),
    ("allowable.json", "", 2, "allowable"), ("check.json", "", 2, "check"),
    ("result_empty.json", "", 2, ()), ("result_array.json", "", 2, ()),
    ("result_syntax.json", "", 2, ()), ("result_latin1.json", "", 2, ()), ("result_foreign.json", "", 2, "format"),
]:
    add(c, "results", res, f"{A.replace('alignment.json', res)} {extra_args} --out CASE:c.csv", code,
        (res,) + ((names,) if isinstance(names, str) else names))
FA = "apply IN:ferraris.csv --alignment IN:{res} --sensor accelerometer --rate-hz 50 --columns acc_x,acc_y,acc_z"
for res, code, names in [("calibration_v99.json", 2, "99|version"), ("calibration_format.json", 2, "format"),
                         ("calibration_noformat.json", 2, "format"), ("calibration_nullM.json", 2, "M"),
                         ("calibration_singular.json", 3, "singular|invertible|det"),
                         ("calibration_det_neg.json", 3, HANDED), ("calibration_sensor.json", 2, "accelerometr"),
                         ("calibration_extrakey.json", 2, "calibraton_note")]:
    add(c, "results", res, FA.format(res=res) + " --out CASE:c.csv", code, (res, names))
AC = "apply IN:accel.csv --alignment IN:{res}"
for res, code, names in [("accelcal_v99.json", 2, "99|version"), ("accelcal_format.json", 2, "format"),
                         ("accelcal_extrakey.json", 2, "calibraton_note")]:
    add(c, "results", res, AC.format(res=res) + " --out CASE:c.csv", code, (res, names))
MA = "apply IN:mag_timed.csv --alignment IN:{res}"
for res, code, names in [("magnetometer_v99.json", 2, "99|version"), ("magnetometer_format.json", 2, "format"),
                         ("magnetometer_noformat.json", 2, "format"), ("magnetometer_null.json", 2, "soft_iron"),
                         ("magnetometer_singular.json", 3, "singular|invertible|det|soft_iron"),
                         ("magnetometer_det_neg.json", 3, HANDED), ("magnetometer_extrakey.json", 2, "calibraton_note")]:
    add(c, "results", res, MA.format(res=res) + " --out CASE:c.csv", code, (res, names))
add(c, "results", "alignment-missing", "apply IN:session.csv --alignment CASE:nope.json --out CASE:c.csv", 2, "nope.json")
add(c, "results", "alignment-is-folder", "apply IN:session.csv --alignment CASE:rdir --out CASE:c.csv", 2, "rdir",
    setup=[("mkdir", "rdir")])
add(c, "usage", "two-sensors-no-sensor", "apply IN:ferraris.csv --alignment IN:calibration.json --rate-hz 50 "
    "--columns acc_x,acc_y,acc_z --out CASE:c.csv", 2, "--sensor")
add(c, "usage", "sensor-not-in-result", "apply IN:accel.csv --alignment IN:accel_cal.json --sensor gyroscope "
    "--out CASE:c.csv", 2, "--sensor")
add(c, "usage", "sensor-unknown", f"{A} --sensor compass --out CASE:c.csv", 2, "--sensor")
add(c, "usage", "no-out", f"{A}", 2, "--out")
add(c, "usage", "nothing", "apply", 2, "LOG|missing")
# logs
for log, names in [("session_nan.csv", "row"), ("session_textcell.csv", ()), ("session_header.csv", ()),
                   ("session_empty.csv", ()), ("session_latin1.csv", ()), ("session_huge.csv", "row"),
                   ("session_onecol.csv", "gyro_x")]:
    add(c, "malformed", log, f"apply IN:{log} --alignment IN:alignment.json --out CASE:c.csv", 2,
        (log,) + ((names,) if isinstance(names, str) else tuple(names)))
add(c, "malformed", "log-missing", "apply CASE:nope.csv --alignment IN:alignment.json --out CASE:c.csv", 2, "nope.csv")
AN = "apply IN:session_notime.csv --alignment IN:alignment.json --columns gyro_x,gyro_y,gyro_z --out CASE:c.csv"
bad_values(c, AN, "--rate-hz", ["0", "nan", "-50", "inf"], "rate-hz", forbid=("no time column",))
add(c, "units", "gyro-units-length", f"{A} --gyro-units m --out CASE:c.csv", 2, "--gyro-units")
add(c, "units", "units-rate-for-accel", "apply IN:accel.csv --alignment IN:accel_cal.json --units deg/s --out CASE:c.csv",
    2, "--units")
add(c, "units", "accel-log-in-g", "apply IN:accel_g.csv --alignment IN:accel_cal.json --out CASE:c.csv", 3,
    "--units", why="the log reads 1 where the calibration expects 9.81 m/s^2")
add(c, "units", "mag-log-in-gauss", "apply IN:mag_timed.csv --alignment IN:magnetometer.json --units gauss "
    "--out CASE:c.csv", 3, "--units", why="100x Earth's field after correction")
# outputs
output_cases(c, A, "--out", "csv", ["session.csv", "alignment.json"])
add(c, "outputs", "out-is-log-process", f"{A} --out IN:session.csv", 2, ("--out", "session.csv"), process=True)
add(c, "outputs", "out-is-log-relative", "apply REL:session.csv --alignment IN:alignment.json --out ./session.csv", 2,
    "--out")
add(c, "outputs", "out-sys", f"{A} --out {SYS}.csv", 2, "--out")

# ====================================================================== simulate

S = "simulate CASE:sim --rate-hz 50 --dwell '2 s' --gap '1 s'"
SIM_OUT = ("sim/session.csv", "sim/plan.toml", "sim/truth.json")
c = "simulate"
add(c, "borderline", "default-rate", S, 0, outputs=SIM_OUT)
add(c, "borderline", "kind-angle", f"{S} --kind angle", 0, outputs=SIM_OUT)
add(c, "borderline", "user-plan", f"{S} --plan IN:plan.toml", 0, outputs=SIM_OUT)
add(c, "borderline", "old-fs-spelling", "simulate CASE:sim --fs 50 --dwell '2 s' --gap '1 s'", 0, outputs=SIM_OUT)
add(c, "borderline", "gyro-units-rad", f"{S} --gyro-units rad/s", 0, outputs=SIM_OUT)
add(c, "borderline", "existing-folder", S, 0, outputs=SIM_OUT, setup=[("mkdir", "sim")])
add(c, "borderline", "nested-new-folder", "simulate CASE:a/b/sim --rate-hz 50 --dwell '2 s' --gap '1 s'", 0,
    outputs=("a/b/sim/session.csv", "a/b/sim/plan.toml", "a/b/sim/truth.json"))
SB = "simulate CASE:sim"
bad_values(c, SB, "--rate-hz", ["0 Hz", "0", "-50", "nan", "inf", "1e300", "50 deg"], "rate-hz")
add(c, "domain", "fs-alias=0Hz", "simulate CASE:sim --fs '0 Hz'", 2, "--rate-hz")
bad_values(c, SB, "--dwell", ["-1 s", "0 s", "nan s", "1 deg", "4"], "dwell")
bad_values(c, SB, "--gap", ["-1 s", "nan s"], "gap")
bad_values(c, SB, "--seed", ["-1", "abc"], "seed")
bad_values(c, SB, "--rate", ["0 deg/s", "100", "100 deg", "nan deg/s", "1e300 deg/s"], "rate")
bad_values(c, SB, "--angle", ["0 deg", "360"], "angle", setup=())
bad_values(c, SB, "--noise", ["-0.3 deg/sqrt(h)", "nan deg/sqrt(h)", "0.3 deg/s"], "noise")
bad_values(c, SB, "--bias-walk", ["-1 deg/h/sqrt(h)"], "bias-walk")
bad_values(c, SB, "--misalignment", ["-0.5 deg", "nan deg", "0.5 mm"], "misalignment")
add(c, "usage", "kind-unknown", f"{SB} --kind spin", 2, "--kind")
add(c, "units", "gyro-units-length", f"{SB} --gyro-units m", 2, "--gyro-units")
add(c, "usage", "no-folder", "simulate", 2, "OUT_DIR|missing")
for plan, key in [("plan_latitud.toml", "latitud"), ("plan_rat.toml", "rat"), ("plan_empty.toml", ()),
                  ("plan_latin1.toml", ()), ("plan_nan.toml", "rate")]:
    add(c, "keys" if plan in ("plan_latitud.toml", "plan_rat.toml") else "malformed", plan, f"{S} --plan IN:{plan}", 2,
        (plan,) + ((key,) if isinstance(key, str) else ()))
add(c, "outputs", "plan-inside-out-dir", "simulate CASE:sim --rate-hz 50 --dwell '2 s' --gap '1 s' --plan CASE:sim/plan.toml",
    2, "plan.toml", setup=[("mkdir", "sim"), ("input", "plan.toml", "sim/plan.toml")],
    why="issue: simulate DIR --plan DIR/plan.toml rewrites the user's plan")
add(c, "outputs", "out-dir-is-file", "simulate CASE:simfile", 2, "simfile", setup=[("file", "simfile", "x")])
add(c, "outputs", "out-dir-proc", f"simulate {PROC}", 2, "OUT_DIR|imu-align-campaign")
add(c, "outputs", "out-dir-readonly", "simulate CASE:ro/sim --rate-hz 50 --dwell '2 s' --gap '1 s'", 2, "ro",
    setup=[("readonly", "ro")])
add(c, "partial", "session-csv-is-folder", S, 2, "session.csv", setup=[("mkdir", "sim/session.csv")])
add(c, "partial", "truth-json-is-folder", S, 2, "truth.json", setup=[("mkdir", "sim/truth.json")])

# ====================================================================== budget

B = "budget IN:mount.toml"
c = "budget"
add(c, "borderline", "plain", B, 0)
add(c, "borderline", "monte-carlo-json-plot", f"{B} --monte-carlo 300 --seed 1 --json CASE:b.json --plot CASE:h.png", 0,
    outputs=("b.json", "h.png"))
add(c, "borderline", "picture", f"{B} --picture CASE:p.png", 0, outputs="p.png")
add(c, "borderline", "glb", f"{B} --glb CASE:a.glb", 0, outputs="a.glb")
add(c, "borderline", "position-tolerance", "budget IN:mount_postol_ok.toml", 0)
add(c, "borderline", "baseplate-stl", "budget IN:mount_plate.toml --json CASE:b.json", 0, outputs="b.json", extra="plate.stl")
add(c, "outputs", "json-is-baseplate-stl", "budget IN:mount_plate.toml --json IN:plate.stl", 2, ("--json", "plate.stl"),
    why="the STL the mount file names is an input too")
add(c, "outputs", "glb-is-baseplate-stl", "budget IN:mount_plate.toml --glb IN:plate.stl", 2, ("--glb", "plate.stl"))
add(c, "malformed", "baseplate-stl-missing", "budget IN:mount_plate_missing.toml", 2, "no_such_plate.stl")
add(c, "malformed", "baseplate-not-stl", "budget IN:mount_plate_notstl.toml", 2,
    ("mount_plate_notstl.toml", "notes.txt|baseplate.stl"), extra="notes.txt")
add(c, "keys", "mount_plate_band.toml", "budget IN:mount_plate_band.toml", 2, ("mount_plate_band.toml", "ledge_bnd"),
    extra="plate.stl")
for mount, key in [("mount_postol.toml", "position_tolerence"), ("mount_axis.toml", "axis_to_packag"),
                   ("mount_height.toml", "heigth_tolerance"), ("mount_packge.toml", "packge"),
                   ("mount_screw.toml", "screw"), ("mount_top.toml", "units")]:
    add(c, "keys", mount, f"budget IN:{mount}", 2, (mount, key))
for mount, what in [("mount_zero.toml", "size_x"), ("mount_neg.toml", "size_x"), ("mount_bare.toml", "size_x"),
                    ("mount_kind.toml", "size_x"), ("mount_nan.toml", "size_x"), ("mount_huge.toml", "height_tolerance"),
                    ("mount_tilt_neg.toml", "axis_to_package"), ("mount_tilt_big.toml", "axis_to_package"),
                    ("mount_part.toml", "ADIS99999"), ("mount_hole.toml", "hole_diameter"),
                    ("mount_dist.toml", "gaussian|distribution"), ("mount_noledges.toml", "ledges")]:
    add(c, "domain", mount, f"budget IN:{mount}", 2, (mount, what))
for mount in ("mount_empty.toml", "mount_syntax.toml", "mount_latin1.toml", "manoeuvre.toml", "session.csv"):
    add(c, "malformed", mount, f"budget IN:{mount}", 2, mount)
add(c, "malformed", "mount-missing", "budget CASE:nope.toml", 2, "nope.toml")
add(c, "malformed", "mount-is-folder", "budget CASE:mdir", 2, "mdir", setup=[("mkdir", "mdir")])
add(c, "malformed", "latin1-process", "budget IN:mount_latin1.toml", 2, "mount_latin1.toml", process=True)
bad_values(c, B, "--monte-carlo", ["-1", "abc", "1.5"], "monte-carlo")
bad_values(c, f"{B} --monte-carlo 10", "--seed", ["-1"], "seed")
bad_values(c, f"{B} --picture CASE:p.png", "--exaggerate", ["nan", "inf", "-1", "0", "1e300"], "exaggerate")
add(c, "usage", "plot-without-monte-carlo", f"{B} --plot CASE:h.png", 2, "--monte-carlo|--plot")
add(c, "usage", "no-mount", "budget", 2, "MOUNT|missing")
BM = f"{B} --monte-carlo 100"
output_cases(c, BM, "--json", "json", ["mount.toml"], other="--plot")
output_cases(c, BM, "--plot", "png", ["mount.toml"])
add(c, "outputs", "picture-is-folder", f"{B} --picture CASE:pdir", 2, "--picture", setup=[("mkdir", "pdir")])
add(c, "outputs", "glb-proc", f"{B} --glb {PROC}.glb", 2, "--glb")
add(c, "outputs", "glb-is-mount", f"{B} --glb IN:mount.toml", 2, "--glb")
add(c, "outputs", "picture-same-as-glb", f"{B} --picture CASE:x.out --glb CASE:x.out", 2, "--picture|--glb")
add(c, "partial", "json-ok-plot-proc", f"{BM} --json CASE:b.json --plot {PROC}.png", 2, "--plot")
add(c, "partial", "json-ok-picture-folder", f"{B} --json CASE:b.json --picture CASE:pdir", 2, "--picture",
    setup=[("mkdir", "pdir")])
add(c, "partial", "json-ok-glb-sys", f"{B} --json CASE:b.json --glb {SYS}.glb", 2, "--glb")
add(c, "partial", "json-plot-ok-picture-missing-folder", f"{BM} --json CASE:b.json --plot CASE:h.png "
    "--picture CASE:nodir/p.png", 2, "--picture")

# ====================================================================== allowable

W = "allowable IN:manoeuvre.toml"
c = "allowable"
add(c, "borderline", "example2-json", f"{W} --json CASE:a.json", 0, outputs="a.json")
add(c, "borderline", "sequence", "allowable IN:sequence.toml", 0)
add(c, "borderline", "series", "allowable IN:series.toml", 0, extra="rates.csv")
add(c, "borderline", "series-rad", "allowable IN:series_units_ok.toml", 0, extra="rates_rad.csv")
add(c, "borderline", "symbolic-pretty", f"{W} --symbolic pretty", 0)
add(c, "borderline", "symbolic-latex", f"{W} --symbolic latex", 0)
for man, key in [("manoeuvre_axs.toml", "axs"), ("manoeuvre_limit.toml", "limit"), ("manoeuvre_zz.toml", "zz"),
                 ("manoeuvre_rotaton.toml", "rotaton")]:
    add(c, "keys", man, f"allowable IN:{man}", 2, (man, key))
add(c, "keys", "series_unit.toml", "allowable IN:series_unit.toml", 2, ("series_unit.toml", "unit"), extra="rates_rad.csv",
    why="issue: series unit = 'rad/s' read as deg/s, every element unconstrained")
add(c, "keys", "series_serie.toml", "allowable IN:series_serie.toml", 2, ("series_serie.toml", "serie"), extra="rates.csv")
for man, what in [("manoeuvre_angle0.toml", "angle"), ("manoeuvre_bare.toml", "angle"), ("manoeuvre_kind.toml", "angle"),
                  ("manoeuvre_nan.toml", "angle"), ("manoeuvre_huge.toml", "angle"), ("manoeuvre_limneg.toml", "limits"),
                  ("manoeuvre_limnan.toml", "limits"), ("manoeuvre_axisw.toml", "axis")]:
    add(c, "domain", man, f"allowable IN:{man}", 2, (man, what))
for man in ("manoeuvre_empty.toml", "manoeuvre_latin1.toml", "mount.toml"):
    add(c, "malformed", man, f"allowable IN:{man}", 2, man)
add(c, "malformed", "series-file-missing", "allowable IN:series_missing.toml", 2, "no_such_rates.csv")
add(c, "malformed", "series-nan", "allowable IN:series_nan.toml", 2, ("rates_nan.csv", "row"), extra="rates_nan.csv")
add(c, "malformed", "series-and-rotations", "allowable IN:series_both.toml", 2, "series_both.toml", extra="rates.csv")
add(c, "malformed", "manoeuvre-missing", "allowable CASE:nope.toml", 2, "nope.toml")
add(c, "usage", "symbolic-unknown", f"{W} --symbolic ascii", 2, "--symbolic")
add(c, "usage", "no-manoeuvre", "allowable", 2, "MANOEUVRE|missing")
add(c, "usage", "unknown-option", f"{W} --limits 1", 2, "--limits")
output_cases(c, W, "--json", "json", ["manoeuvre.toml"])
add(c, "outputs", "json-is-series-data", "allowable IN:series.toml --json IN:rates.csv", 2, ("--json", "rates.csv"))
add(c, "outputs", "json-sys", f"{W} --json {SYS}.json", 2, "--json")

# ====================================================================== check

K = "check IN:mount.toml IN:manoeuvre.toml"
c = "check"
add(c, "borderline", "pass-json", f"{K} --json CASE:c.json", 0, outputs="c.json")
add(c, "borderline", "fails-exit-4", "check IN:mount.toml IN:manoeuvre_tight.toml --json CASE:c.json", 4,
    "phi_yz|psi|exceed", outputs="c.json")
add(c, "borderline", "fails-worst-exit-4", "check IN:mount.toml IN:manoeuvre_tight.toml --basis worst", 4, "phi_yz|psi|exceed")
add(c, "usage", "basis-unknown", f"{K} --basis mean", 2, "--basis")
add(c, "usage", "no-manoeuvre", "check IN:mount.toml", 2, "MANOEUVRE|missing")
add(c, "keys", "mount-misspelt", "check IN:mount_postol.toml IN:manoeuvre.toml", 2, ("mount_postol.toml", "position_tolerence"))
add(c, "keys", "manoeuvre-misspelt", "check IN:mount.toml IN:manoeuvre_limit.toml", 2, ("manoeuvre_limit.toml", "limit"))
add(c, "domain", "mount-nan", "check IN:mount_nan.toml IN:manoeuvre.toml", 2, ("mount_nan.toml", "size_x"))
add(c, "malformed", "manoeuvre-empty", "check IN:mount.toml IN:manoeuvre_empty.toml", 2, "manoeuvre_empty.toml")
add(c, "malformed", "arguments-swapped", "check IN:manoeuvre.toml IN:mount.toml", 2, "manoeuvre.toml|mount.toml")
add(c, "malformed", "mount-twice", "check IN:mount.toml IN:mount.toml", 2, "mount.toml")
output_cases(c, K, "--json", "json", ["mount.toml", "manoeuvre.toml"])
add(c, "outputs", "json-is-series-data", "check IN:mount.toml IN:series.toml --json IN:rates.csv", 2, ("--json", "rates.csv"))
add(c, "outputs", "json-is-baseplate-stl", "check IN:mount_plate.toml IN:manoeuvre.toml --json IN:plate.stl", 2,
    ("--json", "plate.stl"))

# ====================================================================== plan

P = "plan --rate '100 deg/s' --accuracy '0.1 deg'"
PA = f"{P} --arw '0.3 deg/sqrt(h)'"
c = "plan"
add(c, "borderline", "arw", PA, 0)
add(c, "borderline", "arw-bi-rrw", f"{PA} --bias-instability '6 deg/h' --rate-random-walk '3 deg/h/sqrt(h)'", 0)
add(c, "borderline", "imu-preset", f"{P} --imu ADIS16485", 0)
add(c, "borderline", "allan-json", f"{P} --allan IN:allan.json --json CASE:p.json", 0, outputs="p.json")
add(c, "borderline", "steps-12", f"{PA} --steps 12", 0)
add(c, "borderline", "settle-zero", f"{PA} --settle '0 s'", 0)
bad_values(c, PA, "--steps", ["0", "-1", "2.5"], "steps")
bad_values(c, PA, "--settle", ["-1 s", "nan s", "1 deg"], "settle")
bad_values(c, "plan --accuracy '0.1 deg' --arw '0.3 deg/sqrt(h)'", "--rate",
           ["0 deg/s", "-100 deg/s", "100", "100 deg", "nan deg/s", "inf deg/s"], "rate")
bad_values(c, "plan --rate '100 deg/s' --arw '0.3 deg/sqrt(h)'", "--accuracy", ["0 deg", "-0.1 deg", "0.1 s", "nan deg"],
           "accuracy")
bad_values(c, PA, "--noise-ratio", ["0", "-1", "nan", "inf"], "noise-ratio")
bad_values(c, P, "--arw", ["0.3", "0.3 deg", "-0.3 deg/sqrt(h)", "nan deg/sqrt(h)", "0 deg/sqrt(h)"], "arw")
bad_values(c, PA, "--bias-instability", ["-6 deg/h", "6 deg"], "bias-instability")
bad_values(c, PA, "--rate-random-walk", ["-3 deg/h/sqrt(h)"], "rate-random-walk")
bad_values(c, PA, "--turn-angle", ["0 deg", "360", "nan deg"], "turn-angle")
add(c, "domain", "imu-unknown", f"{P} --imu ADIS99999", 2, "ADIS99999|--imu")
add(c, "usage", "no-noise-source", P, 2, "--arw|--imu|--allan")
add(c, "usage", "two-noise-sources", f"{PA} --imu ADIS16485", 2, "--arw|--imu")
add(c, "usage", "bias-instability-without-arw", f"{P} --imu ADIS16485 --bias-instability '6 deg/h'", 2,
    "--bias-instability")
add(c, "usage", "no-rate", "plan --accuracy '0.1 deg' --arw '0.3 deg/sqrt(h)'", 2, "--rate")
for res, names in [("allan_v99.json", "99|version"), ("allan_format.json", "format"), ("allan_noformat.json", "format"),
                   ("allan_missing.json", ()), ("allan_typo.json", ()), ("allan_extrakey.json", "calibraton_note"),
                   ("alignment.json", "alignment"), ("result_empty.json", ()), ("result_syntax.json", ()),
                   ("result_array.json", ()), ("result_latin1.json", ()), ("calibration.json", "calibration")]:
    add(c, "results", res, f"{P} --allan IN:{res}", 2, (res,) + ((names,) if isinstance(names, str) else tuple(names)))
add(c, "results", "allan-missing-file", f"{P} --allan CASE:nope.json", 2, "nope.json")
add(c, "results", "allan-is-folder", f"{P} --allan CASE:adir", 2, "adir", setup=[("mkdir", "adir")])
output_cases(c, f"{P} --allan IN:allan.json", "--json", "json", ["allan.json"])

# ====================================================================== allan

L = "allan IN:static.csv"
LN = "allan IN:static.npy"
c = "allan"
add(c, "borderline", "csv-json-plot", f"{L} --json CASE:a.json --plot CASE:a.png", 0, outputs=("a.json", "a.png"))
add(c, "borderline", "csv-gz", "allan IN:static.csv.gz", 0)
add(c, "borderline", "npy", f"{LN} --rate-hz 100", 0)
add(c, "borderline", "npy-rate-unit", f"{LN} --rate-hz '100 Hz'", 0)
add(c, "borderline", "bin", "allan IN:static.bin --rate-hz 100", 0)
add(c, "borderline", "parquet", "allan IN:static.parquet", 0)
add(c, "borderline", "blank-text", "allan IN:static.txt --rate-hz 100 --columns col1,col2,col3", 0)
add(c, "borderline", "two-runs", "allan IN:static.csv IN:static_run2.csv --json CASE:a.json", 0, outputs="a.json")
add(c, "borderline", "int16-npy", "allan IN:static_int16.npy --rate-hz 100 --gyro-units mdps", 0,
    why="raw integer samples are a normal record")
add(c, "borderline", "accelerometer-g", "allan IN:static_acc.csv --columns acc_x,acc_y,acc_z --units g", 0)
add(c, "borderline", "modified", f"{L} --modified", 0)
add(c, "borderline", "grid-octave", f"{L} --grid octave", 0)
add(c, "borderline", "grid-explicit", f"{L} --grid 0.1,1,10", 0)
add(c, "borderline", "per-decade-3", f"{L} --per-decade 3", 0)
add(c, "borderline", "plan", f"{L} --rate '100 deg/s' --accuracy '0.1 deg' --json CASE:a.json", 0, outputs="a.json")
for log, names in [("static_nan.csv", "row"), ("static_huge.csv", "row"), ("static_textcell.csv", ()),
                   ("static_gap.csv", "gap"), ("static_backwards.csv", "row"), ("static_header.csv", ()),
                   ("static_empty.csv", ()), ("static_short.csv", ()), ("session_bad.npy", ()), ("notes.txt", ())]:
    extra = " --rate-hz 100" if log.endswith(".npy") else ""
    add(c, "malformed", log, f"allan IN:{log}{extra}", 2, (log,) + ((names,) if isinstance(names, str) else tuple(names)))
add(c, "malformed", "latin1-text", "allan IN:static_latin1.txt --rate-hz 100 --columns col1,col2,col3", 2,
    "static_latin1.txt")
add(c, "malformed", "nan-npy", "allan IN:static_nan.npy --rate-hz 100", 2, ("static_nan.npy", "row|sample"))
add(c, "malformed", "nan-bin", "allan IN:static_nan.bin --rate-hz 100", 2, ("static_nan.bin", "row|sample"))
add(c, "malformed", "odd-bin", "allan IN:static_odd.bin --rate-hz 100", 2, "static_odd.bin")
add(c, "malformed", "one-column-npy", "allan IN:static_1d.npy --rate-hz 100", 2, "static_1d.npy")
add(c, "malformed", "npy-without-rate", "allan IN:static.npy", 2, ("static.npy", "--rate-hz"))
add(c, "malformed", "bin-without-rate", "allan IN:static.bin", 2, ("static.bin", "--rate-hz"))
add(c, "malformed", "runs-at-different-rates", "allan IN:static.csv IN:static_200hz.csv", 2, "static_200hz.csv")
add(c, "malformed", "log-missing", "allan CASE:nope.csv", 2, "nope.csv")
add(c, "malformed", "all-zero", "allan IN:static_zero.csv", 3, "static_zero.csv",
    why="a record without any noise is a dead sensor or a file of zeros")
add(c, "malformed", "constant", "allan IN:static_const.csv", 3, "static_const.csv")
add(c, "malformed", "all-zero-npy", "allan IN:static_zero.npy --rate-hz 100", 3, "static_zero.npy")
add(c, "malformed", "all-zero-process", "allan IN:static_zero.csv", 3, "static_zero.csv", process=True)
bad_values(c, LN, "--rate-hz", ["0", "nan", "-100", "1e300", "inf", "100 deg"], "rate-hz",
           forbid=("no time column", "rows with nan"))
bad_values(c, f"{L} --accuracy '0.1 deg'", "--rate", ["0 deg/s", "-100 deg/s", "100"], "rate")
bad_values(c, f"{L} --rate '100 deg/s'", "--accuracy", ["-0.1 deg", "0 deg", "0.1 s"], "accuracy")
bad_values(c, f"{L} --rate '100 deg/s' --accuracy '0.1 deg'", "--noise-ratio", ["0", "nan"], "noise-ratio")
add(c, "usage", "rate-without-accuracy", f"{L} --rate '100 deg/s'", 2, "--accuracy")
bad_values(c, L, "--per-decade", ["0", "-1"], "per-decade", forbid=("--taus",))
bad_values(c, L, "--grid", ["0,1", "-1,1", "bogus", "nan,1"], "grid")
bad_values(c, L, "--memory-limit-mb", ["0", "-1", "nan"], "memory-limit-mb")
add(c, "units", "units-length", f"{L} --units m", 2, "--units")
add(c, "units", "gyro-units-acceleration", f"{L} --gyro-units m/s^2", 2, "--gyro-units")
add(c, "units", "gyro-units-unknown", f"{L} --gyro-units furlong", 2, "--gyro-units")
add(c, "malformed", "column-missing", f"{L} --columns gyro_x,nope,gyro_z", 2, "nope")
add(c, "usage", "no-logs", "allan", 2, "LOG|missing")
add(c, "usage", "grid-without-value", f"{L} --grid", 2, "--grid")
output_cases(c, L, "--json", "json", ["static.csv"], other="--plot")
output_cases(c, L, "--plot", "png", ["static.csv"])
add(c, "outputs", "json-is-second-run", "allan IN:static.csv IN:static_run2.csv --json IN:static_run2.csv", 2,
    ("--json", "static_run2.csv"))
add(c, "partial", "json-ok-plot-proc", f"{L} --json CASE:a.json --plot {PROC}.png", 2, "--plot")
add(c, "partial", "json-ok-plot-folder", f"{L} --json CASE:a.json --plot CASE:pdir", 2, "--plot", setup=[("mkdir", "pdir")])
add(c, "partial", "json-ok-plot-missing-folder", f"{L} --json CASE:a.json --plot CASE:nodir/a.png", 2, "--plot")
add(c, "partial", "dead-record-writes-nothing", "allan IN:static_zero.csv --json CASE:a.json --plot CASE:a.png", 3,
    "static_zero.csv")

# ====================================================================== report

R = "report --mount IN:mount.toml --manoeuvre IN:manoeuvre.toml --monte-carlo 200"
RL = f"{R} --log IN:session.csv --plan IN:plan.toml"
c = "report"
add(c, "borderline", "mount-manoeuvre", f"{R} --out CASE:r.html", 0, outputs="r.html")
add(c, "borderline", "with-alignment", f"{RL} --out CASE:r.html", 0, outputs="r.html")
add(c, "borderline", "with-allan", f"{R} --allan IN:static.csv --out CASE:r.html", 0, outputs="r.html")
add(c, "borderline", "with-allan-columns", f"{R} --allan IN:static.csv --columns gyro_x,gyro_y,gyro_z --out CASE:r.html",
    0, outputs="r.html")
add(c, "borderline", "with-allan-npy", f"{R} --allan IN:static.npy --rate-hz 100 --out CASE:r.html", 0, outputs="r.html")
add(c, "malformed", "mount-missing", "report --mount CASE:nope.toml --manoeuvre IN:manoeuvre.toml --out CASE:r.html", 2,
    "nope.toml", why="issue: read before the checked reader")
add(c, "malformed", "manoeuvre-missing", "report --mount IN:mount.toml --manoeuvre CASE:nope.toml --out CASE:r.html", 2,
    "nope.toml")
add(c, "keys", "mount-misspelt", "report --mount IN:mount_postol.toml --manoeuvre IN:manoeuvre.toml --monte-carlo 200 "
    "--out CASE:r.html", 2, ("mount_postol.toml", "position_tolerence"))
add(c, "keys", "manoeuvre-misspelt", "report --mount IN:mount.toml --manoeuvre IN:manoeuvre_axs.toml --monte-carlo 200 "
    "--out CASE:r.html", 2, ("manoeuvre_axs.toml", "axs"))
add(c, "keys", "plan-misspelt", f"{R} --log IN:session.csv --plan IN:plan_latitud.toml --out CASE:r.html", 2,
    ("plan_latitud.toml", "latitud"))
add(c, "malformed", "log-nan", f"{R} --log IN:session_nan.csv --plan IN:plan.toml --out CASE:r.html", 2,
    ("session_nan.csv", "row"))
add(c, "malformed", "allan-nan", f"{R} --allan IN:static_nan.csv --out CASE:r.html", 2, ("static_nan.csv", "row"))
add(c, "malformed", "allan-column-missing", f"{R} --allan IN:static.csv --columns gyro_x,nope,gyro_z --out CASE:r.html", 2,
    ("static.csv", "nope"))
add(c, "malformed", "allan-zero", f"{R} --allan IN:static_zero.csv --out CASE:r.html", 3, "static_zero.csv")
add(c, "malformed", "mount-latin1", "report --mount IN:mount_latin1.toml --manoeuvre IN:manoeuvre.toml --out CASE:r.html",
    2, "mount_latin1.toml")
add(c, "malformed", "manoeuvre-latin1", "report --mount IN:mount.toml --manoeuvre IN:manoeuvre_latin1.toml "
    "--out CASE:r.html", 2, "manoeuvre_latin1.toml")
add(c, "units", "log-in-rad", f"{R} --log IN:session_rad.csv --plan IN:plan.toml --out CASE:r.html", 3, "--gyro-units")
add(c, "units", "gyro-units-rad", f"{RL} --gyro-units rad/s --out CASE:r.html", 3, "--gyro-units")
add(c, "units", "allan-units-length", f"{R} --allan IN:static.csv --units m --out CASE:r.html", 2, "--units")
add(c, "handedness", "flipped-gyro", f"{R} --log IN:session_flipy.csv --plan IN:plan.toml --out CASE:r.html", 3, HANDED)
RA = f"{R} --allan IN:static.csv --out CASE:r.html"
bad_values(c, RA, "--rate", ["0 deg/s", "100", "nan deg/s"], "rate")
bad_values(c, RA, "--accuracy", ["-0.1 deg", "0.1 s"], "accuracy")
bad_values(c, "report --mount IN:mount.toml --manoeuvre IN:manoeuvre.toml --out CASE:r.html", "--monte-carlo", ["-1"],
           "monte-carlo")
bad_values(c, f"{R} --allan IN:static.npy --out CASE:r.html", "--rate-hz", ["0", "nan"], "rate-hz",
           forbid=("no time column",))
bad_values(c, f"{R} --out CASE:r.html", "--seed", ["-1"], "seed")
add(c, "usage", "log-without-plan", f"{R} --log IN:session.csv --out CASE:r.html", 2, "--plan")
add(c, "usage", "plan-without-log", f"{R} --plan IN:plan.toml --out CASE:r.html", 2, "--log")
add(c, "usage", "no-out", R, 2, "--out")
add(c, "usage", "nothing-to-report", "report --out CASE:r.html", 2, ("nothing to report", "--mount"))
output_cases(c, RL, "--out", "html", ["mount.toml", "session.csv", "plan.toml", "manoeuvre.toml"])
add(c, "outputs", "out-is-allan-record", f"{R} --allan IN:static.csv --out IN:static.csv", 2, ("--out", "static.csv"))
add(c, "outputs", "out-sys", f"{R} --out {SYS}.html", 2, "--out")
add(c, "outputs", "out-is-series-data", "report --mount IN:mount.toml --manoeuvre IN:series.toml --monte-carlo 200 "
    "--out IN:rates.csv", 2, ("--out", "rates.csv"))
add(c, "outputs", "out-is-baseplate-stl", "report --mount IN:mount_plate.toml --manoeuvre IN:manoeuvre.toml "
    "--monte-carlo 200 --out IN:plate.stl", 2, ("--out", "plate.stl"))
add(c, "borderline", "series-and-baseplate", "report --mount IN:mount_plate.toml --manoeuvre IN:series.toml "
    "--monte-carlo 200 --out CASE:r.html", 0, outputs="r.html", extra=("plate.stl", "rates.csv"))

# ====================================================================== demo

c = "demo"
add(c, "borderline", "folder", "demo --out CASE:d", 0, outputs=tuple(f"d/{f}" for f in DEMO_FILES))
add(c, "outputs", "out-is-file", "demo --out CASE:afile", 2, "--out", setup=[("file", "afile", "x")],
    why="issue: demo --out FILE")
add(c, "outputs", "out-proc", f"demo --out {PROC}", 2, "--out")
add(c, "outputs", "out-readonly", "demo --out CASE:ro/d", 2, "--out", setup=[("readonly", "ro")])
add(c, "partial", "report-html-is-folder", "demo --out CASE:d", 2, "report.html", setup=[("mkdir", "d/report.html")],
    why="issue: demo leaves 10 files when the report cannot be written")
add(c, "partial", "budget-json-is-folder", "demo --out CASE:d", 2, "budget.json", setup=[("mkdir", "d/budget.json")])
add(c, "usage", "unknown-option", "demo --folder CASE:d", 2, "--folder")
add(c, "usage", "out-without-value", "demo --out", 2, "--out")

# ====================================================================== calibrate (group)

c = "calibrate"
add(c, "usage", "no-subcommand", "calibrate", 2, "ferraris|accel|mag|command")
add(c, "usage", "unknown-subcommand", "calibrate ferrari", 2, "ferraris")
add(c, "borderline", "help", "calibrate --help", 0)

# ====================================================================== calibrate ferraris

F = "calibrate ferraris IN:ferraris.csv --sections IN:sections.json --rate-hz 50"
c = "calibrate ferraris"
add(c, "borderline", "json-imucal", f"{F} --json CASE:f.json --imucal-json CASE:i.json", 0, outputs=("f.json", "i.json"))
add(c, "borderline", "bias-lsq", f"{F} --bias lsq", 0)
add(c, "borderline", "no-g-sensitivity", f"{F} --no-g-sensitivity", 0)
add(c, "borderline", "g-sensitivity", f"{F} --g-sensitivity", 0)
add(c, "borderline", "accel-in-g-declared", "calibrate ferraris IN:ferraris_g.csv --sections IN:sections.json --rate-hz 50 "
    "--accel-units g", 0)
add(c, "borderline", "gyro-in-rad-declared", "calibrate ferraris IN:ferraris_radgyr.csv --sections IN:sections.json "
    "--rate-hz 50 --gyro-units rad/s", 0)
add(c, "borderline", "old-acc-units-spelling", f"{F} --acc-units m/s^2", 0)
add(c, "borderline", "rate-hz-unit", "calibrate ferraris IN:ferraris.csv --sections IN:sections.json --rate-hz '50 Hz'", 0)
add(c, "borderline", "gravity-local", f"{F} --gravity '9.81 m/s^2'", 0)
FL = "calibrate ferraris IN:{log} --sections IN:sections.json --rate-hz 50"
add(c, "malformed", "nan-cell", FL.format(log="ferraris_nan.csv"), 2, ("ferraris_nan.csv", "row"),
    forbid=("10376",), why="issue: reported with no file name")
add(c, "malformed", "text-cell", FL.format(log="ferraris_textcell.csv"), 2, "ferraris_textcell.csv")
add(c, "malformed", "short-log", FL.format(log="ferraris_short.csv"), 2, "sections.json|ferraris_short.csv|--sections")
add(c, "malformed", "log-missing", "calibrate ferraris CASE:nope.csv --sections IN:sections.json --rate-hz 50", 2,
    "nope.csv")
add(c, "malformed", "log-header-only", FL.format(log="ferraris_header.csv"), 2, "ferraris_header.csv")
add(c, "malformed", "wrong-columns", FL.format(log="session.csv"), 2, ("session.csv", "acc_x"))
add(c, "malformed", "huge-value", FL.format(log="ferraris_huge.csv"), 2, ("ferraris_huge.csv", "row"))
add(c, "borderline", "csv-gz", FL.format(log="ferraris.csv.gz"), 0)
add(c, "borderline", "parquet", FL.format(log="ferraris.parquet"), 0)
add(c, "malformed", "all-zero", FL.format(log="ferraris_zero.csv"), 3, "ferraris_zero.csv|--accel-units|gravity",
    why="|a| = 0 at rest is not gravity")
add(c, "units", "accel-g-read-as-ms2", FL.format(log="ferraris_g.csv"), 3, "--accel-units")
add(c, "units", "accel-ms2-declared-g", f"{F} --accel-units g", 3, "--accel-units")
add(c, "units", "gyro-rad-read-as-deg", FL.format(log="ferraris_radgyr.csv"), 3, "--gyro-units")
add(c, "units", "gyro-deg-declared-rad", f"{F} --gyro-units rad/s", 3, "--gyro-units")
add(c, "units", "accel-units-rate", f"{F} --accel-units deg/s", 2, "--accel-units")
add(c, "units", "gyro-units-acceleration", f"{F} --gyro-units m/s^2", 2, "--gyro-units")
add(c, "handedness", "flipped-accel-axis", FL.format(log="ferraris_flipacc.csv"), 3, HANDED)
add(c, "handedness", "flipped-gyro-axis", FL.format(log="ferraris_flipgyr.csv"), 3, HANDED + "|x_rot|y_rot|z_rot")
add(c, "handedness", "faces-swapped", "calibrate ferraris IN:ferraris.csv --sections IN:sections_swapped.json --rate-hz 50",
    3, HANDED + "|x_p|x_a")
add(c, "handedness", "turn-angle-wrong-sign", f"{F} --turn-angle '360 deg'", 3, "x_rot|--turn-angle|direction|wrong way")
FS = "calibrate ferraris IN:ferraris.csv --sections IN:{s} --rate-hz 50"
add(c, "handedness", "x_a-equals-x_p", FS.format(s="sections_xa_eq_xp.json"), 2, ("sections_xa_eq_xp.json|--sections", "x_a|x_p"),
    why="issue: gives a zero column and A entries of 1e19")
for sec, key in [("sections_xpp.json", "x_pp"), ("sections_extra.json", "w_rot"), ("sections_stat.json", "stat")]:
    add(c, "keys", sec, FS.format(s=sec), 2, (sec, key))
for sec, what in [("sections_range.json", "z_rot"), ("sections_negative.json", "x_p"), ("sections_reversed.json", "y_a"),
                  ("sections_float.json", "z_p")]:
    add(c, "malformed", sec, FS.format(s=sec), 2, (f"{sec}|--sections", what))
add(c, "malformed", "sections_moving.json", FS.format(s="sections_moving.json"), 3, "z_a")
add(c, "malformed", "sections_shortrot.json", FS.format(s="sections_shortrot.json"), 3, "x_rot", forbid="--min-dwell",
    why="issue: messages name options the command does not have (--min-dwell in ferraris)")
add(c, "malformed", "sections_empty.json", FS.format(s="sections_empty.json"), 2, "sections_empty.json|--sections")
for sec in ("sections_list.json", "sections_syntax.json", "sections_latin1.json"):
    add(c, "malformed", sec, FS.format(s=sec), 2, sec)
add(c, "malformed", "sections-missing", "calibrate ferraris IN:ferraris.csv --sections CASE:nope.json --rate-hz 50", 2,
    "nope.json")
add(c, "malformed", "sections-is-plan", "calibrate ferraris IN:ferraris.csv --sections IN:plan.toml --rate-hz 50", 2,
    "plan.toml")
FB = "calibrate ferraris IN:ferraris.csv --sections IN:sections.json"
bad_values(c, FB, "--rate-hz", ["0", "nan", "-50", "inf", "1e300", "50 deg"], "rate-hz", forbid=("no time column",))
bad_values(c, F, "--turn-angle", ["0 deg", "360 mm", "-360", "nan deg"], "turn-angle")
bad_values(c, F, "--gravity", ["0 m/s^2", "-9.8 m/s^2", "9.81", "9.81 m", "1e300 m/s^2", "nan m/s^2"], "gravity")
add(c, "usage", "bias-unknown", f"{F} --bias median", 2, "--bias")
add(c, "malformed", "accel-columns-two", f"{F} --accel-columns acc_x,acc_y", 2, "--accel-columns")
add(c, "malformed", "accel-columns-missing", f"{F} --accel-columns ax,ay,az", 2, ("ferraris.csv", "ax"))
add(c, "malformed", "gyro-columns-missing", f"{F} --gyro-columns gx,gy,gz", 2, ("ferraris.csv", "gx"))
add(c, "usage", "min-dwell-not-an-option", f"{F} --min-dwell '1 s'", 2, "--min-dwell")
add(c, "usage", "no-rate-hz", FB, 2, "--rate-hz")
add(c, "usage", "no-sections", "calibrate ferraris IN:ferraris.csv --rate-hz 50", 2, "--sections")
output_cases(c, F, "--json", "json", ["ferraris.csv", "sections.json"], other="--imucal-json")
output_cases(c, F, "--imucal-json", "json", ["sections.json"])
add(c, "partial", "json-ok-imucal-proc", f"{F} --json CASE:f.json --imucal-json {PROC}.json", 2, "--imucal-json")
add(c, "partial", "json-ok-imucal-folder", f"{F} --json CASE:f.json --imucal-json CASE:idir", 2, "--imucal-json",
    setup=[("mkdir", "idir")])
add(c, "partial", "unit-mixup-writes-nothing", "calibrate ferraris IN:ferraris_g.csv --sections IN:sections.json "
    "--rate-hz 50 --json CASE:f.json --imucal-json CASE:i.json", 3, "--accel-units")

# ====================================================================== calibrate accel

C = "calibrate accel IN:accel.csv --positions IN:positions.toml"
CL = "calibrate accel IN:{log} --positions IN:positions.toml"
c = "calibrate accel"
add(c, "borderline", "positions-json", f"{C} --json CASE:c.json", 0, outputs="c.json")
add(c, "borderline", "free-fit", "calibrate accel IN:accel.csv", 0)
add(c, "borderline", "positions-detected", "calibrate accel IN:accel.csv --positions IN:positions_auto.toml", 0)
add(c, "borderline", "g-declared", "calibrate accel IN:accel_g.csv --positions IN:positions.toml --accel-units g", 0)
add(c, "borderline", "old-units-spelling", f"{C} --units m/s^2", 0)
add(c, "borderline", "gravity-local", f"{C} --gravity '9.81 m/s^2'", 0)
add(c, "borderline", "csv-gz", CL.format(log="accel.csv.gz"), 0)
add(c, "borderline", "parquet", CL.format(log="accel.parquet"), 0)
add(c, "malformed", "nan-row", CL.format(log="accel_nan.csv"), 2, ("accel_nan.csv", "row"))
add(c, "malformed", "huge-value", CL.format(log="accel_huge.csv"), 2, ("accel_huge.csv", "row"))
add(c, "malformed", "time-backwards", CL.format(log="accel_backwards.csv"), 2, ("accel_backwards.csv", "row"))
add(c, "malformed", "wrong-columns", CL.format(log="session.csv"), 2, ("session.csv", "acc_x"))
add(c, "malformed", "log-missing", "calibrate accel CASE:nope.csv", 2, "nope.csv")
add(c, "malformed", "constant", "calibrate accel IN:accel_const.csv", 3, "accel_const.csv|static|attitude",
    why="one attitude cannot calibrate anything")
add(c, "units", "g-read-as-ms2", CL.format(log="accel_g.csv"), 3, "--accel-units")
add(c, "units", "ms2-declared-g", f"{C} --accel-units g", 3, "--accel-units")
add(c, "units", "g-read-as-ms2-free-fit", "calibrate accel IN:accel_g.csv", 3, "--accel-units")
add(c, "units", "accel-units-rate", f"{C} --accel-units deg/s", 2, "--accel-units")
add(c, "handedness", "flipped-axis", CL.format(log="accel_flipy.csv"), 3, HANDED)
add(c, "handedness", "positions-swapped", "calibrate accel IN:accel.csv --positions IN:positions_swapped.toml", 3,
    HANDED + "|p1|p2")
for pos, key in [("positions_upp.toml", "upp"), ("positions_gravty.toml", "gravty"), ("positions_holdot.toml", "holdot")]:
    add(c, "keys", pos, f"calibrate accel IN:accel.csv --positions IN:{pos}", 2, (pos, key))
for pos, what in [("positions_empty.toml", ()), ("positions_axis_w.toml", "up"), ("positions_zero_up.toml", "up"),
                  ("positions_gravity_mm.toml", "gravity"), ("positions_gravity_neg.toml", "gravity"),
                  ("positions_gravity_zero.toml", "gravity"), ("positions_range.toml", ()), ("positions_mixed.toml", ()),
                  ("positions_latin1.toml", ()), ("positions_syntax.toml", ())]:
    add(c, "domain" if what else "malformed", pos, f"calibrate accel IN:accel.csv --positions IN:{pos}", 2,
        (pos,) + ((what,) if isinstance(what, str) else ()),
        why="issue: an empty positions file silently switches method" if pos == "positions_empty.toml" else "")
add(c, "malformed", "positions-missing", "calibrate accel IN:accel.csv --positions CASE:nope.toml", 2, "nope.toml")
bad_values(c, C, "--gravity", ["0 m/s^2", "-9.8 m/s^2", "9.8", "9.8 m", "nan m/s^2"], "gravity")
bad_values(c, C, "--window", ["0 s", "-1 s", "nan s"], "window")
bad_values(c, C, "--factor", ["0", "-1", "nan", "inf"], "factor")
bad_values(c, C, "--min-static", ["-1 s", "nan s"], "min-static")
bad_values(c, C, "--init-static", ["-5 s", "0 s"], "init-static")
bad_values(c, "calibrate accel IN:accel.csv --columns acc_x,acc_y,acc_z", "--rate-hz", ["0", "nan"], "rate-hz",
           forbid=("no time column",))
add(c, "usage", "no-log", "calibrate accel", 2, "LOG|missing")
output_cases(c, C, "--json", "json", ["accel.csv", "positions.toml"])
add(c, "partial", "unit-mixup-writes-nothing", "calibrate accel IN:accel_g.csv --positions IN:positions.toml "
    "--json CASE:c.json", 3, "--accel-units")

# ====================================================================== calibrate mag

G_ = "calibrate mag IN:mag.csv"
c = "calibrate mag"
add(c, "borderline", "json", f"{G_} --json CASE:m.json", 0, outputs="m.json")
add(c, "borderline", "blank-text", "calibrate mag IN:mag.txt --columns col0,col1,col2", 0)
add(c, "borderline", "npy", "calibrate mag IN:mag.npy --columns col0,col1,col2", 0)
add(c, "borderline", "parquet", "calibrate mag IN:mag.parquet", 0)
add(c, "borderline", "with-accelerometer", f"{G_} --accel-columns acc_x,acc_y,acc_z", 0)
add(c, "borderline", "model-sphere", f"{G_} --model sphere", 0)
add(c, "borderline", "model-diagonal", f"{G_} --model diagonal", 0)
add(c, "borderline", "known-field", f"{G_} --field '48 uT'", 0)
add(c, "borderline", "nT-declared", "calibrate mag IN:mag_nt.csv --mag-units nT", 0)
add(c, "borderline", "gauss-declared", "calibrate mag IN:mag_gauss.csv --mag-units gauss", 0)
add(c, "borderline", "dip", f"{G_} --dip '60 deg'", 0)
if (SHARED_DATA / "magnetometer" / "bazhin" / "mag_out.txt").is_file():
    add(c, "borderline", "real-capture-counts", "calibrate mag IN:bazhin_mag_out.txt --columns col0,col1,col2 "
        "--mag-units counts", 0)
add(c, "units", "gauss-read-as-uT", "calibrate mag IN:mag_gauss.csv", 3, "--mag-units",
    why="issue: field 0.31 uT on a real capture")
add(c, "units", "nT-read-as-uT", "calibrate mag IN:mag_nt.csv", 3, "--mag-units", why="issue: 50,700 uT")
add(c, "units", "uT-declared-gauss", f"{G_} --mag-units gauss", 3, "--mag-units")
add(c, "units", "uT-declared-nT", f"{G_} --mag-units nT", 3, "--mag-units")
add(c, "units", "uT-declared-mG", f"{G_} --mag-units mG", 3, "--mag-units")
add(c, "units", "mag-units-angle", f"{G_} --mag-units deg", 2, "--mag-units")
add(c, "units", "mag-units-acceleration", f"{G_} --mag-units m/s^2", 2, "--mag-units")
add(c, "units", "gauss-process", "calibrate mag IN:mag_gauss.csv", 3, "--mag-units", process=True)
add(c, "malformed", "constant", "calibrate mag IN:mag_const.csv", 3, "mag_const.csv|move|moved")
add(c, "malformed", "all-zero", "calibrate mag IN:mag_zero.csv", 3, "mag_zero.csv|move|moved|--mag-units")
add(c, "malformed", "planar", "calibrate mag IN:mag_planar.csv", 3, "planar|plane")
for log, names in [("mag_nan.csv", "row"), ("mag_textcell.csv", ()), ("mag_huge.csv", "row"), ("mag_empty.csv", ()),
                   ("mag_header.csv", ()), ("mag_short.csv", ())]:
    add(c, "malformed", log, f"calibrate mag IN:{log}", 2, (log,) + ((names,) if isinstance(names, str) else ()))
add(c, "malformed", "latin1-text", "calibrate mag IN:mag_latin1.txt --columns col0,col1,col2", 2, "mag_latin1.txt")
add(c, "malformed", "log-missing", "calibrate mag CASE:nope.csv", 2, "nope.csv")
bad_values(c, G_, "--field", ["0 uT", "-48 uT", "48", "48 deg", "nan uT", "480 uT"], "field")
bad_values(c, G_, "--dip", ["120 deg", "-91 deg", "60", "60 mm", "nan deg"], "dip")
add(c, "usage", "model-unknown", f"{G_} --model ellipse", 2, "--model")
add(c, "malformed", "columns-two", f"{G_} --columns mag_x,mag_y", 2, "--columns")
add(c, "malformed", "columns-missing", f"{G_} --columns mx,my,mz", 2, ("mag.csv", "mx"))
add(c, "malformed", "accel-columns-missing", f"{G_} --accel-columns ax,ay,az", 2, ("mag.csv", "ax"))
add(c, "usage", "no-log", "calibrate mag", 2, "LOG|missing")
output_cases(c, G_, "--json", "json", ["mag.csv"])
add(c, "partial", "unit-mixup-writes-nothing", "calibrate mag IN:mag_gauss.csv --json CASE:m.json", 3, "--mag-units")

# ====================================================================== logger files (issue 12): every log reader

P_ = "--plan IN:plan.toml"
c = "matrix"
add(c, "borderline", "time-in-ms", f"matrix IN:session_ms.csv {P_}", 0, why="the time unit is detected")
add(c, "borderline", "time-in-ns", f"matrix IN:session_ns.csv {P_}", 0)
add(c, "borderline", "time-in-ms-given", f"matrix IN:session_ms.csv {P_} --time-units ms", 0)
add(c, "borderline", "skip-rows", f"matrix IN:session_preamble.csv {P_} --skip-rows 3", 0)
add(c, "borderline", "comments", f"matrix IN:session_comments.csv {P_} --comment '#'", 0)
add(c, "borderline", "semicolon-with-delimiter", f"matrix IN:session_semicolon.csv {P_} --delimiter ';'", 0)
add(c, "borderline", "tab-delimiter", f"matrix IN:session_tab.csv {P_} --delimiter tab", 0)
add(c, "borderline", "blank-delimiter", f"matrix IN:session_blanks.txt {P_} --delimiter space", 0)
add(c, "borderline", "count-size", f"matrix IN:session_counts.csv {P_} --gyro-units '131 LSB/(deg/s)'", 0)
add(c, "borderline", "count-size-per-lsb", f"matrix IN:session_counts.csv {P_} --gyro-units '0.0076336 deg/s/LSB'", 0)
add(c, "malformed", "preamble-without-skip-rows", f"matrix IN:session_preamble.csv {P_}", 2,
    ("session_preamble.csv", "--skip-rows 3"), forbid=("Expected",))
add(c, "malformed", "comments-without-comment", f"matrix IN:session_comments.csv {P_}", 2,
    ("session_comments.csv", "--comment"))
add(c, "malformed", "tabs-without-delimiter", f"matrix IN:session_tab.csv {P_}", 2, ("session_tab.csv", "--delimiter"))
add(c, "units", "time-ms-declared-s", f"matrix IN:session_ms.csv {P_} --time-units s", 2,
    ("time column 'time'", "--time-units ms"))
add(c, "units", "time-s-declared-us", f"matrix IN:session.csv {P_} --time-units us", 2,
    ("time column 'time'", "--time-units s"))
add(c, "units", "raw-counts", f"matrix IN:session_counts.csv {P_} --gyro-units counts", 2,
    ("--gyro-units", "count"))
add(c, "usage", "skip-rows-on-npy", f"matrix IN:session.npy {P_} --skip-rows 2", 2, ("--skip-rows", "session.npy"))
add(c, "usage", "time-units-with-rate-hz", f"{MN} --rate-hz 50 --time-units s", 2, ("--time-units", "--rate-hz"))
add(c, "usage", "comment-is-delimiter", f"{M} --comment ';' --delimiter ';'", 2, "--comment")
bad_values(c, M, "--skip-rows", ["-1", "two", "1.5", ""], "skip-rows")
bad_values(c, M, "--comment", ["", "ab", "1", ","], "comment")
bad_values(c, M, "--delimiter", ["", "ab", "7", "newline"], "delimiter")
bad_values(c, M, "--time-units", ["", "h", "sec", "min"], "time-units")
bad_values(c, M, "--gyro-units", ["0 deg/s", "-131 LSB/(deg/s)", "131 LSB/g"], "gyro-units-count-size")
c = "apply"
add(c, "borderline", "time-in-ms", "apply IN:session_ms.csv --alignment IN:alignment.json --out CASE:c.csv", 0,
    outputs="c.csv")
add(c, "borderline", "skip-rows", "apply IN:session_preamble.csv --alignment IN:alignment.json --skip-rows 3 "
    "--out CASE:c.csv", 0, outputs="c.csv")
add(c, "malformed", "preamble-without-skip-rows", "apply IN:session_preamble.csv --alignment IN:alignment.json "
    "--out CASE:c.csv", 2, ("session_preamble.csv", "--skip-rows 3"))
c = "allan"
add(c, "borderline", "time-in-ms", "allan IN:static_ms.csv", 0)
add(c, "borderline", "skip-rows", "allan IN:static_preamble.csv --skip-rows 4", 0)
add(c, "malformed", "preamble-without-skip-rows", "allan IN:static_preamble.csv", 2,
    ("static_preamble.csv", "--skip-rows 4"))
add(c, "units", "time-ms-declared-ns", "allan IN:static_ms.csv --time-units ns", 2, ("time column 'time'", "--time-units"))
add(c, "units", "raw-counts", "allan IN:static_int16.npy --rate-hz 100 --gyro-units counts", 2, ("--gyro-units", "count"))
add(c, "borderline", "count-size", "allan IN:static_int16.npy --rate-hz 100 --gyro-units '0.001 deg/s'", 0)
add(c, "usage", "skip-rows-on-bin", "allan IN:static.bin --rate-hz 100 --skip-rows 1", 2, ("--skip-rows", "static.bin"))
bad_values(c, L, "--delimiter", ["ab", ""], "delimiter")
c = "calibrate accel"
add(c, "borderline", "time-in-us", "calibrate accel IN:accel_us.csv --positions IN:positions.toml", 0)
add(c, "borderline", "count-size", "calibrate accel IN:accel.csv --positions IN:positions.toml --accel-units "
    "'1 m/s^2'", 0)
bad_values(c, "calibrate accel IN:accel.csv", "--time-units", ["hours"], "time-units")
c = "calibrate mag"
add(c, "borderline", "semicolons-and-comment", "calibrate mag IN:mag_semicolon.csv --delimiter ';' --comment '#'", 0)
add(c, "malformed", "semicolons-without-delimiter", "calibrate mag IN:mag_semicolon.csv --comment '#'", 2,
    ("mag_semicolon.csv", "--delimiter"))
c = "calibrate ferraris"
add(c, "borderline", "skip-rows", "calibrate ferraris IN:ferraris_preamble.csv --sections IN:sections.json --rate-hz 50 "
    "--skip-rows 2", 0)
add(c, "malformed", "preamble-without-skip-rows", "calibrate ferraris IN:ferraris_preamble.csv --sections "
    "IN:sections.json --rate-hz 50", 2, ("ferraris_preamble.csv", "--skip-rows 2"))


def _unique() -> None:
    ids = [case.id for case in CASES]
    dup = {i for i in ids if ids.count(i) > 1}
    assert not dup, f"duplicate case ids: {sorted(dup)}"


_unique()
COMMAND_ORDER = ["top", "matrix", "apply", "simulate", "budget", "allowable", "check", "plan", "allan", "report", "demo",
                 "calibrate", "calibrate ferraris", "calibrate accel", "calibrate mag"]
assert {case.command for case in CASES} <= set(COMMAND_ORDER)
assert all(isinstance(case.code, int) for case in CASES)
