"""Scale, misalignment and bias against temperature from calibrations made at several temperatures.

Every element ``e`` of ``M`` (9) and of the bias ``b`` (3), in the convention ``g = M w + b``, is fitted as a
polynomial in the temperature about a reference ``Tref``::

    e(T) = sum_k c_k (T - Tref)^k,   k = 0 .. order (1 by default; 2 where the rule below asks for it)

by weighted least squares over the K calibrations, each weighted by its effective variance
``sigma_e,k^2 + (de/dT)^2 sigma_T,k^2`` (the element's 1-sigma and the temperature's, through the fitted slope;
iterated), with the coefficients' covariance ``(X^T W X)^-1``. When the fit's chi-square says the given sigmas
are too small (``P(chi2 >= chi2_obs; dof) < 0.01``), the covariance is inflated by ``chi2 / dof`` (sigmas by
``sqrt(chi2 / dof)``) and the element says so.

Order (``order=None``, K >= 4): an element takes order 2 when the drop in chi-square from order 1 to 2, divided
by ``max(1, chi2_2 / (K - 3))`` (the scatter's own scale when it exceeds the given sigmas), exceeds the chi-square
(1 dof) 99 % point, 6.63: a likelihood-ratio test at 1 %.

Significance: an element changes significantly when the Wald test of its non-constant coefficients (``z^2`` for a
line, ``z = slope / sigma``) rejects "no change" at ``0.0027 / 12`` (the two-sided 3-sigma rate shared, Bonferroni,
by the 12 elements tested: ``|z| > 3.69`` for a line with the given sigmas; with inflated sigmas the F (Student t)
distribution of the fit's degrees of freedom): an unchanging sensor flags any of its 12 elements in <= 0.27 % of fits.

Public names: Calibrated, ElementFit, Evaluated, MatrixThermal, fit_element, fit_matrix, ELEMENTS, FORMAT,
FAMILY_ALPHA, SCATTER_ALPHA, ORDER_ALPHA
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from align.errors import InputError
from align.merit import Figure
from align.results import Result
from align.units import parse_unit
from align.values import Value, frozen_array
from align.wellformed import malformed

__all__ = ["Calibrated", "ElementFit", "Evaluated", "MatrixThermal", "fit_element", "fit_matrix", "ELEMENTS", "FORMAT",
           "FAMILY_ALPHA", "SCATTER_ALPHA", "ORDER_ALPHA"]

FORMAT = "imu-align.thermal-matrix"
CONVENTION = ("g = M w + b; every element e of M and b: e(T) = sum_k c_k (T - Tref)^k, T in degC clamped to the "
              "calibrations' range; M dimensionless, b in units.bias")
AXES = "xyz"
#: the fitted elements, in order
ELEMENTS = tuple(f"M_{a}{b}" for a in AXES for b in AXES) + tuple(f"bias_{a}" for a in AXES)
#: family-wise false-alarm rate over the 12 elements (the two-sided 3-sigma rate), shared by Bonferroni
FAMILY_ALPHA = 0.0027
#: a fit whose chi-square is this improbable has its sigmas inflated by sqrt(chi2 / dof)
SCATTER_ALPHA = 0.01
#: level of the likelihood-ratio test that takes order 2 (``order=None``)
ORDER_ALPHA = 0.01
RULES = (f"weighted least squares per element with effective variances; sigmas inflated by sqrt(chi2/dof) where "
         f"P(chi2) < {SCATTER_ALPHA}; significant: Wald test of the non-constant coefficients at {FAMILY_ALPHA}/12 "
         f"(Bonferroni over 12 elements; normal, or F with the fit's dof when inflated); order 2 (auto, K >= 4) by a "
         f"likelihood-ratio test at {ORDER_ALPHA}")


@dataclass(frozen=True, eq=False)
class Calibrated(Value):
    """One calibration at one temperature.

    Attributes
    ----------
    temperature, sigma_temperature : float
        The session's (plateau) temperature and its 1-sigma, degC.
    M, sigma_M : ndarray, shape (3, 3)
        Dimensionless (or counts per SI unit). ``bias, sigma_bias`` : ndarray, shape (3,), SI (or counts).
    where : str
        Where it came from (a file), for messages.
    """

    temperature: float
    sigma_temperature: float
    M: np.ndarray
    sigma_M: np.ndarray
    bias: np.ndarray
    sigma_bias: np.ndarray
    where: str = "calibration"

    def values(self) -> tuple[np.ndarray, np.ndarray]:
        """The 12 elements (:data:`ELEMENTS` order) and their 1-sigma."""
        return (np.concatenate([np.ravel(self.M), self.bias]),
                np.concatenate([np.ravel(self.sigma_M), self.sigma_bias]))


@dataclass(frozen=True, eq=False)
class ElementFit(Value):
    """One element's polynomial in ``T - Tref``.

    Attributes: ``name`` (``M_xy``, ``bias_x``); ``coefficients`` (order + 1,), ``c_k`` in the element's unit per
    degC^k, SI, and their ``covariance`` (inflated when ``inflation > 1``); ``chi2`` with the given sigmas over
    ``dof`` (K minus the coefficients); ``inflation`` (``sqrt(chi2 / dof)`` or 1); ``p_value`` of "no change" (Wald
    test of ``c_1 ..``) and ``significant`` (``p_value < FAMILY_ALPHA / 12``).
    """

    name: str
    coefficients: np.ndarray
    covariance: np.ndarray
    chi2: float
    dof: int
    inflation: float
    p_value: float
    significant: bool

    @property
    def order(self) -> int:
        """The polynomial's order."""
        return len(self.coefficients) - 1

    @property
    def slope(self) -> tuple[float, float]:
        """``de/dT`` at ``Tref`` (``c_1``) and its 1-sigma, per K."""
        return float(self.coefficients[1]), float(math.sqrt(self.covariance[1, 1]))

    def critical(self) -> float:
        """The ``|z|`` beyond which a slope alone is significant: normal, or Student t with ``dof`` when inflated."""
        from scipy import stats

        alpha = FAMILY_ALPHA / len(ELEMENTS)
        return float(stats.t.isf(alpha / 2, self.dof) if self.inflation > 1 else stats.norm.isf(alpha / 2))

    def value(self, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Value and 1-sigma at ``d = T - Tref`` (n,), degC."""
        x = np.vander(np.atleast_1d(np.asarray(d, float)), len(self.coefficients), increasing=True)
        return x @ self.coefficients, np.sqrt(np.einsum("ij,jk,ik->i", x, self.covariance, x))


def fit_element(name: str, d: np.ndarray, sigma_d: np.ndarray, y: np.ndarray, sigma_y: np.ndarray,
                order: int) -> ElementFit:
    """Weighted polynomial fit of one element against ``d = T - Tref`` (module docstring).

    Parameters
    ----------
    name : str
    d, sigma_d, y, sigma_y : ndarray, shape (K,)
        Temperatures about the reference and their 1-sigma, degC; the element and its 1-sigma (> 0).
    order : int
        1 or 2; K > order.

    Returns
    -------
    ElementFit

    Examples
    --------
    >>> f = fit_element("M_xx", np.array([-20.0, 0.0, 20.0]), np.zeros(3), np.array([0.998, 1.0, 1.002]),
    ...                 np.full(3, 1e-5), 1)
    >>> round(f.slope[0] * 1e6, 3), f.significant
    (100.0, True)
    """
    from scipy import stats

    x = np.vander(d, order + 1, increasing=True)
    var = sigma_y**2
    for _ in range(5):  # effective variance: the temperature's sigma through the slope at each point
        w = 1.0 / var
        cov = np.linalg.inv(x.T @ (w[:, None] * x))
        c = cov @ (x.T @ (w * y))
        var = sigma_y**2 + (sum(k * c[k] * d ** (k - 1) for k in range(1, order + 1)) * sigma_d) ** 2
    chi2 = float(np.sum(w * (y - x @ c) ** 2))
    dof = len(y) - order - 1
    inflated = dof > 0 and stats.chi2.sf(chi2, dof) < SCATTER_ALPHA
    inflation = math.sqrt(chi2 / dof) if inflated else 1.0
    cov = cov * inflation**2
    tail = c[1:]
    wald = float(tail @ np.linalg.solve(cov[1:, 1:], tail))
    p = float(stats.f.sf(wald / order, order, dof) if inflated else stats.chi2.sf(wald, order))
    return ElementFit(name, c, cov, chi2, dof, inflation, p, p < FAMILY_ALPHA / len(ELEMENTS))


def _choose(name: str, d: np.ndarray, sd: np.ndarray, y: np.ndarray, sy: np.ndarray) -> ElementFit:
    """Order 1, or 2 when the likelihood-ratio test at :data:`ORDER_ALPHA` asks for it (module docstring)."""
    from scipy import stats

    line = fit_element(name, d, sd, y, sy, 1)
    if len(y) < 4:
        return line
    curve = fit_element(name, d, sd, y, sy, 2)
    scale = max(1.0, curve.chi2 / curve.dof)
    return curve if (line.chi2 - curve.chi2) / scale > stats.chi2.isf(ORDER_ALPHA, 1) else line


@dataclass(frozen=True, eq=False)
class Evaluated(Value):
    """``M(T)`` and ``b(T)`` with their 1-sigma; unpacks as ``M, b = result.at(T)``.

    Attributes: ``M, sigma_M`` (3, 3) and ``bias, sigma_bias`` (3,), SI; ``temperature`` evaluated at (after
    clamping), degC; ``clamped``: the temperature asked for was outside the calibrations' range; ``note`` says so.
    """

    M: np.ndarray
    sigma_M: np.ndarray
    bias: np.ndarray
    sigma_bias: np.ndarray
    temperature: float
    clamped: bool
    note: str = ""

    def __iter__(self) -> Iterator[np.ndarray]:
        return iter((self.M, self.bias))


def _jacobian(m0: np.ndarray, n: np.ndarray) -> list[tuple[str, np.ndarray]]:
    """``d scale_i`` and ``d phi_ij`` of ``M N^T`` (:func:`align.model.angles`) per ``dM`` at ``M0``: each figure's
    name and its gradient (9,) over the elements of ``M`` in row order (``scale_i = |m_i|``, ``phi_ij = asin(u_ij)``,
    ``u_i = m_i / |m_i|``, ``m = M N^T``)."""
    m = m0 @ n.T
    norm = np.linalg.norm(m, axis=1)
    u = m / norm[:, None]
    out = []
    for (i, a), (j, b) in ((p, q) for p in enumerate(AXES) for q in enumerate(AXES)):
        g = np.zeros((3, 3))
        g[i] = u[i] if i == j else (np.eye(3)[j] - u[i, j] * u[i]) / (norm[i] * math.sqrt(max(1e-300, 1 - u[i, j]**2)))
        out.append((f"dscale_{a}_dT" if i == j else f"dphi_{a}{b}_dT", (g @ n).ravel()))
    return sorted(out, key=lambda f: not f[0].startswith("dscale"))  # the scales first


def _counts(units: str) -> bool:  # a calibration in counts: its bias is written as is
    return units.strip().lower() in ("count", "counts")


def _unit_per_k(name: str, sensor: str, units: str) -> str:
    """The SI unit of figure ``name`` (``dscale_x_dT``, ``dphi_xy_dT``, ``dbias_x_dT``)."""
    if not name.startswith("dbias"):
        return "1/K" if name.startswith("dscale") else "rad/K"
    return "count/K" if _counts(units) else {"gyroscope": "rad/s/K", "accelerometer": "m/s^2/K"}.get(sensor, "1/K")


class MatrixThermal(Result, format=FORMAT, convention=CONVENTION):
    """``M(T)`` and ``b(T)`` of one sensor from calibrations at several temperatures (module docstring).

    Attributes: ``sensor`` (``gyroscope``, ``accelerometer``); ``units``, the unit the bias is written in (the
    calibrations' display unit); ``reference`` ``Tref`` and ``valid_range`` (lowest, highest calibration temperature,
    which :meth:`at` clamps to), degC; ``elements``, one :class:`ElementFit` per :data:`ELEMENTS` name (SI);
    ``points``, the :class:`Calibrated` fitted; ``mounting``, the nominal ``N`` the scale and angles are read
    relative to (``M N^T``); ``notes``; ``inputs``.
    """

    sensor: str
    units: str
    reference: float
    valid_range: tuple
    elements: tuple
    points: tuple
    mounting: np.ndarray = field(default_factory=lambda: np.eye(3))
    notes: tuple = ()
    inputs: dict = field(default_factory=dict)

    def element(self, name: str) -> ElementFit:
        """The fit of element ``name`` (``M_xy``, ``bias_z``)."""
        return self.elements[ELEMENTS.index(name)]

    def significant(self) -> tuple[str, ...]:
        """The elements that change significantly with temperature."""
        return tuple(e.name for e in self.elements if e.significant)

    def at(self, temperature: float) -> Evaluated:
        """``M`` and ``b`` (SI) at ``temperature`` (degC), clamped to :attr:`valid_range` (saying so).

        Examples
        --------
        >>> pts = [Calibrated(t, 0.1, np.eye(3) * (1 + 1e-4 * t), np.full((3, 3), 1e-6), np.full(3, 1e-3 * t),
        ...                   np.full(3, 1e-5)) for t in (10.0, 30.0, 50.0)]
        >>> r = fit_matrix(pts, "gyroscope", "deg/s")
        >>> M, b = r.at(40.0)
        >>> round(float(M[0, 0]), 6), r.at(80.0).note
        (1.004, 'temperature 80 degC clamped to the calibrated range 10 .. 50 degC')
        """
        lo, hi = self.valid_range
        t = float(min(max(temperature, lo), hi))
        vals = [e.value(np.array([t - self.reference])) for e in self.elements]
        v = np.array([a[0] for a, _ in vals])
        s = np.array([b[0] for _, b in vals])
        clamped = t != float(temperature)
        note = f"temperature {temperature:g} degC clamped to the calibrated range {lo:g} .. {hi:g} degC" if clamped \
            else ""
        return Evaluated(v[:9].reshape(3, 3), s[:9].reshape(3, 3), v[9:], s[9:], t, clamped, note)

    def figures_of_merit(self) -> tuple[Figure, ...]:
        """Per axis ``dscale_i_dT`` (1/K), per pair ``dphi_ij_dT`` (rad/K) of ``M N^T`` at ``Tref`` and
        ``dbias_i_dT`` (reading/K), with 1-sigma (first-order propagation of the element slopes, taken
        independent); the detail says ``z`` and whether it changes significantly."""
        m0 = np.array([e.coefficients[0] for e in self.elements[:9]]).reshape(3, 3)
        slope, crit = np.array([e.slope for e in self.elements]), np.array([e.critical() for e in self.elements])
        lo, hi = self.valid_range
        method = f"weighted least squares over {len(self.points)} calibrations, {lo:g} .. {hi:g} degC, slope at " \
                 f"{self.reference:g} degC"
        figs = [self._figure(name, float(j @ slope[:9, 0]), float(np.sqrt(np.sum((j * slope[:9, 1]) ** 2))),
                             float(crit[:9][np.abs(j) > 1e-12].max(initial=crit[0])), method)
                for name, j in _jacobian(m0, np.asarray(self.mounting, float))]
        return tuple(figs) + tuple(self._figure(f"dbias_{a}_dT", slope[9 + i, 0], slope[9 + i, 1], crit[9 + i], method)
                                   for i, a in enumerate(AXES))

    def _figure(self, name: str, value: float, sigma: float, crit: float, method: str) -> Figure:
        z = value / sigma if sigma > 0 else math.inf
        word = "changes significantly" if abs(z) > crit else "no significant change"
        titles = {"dscale": "scale-factor temperature coefficient", "dphi": "misalignment temperature coefficient",
                  "dbias": "bias temperature coefficient"}
        return Figure(name, self.sensor, value, sigma, _unit_per_k(name, self.sensor, self.units),
                      titles[name.split("_")[0]], method, detail=f"z = {z:.3g}: {word} (threshold |z| = {crit:.3g}: "
                                                                 "3-sigma shared by 12 elements, Bonferroni)")

    def to_dict(self) -> dict[str, Any]:
        """The versioned JSON form: the envelope, the rules, the calibrations, then one entry per element."""
        f = 1.0 if _counts(self.units) else parse_unit(self.units).factor

        def elem(e: ElementFit) -> dict[str, Any]:
            k = f if e.name.startswith("bias") else 1.0
            s, ss = e.slope
            return {"element": e.name, "order": e.order, "coefficients": (e.coefficients / k).tolist(),
                    "covariance": (e.covariance / (k * k)).tolist(), "chi2": e.chi2, "dof": e.dof,
                    "inflation": e.inflation, "slope": s / k, "slope_sigma": ss / k, "p_value": e.p_value,
                    "significant": e.significant}

        pts = [{"temperature": p.temperature, "temperature_sigma": p.sigma_temperature, "source": p.where,
                "M": np.asarray(p.M).tolist(), "sigma_M": np.asarray(p.sigma_M).tolist(),
                "bias": (np.asarray(p.bias) / f).tolist(), "sigma_bias": (np.asarray(p.sigma_bias) / f).tolist()}
               for p in self.points]
        units = {"M": "1", "bias": self.units, "temperature": "degC", "coefficients": "element unit per degC^k"}
        return {**self.envelope(units), "sensor": self.sensor, "reference_temperature": self.reference,
                "valid_range": list(self.valid_range), "rules": RULES, "mounting": np.asarray(self.mounting).tolist(),
                "significant": list(self.significant()), "notes": list(self.notes), "inputs": dict(self.inputs),
                "calibrations": pts, "elements": [elem(e) for e in self.elements]}

    @classmethod
    def from_dict(cls, d: dict[str, Any], where: str = "thermal matrix") -> MatrixThermal:
        """Read the form written by :meth:`to_dict`."""
        keys = ["sensor", "reference_temperature", "valid_range", "rules", "mounting", "significant", "notes", "inputs",
                "calibrations", "elements"]
        cls.check_envelope(d, where, keys=keys)
        try:
            units = str(d["units"]["bias"])
            f = 1.0 if _counts(units) else parse_unit(units, None, f"{where}: units").factor
            elements = []
            for name, e in zip(ELEMENTS, d["elements"], strict=True):
                k = f if name.startswith("bias") else 1.0
                if e["element"] != name:
                    raise ValueError(f"element {e['element']!r} where {name} was expected")
                elements.append(ElementFit(name, np.array(e["coefficients"], float) * k,
                                           np.array(e["covariance"], float) * k * k, float(e["chi2"]), int(e["dof"]),
                                           float(e["inflation"]), float(e["p_value"]), bool(e["significant"])))
            points = tuple(Calibrated(float(p["temperature"]), float(p["temperature_sigma"]), np.array(p["M"], float),
                                      np.array(p["sigma_M"], float), np.array(p["bias"], float) * f,
                                      np.array(p["sigma_bias"], float) * f, str(p["source"]))
                           for p in d["calibrations"])
            lo, hi = (float(v) for v in d["valid_range"])
            return cls(str(d["sensor"]), units, float(d["reference_temperature"]), (lo, hi), tuple(elements), points,
                       frozen_array(d["mounting"], (3, 3)), tuple(str(n) for n in d["notes"]), dict(d["inputs"] or {}))
        except (KeyError, TypeError, ValueError, IndexError) as exc:
            raise InputError(f"malformed thermal matrix result ({malformed(exc)}); regenerate it", where) from None


def fit_matrix(points: Sequence[Calibrated], sensor: str, units: str, *, order: int | None = 1,
               reference: float | None = None, mounting: np.ndarray | None = None) -> MatrixThermal:
    """Fit every element of ``M`` and ``b`` against temperature (module docstring).

    Parameters
    ----------
    points : sequence of Calibrated
        K calibrations of one sensor.
    sensor, units : str
        ``gyroscope`` or ``accelerometer``; the unit the bias is written in.
    order : int or None
        1 or 2 for every element (2 needs K >= 4); None: 1, or 2 per element by the likelihood-ratio test.
    reference : float, optional
        ``Tref``, degC; None: the mean of the calibrations' temperatures.
    mounting : ndarray, shape (3, 3), optional
        Nominal mounting for the scale and angles (identity when None).

    Returns
    -------
    MatrixThermal

    Raises
    ------
    InputError
        Too few calibrations, all at one temperature, a sigma that is not positive and finite.
    """
    if order not in (1, 2, None):
        raise InputError(f"order {order} is not 1 or 2 (or automatic)", "{order}")
    k, need = len(points), 2 if order in (1, None) else 4
    if k < need:
        raise InputError(f"{k} calibration{'s' if k != 1 else ''} given; a fit of order {order or 1} against "
                         f"temperature needs {need} or more at different temperatures", "{results}")
    temps = np.array([p.temperature for p in points], float)
    if len(np.unique(temps)) < (order or 1) + 1:
        raise InputError(f"the calibrations' temperatures ({', '.join(f'{t:g}' for t in temps)} degC) do not span "
                         f"{(order or 1) + 1} different temperatures; give calibrations at different ones",
                         "{temperatures}")
    sig_t = np.array([p.sigma_temperature for p in points], float)
    vals, sigs = zip(*(p.values() for p in points))
    y, sy = np.array(vals), np.array(sigs)
    for p, v, s in zip(points, y, sy):
        if not (np.all(np.isfinite(v)) and np.all(np.isfinite(s)) and np.all(s > 0)):
            raise InputError("M, b and their 1-sigma must all be determined (finite, sigmas > 0); a calibration "
                             "without its uncertainty cannot be weighed", p.where)
        if not (math.isfinite(p.sigma_temperature) and p.sigma_temperature >= 0 and math.isfinite(p.temperature)):
            raise InputError(f"temperature {p.temperature} +/- {p.sigma_temperature} degC is not usable", p.where)
    tref = float(np.mean(temps)) if reference is None else float(reference)
    d = temps - tref
    elements = tuple(_choose(n, d, sig_t, y[:, i], sy[:, i]) if order is None else
                     fit_element(n, d, sig_t, y[:, i], sy[:, i], order) for i, n in enumerate(ELEMENTS))
    notes = [f"{e.name}: the scatter exceeds the given sigmas (chi2 = {e.chi2:.3g} over {e.dof} dof); its sigmas "
             f"are inflated by {e.inflation:.3g}" for e in elements if e.inflation > 1]
    if order is None:
        curved = [e.name for e in elements if e.order == 2]
        notes.append(f"order 2 taken for {', '.join(curved)}" if curved else "order 1 for every element")
    if k == need:
        notes.append(f"{k} calibrations for {need} coefficients: no degree of freedom checks the sigmas")
    return MatrixThermal(sensor, units, tref, (float(temps.min()), float(temps.max())), elements, tuple(points),
                         np.eye(3) if mounting is None else np.asarray(mounting, float), tuple(notes))
