"""The thermal bias model of one sensor: a polynomial in temperature per axis, an optional thermal-lag term, its
covariance, the reference temperature and the valid range (outside which it clamps, as firmware does).

Per axis ``i`` (issue 25; the ArduPilot and PX4 form, with a lag term beside it)::

    bias_i(T, dT/dt) = sum_k c_ik d^k + l_i dT/dt,    d = clip(T, tmin, tmax) - tref

``c_ik`` in the readings' SI unit per C^k, ``l_i`` in SI per (C/s). The static curve (``dT/dt = 0``) is what a
soaked sensor shows and what the firmware files carry; the lag term describes the sensor lagging its temperature
reading while the temperature moves. ``cov_i`` is the covariance of ``(c_i0, ..., c_iK[, l_i])``.

Public names
------------
AxisModel, ThermalModel, Compensated, design, shift_reference, clamp
"""

from __future__ import annotations

from dataclasses import dataclass
from math import comb

import numpy as np

from align.values import Value, frozen_array

__all__ = ["AxisModel", "ThermalModel", "Compensated", "design", "shift_reference", "clamp"]


def design(d: np.ndarray, order: int, rate: np.ndarray | None = None) -> np.ndarray:
    """The design matrix ``[1, d, d^2, ..., d^order (, rate)]``.

    Parameters
    ----------
    d : ndarray, shape (n,)
        Temperature minus the reference, C (or any scaled temperature).
    order : int
        Polynomial order, >= 0.
    rate : ndarray, shape (n,), optional
        Temperature rate, C/s (or scaled): the lag column.

    Returns
    -------
    ndarray, shape (n, order + 1 [+ 1])

    Examples
    --------
    >>> design(np.array([1.0, 2.0]), 2).tolist()
    [[1.0, 1.0, 1.0], [1.0, 2.0, 4.0]]
    """
    d = np.asarray(d, float)
    cols = [np.ones_like(d)]
    for _ in range(order):
        cols.append(cols[-1] * d)
    if rate is not None:
        cols.append(np.asarray(rate, float))
    return np.column_stack(cols)


def shift_reference(c: np.ndarray, delta: float, scale: float = 1.0) -> np.ndarray:
    """Coefficients of ``p(x) = sum_k c_k x^k`` with ``x = (d + delta) / scale`` as powers of ``d``.

    ``x^k = sum_j C(k, j) delta^(k-j) d^j / scale^k`` (binomial theorem): the matrix ``L`` returned by
    :func:`_shift_matrix` maps ``c`` to the new coefficients exactly (used for a new reference temperature:
    ``delta = tref_new - tref_old``, and to undo the scaling of the fit).

    Parameters
    ----------
    c : ndarray, shape (K + 1,)
    delta : float
        Old variable's origin seen from the new one, C.
    scale : float
        Scale of the old variable, C.

    Returns
    -------
    ndarray, shape (K + 1,)

    Examples
    --------
    >>> shift_reference(np.array([0.0, 0.0, 1.0]), 1.0).tolist()   # (d + 1)^2 = 1 + 2 d + d^2
    [1.0, 2.0, 1.0]
    """
    return _shift_matrix(len(c) - 1, delta, scale) @ np.asarray(c, float)


def _shift_matrix(order: int, delta: float, scale: float = 1.0) -> np.ndarray:
    """``L[j, k] = C(k, j) delta^(k-j) / scale^k`` for ``j <= k`` (see :func:`shift_reference`)."""
    L = np.zeros((order + 1, order + 1))
    for k in range(order + 1):
        for j in range(k + 1):
            L[j, k] = comb(k, j) * delta ** (k - j) / scale ** k
    return L


def clamp(temperature: np.ndarray, tmin: float, tmax: float) -> tuple[np.ndarray, int]:
    """Temperatures clipped to ``[tmin, tmax]`` and how many were outside.

    Examples
    --------
    >>> clamp(np.array([-5.0, 10.0, 50.0]), 0.0, 40.0)[1]
    2
    """
    t = np.asarray(temperature, float)
    outside = int(np.count_nonzero((t < tmin) | (t > tmax)))
    return (np.clip(t, tmin, tmax) if outside else t), outside


@dataclass(frozen=True, eq=False)
class AxisModel(Value):
    """One axis: polynomial coefficients about the reference, the lag coefficient and their covariance.

    Attributes
    ----------
    coefficients : ndarray, shape (K + 1,)
        ``c_0 .. c_K``, SI per C^k (``c_0``: the bias at the reference temperature).
    lag : float or None
        ``l``, SI per (C/s); None: no lag term.
    covariance : ndarray, shape (p, p)
        Of ``(c_0, ..., c_K[, l])``, ``p = K + 1 (+ 1)``; how it was estimated is the result's ``band`` note.
    """

    coefficients: np.ndarray
    lag: float | None
    covariance: np.ndarray

    def __post_init__(self) -> None:
        super().__post_init__()
        p = len(self.coefficients) + (self.lag is not None)
        if self.covariance.shape != (p, p):
            raise ValueError(f"covariance must be {p}x{p}, not {self.covariance.shape}")

    @property
    def order(self) -> int:
        """Polynomial order K."""
        return len(self.coefficients) - 1

    def curve(self, d: np.ndarray) -> np.ndarray:
        """The static curve ``sum_k c_k d^k`` (n,), SI, at ``d = T - tref`` (not clamped here)."""
        return np.polynomial.polynomial.polyval(np.asarray(d, float), self.coefficients)

    def sigma(self, d: np.ndarray) -> np.ndarray:
        """1-sigma of the static curve at ``d`` (n,): ``sqrt(x^T C x)``, ``x = (1, d, ..., d^K)``."""
        k = self.order + 1
        x = design(np.atleast_1d(d), self.order)
        return np.sqrt(np.maximum(np.einsum("ni,ij,nj->n", x, self.covariance[:k, :k], x), 0.0))

    @property
    def lag_sigma(self) -> float | None:
        """1-sigma of the lag coefficient, SI per (C/s) (None without a lag term)."""
        return None if self.lag is None else float(np.sqrt(self.covariance[-1, -1]))


@dataclass(frozen=True)
class Compensated:
    """Readings with the thermal bias removed, and what the clamping did.

    Attributes
    ----------
    data : ndarray, shape (n, 3)
        ``raw - bias(clip(T))``, SI.
    clamped : int
        Samples outside the valid range, compensated at its nearest end.
    note : str or None
        One sentence when any were clamped.
    """

    data: np.ndarray
    clamped: int
    note: str | None


@dataclass(frozen=True, eq=False)
class ThermalModel(Value):
    """One sensor's thermal bias model (module docstring): three axes, one reference and one valid range.

    Attributes
    ----------
    sensor : str
        ``"gyroscope"`` or ``"accelerometer"``.
    tref : float
        Reference temperature, C.
    tmin, tmax : float
        The range the model was fitted over, C; outside it, the temperature is clamped.
    axes : tuple of AxisModel
        x, y, z.

    Examples
    --------
    >>> ax = AxisModel(np.array([0.1, 0.01]), None, np.zeros((2, 2)))
    >>> m = ThermalModel("accelerometer", 20.0, 0.0, 40.0, (ax, ax, ax))
    >>> b, n = m.bias(np.array([30.0, 60.0]))
    >>> b[:, 0].round(3).tolist(), n
    ([0.2, 0.3], 1)
    """

    sensor: str
    tref: float
    tmin: float
    tmax: float
    axes: tuple[AxisModel, ...]

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "axes", tuple(self.axes))
        if len(self.axes) != 3:
            raise ValueError("a thermal model has three axes")
        if not self.tmin < self.tmax:
            raise ValueError("tmin must be below tmax")

    def bias(self, temperature: np.ndarray, rate: np.ndarray | None = None) -> tuple[np.ndarray, int]:
        """The bias (n, 3), SI, at ``temperature`` (C) clamped to the range, plus ``lag * rate`` where there is
        a lag term and ``rate`` (C/s) is given; and how many samples were clamped."""
        t, outside = clamp(temperature, self.tmin, self.tmax)
        d = t - self.tref
        out = np.empty((len(d), 3))
        acc = np.empty(len(d))
        for i, ax in enumerate(self.axes):
            c = ax.coefficients
            acc.fill(c[-1])  # Horner's rule in place, the operations of numpy's polyval in its order
            for k in range(len(c) - 2, -1, -1):
                acc *= d
                acc += c[k]
            out[:, i] = acc
            if rate is not None and ax.lag is not None:
                out[:, i] += ax.lag * np.asarray(rate, float)
        return out, outside

    def sigma(self, temperature: np.ndarray) -> np.ndarray:
        """1-sigma of the static curves (n, 3), SI, at ``temperature`` (C), clamped as :meth:`bias` is."""
        t, _ = clamp(temperature, self.tmin, self.tmax)
        return np.column_stack([ax.sigma(t - self.tref) for ax in self.axes])

    def compensate(self, raw: np.ndarray, temperature: np.ndarray, rate: np.ndarray | None = None) -> Compensated:
        """``raw - bias`` (see :meth:`bias`); clamped samples counted and stated.

        Parameters
        ----------
        raw : ndarray, shape (n, 3)
            Readings, SI.
        temperature : ndarray, shape (n,)
            C.
        rate : ndarray, shape (n,), optional
            dT/dt, C/s: the lag term is applied when given (the firmware files carry the static curve only).

        Returns
        -------
        Compensated
        """
        b, outside = self.bias(temperature, rate)
        note = None
        if outside:
            note = (f"{outside} samples outside the valid range {self.tmin:.2f} to {self.tmax:.2f} C were compensated "
                    "at its nearest end (clamped, as firmware does)")
        return Compensated(np.asarray(raw, float) - b, outside, note)

    def at_reference(self, tref: float) -> ThermalModel:
        """The same curves about another reference temperature (coefficients re-expanded exactly, covariance
        carried through the same linear map)."""
        axes = []
        for ax in self.axes:
            L = _shift_matrix(ax.order, tref - self.tref)
            if ax.lag is not None:
                L = np.block([[L, np.zeros((len(L), 1))], [np.zeros((1, len(L))), np.ones((1, 1))]])
            full = L @ np.r_[ax.coefficients, [] if ax.lag is None else [ax.lag]]
            axes.append(AxisModel(frozen_array(full[:ax.order + 1]), ax.lag, L @ ax.covariance @ L.T))
        return ThermalModel(self.sensor, float(tref), self.tmin, self.tmax, tuple(axes))
