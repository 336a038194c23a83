"""The result of an electronic alignment: ``M``, ``A``, bias, uncertainties, checks, and its versioned file.

Public names
------------
AlignmentResult, SegmentReport, FILE_KEYS, FORMAT, FORMAT_VERSION
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import cast

import numpy as np

from align import CONVENTION
from align.alignment.checks import Check
from align.alignment.geometry import mounting_axes, mounting_label
from align.alignment.linearity import Linearity
from align.alignment.segment import Motion
from align.errors import InputError
from align.io import c_header
from align.model import Angles, SensorModel, angles
from align.results import Result, file_unit
from align.units import DEG, parse_unit, to_unit
from align.values import Value
from align.wellformed import array_field, check_inverse, malformed

FORMAT = "imu-align.alignment"
FORMAT_VERSION = 1


@dataclass(frozen=True, eq=False)
class SegmentReport(Value):
    """A segment as used in the fit; ``residual`` in rad/s (dwells, static) or rad (turns)."""

    name: str
    kind: str
    start: int
    end: int
    t_start: float
    t_end: float
    residual: tuple[float, float, float]
    noise: tuple[float, float, float]


#: the keys of an alignment result file after the envelope
FILE_KEYS = ("sensor", "method", "M", "A", "bias", "uncertainty", "angles", "condition_number", "dof", "inferred_axis",
             "segments", "checks", "notes", "inputs", "mounting", "motions", "linearity")


class AlignmentResult(Result, format=FORMAT, version=FORMAT_VERSION, convention=CONVENTION):
    """Result of an electronic alignment (``g = M w + b``, ``w = A (g - b)``).

    ``bias`` and ``sigma_bias`` are rad/s; ``M``, ``A`` and their sigmas are
    dimensionless; ``units`` is the display/file unit of rates. ``M`` and ``A`` are whole (``A`` maps raw
    readings to system rates); ``mounting`` is the nominal mounting ``N`` (rows: gyro axes in the system
    frame) and the angles are those of ``M N^T``, relative to it.
    """

    method: str
    M: np.ndarray
    A: np.ndarray
    bias: np.ndarray
    sigma_M: np.ndarray
    sigma_A: np.ndarray
    sigma_bias: np.ndarray
    condition_number: float
    dof: int
    segments: tuple[SegmentReport, ...]
    checks: tuple[Check, ...]
    notes: tuple[str, ...]
    units: str = "deg/s"
    inferred_axis: int | None = None
    inputs: dict = field(default_factory=dict)
    mounting: np.ndarray = field(default_factory=lambda: np.eye(3))
    mounting_source: str = "identity"
    motions: tuple[Motion, ...] = ()
    #: the scale factor across the range (a plan with two or more rates in each direction about an axis), else None
    linearity: Linearity | None = None

    @property
    def angles(self) -> Angles:
        """Scale factors and misalignment angles of ``M N^T``: relative to the nominal mounting (reference section 1)."""
        return angles(self.M @ self.mounting.T)

    @property
    def model(self) -> SensorModel:
        """The measurement model ``g = M w + b`` this result estimated."""
        return SensorModel(self.M, self.bias)

    @property
    def sensor(self) -> str:
        """The sensor this result corrects: always ``"gyroscope"``."""
        return "gyroscope"

    def figures_of_merit(self) -> tuple:
        """``M``, its decomposition relative to the nominal mounting and the bias, each with its 1-sigma
        (:func:`align.keyfigures.matrix_figures`)."""
        from align.keyfigures import figures_from, matrix_figures, vector_figures

        values = matrix_figures(self.M, self.sigma_M, self.mounting, angle_sigmas_too=True)
        out = figures_from(values | vector_figures("bias", self.bias, self.sigma_bias), "gyroscope",
                           method=f"rate-table alignment ({self.method})")
        if self.linearity is None:
            return out
        return out + tuple(f for f in self.linearity.figures() if not f.name.startswith("scale_"))

    def correct(self, g: np.ndarray) -> np.ndarray:
        """Aligned rates ``w = A (g - b)`` (Eq 15) for readings of shape (3,) or (n, 3), rad/s."""
        return self.model.correct(g)

    def correction(self, sensor: str | None = None, where: str = "result") -> AlignmentResult:
        """This result, which corrects gyro logs (see :class:`align.results.Correction`).

        Refuses (naming ``where``) an ``M`` that is not finite, singular or has ``det <= 0``
        (:func:`align.plausible.check_usable_model`).
        """
        return self._only_sensor("gyroscope", sensor, where, "M")

    def as_c_header(self, comment: str, name: str = "IMU_ALIGN") -> str:
        """A C header with ``A`` and the bias (in :attr:`units`) for ``w = A (g - b)`` in firmware."""
        return c_header(name, self.A, to_unit(self.bias, self.units), self.units, comment)

    def to_dict(self) -> dict:
        """The versioned JSON form; rates in ``self.units``, angles in deg; ``linearity`` only when measured."""
        d = self._to_dict()
        if self.linearity is not None:
            d["units"]["linearity_rate"] = self.units
            d["linearity"] = self.linearity.to_dict(parse_unit(self.units).factor)
        return d

    def _to_dict(self) -> dict:
        u = self.units
        ang = self.angles
        pairs = ("xy", "xz", "yz")
        phi = {f"phi_{'xyz'[i]}{'xyz'[j]}": float(ang.phi[i, j] / DEG) for i in range(3) for j in range(3) if i != j}
        return {
            **self.envelope({"M": "1", "A": "1", "bias": u, "angles": "deg",
                             "residual_rate": u, "residual_angle": "deg", "time": "s", "motion_rate": u,
                             "motion_angle": "deg"}),
            "sensor": "gyroscope",
            "method": self.method,
            "M": self.M.tolist(),
            "A": self.A.tolist(),
            "bias": to_unit(self.bias, u).tolist(),
            "uncertainty": {
                "level": "1 sigma",
                "M": self.sigma_M.tolist(),
                "A": self.sigma_A.tolist(),
                "bias": to_unit(self.sigma_bias, u).tolist(),
            },
            "angles": {
                "scale": ang.scale.tolist(),
                "psi_deg": {f"psi_{a}": float(v / DEG) for a, v in zip("xyz", ang.psi)},
                "phi_deg": phi,
                "delta_deg": {f"delta_{p}": float(v / DEG) for p, v in zip(pairs, ang.delta)},
                "mounting_rotvec_deg": (ang.mounting_rotvec / DEG).tolist(),
                "relative_to": "nominal mounting",
                "assumed_scale": None if self.inferred_axis is None else
                "xyz"[int(np.argmax(np.abs(self.mounting[:, self.inferred_axis])))],
            },
            "condition_number": self.condition_number,
            "dof": self.dof,
            "inferred_axis": None if self.inferred_axis is None else "xyz"[self.inferred_axis],
            "segments": [
                {"name": s.name, "kind": s.kind, "start": s.start, "end": s.end,
                 "t_start": s.t_start, "t_end": s.t_end,
                 "residual": (np.array(s.residual) / (DEG if s.kind == "angle" else parse_unit(u).factor)).tolist(),
                 "noise": (np.array(s.noise) / (DEG if s.kind == "angle" else parse_unit(u).factor)).tolist()}
                for s in self.segments
            ],
            "checks": [c.to_dict() for c in self.checks],
            "notes": list(self.notes),
            "inputs": self.inputs,
            "mounting": {"matrix": self.mounting.tolist(), "axes": mounting_axes(self.mounting),
                         "source": self.mounting_source, "label": mounting_label(self.mounting)},
            "motions": [{**mo.to_dict(), "value": float(mo.value / (parse_unit(u).factor if mo.kind == "rate" else DEG))}
                        for mo in self.motions],
        }

    @classmethod
    def from_dict(cls, d: dict, where: str = "result") -> AlignmentResult:
        """Read the form written by :meth:`to_dict` (any version up to the current one)."""
        cls.check_envelope(d, where, keys=FILE_KEYS)  # a misspelled key is refused, not ignored
        try:
            u, f = file_unit(d, "bias", "angular_rate", where)
            m = array_field(d, "M", (3, 3), "alignment result", where)
            unc = d.get("uncertainty", {})
            segs = tuple(
                SegmentReport(s["name"], s["kind"], s["start"], s["end"], s["t_start"], s["t_end"],
                              tuple(np.array(s["residual"], float) * (DEG if s["kind"] == "angle" else f)),
                              tuple(np.array(s["noise"], float) * (DEG if s["kind"] == "angle" else f)))
                for s in d.get("segments", [])
            )
            inferred = d.get("inferred_axis")
            a = array_field(d, "A", (3, 3), "alignment result", where)
            check_inverse(m, a, where, "")  # a hand-edited A is refused where it is read, for every command
            bias = array_field(d, "bias", (3,), "alignment result", where, f)
            return cls(
                method=d["method"], M=m, A=a, bias=bias,
                sigma_M=np.array(unc.get("M", np.full((3, 3), np.nan)), float).reshape(3, 3),
                sigma_A=np.array(unc.get("A", np.full((3, 3), np.nan)), float).reshape(3, 3),
                sigma_bias=np.array(unc.get("bias", [np.nan] * 3), float).reshape(3) * f,
                condition_number=float(d.get("condition_number") or np.nan), dof=int(d.get("dof", 0)),
                segments=segs,
                checks=tuple(Check(c["name"], c["status"], c["detail"]) for c in d.get("checks", [])),
                notes=tuple(d.get("notes", [])), units=u,
                inferred_axis=None if inferred is None else "xyz".index(inferred),
                inputs=dict(d.get("inputs", {})),
                mounting=np.array(d.get("mounting", {}).get("matrix", np.eye(3).tolist()), float).reshape(3, 3),
                mounting_source=str(d.get("mounting", {}).get("source", "identity")),
                motions=tuple(Motion(mo["name"], mo["kind"], int(mo["start"]), int(mo["end"]), float(mo["t_start"]),
                                     float(mo["t_end"]), float(mo["value"]) * (f if mo["kind"] == "rate" else DEG),
                                     # three numbers as to_dict writes them (the length is not checked here)
                                     cast("tuple[float, float, float]", tuple(float(v) for v in mo["axis"])),
                                     str(mo["label"]))
                              for mo in d.get("motions", [])),
                linearity=None if d.get("linearity") is None else
                Linearity.from_dict(d["linearity"], file_unit(d, "linearity_rate", "angular_rate", where)[1]),
            )
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise InputError(f"malformed alignment result ({malformed(exc)}); regenerate it with imu-align matrix",
                             where) from None
