"""The measured misalignment against a manoeuvre's limits: propagated through the manoeuvre (the verdict)
and element by element against each element's allowance (the diagnosis), with a guard band on the 1-sigma.

The verdict propagates the measured misalignment, ``D = M N^T`` with its rows scaled to unit length (the
directions of the gyro axes relative to the nominal mounting ``N``; scale-factor errors are the
calibration's, not a misalignment), through the manoeuvre by attitude propagation
(:func:`align.sensitivity.propagation.output_errors`), so that the errors of several elements add up as they
do in flight; its 1-sigma is the first-order propagation of ``sigma(M)`` through the same computation
(central differences, the elements taken independent). Each limited output is then judged with a guard
band of ``k`` sigma (:func:`guard`): PASS when ``limit - error > k sigma``, FAIL when
``limit - error < -k sigma``, WARN in between (within ``k`` sigma of the limit). ``k = 2`` (:data:`GUARD_K`)
is the usual choice of test reports (a guard band of twice the standard uncertainty, as in ILAC-G8 and
ISO 14253-1's acceptance zones).

Each element alone against its allowance (:func:`measured_margins`, the allowance of
:func:`align.sensitivity.allowable` computed with the other elements at zero) shows which element uses
the allowance up; it does not decide the verdict, since errors from several elements add.

Public names
------------
GUARD_K, guard, worst_status, OutputMargin, MeasuredMargin, output_margins, measured_margins, measured_section,
describe, headline
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.present.digits import ratio_text, with_sigma
from align.present.html import Section, table
from align.present.verdicts import FAIL, PASS, WARN, angle_sigmas
from align.sensitivity.symbolic import ELEMENTS
from align.units import DEG
from align.vocab import Status

#: the guard band, in units of the 1-sigma
GUARD_K = 2.0


def guard(margin: float, sigma: float, k: float = GUARD_K) -> str:
    """``PASS`` when ``margin > k sigma``, ``FAIL`` when ``margin < -k sigma``, ``WARN`` in between;
    ``"-"`` for an unconstrained margin (``inf`` / NaN); an unknown sigma counts as 0 (the sign decides)."""
    if not np.isfinite(margin):
        return "-"
    band = k * sigma if np.isfinite(sigma) and sigma > 0 else 0.0
    if margin > band:
        return PASS
    if margin < -band:
        return FAIL
    return WARN


def worst_status(statuses) -> Status:
    """FAIL over WARN over PASS (``"-"`` ignored; PASS when nothing was judged)."""
    s = set(statuses)
    return FAIL if FAIL in s else WARN if WARN in s else PASS


@dataclass(frozen=True)
class OutputMargin:
    """One limited output of the manoeuvre: the largest error the measured misalignment gives it (rad).

    ``margin = limit - error``; :attr:`status` by :func:`guard` with :attr:`k`.
    """

    output: str
    error: float
    sigma: float
    limit: float
    k: float = GUARD_K

    @property
    def margin(self) -> float:
        return self.limit - self.error

    @property
    def status(self) -> str:
        return guard(self.margin, self.sigma, self.k)

    @property
    def sigmas(self) -> float:
        """The margin in units of the 1-sigma (NaN when the sigma is unknown)."""
        return self.margin / self.sigma if np.isfinite(self.sigma) and self.sigma > 0 else float("nan")


@dataclass(frozen=True)
class MeasuredMargin:
    """One element of the measured misalignment against its allowance alone (angles in rad).

    ``measured`` is signed (``phi_ij``); the check compares ``|measured|`` with ``allowed`` (``inf``:
    unconstrained); ``margin = allowed - |measured|``; :attr:`status` by :func:`guard` (``"-"``: unconstrained).
    """

    element: str
    measured: float
    sigma: float
    allowed: float
    k: float = GUARD_K

    @property
    def margin(self) -> float:
        return self.allowed - abs(self.measured)

    @property
    def status(self) -> str:
        return guard(self.margin, self.sigma, self.k)

    @property
    def ok(self) -> bool:
        """Not FAIL (PASS, WARN or unconstrained)."""
        return self.status != FAIL

    @property
    def sigmas(self) -> float:
        """The margin in units of the measurement's 1-sigma (NaN when unconstrained or sigma unknown)."""
        if not np.isfinite(self.allowed) or not self.sigma > 0:
            return float("nan")
        return self.margin / self.sigma


def _directions(m: np.ndarray, mounting: np.ndarray) -> np.ndarray:
    """``M N^T`` with unit rows: the gyro axes' directions relative to the nominal mounting."""
    d = np.asarray(m, float) @ np.asarray(mounting, float).T
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def output_margins(m: np.ndarray, sigma_m: np.ndarray, mounting: np.ndarray | None, man,
                   k: float = GUARD_K) -> list[OutputMargin]:
    """The measured misalignment propagated through a manoeuvre, output by output, with its 1-sigma.

    ``e_o = max_t |error_o(t)|`` of :func:`~align.sensitivity.propagation.output_errors` for ``D`` = ``M N^T``
    with unit rows; ``sigma_e_o^2 = sum_kl (d e_o / d M_kl)^2 sigma_M,kl^2`` (central differences, step
    1e-7; the elements taken independent, as the result states no covariance).

    Parameters
    ----------
    m, sigma_m : ndarray, shape (3, 3)
        The measured ``M`` (rows: gyro axes) and its 1-sigma (NaN: unknown, giving a NaN sigma).
    mounting : ndarray, shape (3, 3) or None
        Nominal mounting ``N`` (rows: gyro axes in the system frame); the identity when None.
    man : Manoeuvre
        With its ``increments`` (n, 3), rad, and ``limits`` (output -> rad).
    k : float
        Guard band, in sigmas.

    Returns
    -------
    list of OutputMargin
        One per limited output, in the manoeuvre's order; rad.
    """
    from align.sensitivity.propagation import output_errors

    n = np.eye(3) if mounting is None else np.asarray(mounting, float)
    m = np.asarray(m, float)
    names = list(man.limits)

    def errors(x: np.ndarray) -> np.ndarray:
        e = output_errors(man, _directions(x, n))
        return np.array([e[o] for o in names])

    e0, h = errors(m), 1e-7
    jac = np.zeros((len(names), 9))
    for j in range(9):
        step = np.zeros(9)
        step[j] = h
        d = step.reshape(3, 3)
        jac[:, j] = (errors(m + d) - errors(m - d)) / (2 * h)
    sigma = np.sqrt((jac**2) @ np.square(np.asarray(sigma_m, float)).ravel())
    return [OutputMargin(o, float(e0[i]), float(sigma[i]), float(man.limits[o]), k) for i, o in enumerate(names)]


def measured_margins(result, allow, k: float = GUARD_K) -> list[MeasuredMargin]:
    """An alignment result's misalignment against a manoeuvre's allowance, element by element (the diagnosis).

    Parameters
    ----------
    result : AlignmentResult
        Its angles are those of ``M N^T`` (relative to the nominal mounting).
    allow : Allowable
        Allowance per element alone, rad (``inf``: unconstrained).
    k : float
        Guard band, in sigmas.

    Returns
    -------
    list of MeasuredMargin
        In :data:`~align.sensitivity.symbolic.ELEMENTS` order; ``psi_i`` and ``phi_ij`` from
        :attr:`AlignmentResult.angles`, the 1-sigma from :func:`~align.present.verdicts.angle_sigmas`.
    """
    ang = result.angles
    sig = angle_sigmas(result.M, result.sigma_M, result.mounting)
    value = {f"psi_{a}": float(ang.psi[i]) for i, a in enumerate("xyz")}
    value.update({f"phi_{a}{b}": float(ang.phi[i, j]) for i, a in enumerate("xyz") for j, b in enumerate("xyz") if i != j})
    return [MeasuredMargin(e, value[e], sig[e], float(allow.allowable[e]), k) for e in ELEMENTS]


def _cls(status: str) -> str:
    classes: dict[str, str] = {PASS: "pass", FAIL: "fail", WARN: "warn"}
    return classes.get(status, "")


def _deg(value: float, sigma: float, sign: bool = False) -> tuple[str, str]:
    """An angle (rad) and its 1-sigma in degrees, the digits following the 1-sigma (:mod:`align.present.digits`)."""
    return with_sigma(value / DEG, sigma / DEG, 4, sign)


def _given(x: float) -> str:
    """A limit or an allowance (a requirement, not a measurement), degrees to 4 decimals."""
    return f"{x / DEG:.4f}"


def measured_section(outputs: list[OutputMargin], rows: list[MeasuredMargin], k: float = GUARD_K) -> Section:
    """The verdict table (each limited output) and the diagnosis table (each element alone)."""
    status = worst_status(o.status for o in outputs)
    out_rows = []
    for o in outputs:
        error, sigma = _deg(o.error, o.sigma)
        out_rows.append([o.output, error, sigma, _given(o.limit), _deg(o.margin, o.sigma, True)[0],
                         ratio_text(o.margin, o.sigma), (o.status, _cls(o.status))])
    el_rows = []
    for r in rows:
        bounded = np.isfinite(r.allowed)
        sign = r.element.startswith("phi")  # phi_ij is signed, psi_i an angle from the axis
        measured, sigma = _deg(r.measured, r.sigma, sign)
        el_rows.append([r.element, measured, sigma, _given(r.allowed) if bounded else "unconstrained",
                        _deg(r.margin, r.sigma, True)[0] if bounded else "-",
                        ratio_text(r.margin, r.sigma) if bounded else "-", (r.status, _cls(r.status))])
    band = (f"Guard band k = {k:g}: PASS when the margin exceeds {k:g} sigma, FAIL when it is below -{k:g} sigma, WARN "
            f"when it is within {k:g} sigma of the limit (the measurement cannot tell). Each value is shown to the decimal "
            "place of its 1-sigma; margin / sigma to two digits, \"> +1000\" beyond a thousand, and not at all "
            "against a 1-sigma of 0.")
    body = (f"<p>Measured misalignment propagated through the manoeuvre: <b class=\"{_cls(status)}\">{status}</b>. "
            "The gyro axes' measured directions relative to the nominal mounting (<code>M N<sup>T</sup></code>, rows "
            "scaled to unit length: scale-factor errors are left out) turn the manoeuvre's rotations by attitude "
            "propagation; each limited output's largest error is compared with its limit; margin = limit - error. "
            "1-sigma by first-order propagation of sigma(M) through the same computation, its elements taken "
            f"independent. {band}</p>"
            + table(["output", "error [deg]", "1-sigma [deg]", "limit [deg]", "margin [deg]", "margin / sigma",
                     "result"], out_rows)
            + "<p>Diagnosis, each element alone against its allowance (computed with the other elements at zero: "
            "errors of several elements add, so this table does not decide the verdict). |measured| is compared "
            "with the allowed angle; margin = allowed - |measured|; the same guard band; \"-\": unconstrained.</p>"
            + table(["element", "measured [deg]", "1-sigma [deg]", "allowed [deg]", "margin [deg]", "margin / sigma",
                     "alone"], el_rows)
            + '<p class="note">The angles are relative to the nominal mounting; their 1-sigma by first-order '
            "propagation of sigma(M), its elements taken independent.</p>")
    return Section("Measured misalignment against the allowance", body)


def describe(outputs: list[OutputMargin], rows: list[MeasuredMargin]) -> tuple[Status, OutputMargin, str]:
    """``(status, the output of smallest margin in sigmas, one line of detail)`` for the summary."""
    status = worst_status(o.status for o in outputs)
    w = min(outputs, key=lambda o: o.margin)
    bounded = [r for r in rows if np.isfinite(r.allowed)]
    near = min(bounded, key=lambda r: r.margin) if bounded else None
    error, sigma = _deg(w.error, w.sigma)
    detail = (f"output {w.output}: error {error} ± {sigma} deg against the {_given(w.limit)} deg "
              f"limit (the measured misalignment propagated through the manoeuvre; guard band {w.k:g} sigma)"
              + ("" if near is None else f"; element nearest its allowance alone: {near.element} "
                 f"{_deg(near.measured, near.sigma, True)[0]} deg of {_given(near.allowed)} deg"))
    over = [o.output for o in outputs if o.status == FAIL]
    if over:
        detail += "; over the limit: " + ", ".join(over)
    return status, w, detail


def headline(w: OutputMargin) -> str:
    """The terminal's line for the binding output, its digits following its 1-sigma
    (``output y: error 0.1559 ± 0.0004 deg, limit 1.0000 deg, margin +0.8441 deg; guard band 2 sigma``).

    Examples
    --------
    >>> headline(OutputMargin("z", 0.0015 * DEG, 4.2e-6 * DEG, 1.0 * DEG))
    'output z: error 0.0015000 ± 0.0000042 deg, limit 1.0000 deg, margin +0.9985000 deg; guard band 2 sigma'
    """
    error, sigma = _deg(w.error, w.sigma)
    return (f"output {w.output}: error {error} ± {sigma} deg, limit {_given(w.limit)} deg, margin "
            f"{_deg(w.margin, w.sigma, True)[0]} deg; guard band {w.k:g} sigma")
