"""The accelerometer from static attitudes of unknown orientation: ``|U (a_k - b)| = g`` (imu_tk's idea).

Over ``k`` static attitudes the mean readings ``a_k`` satisfy::

    r_k(U, b) = |U (a_k - b)| - g = 0                                                (A1)

with ``U`` upper triangular (x along the accelerometer's x axis, y in its x-y plane: the rotation to
the case is not observable) and ``M = U^-1`` (``raw = M f + b``). Nine parameters, solved by
Levenberg-Marquardt (scipy) from several starts, the lowest cost kept: the algebraic ellipsoid
through the means (the quadric ``a^T Q a + p^T a + c = 0`` by linear least squares; then ``U^T U =
g^2 Q / (b^T Q b - c)`` with ``b = -Q^-1 p / 2``, ``U`` its Cholesky factor), and spheres about the
means' centre and about zero. A start from the centre alone can end in a wrong minimum (an ellipsoid
a hundred times too large fitting poses that cluster on one side); and a degenerate ellipsoid (axes
nearly parallel, the centre far out) can even fit the noise a little better than the sensor's: the
solution kept is the lowest cost among those an accelerometer can have (``cond(M)`` at most
:data:`MAX_CONDITION`, scale factors within 1 +/- 0.2 in physical units), else the fit is refused.

Uncertainty: ``cov(theta) = s^2 w^2 (J^T J)^-1`` with ``s^2 = sum r_k^2 / (k - 9)`` and ``w =
t_(k-9)(0.99865) / 3`` (Student's t): the stated 1-sigma is the t distribution's 99.73 % bound over
3, so that "3 sigma" keeps its normal coverage on few degrees of freedom (``w`` = 78.6 at 1 degree of
freedom, 1.28 at 11, 1.09 at 29). ``M = U^-1`` gets the full covariance of ``U`` (its elements are
correlated): ``dM = -M dU M``, ``cov(vec M) = G cov(U) G^T``. With ``k = 9`` the fit is exact and
the 1-sigma unknown (NaN).

Public names
------------
calibrate_accel_free, ellipsoid_start, t_widening, widened_level, MAX_CONDITION
"""

from __future__ import annotations

import numpy as np

from align.calibration.results import Calibration
from align.errors import InputError, TestError
from align.io.consumers import matrix_unit
from align.model import AXES
from align.plausible import check_at_rest, check_gravity, scale_outside
from align.units import STANDARD_GRAVITY

_IU = np.triu_indices(3)
#: largest condition number of an accelerometer's M (one chip's axes match in scale to a few % and are orthogonal
#: to a degree or two: about 1.05; 1.5 allows scale factors differing by half)
MAX_CONDITION = 1.5


def t_widening(dof: int) -> float:
    """``t_dof(0.99865) / 3``: the factor that makes 3 sigma a 99.73 % bound on ``dof`` degrees of freedom."""
    from scipy.stats import t as student

    return float(student.ppf(0.99865, dof) / 3.0)


def widened_level(widening: float, dof: int, what: str = "") -> str:
    """The ``uncertainty.level`` of a result whose 1-sigma is t-widened (``what``: which part, if not all)."""
    return (f"1 sigma = (99.73 % bound of Student's t on {dof} degrees of freedom) / 3, {widening:.3g}x the "
            f"Jacobian's{what}")


def ellipsoid_start(a: np.ndarray, gravity: float) -> tuple[np.ndarray, np.ndarray] | None:
    """``(U, b)`` of the algebraic ellipsoid through the points ``a`` (k, 3), k >= 9 (the module's start),
    or None when the quadric through them is not an ellipsoid."""
    c0 = a.mean(axis=0)
    s0 = float(np.sqrt(np.mean(np.sum((a - c0) ** 2, axis=1))))
    if not s0 > 0:
        return None
    x = (a - c0) / s0
    d = np.column_stack([x ** 2, 2 * x[:, 0] * x[:, 1], 2 * x[:, 0] * x[:, 2], 2 * x[:, 1] * x[:, 2], 2 * x,
                         np.ones(len(x))])
    p = np.linalg.svd(d)[2][-1]
    q = np.array([[p[0], p[3], p[4]], [p[3], p[1], p[5]], [p[4], p[5], p[2]]])
    try:
        centre = -np.linalg.solve(q, p[6:9])
    except np.linalg.LinAlgError:
        return None
    level = float(centre @ q @ centre - p[9])
    if not (np.isfinite(level) and level != 0):
        return None
    s = q / level
    if not np.all(np.linalg.eigvalsh(s) > 0):
        return None
    u = np.linalg.cholesky(s).T * (gravity / s0)          # S = L L^T, U = L^T: upper, positive diagonal
    return u, c0 + s0 * centre


def _pack(u: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.concatenate([np.asarray(u, float)[_IU], b])


def _unpack(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    u = np.zeros((3, 3))
    u[_IU] = p[:6]
    return u, p[6:]


def _fit(a: np.ndarray, gravity: float, starts: list) -> list:
    """Levenberg-Marquardt of A1 from every start; the solutions, lowest cost first."""
    from scipy.optimize import least_squares

    def resid(p):
        u, b = _unpack(p)
        return np.linalg.norm((a - b) @ u.T, axis=1) - gravity

    out = []
    for x0 in starts:
        if not np.all(np.isfinite(x0)):
            continue
        sol = least_squares(resid, x0, method="lm", x_scale="jac")
        if np.all(np.isfinite(sol.x)) and np.all(np.isfinite(sol.jac)):
            out.append(sol)
    return sorted(out, key=lambda sol: sol.cost)


def _m_covariance(m: np.ndarray, cov_u: np.ndarray) -> np.ndarray:
    """``cov(vec M)`` (9, 9) from the covariance of U's six upper elements: ``dM = -M dU M``."""
    g = np.zeros((9, 6))
    for c, (p, q) in enumerate(zip(*_IU)):
        g[:, c] = -np.outer(m[:, p], m[q, :]).ravel()
    return g @ cov_u @ g.T


def _implausible(m: np.ndarray, units: str, fields: tuple[str, str]) -> str | None:
    """Why ``M`` is no accelerometer's (a wrong minimum, a unit or column mix-up), or None: scale factors outside
    1 +/- 0.2 (physical units), or axes that are no triad (``cond(M)`` above :data:`MAX_CONDITION`: scale factors
    differing by half, or axes far from orthogonal; raw counts too)."""
    units_field, columns_field = fields
    if matrix_unit(units, "accelerometer") == "1":
        bad = scale_outside(m, 0.2)
        if bad is not None:
            return (f"the accelerometer's {AXES[bad[0]]} scale factor from its |a| = g fit is {bad[1]:.3g}, outside "
                    f"1 +/- 0.2: wrong {{{units_field}}} or {{{columns_field}}}, too few or too similar attitudes, or a "
                    "broken axis")
    sv = np.linalg.svd(m, compute_uv=False)
    if not sv[0] <= MAX_CONDITION * sv[-1]:
        rows = m / np.linalg.norm(m, axis=1, keepdims=True)
        skew = max(abs(90.0 - float(np.degrees(np.arccos(np.clip(abs(rows[i] @ rows[j]), 0, 1)))))
                   for i, j in ((0, 1), (0, 2), (1, 2)))
        shown = "/".join(f"{v:.4g}" for v in np.linalg.norm(m, axis=1))
        return (f"the accelerometer's |a| = g fit gives no triad of axes (scale factors {shown} {units} per m/s^2 for "
                f"x/y/z, axes up to {skew:.3g} deg from orthogonal): wrong {{{columns_field}}}, too few or too similar "
                "attitudes, or a broken axis")
    return None


def _solution(sol) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(U, b, M, flip)`` of a solution, each row of ``U`` signed for a positive diagonal: ``|U v| = |D U v|`` for
    ``D = diag(+/-1)``, so each axis reads +g along itself (a flipped axis cannot be seen here: only known
    orientations show it)."""
    u, b = _unpack(sol.x)
    flip = np.where(np.diag(u) < 0, -1.0, 1.0)
    u = flip[:, None] * u
    with np.errstate(all="ignore"):
        m = np.linalg.inv(u) if np.all(np.isfinite(u)) and np.linalg.cond(u) < 1e8 else np.full((3, 3), np.nan)
    return u, b, m, flip


def calibrate_accel_free(means: np.ndarray, gravity: float = STANDARD_GRAVITY, units: str = "m/s^2",
                         guess_scale: float | None = None, guess_bias=None, where: str = "static intervals",
                         fields: tuple[str, str] = ("units", "columns")) -> Calibration:
    """Accelerometer ``[M | b]`` from static attitudes of unknown orientation (A1).

    Parameters
    ----------
    means : ndarray, shape (k, 3)
        Mean reading of each static attitude, SI or counts; ``k >= 9``.
    gravity : float
        Local gravity, m/s^2.
    units : str
        Unit of the readings, for the result's file form and the plausibility checks.
    guess_scale : float, optional
        Scale (readings per m/s^2) of the sphere start about the centre; default from the spread of ``means``.
    guess_bias : array_like, shape (3,), optional
        Centre of that start; default the mean of ``means``.
    where : str
        The log, for messages.
    fields : (str, str)
        The inputs holding the readings' unit and columns (placeholders of the fixes).

    Returns
    -------
    Calibration
        ``M`` upper triangular, its 1-sigma t-widened (``level`` says so); residuals ``|a| - g`` per
        attitude, in readings, on the x component.

    Raises
    ------
    TestError
        Readings at rest that are not gravity in ``units``, attitudes nearly in a plane, a degenerate fit,
        scale factors no accelerometer has (outside 1 +/- 0.2 in physical units; ``cond(M)`` above
        :data:`MAX_CONDITION`, counts too).
    """
    a = np.asarray(means, float)
    gravity = check_gravity(gravity)
    check_at_rest(np.linalg.norm(a, axis=1), gravity, units, fields[0], where)
    k = len(a)
    if k < 9:
        raise InputError(f"only {k} static attitudes; the 9-parameter fit needs at least 9 (12 or more recommended)",
                         where)
    centre = a.mean(axis=0) if guess_bias is None else np.asarray(guess_bias, float)
    spread = np.linalg.svd(a - centre, compute_uv=False)
    if spread[-1] < 0.05 * spread[0]:
        raise TestError("the static attitudes lie nearly in a plane: turn the sensor through all directions", where)
    scale = np.median(np.linalg.norm(a - centre, axis=1)) / gravity if guess_scale is None else guess_scale
    starts = [_pack(np.eye(3) / scale, centre),
              _pack(np.eye(3) * gravity / np.median(np.linalg.norm(a, axis=1)), np.zeros(3))]
    algebraic = ellipsoid_start(a, gravity)
    if algebraic is not None:
        starts.insert(0, _pack(*algebraic))
    # the lowest cost among the solutions an accelerometer can have: with poses that leave a direction weakly
    # covered, a degenerate ellipsoid (axes nearly parallel, a centre far out) can fit the noise a little better
    solutions = [(sol, *_solution(sol)) for sol in _fit(a, gravity, starts)]
    usable = [x for x in solutions if np.all(np.isfinite(x[3]))]
    if not usable:
        raise TestError("the fit is degenerate (a singular matrix): turn the sensor through all directions", where)
    sol, u, b, m, flip = next((x for x in usable if _implausible(x[3], units, fields) is None), usable[0])
    why = _implausible(m, units, fields)
    if why is not None:
        raise TestError(why, where)
    dof = k - 9
    if dof > 0:
        widening = t_widening(dof)
        s2 = float(np.sum(sol.fun ** 2)) / dof
        # columns scaled to unit norm first: in raw counts U (~1e-4) and b (~1e3) differ by 1e7, and an unscaled
        # pseudo-inverse would drop the small directions (a bias sigma 500x too small); the row flips of U carry over
        jac = sol.jac * np.concatenate([flip[_IU[0]], np.ones(3)])
        norms = np.linalg.norm(jac, axis=0)
        norms[norms == 0] = 1.0
        js = jac / norms
        cov = np.linalg.pinv(js.T @ js) / np.outer(norms, norms) * s2 * widening ** 2
        sigma_m = np.sqrt(np.maximum(np.diag(_m_covariance(m, cov[:6, :6])), 0.0)).reshape(3, 3)
        sigma_b = np.sqrt(np.maximum(np.diag(cov)[6:], 0.0))
        level = widened_level(widening, dof)
        how = f"1-sigma from the Jacobian and the residual variance, widened {widening:.3g}x for {dof} degrees of freedom"
    else:
        sigma_m, sigma_b = np.full((3, 3), np.nan), np.full(3, np.nan)
        level, how = "1 sigma", "9 attitudes fit the 9 parameters exactly: the 1-sigma is unknown (NaN)"
    per = float(np.mean(np.diag(m)))  # residuals of |a| (m/s^2) expressed in readings
    resid_norm = {f"attitude {i + 1}": np.array([r * per, 0.0, 0.0]) for i, r in enumerate(sol.fun)}
    note = (f"|a| = g fit over {k} static attitudes (local gravity {gravity:.6g} m/s^2); U upper triangular: "
            f"the accelerometer-to-case rotation is not observable; rms |a| residual "
            f"{np.sqrt(np.mean(sol.fun ** 2)):.3g} m/s^2; {how}")
    return Calibration("accelerometer", m, b, sigma_m, sigma_b, units, "|a| = g fit (unknown attitudes)",
                       resid_norm, {}, (note,), level=level)
