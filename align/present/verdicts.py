"""The report's verdicts: each check with its outcome and the one number behind it, and the measured
misalignment against what the manoeuvre allows, element by element.

A :class:`Verdict` is one line of the summary at the top of the report (``PASS``, ``FAIL``, ``WARN``
for a result within its guard band of a limit or a caution, or ``INFO`` for a result that has no requirement
to meet). A design check (the mounting budget against the allowance) governs the report's outcome only
when no measured misalignment is checked: the measured unit governs, and the budget's outcome is shown
labelled as a design check. :func:`angle_sigmas` gives the 1-sigma of every angle of reference section 1;
the measured misalignment against the manoeuvre is :mod:`align.present.measured`.

Public names
------------
Verdict, angle_vector, angle_sigmas, summary_section, worst, ANGLE_NAMES, PASS, FAIL, WARN, INFO, NOT_CHECKED
(the members of :class:`align.vocab.Status`, the one verdict type)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.present.html import Section, esc, table
from align.vocab import Status

PASS, FAIL, WARN, INFO, NOT_CHECKED = Status.PASS, Status.FAIL, Status.WARN, Status.INFO, Status.NOT_CHECKED
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
    status : Status
        ``WARN``: a caution that fails nothing; ``NOT CHECKED``: a requirement that could not be judged (never
        counted as passed); ``INFO``: a result shown without a requirement to meet.
    number : str
        The one number behind the verdict, with its unit, as shown.
    value : float
        That number, in the unit shown (for tests and machine readers; NaN when there is none).
    detail : str
        One line: which element, against what.
    design : bool
        A design-stage check (the mounting budget against the allowance), not a measurement of the unit.
    governs : bool
        Whether a FAIL fails the report (False for a design check when a measurement is checked too).
    """

    check: str
    status: Status
    number: str
    value: float = float("nan")
    detail: str = ""
    design: bool = False
    governs: bool = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "status", Status.parse(self.status))

    @property
    def failed(self) -> bool:
        """A FAIL that fails the report (a design check's FAIL does not when a measurement governs)."""
        return self.status == FAIL and self.governs

    @property
    def shown(self) -> str:
        """The status as the summary shows it: ``FAIL (design check)`` when it does not govern."""
        return f"{self.status} (design check)" if self.design and not self.governs and self.status != INFO \
            else self.status


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
        flat = np.zeros(9)
        flat[k] = h
        d = flat.reshape(3, 3)
        jac[:, k] = (angle_vector((m + d) @ n.T) - angle_vector((m - d) @ n.T)) / (2 * h)
    var = (jac**2) @ np.square(np.asarray(sigma_m, float)).ravel()
    return dict(zip(ANGLE_NAMES, np.sqrt(var).tolist()))


def worst(rows: list) -> object:
    """The row of smallest margin (the binding one), constrained rows first."""
    bounded = [r for r in rows if np.isfinite(r.allowed)]
    return min(bounded or rows, key=lambda r: r.margin if np.isfinite(r.allowed) else np.inf)


def _cls(status: str) -> str:
    return {PASS: "pass", FAIL: "fail", WARN: "warn", NOT_CHECKED: "warn"}.get(Status.parse(status), "info")


def summary_section(verdicts: list[Verdict]) -> Section:
    """The summary: the overall outcome in one line, then each check, its verdict, its number and what it means."""
    if not verdicts:
        return Section("Summary", "<p>No check: no input was given that a requirement applies to.</p>")
    governing = [v for v in verdicts if v.governs]
    failed = [v for v in governing if v.status == FAIL]
    warned = [v for v in governing if v.status == WARN]
    checked = [v for v in governing if v.status.judged]
    unchecked = [v for v in governing if v.status == NOT_CHECKED]
    n = f"{len(checked)} check{'s' if len(checked) != 1 else ''}"
    cautions = "" if not warned else (f" {len(warned)} WARN ({esc(', '.join(v.check for v in warned))}): within the "
                                      "guard band of a limit, or a caution.")
    if unchecked:  # never counted as passed, and said in the banner
        cautions += (f" {len(unchecked)} NOT CHECKED ({esc(', '.join(v.check for v in unchecked))}): "
                     "the data or the limit to judge it were not there.")
    if failed:
        head = (f'<p class="banner fail">FAIL: {len(failed)} of {n} failed ({esc(", ".join(v.check for v in failed))}).'
                f"{cautions}</p>")
    elif warned:
        head = f'<p class="banner warn">WARN: none of {n} failed;{cautions}</p>'
    elif checked and unchecked:
        head = (f'<p class="banner warn">PASS on the {n} that ran, but not everything was checked:{cautions}</p>')
    elif checked:
        head = ('<p class="banner pass">PASS: ' + ("the one check passed" if len(checked) == 1
                                                   else f"all {len(checked)} checks passed") + ".</p>")
    elif unchecked:
        head = f'<p class="banner warn">NOT CHECKED: no requirement could be judged.{cautions}</p>'
    else:
        head = '<p class="banner info">No requirement was given: the results below are reported without a verdict.</p>'
    design = [v for v in verdicts if not v.governs and v.status in (FAIL, WARN)]
    if design:
        head += (f'<p class="note">Design check{"s" if len(design) > 1 else ""} '
                 f"{esc(', '.join(v.check for v in design))}: {esc(', '.join(v.status for v in design))}. A design check "
                 "(what the mounting is predicted to give) does not set this report's outcome when the unit's "
                 "misalignment is measured: the measurement governs.</p>")
    rows = [[v.check, (v.shown, _cls(v.status)), v.number, v.detail] for v in verdicts]
    return Section("Summary", head + table(["check", "verdict", "number", "what it means"], rows, left=4))
