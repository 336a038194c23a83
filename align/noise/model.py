"""The IEEE five-term noise model of an Allan variance curve: the one place it is written.

IEEE Std 952 (Annex C) / Std 1554, reference section 6::

    sigma^2(tau) = 3 Q^2 / tau^2 + N^2 / tau + (2 ln 2 / pi) B^2 + K^2 tau / 3 + R^2 tau^2 / 2

with quantization ``Q`` (rad), angle (velocity) random walk ``N`` (rad/sqrt(s)),
bias instability ``B`` (rad/s; the curve's floor is ``sqrt(2 ln 2 / pi) B =
0.664 B``), rate random walk ``K`` (rad/s/sqrt(s)) and rate ramp ``R``
(rad/s^2); gyro wording, an accelerometer reads the same in m/s. The model is
linear in the squared parameters, which the fit (:mod:`align.noise.fit`) uses;
the planner (:mod:`align.noise.planner`) evaluates it as a curve.

The names engineers use (quantization Q, angle random walk N -- velocity
random walk for an accelerometer --, bias instability B, rate random walk K --
acceleration random walk --, rate ramp R) are in one table, :data:`TERM_TABLE`;
the internal keys of :data:`TERMS` stay as the code's field names.

Public names
------------
TERMS, Term, TERM_TABLE, term, NOISE_ALPHA, FLICKER_FACTOR, avar_design, model_avar, model_adev, NoiseModel
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from align.values import Value

#: the five terms' internal keys, in the order of every parameter vector ``(Q, N, B, K, R)``
TERMS = ("quantization", "white", "flicker", "random_walk", "ramp")


@dataclass(frozen=True)
class Term:
    """One term of the model as engineers name it (IEEE Std 952 / 1554 letters).

    ``key`` is the internal name (the field of :class:`NoiseModel`, the order of :data:`TERMS`);
    ``symbol`` the IEEE letter; ``gyro`` / ``accel`` the name for a gyroscope / an accelerometer;
    ``alpha`` the power-law exponent of the frequency PSD; ``units`` the engineering units
    ``(gyroscope, accelerometer)`` it is shown in (SI inside).
    """

    key: str
    symbol: str
    gyro: str
    accel: str
    alpha: int
    units: tuple

    def unit(self, sensor: str = "gyroscope") -> str:
        """The engineering unit shown, e.g. ``deg/sqrt(h)`` (``m/s/sqrt(h)`` for an accelerometer)."""
        return self.units[0] if sensor == "gyroscope" else self.units[1]

    def name(self, sensor: str = "gyroscope") -> str:
        """The engineering name, e.g. ``angle random walk`` (``velocity random walk`` for an accelerometer)."""
        return self.gyro if sensor == "gyroscope" else self.accel

    def json_key(self, sensor: str = "gyroscope") -> str:
        """The name written in a result file, e.g. ``angle_random_walk``."""
        return self.name(sensor).replace(" ", "_")

    def label(self, sensor: str = "gyroscope") -> str:
        """``N (angle random walk)``: the letter and the name, as messages print it."""
        return f"{self.symbol} ({self.name(sensor)})"


#: the one vocabulary of the five terms (terminal, JSON, report, plot), in the order of :data:`TERMS`
TERM_TABLE = (
    Term("quantization", "Q", "quantization", "quantization", 2, ("deg", "m/s")),
    Term("white", "N", "angle random walk", "velocity random walk", 0, ("deg/sqrt(h)", "m/s/sqrt(h)")),
    Term("flicker", "B", "bias instability", "bias instability", -1, ("deg/h", "ug")),
    Term("random_walk", "K", "rate random walk", "acceleration random walk", -2, ("deg/h/sqrt(h)", "ug/sqrt(h)")),
    Term("ramp", "R", "rate ramp", "acceleration ramp", -2, ("deg/h^2", "ug/h")),
)
_BY_NAME = {n: t for t in TERM_TABLE for n in (t.key, t.symbol, t.json_key("gyroscope"), t.json_key("accelerometer"))}


def term(name: str) -> Term:
    """The :class:`Term` of an internal key, an IEEE letter or a file name of either sensor.

    Raises
    ------
    KeyError
        An unknown name.
    """
    return _BY_NAME[name]


#: power-law exponent alpha of the frequency PSD (S_y ~ f^alpha) for each noise term
NOISE_ALPHA = {t.key: t.alpha for t in TERM_TABLE}

#: the flicker (bias instability) coefficient of the Allan variance, 2 ln 2 / pi
FLICKER_FACTOR = 2 * np.log(2) / np.pi


def avar_design(tau) -> np.ndarray:
    """Columns of the Allan-variance model for the squared parameters ``(Q^2, N^2, B^2, K^2, R^2)``.

    Parameters
    ----------
    tau : array_like, shape (...)
        Averaging times, s.

    Returns
    -------
    ndarray, shape (..., 5)
        ``[3 / tau^2, 1 / tau, 2 ln 2 / pi, tau / 3, tau^2 / 2]`` (IEEE Std 952).
    """
    tau = np.asarray(tau, dtype=float)
    return np.stack([3 / tau**2, 1 / tau, np.full_like(tau, FLICKER_FACTOR), tau / 3, tau**2 / 2], axis=-1)


def model_avar(tau, params) -> np.ndarray:
    """Allan variance of the model, shape of ``tau``, for ``params = (Q, N, B, K, R)`` (SI)."""
    return avar_design(tau) @ np.square(np.asarray(params, dtype=float))


def model_adev(tau, params) -> np.ndarray:
    """Allan deviation of the model, shape of ``tau``, for ``params = (Q, N, B, K, R)`` (SI)."""
    return np.sqrt(model_avar(tau, params))


@dataclass(frozen=True, eq=False)
class NoiseModel(Value):
    """The five noise terms of one sensor axis as a curve ``sigma(tau)`` (SI; see module docstring).

    A ``NoiseModel`` is callable: ``model(tau)`` is the Allan deviation at
    ``tau`` (s), of the shape of ``tau``.
    """

    quantization: float = 0.0
    white: float = 0.0
    flicker: float = 0.0
    random_walk: float = 0.0
    ramp: float = 0.0

    @classmethod
    def from_params(cls, params) -> NoiseModel:
        """The model of a parameter vector ``(Q, N, B, K, R)``, shape (5,)."""
        return cls(*(float(p) for p in np.asarray(params, dtype=float).reshape(5)))

    @property
    def params(self) -> np.ndarray:
        """``(Q, N, B, K, R)``, shape (5,)."""
        return np.array([self.quantization, self.white, self.flicker, self.random_walk, self.ramp])

    def only(self, term: str) -> NoiseModel:
        """The model of one term alone (``term`` one of :data:`TERMS`)."""
        return NoiseModel(**{term: getattr(self, term)})

    def avar(self, tau) -> np.ndarray:
        """Allan variance at ``tau`` (s)."""
        return model_avar(tau, self.params)

    def adev(self, tau) -> np.ndarray:
        """Allan deviation at ``tau`` (s)."""
        return model_adev(tau, self.params)

    __call__ = adev
