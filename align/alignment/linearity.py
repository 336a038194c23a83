"""Scale factor across the input range: least-squares scale factor, nonlinearity and asymmetry per gyro.

The definitions of IEEE Std 528 (terminology) as the scale-factor tests of IEEE Std 952-1997 (interferometric
fiber optic gyros) and IEEE Std 1431-2004 (Coriolis vibratory gyros) apply them, over a cyclic sequence of rates:

* **scale factor** ``K``: the slope of the least-squares straight line through the output against the input
  over the rates tested (Eq L1: ``y_k = K x_k + c``, ordinary least squares on the mean output at each rate);
* **scale-factor nonlinearity**: the systematic deviation of the output from that line, stated as the largest
  deviation over the rates tested, as a fraction of full-scale output, ``max_k |r_k| / (K FS)`` with
  ``FS = max_k |x_k|`` the largest rate used (Eq L2; reported in ppm of full scale);
* **scale-factor asymmetry**: the difference of the scale factors found with positive and with negative inputs
  (a least-squares line each, Eq L1 on one direction), over their mean:
  ``(K+ - K-) / ((K+ + K-) / 2)`` (Eq L3).

The input ``x_k`` of gyro ``i`` at dwell ``k`` is the table rate along the gyro's nominal axis
(``N_i . w_k``; the modelled Earth rate included), about the system axis that axis is nearest; the output is
the dwell's mean reading. Dwells at the same rate are averaged first. Every figure is linear in the readings
up to the choice of the largest deviation, so its 1-sigma is propagated exactly through that linear map from
the covariance of the dwell means: their noise and, from the alignment's drift model
(:mod:`align.alignment.biasdrift`), the bias change between them (Eq D2; each combination used sums to zero,
the line's intercept taking the constant bias and Earth rate). A common table-rate error scales ``K`` only.

The largest deviation is the largest of several noisy ones: when the nonlinearity is not above three of its
1-sigma it is the noise's, an upper bound rather than a measurement, and the figure says so; when two rates
deviate about equally (symmetric rates often put it at +FS and -FS) it lies about half a sigma high.

Public names
------------
AxisLinearity, Linearity, ScaleErrors, fit_axis, linearity_axes, measure_linearity, linearity_plan, expected_linearity
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from align.alignment.plan import Plan, Step, axis_name
from align.errors import InputError
from align.keyfigures import AXES, title
from align.units import DEG_S, to_unit
from align.values import Value

#: relative difference below which two table rates are the same rate
_SAME_RATE = 1e-6
#: a gyro whose nominal axis is farther than this (cosine) from every system axis has no input axis here
_ALONG = math.cos(math.radians(10.0))


@dataclass(frozen=True, eq=False)
class AxisLinearity(Value):
    """The scale factor of one gyro across the range (SI; the module docstring's Eq L1-L3).

    Attributes
    ----------
    gyro : int
        0, 1, 2 for x, y, z.
    input_axis : str
        The system axis the gyro's input is about (``"+x"``, ``"-y"``).
    scale, scale_sigma : float
        ``K`` of the least-squares line and its 1-sigma, dimensionless (rad/s per rad/s).
    nonlinearity, nonlinearity_sigma : float
        Largest deviation from the line over full-scale output, a fraction (1e-6 = 1 ppm), and its 1-sigma.
    asymmetry, asymmetry_sigma : float
        ``(K+ - K-) / mean``, a fraction, and its 1-sigma.
    slope_positive, slope_negative : float
        ``K+`` and ``K-``, dimensionless.
    full_scale : float
        The largest ``|rate|`` used, rad/s.
    worst_rate : float
        The rate at which the largest deviation lies, rad/s.
    rates : ndarray, shape (p,)
        The distinct rates tested, rad/s, ascending.
    residuals, residual_sigma : ndarray, shape (p,)
        The deviation of each rate's mean output from the line, and its 1-sigma, fractions of full-scale output.
    peak : float
        The largest ``|reading|`` of this gyro in the dwells used, rad/s (NaN: not known).
    clipped : bool
        Readings stuck at one extreme value in a dwell (saturation), seen in the data.
    """

    gyro: int
    input_axis: str
    scale: float
    scale_sigma: float
    nonlinearity: float
    nonlinearity_sigma: float
    asymmetry: float
    asymmetry_sigma: float
    slope_positive: float
    slope_negative: float
    full_scale: float
    worst_rate: float
    rates: np.ndarray
    residuals: np.ndarray
    residual_sigma: np.ndarray
    peak: float = math.nan
    clipped: bool = False

    @property
    def significant(self) -> bool:
        """The nonlinearity exceeds three of its 1-sigma (otherwise it is the noise's largest deviation)."""
        return bool(self.nonlinearity > 3 * self.nonlinearity_sigma)

    def to_dict(self, factor: float) -> dict:
        """JSON values; rates divided by ``factor`` (the file's rate unit in rad/s), ratios as fractions."""
        return {"gyro": AXES[self.gyro], "input_axis": self.input_axis, "scale": self.scale,
                "scale_sigma": self.scale_sigma, "nonlinearity": self.nonlinearity,
                "nonlinearity_sigma": self.nonlinearity_sigma, "asymmetry": self.asymmetry,
                "asymmetry_sigma": self.asymmetry_sigma, "slope_positive": self.slope_positive,
                "slope_negative": self.slope_negative, "full_scale": self.full_scale / factor,
                "worst_rate": self.worst_rate / factor, "rates": (self.rates / factor).tolist(),
                "residuals": self.residuals.tolist(), "residual_sigma": self.residual_sigma.tolist(),
                "peak": None if math.isnan(self.peak) else self.peak / factor, "clipped": self.clipped,
                "significant": self.significant}

    @classmethod
    def from_dict(cls, d: dict, factor: float) -> AxisLinearity:
        """Read :meth:`to_dict`'s form (KeyError, TypeError, ValueError when malformed)."""
        num = {k: float(d[k]) for k in ("scale", "scale_sigma", "nonlinearity", "nonlinearity_sigma", "asymmetry",
                                        "asymmetry_sigma", "slope_positive", "slope_negative")}
        return cls(AXES.index(d["gyro"]), str(d["input_axis"]), **num, full_scale=float(d["full_scale"]) * factor,
                   worst_rate=float(d["worst_rate"]) * factor, rates=np.array(d["rates"], float) * factor,
                   residuals=np.array(d["residuals"], float), residual_sigma=np.array(d["residual_sigma"], float),
                   peak=math.nan if d.get("peak") is None else float(d["peak"]) * factor, clipped=bool(d["clipped"]))


@dataclass(frozen=True, eq=False)
class Linearity(Value):
    """The scale factor across the range of the three gyros (None: no such test about that gyro's axis).

    Attributes
    ----------
    axes : tuple of 3 (AxisLinearity or None)
    gyro_range : float or None
        The stated gyro range, rad/s (None: not stated; saturation then judged from the readings alone).
    """

    axes: tuple[AxisLinearity | None, ...]
    gyro_range: float | None = None

    def figures(self) -> tuple:
        """``nonlinearity_x..z``, ``asymmetry_x..z``, ``scale_x..z`` (unit ``"1"``, fractions), status INFO; a gyro
        the plan did not test across the range gives NaN (judged NOT CHECKED, never PASS)."""
        from align.merit import Figure

        out = []
        for name in ("nonlinearity", "asymmetry", "scale"):
            for i, a in enumerate(self.axes):
                label = f"{name}_{AXES[i]}"
                if a is None:
                    out.append(Figure(label, "gyroscope", math.nan, math.nan, "1", title(label), "", "matrix",
                                      detail="not measured: the plan has fewer than 2 rates per direction about it"))
                    continue
                how = (f"least-squares line over {len(a.rates)} rates up to {a.full_scale / DEG_S:.4g} deg/s about "
                       f"{a.input_axis} (IEEE Std 952/1431)")
                detail = "" if name != "nonlinearity" else f"largest at {a.worst_rate / DEG_S:+.4g} deg/s" \
                    if a.significant else "not above 3 sigma: the largest deviation is the noise's (an upper bound)"
                out.append(Figure(label, "gyroscope", getattr(a, name), getattr(a, f"{name}_sigma"), "1", title(label),
                                  how, "matrix", detail=detail))
        return tuple(out)

    def summary(self, units: str = "deg/s") -> str:
        """One line per gyro measured: nonlinearity and asymmetry in ppm, full scale, saturation."""
        lines = []
        for a in self.axes:
            if a is None:
                continue
            sat = ("clipped readings (saturation)" if a.clipped else
                   f"peak {100 * a.peak / self.gyro_range:.0f} % of range" if self.gyro_range and a.peak == a.peak
                   else "no clipping seen")
            lines.append(f"  gyro {AXES[a.gyro]}: nonlinearity {1e6 * a.nonlinearity:.1f} ± "
                         f"{1e6 * a.nonlinearity_sigma:.1f} ppm FS{'' if a.significant else ' (noise)'}, asymmetry "
                         f"{1e6 * a.asymmetry:+.1f} ± {1e6 * a.asymmetry_sigma:.1f} ppm, FS "
                         f"{float(to_unit(a.full_scale, units)):.4g} {units}, {sat}")
        return "\n".join(["scale factor across the range (IEEE Std 952/1431):", *lines])

    def to_dict(self, factor: float) -> dict:
        """JSON values (rates divided by ``factor``)."""
        return {"method": "IEEE Std 952/1431: least-squares line, largest deviation of full scale, K+ vs K-",
                "gyro_range": None if self.gyro_range is None else self.gyro_range / factor,
                "axes": [None if a is None else a.to_dict(factor) for a in self.axes]}

    @classmethod
    def from_dict(cls, d: dict, factor: float) -> Linearity:
        """Read :meth:`to_dict`'s form (KeyError, TypeError, ValueError when malformed)."""
        axes = tuple(None if a is None else AxisLinearity.from_dict(a, factor) for a in d["axes"])
        if len(axes) != 3:
            raise ValueError("linearity needs three axes")
        rng = d.get("gyro_range")
        return cls(axes, None if rng is None else float(rng) * factor)


def _line(x: np.ndarray) -> np.ndarray:
    """``P`` (2, p): the ordinary least-squares slope and intercept of a line through ``x`` as linear maps."""
    design = np.column_stack([x, np.ones_like(x)])
    return np.linalg.solve(design.T @ design, design.T)


def fit_axis(x: npt.ArrayLike, y: npt.ArrayLike, cov: npt.ArrayLike, gyro: int = 0, input_axis: str = "",
             rate_accuracy: float = 0.0) -> AxisLinearity:
    """Scale factor, nonlinearity and asymmetry of one gyro from its dwell means (Eq L1-L3).

    Parameters
    ----------
    x : array_like, shape (k,)
        Input rate of each dwell along the gyro's axis, rad/s (at least two distinct rates of each sign).
    y : array_like, shape (k,)
        Mean output of each dwell, rad/s.
    cov : array_like, shape (k, k) or (k,)
        Covariance of the dwell means, (rad/s)^2 (a vector: their variances); only combinations that sum to
        zero are used, so a generalised covariance (a bias drift, Eq D2) is fine.
    gyro : int
    input_axis : str
    rate_accuracy : float
        Relative table-rate accuracy (1-sigma), added to ``scale_sigma`` only.

    Returns
    -------
    AxisLinearity

    Examples
    --------
    A 0.1 % asymmetry and nothing else, noise-free, at +/-10, 50, 100 deg/s:

    >>> import numpy as np
    >>> x = np.radians([10, -10, 50, -50, 100, -100])
    >>> r = fit_axis(x, x * (1 + 0.0005 * np.sign(x)), np.zeros(6))
    >>> round(r.asymmetry, 9), round(r.scale, 9)
    (0.001, 1.0)
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    cov = np.asarray(cov, float)
    cov = np.diag(cov) if cov.ndim == 1 else cov
    rates_arr = np.array(_distinct(list(x)))
    group = np.abs(x[None, :] - rates_arr[:, None]) <= _SAME_RATE * np.abs(rates_arr[:, None])
    group = group / group.sum(axis=1, keepdims=True)  # (p, k): the mean output at each rate
    pos, neg = rates_arr > 0, rates_arr < 0
    if pos.sum() < 2 or neg.sum() < 2:
        raise InputError("the scale factor across the range needs at least two rates in each direction", "plan")
    p_all = _line(rates_arr) @ group
    k = float(p_all[0] @ y)
    resid_map = group - np.column_stack([rates_arr, np.ones_like(rates_arr)]) @ p_all  # (p, k)
    r = resid_map @ y
    fs = float(np.max(np.abs(rates_arr)))
    worst = int(np.argmax(np.abs(r)))
    nl = abs(float(r[worst])) / (k * fs)
    grad_nl = np.sign(r[worst]) * resid_map[worst] / (k * fs) - nl / k * p_all[0]
    slopes = [_line(rates_arr[side])[0] @ group[side] for side in (pos, neg)]
    kp, kn = float(slopes[0] @ y), float(slopes[1] @ y)
    mean = (kp + kn) / 2
    asym = (kp - kn) / mean
    grad_a = (1 / mean - asym / (2 * mean)) * slopes[0] + (-1 / mean - asym / (2 * mean)) * slopes[1]

    def sd(c: np.ndarray) -> float:
        return math.sqrt(max(float(c @ cov @ c), 0.0))

    var_k = sd(p_all[0]) ** 2 + (k * rate_accuracy) ** 2
    res_sd = np.array([sd(row) for row in resid_map]) / (k * fs)
    return AxisLinearity(gyro, input_axis, k, math.sqrt(var_k), nl, sd(grad_nl), asym, sd(grad_a), kp, kn, fs,
                         float(rates_arr[worst]), rates_arr, r / (k * fs), res_sd)


def _distinct(values: list[float]) -> list[float]:
    """The distinct values, ascending (values within :data:`_SAME_RATE` of each other are one)."""
    out: list[float] = []
    for v in sorted(values):
        if not out or abs(v - out[-1]) > _SAME_RATE * abs(v):
            out.append(v)
    return out


def linearity_axes(plan: Plan) -> tuple[bool, bool, bool]:
    """For each system axis: the plan's rate steps about it hold at least two distinct rates in each direction."""
    out = []
    for j in range(3):
        turns = [s.rate * s.sign for s in plan.steps if s.axis == j and s.rate is not None]
        out.append(len(_distinct([v for v in turns if v > 0])) >= 2 and len(_distinct([v for v in turns if v < 0])) >= 2)
    return out[0], out[1], out[2]


def _clipped(samples: np.ndarray) -> bool:
    """Readings stuck at the extreme value: more than 1 % (and at least 5) of a dwell's samples equal its largest |g|."""
    a = np.abs(samples)
    top = int(np.sum(a == a.max()))
    return top >= max(5, 0.01 * len(a))


def measure_linearity(obs, plan: Plan, mounting: np.ndarray, g: np.ndarray | None = None,
                      gyro_range: float | None = None) -> Linearity | None:
    """The scale factor across the range of each gyro whose axis the plan tests at several rates (Eq L1-L3).

    Parameters
    ----------
    obs : list of Observation
        The alignment's observations (:func:`~align.alignment.observe.observe`, or with the drift model of
        :func:`~align.alignment.biasdrift.with_drift`); the constant-rate dwells are used.
    plan : Plan
    mounting : ndarray, shape (3, 3)
        Nominal mounting ``N`` (rows: the gyros' nominal axes in the system frame).
    g : ndarray, shape (n, 3), optional
        The readings, rad/s, for the peak and clipping of the dwells.
    gyro_range : float or None
        Stated range, rad/s.

    Returns
    -------
    Linearity or None
        None when no axis has two distinct rates in each direction.
    """
    tested = linearity_axes(plan)
    if not any(tested):
        return None
    from align.alignment.biasdrift import DriftObservation

    dwells = [o for o in obs if o.segment.kind == "rate" and o.segment.step is not None]
    drift = all(isinstance(o, DriftObservation) for o in dwells) and bool(dwells)
    axes: list[AxisLinearity | None] = []
    for i in range(3):
        j = int(np.argmax(np.abs(mounting[i])))
        use = [o for o in dwells if plan.steps[o.segment.step].axis == j]
        if not tested[j] or abs(mounting[i, j]) < _ALONG or not use:
            axes.append(None)
            continue
        x = np.array([float(mounting[i] @ o.phi[:3]) for o in use])
        y = np.array([float(o.y[i]) for o in use])
        if drift:
            spans = np.array([o.span for o in use])
            cov = use[0].drift.covariance(spans)[i] + np.diag([o.noise_var[i] for o in use])
        else:
            cov = np.diag([o.var[i] for o in use])
        try:
            a = fit_axis(x, y, cov, i, axis_name(j, 1 if mounting[i, j] > 0 else -1), plan.rate_accuracy)
        except InputError:  # the dwells found hold fewer rates than the plan lists
            axes.append(None)
            continue
        if g is not None:
            parts = [g[o.segment.start:o.segment.end, i] for o in use]
            a = a.replace(peak=float(max(np.max(np.abs(p)) for p in parts)), clipped=any(_clipped(p) for p in parts))
        axes.append(a)
    return Linearity(tuple(axes), gyro_range) if any(a is not None for a in axes) else None


def linearity_plan(rates: npt.ArrayLike, axes: tuple[int, ...] = (0, 1, 2), latitude: float | None = None) -> Plan:
    """A cyclic plan across the range: about each axis, ``+r, -r`` for each rate (rad/s, positive) in turn, up.

    >>> from align.units import DEG
    >>> p = linearity_plan([10 * DEG, 100 * DEG], axes=(2,))
    >>> [round(s.rate / DEG) for s in p.steps], linearity_axes(p)
    ([10, -10, 100, -100], (False, False, True))
    """
    up = sorted(abs(float(r)) for r in np.ravel(rates))
    return Plan(tuple(Step(j, 1, rate=s * r) for j in axes for r in up for s in (1, -1)), latitude)


@dataclass(frozen=True)
class ScaleErrors:
    """A gyro's departure from a straight line, for the simulator: per gyro ``i``, of its linear reading ``u``
    (rad/s), ``u (1 + a_i sign(u) / 2) + q_i u^2 + c_i u^3`` (so that a pure ``a_i`` is the asymmetry of Eq L3).

    Attributes
    ----------
    asymmetry : tuple of 3 float
        Fractions.
    quadratic : tuple of 3 float
        s/rad.
    cubic : tuple of 3 float
        (s/rad)^2.
    """

    asymmetry: tuple[float, float, float] = (0.0, 0.0, 0.0)
    quadratic: tuple[float, float, float] = (0.0, 0.0, 0.0)
    cubic: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:  # three finite floats each
        for name in ("asymmetry", "quadratic", "cubic"):
            v = np.asarray(getattr(self, name), float)
            if v.shape != (3,) or not np.isfinite(v).all():
                raise InputError("three finite numbers, one per gyro", "{" + name + "}")
            object.__setattr__(self, name, (float(v[0]), float(v[1]), float(v[2])))

    @classmethod
    def from_full_scale(cls, full_scale: float, asymmetry: npt.ArrayLike = 0.0, quadratic: npt.ArrayLike = 0.0,
                        cubic: npt.ArrayLike = 0.0) -> ScaleErrors:
        """Terms given as fractions of full-scale output at full scale (rad/s): ``q = quadratic / FS``,
        ``c = cubic / FS^2``; each a number or three."""
        if not (math.isfinite(full_scale) and full_scale > 0):
            raise InputError("the full scale must be a positive rate", "{full_scale}")

        def three(v: npt.ArrayLike) -> np.ndarray:
            return np.broadcast_to(np.asarray(v, float), (3,))

        return cls(tuple(three(asymmetry)), tuple(three(quadratic) / full_scale),  # type: ignore[arg-type]
                   tuple(three(cubic) / full_scale**2))  # type: ignore[arg-type]

    def apply(self, u: np.ndarray) -> np.ndarray:
        """The readings (n, 3), rad/s, of linear readings ``u`` (n, 3), rad/s."""
        a, q, c = (np.asarray(v) for v in (self.asymmetry, self.quadratic, self.cubic))
        return u * (1 + a * np.sign(u) / 2) + q * u**2 + c * u**3


def expected_linearity(plan: Plan, m: np.ndarray, errors: ScaleErrors, mounting: np.ndarray | None = None,
                       earth_along: float = 0.0) -> Linearity | None:
    """The figures a noise-free session of ``plan`` with ``g = errors(M w) + b`` gives (the rehearsal's truth),
    ``earth_along`` (rad/s) the Earth rate along the table axis."""
    n = np.eye(3) if mounting is None else np.asarray(mounting, float)
    tested = linearity_axes(plan)
    axes: list[AxisLinearity | None] = []
    for i in range(3):
        j = int(np.argmax(np.abs(n[i])))
        if not tested[j] or abs(n[i, j]) < _ALONG:
            axes.append(None)
            continue
        w = np.array([s.rate * s.sign + earth_along for s in plan.steps if s.axis == j and s.rate is not None])
        y = errors.apply(np.outer(w, m[:, j]))[:, i]
        axes.append(fit_axis(w * n[i, j], y, np.zeros(len(w)), i, axis_name(j, 1 if n[i, j] > 0 else -1)))
    return Linearity(tuple(axes)) if any(a is not None for a in axes) else None
