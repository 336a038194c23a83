"""``verify``: a gyro alignment or calibration replayed on a rate-table session it was not fitted to.

The validation log is read as ``matrix`` reads it (:func:`~align.alignment.jobs.matrix_job.read_matrix`), corrected
with the result (``w = A (g - b)``, the result's own :meth:`~align.results.Result.correction`), and ``M`` is
estimated again on the corrected rates with the plan (:func:`align.alignment.pipeline.align`). A correction that
works leaves ``M_res = I`` within the session's noise: the residual scale errors ``|M_res,i| - 1`` and the
residual cross-axis misalignments ``phi_ij`` of ``M_res`` (reference section 1) are the figures of merit
``residual_scale_i`` and ``residual_phi_ij``, each with its 1-sigma, judged against the tolerances
(``|residual_phi_*| <= tolerance_angle``, ``|residual_scale_*| <= tolerance_scale``, a guard band of 2 sigma: WARN
inside it) and a limits file. A FAIL exits 4 on the command line, its file written.

A log read in another unit than it was recorded in is not passed: its corrected rates are off by the ratio of the
units, and the residual scale says so.

Public names
------------
VerifyOptions, VerifyInputs, VerifyResult, VERIFY, verify, FORMAT
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from align.alignment.jobs.matrix_job import MatrixInputs, MatrixOptions, read_matrix
from align.alignment.pipeline import align
from align.errors import InputError, literal
from align.io.source import LogSource
from align.job import Job, Progress, fields_signature, quantity
from align.keyfigures import AXES, figures_from, matrix_figures
from align.provenance import prehashed_record
from align.results import Result
from align.units import DEG

FORMAT = "imu-align.verification"
CONVENTION = ("M_res: g_corrected = M_res w + b_res with g_corrected = A (g - b) of the result verified; a working "
              "correction leaves M_res = I")


@dataclass(frozen=True, kw_only=True)
class VerifyOptions:
    """What ``verify`` replays, on what, and the tolerances (SI).

    Attributes
    ----------
    result : Path
        The alignment (``matrix``) or gyro calibration verified.
    log : LogSource
        The validation session: a rate-table log it was not fitted to (read as ``matrix`` reads it).
    plan : Path
        The validation session's plan.
    sensor : str or None
        The sensor of a calibration holding several (``"gyroscope"``).
    tolerance_angle : float
        Largest residual cross-axis misalignment, rad.
    tolerance_scale : float
        Largest residual scale error, dimensionless.
    limits : Path or None
        A limits file (:mod:`align.limits`) beside the tolerances.
    """

    result: Path
    log: LogSource
    plan: Path
    sensor: str | None = None
    tolerance_angle: float = quantity(0.05 * DEG, "angle", gt=0)
    tolerance_scale: float = quantity(0.001, "dimensionless", gt=0, le=1)
    limits: Path | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "result", Path(self.result))

    def tolerance_limits(self) -> dict[str, Any]:
        """The tolerances as a limits table (:func:`align.limits.limits_from_dict`), SI."""
        return {"residual_phi_*": {"abs_max": f"{self.tolerance_angle / DEG!r} deg"},
                "residual_scale_*": {"abs_max": f"{self.tolerance_scale * 100!r} %"}}

    def matrix_options(self) -> MatrixOptions:
        """The session read as ``matrix`` reads it."""
        return MatrixOptions(log=self.log, plan=self.plan)


@dataclass(frozen=True)
class VerifyInputs:
    """The validation session as read (``matrix``'s checked inputs) and the correction verified."""

    session: MatrixInputs
    correction: Any


class VerifyResult(Result, format=FORMAT, convention=CONVENTION):
    """The residual of a correction on a session it was not fitted to.

    Attributes
    ----------
    M_res, sigma_M_res : ndarray, shape (3, 3)
        ``M`` estimated on the corrected rates, and its 1-sigma.
    verified : str
        The result file verified.
    inputs : dict
        The session and the tolerances.
    """

    M_res: np.ndarray
    sigma_M_res: np.ndarray
    verified: str
    inputs: dict = field(default_factory=dict)

    def figures_of_merit(self) -> tuple:
        """``residual_scale_i = |M_res,i| - 1`` and ``residual_phi_ij`` with their 1-sigma (:mod:`align.keyfigures`)."""
        values = matrix_figures(self.M_res, self.sigma_M_res, None, angle_sigmas_too=True)
        out: dict[str, float] = {}
        for a in AXES:
            out[f"residual_scale_{a}"] = values[f"scale_{a}"] - 1.0
            out[f"residual_scale_{a}_sigma"] = values[f"scale_{a}_sigma"]
            for b in AXES:
                if a != b:
                    out[f"residual_phi_{a}{b}"] = values[f"phi_{a}{b}"]
                    out[f"residual_phi_{a}{b}_sigma"] = values[f"phi_{a}{b}_sigma"]
        return figures_from(out, "gyroscope", method="M estimated again on the corrected validation session")

    def to_dict(self) -> dict[str, Any]:
        """The JSON form (``M_res`` dimensionless)."""
        return {**self.envelope({"M_res": "1"}), "verified": self.verified, "M_res": self.M_res.tolist(),
                "sigma_M_res": self.sigma_M_res.tolist(), "inputs": self.inputs}

    @classmethod
    def from_dict(cls, d: dict, where: str = "verification") -> VerifyResult:
        """The result :meth:`to_dict` wrote."""
        cls.check_envelope(d, where, ("verified", "M_res", "sigma_M_res", "inputs"))
        try:
            return cls(np.array(d["M_res"], float).reshape(3, 3), np.array(d["sigma_M_res"], float).reshape(3, 3),
                       str(d["verified"]), dict(d.get("inputs") or {}))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"malformed verification ({exc}); regenerate it", where) from None


def read_verify(options: VerifyOptions) -> VerifyInputs:
    """The correction (a gyro's: an alignment, or a calibration's gyroscope) and the session read as ``matrix``
    reads it; a result of another sensor is refused naming ``{sensor}``."""
    from align.results import load_result

    where = str(options.result)
    result = load_result(options.result)
    if result.FORMAT == "imu-align.thermal":
        raise InputError("is a thermal calibration (bias against temperature); verify replays an alignment or a gyro "
                         "calibration on a rate-table session: give one of those, or check a thermal result with "
                         "apply on a held-out log", where)
    correction = result.correction(options.sensor, where)
    if str(correction.sensor) != "gyroscope":
        raise InputError(f"corrects a {correction.sensor}; verify replays a gyro's correction on a rate-table "
                         "session (give its gyroscope with {sensor})", where)
    session = read_matrix(options.matrix_options())
    fitted = {f.sha256 for f in getattr(result.provenance, "files", ()) if f.role == "log" and f.sha256}
    if fitted and prehashed_record("log", options.log.path, keep=True).sha256 in fitted:
        raise InputError(f"is the session {literal(where)} was fitted on (the same bytes as its provenance's log): its "
                         "residual says nothing of other sessions; verify on another session of the unit",
                         str(options.log.path))
    return VerifyInputs(session, correction)


def compute_verify(inputs: VerifyInputs, options: VerifyOptions, progress: Progress | None = None) -> VerifyResult:
    """``M`` estimated again on the corrected session (module docstring)."""
    got, matrix = inputs.session.log, options.matrix_options()
    corrected = np.asarray(inputs.correction.correct(got.data), float)
    again = align(got.t, corrected, inputs.session.plan, matrix.align_options(), inputs.session.segments, got.shown,
                  str(options.log.path))
    if progress is not None:
        progress(len(got.t))
    return VerifyResult(again.M, again.sigma_M, str(options.result),
                        {"log": str(options.log.path), "plan": str(options.plan), "gyro_units": got.units,
                         "tolerance_angle_deg": options.tolerance_angle / DEG, "tolerance_scale": options.tolerance_scale,
                         "method": again.method})


def verify_files(options: VerifyOptions) -> dict[str, Path | None]:
    """The input files: the result verified, the session and its plan."""
    return {"result": options.result, "log": options.log.path, "plan": options.plan}


VERIFY: Job[VerifyOptions, VerifyInputs, VerifyResult] = Job(
    "verify", VerifyOptions, read_verify, compute_verify, verify_files,
    "replay a gyro correction on a session it was not fitted to: the residual M and its verdict")


@fields_signature(VerifyOptions)
def verify(*, progress: Progress | None = None, **fields: Any) -> VerifyResult:
    """The residual of a correction on a validation session, as ``imu-align verify`` finds it (module docstring)."""
    from align.alignment.jobs.common import source

    if "log" in fields:
        fields["log"] = source(fields["log"])
    return VERIFY.run(VerifyOptions(**fields), progress=progress)


__all__ = ["VerifyOptions", "VerifyInputs", "VerifyResult", "VERIFY", "verify", "FORMAT"]
