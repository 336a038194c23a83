"""The report's verdicts: each check with its outcome and the one number behind it, and the measured
misalignment against what the manoeuvre allows, element by element.

A :class:`Verdict` is one line of the summary at the top of the report (``PASS``, ``FAIL``, or ``INFO``
for a result that has no requirement to meet); :func:`measured_margins` sets an alignment result's
angles (with their 1-sigma, :func:`angle_sigmas`) against an :class:`~align.sensitivity.allowable.Allowable`.

Public names
------------
Verdict, MeasuredMargin, angle_vector, angle_sigmas, measured_margins, summary_section, measured_section,
PASS, FAIL, WARN, INFO
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.present.html import Section, esc, table
from align.sensitivity.symbolic import ELEMENTS
from align.units import DEG

PASS, FAIL, WARN, INFO = "PASS", "FAIL", "WARN", "INFO"
#: the angles :func:`angle_vector` returns, in order
ANGLE_NAMES = ("psi_x", "psi_y", "psi_z", "phi_xy", "phi_xz", "phi_yx", "phi_yz", "phi_zx", "phi_zy",
               "delta_xy", "delta_xz", "delta_yz", "rot_x", "rot_y", "rot_z")


@dataclass(frozen=True)
class Verdict:
    """One check of the report's summary.

    Attributes
    ----------
    check : str
        What was checked (``"measured misalignment vs allowance"``).
    status : {"PASS", "FAIL", "WARN", "INFO"}
        ``WARN``: a caution that fails nothing; ``INFO``: a result shown without a requirement to meet.
    number : str
        The one number behind the verdict, with its unit, as shown.
    value : float
        That number, in the unit shown (for tests and machine readers; NaN when there is none).
    detail : str
        One line: which element, against what.
    """

    check: str
    status: str
    number: str
    value: float = float("nan")
    detail: str = ""

    @property
    def failed(self) -> bool:
        return self.status == FAIL


@dataclass(frozen=True)
class MeasuredMargin:
    """One element of the measured misalignment against the allowance (angles in rad).

    ``measured`` is signed (``phi_ij``); the check compares ``|measured|`` with ``allowed`` (``inf``:
    unconstrained); ``margin = allowed - |measured|``.
    """

    element: str
    measured: float
    sigma: float
    allowed: float

    @property
    def margin(self) -> float:
        return self.allowed - abs(self.measured)

    @property
    def ok(self) -> bool:
        return abs(self.measured) <= self.allowed

    @property
    def sigmas(self) -> float:
        """The margin in units of the measurement's 1-sigma (NaN when unconstrained or sigma unknown)."""
        if not np.isfinite(self.allowed) or not self.sigma > 0:
            return float("nan")
        return self.margin / self.sigma


def angle_vector(m: np.ndarray) -> np.ndarray:
    """The angles of reference section 1 read from ``M`` (already relative to the nominal mounting), rad.

    ``psi_i = atan2(|u_i x e_i|, u_i . e_i)`` (equal to ``acos(u_i . e_i)``, well conditioned near 0),
    ``phi_ij = asin(u_i . e_j)``, ``delta_ij = asin(u_i . u_j)``, and the rotation vector of the mounting
    rotation ``R`` with ``R^T`` the nearest proper rotation to ``M`` (:func:`align.model.angles`).

    Returns
    -------
    ndarray, shape (15,)
        In :data:`ANGLE_NAMES` order.
    """
    from align.model import angles

    m = np.asarray(m, float)
    u = m / np.linalg.norm(m, axis=1, keepdims=True)
    psi = [np.arctan2(np.linalg.norm(np.cross(u[i], np.eye(3)[i])), u[i, i]) for i in range(3)]
    phi = [np.arcsin(np.clip(u[i, j], -1, 1)) for i in range(3) for j in range(3) if i != j]
    delta = [np.arcsin(np.clip(u[i] @ u[j], -1, 1)) for i, j in ((0, 1), (0, 2), (1, 2))]
    return np.concatenate([psi, phi, delta, angles(m).mounting_rotvec])


def angle_sigmas(m: np.ndarray, sigma_m: np.ndarray, mounting: np.ndarray | None = None) -> dict:
    """1-sigma of every angle of ``M N^T`` by first-order propagation of the elements' 1-sigma.

    ``sigma_a^2 = sum_kl (d a / d M_kl)^2 sigma_M,kl^2`` (the elements taken independent, as the result
    states no covariance), the derivatives by central differences of :func:`angle_vector`.

    Parameters
    ----------
    m, sigma_m : ndarray, shape (3, 3)
        The measured ``M`` and its 1-sigma (NaN: unknown, giving NaN sigmas).
    mounting : ndarray, shape (3, 3), optional
        Nominal mounting ``N`` (rows: gyro axes in the system frame); the identity when None.

    Returns
    -------
    dict of str -> float
        :data:`ANGLE_NAMES` -> 1-sigma, rad.
    """
    n = np.eye(3) if mounting is None else np.asarray(mounting, float)
    m = np.asarray(m, float)
    h = 1e-7
    jac = np.zeros((len(ANGLE_NAMES), 9))
    for k in range(9):
        d = np.zeros(9)
        d[k] = h
        d = d.reshape(3, 3)
        jac[:, k] = (angle_vector((m + d) @ n.T) - angle_vector((m - d) @ n.T)) / (2 * h)
    var = (jac**2) @ np.square(np.asarray(sigma_m, float)).ravel()
    return dict(zip(ANGLE_NAMES, np.sqrt(var).tolist()))


def measured_margins(result, allow) -> list[MeasuredMargin]:
    """An alignment result's misalignment against a manoeuvre's allowance, element by element.

    Parameters
    ----------
    result : AlignmentResult
        Its angles are those of ``M N^T`` (relative to the nominal mounting).
    allow : Allowable
        Allowance per element, rad (``inf``: unconstrained).

    Returns
    -------
    list of MeasuredMargin
        In :data:`~align.sensitivity.symbolic.ELEMENTS` order; ``psi_i`` and ``phi_ij`` from
        :attr:`AlignmentResult.angles`, the 1-sigma from :func:`angle_sigmas`.
    """
    ang = result.angles
    sig = angle_sigmas(result.M, result.sigma_M, result.mounting)
    value = {f"psi_{a}": float(ang.psi[i]) for i, a in enumerate("xyz")}
    value.update({f"phi_{a}{b}": float(ang.phi[i, j]) for i, a in enumerate("xyz") for j, b in enumerate("xyz") if i != j})
    return [MeasuredMargin(e, value[e], sig[e], float(allow.allowable[e])) for e in ELEMENTS]


def worst(rows: list) -> object:
    """The row of smallest margin (the binding one), constrained rows first."""
    bounded = [r for r in rows if np.isfinite(r.allowed)]
    return min(bounded or rows, key=lambda r: r.margin if np.isfinite(r.allowed) else np.inf)


def _cls(status: str) -> str:
    return {PASS: "pass", FAIL: "fail", WARN: "warn"}.get(status, "info")


def summary_section(verdicts: list[Verdict]) -> Section:
    """The summary: the overall outcome in one line, then each check, its verdict, its number and what it means."""
    if not verdicts:
        return Section("Summary", "<p>No check: no input was given that a requirement applies to.</p>")
    failed = [v for v in verdicts if v.failed]
    checked = [v for v in verdicts if v.status in (PASS, FAIL)]
    if failed:
        head = (f'<p class="banner fail">FAIL: {len(failed)} of {len(checked)} check{"s" if len(checked) != 1 else ""} '
                f"failed ({esc(', '.join(v.check for v in failed))}).</p>")
    elif checked:
        head = ('<p class="banner pass">PASS: ' + ("the one check passed" if len(checked) == 1
                                                   else f"all {len(checked)} checks passed") + ".</p>")
    else:
        head = '<p class="banner info">No requirement was given: the results below are reported without a verdict.</p>'
    rows = [[v.check, (v.status, _cls(v.status)), v.number, v.detail] for v in verdicts]
    return Section("Summary", head + table(["check", "verdict", "number", "what it means"], rows, left=4))


def measured_section(rows: list[MeasuredMargin], note: str = "") -> Section:
    """The measured misalignment (with its 1-sigma) against the allowance, element by element."""
    out = []
    for r in rows:
        bounded = np.isfinite(r.allowed)
        sign = "+" if r.element.startswith("phi") else ""  # phi_ij is signed, psi_i an angle from the axis
        out.append([r.element, f"{r.measured / DEG:{sign}.4f}", "-" if not np.isfinite(r.sigma) else f"{r.sigma / DEG:.4f}",
                    f"{r.allowed / DEG:.4f}" if bounded else "unconstrained",
                    f"{r.margin / DEG:+.4f}" if bounded else "-",
                    "-" if not np.isfinite(r.sigmas) else f"{r.sigmas:+.1f}",
                    ("PASS", "pass") if r.ok else ("FAIL", "fail")])
    ok = all(r.ok for r in rows)
    body = (f"<p>Measured misalignment against the allowance: <b class=\"{'pass' if ok else 'fail'}\">"
            f"{'PASS' if ok else 'FAIL'}</b>. |measured| is compared with the allowed angle; margin = allowed - "
            "|measured|.</p>"
            + table(["element", "measured [deg]", "1-sigma [deg]", "allowed [deg]", "margin [deg]", "margin / sigma",
                     "result"], out)
            + (f'<p class="note">{esc(note)}</p>' if note else ""))
    return Section("Measured misalignment against the allowance", body)
