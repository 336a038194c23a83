"""The mounting-misalignment budget three ways: the source's, worst case, Monte Carlo.

* Source (reference section 2): tilts about x and y from the full ledge-height
  band (Eq 2-3), skew about z from the screw clearance (Eq 4), mounting term the
  largest of the three, total by RSS with the datasheet axis-to-package figure (Eq 1).
* Per gyro axis: a tilt about x moves the y and z gyro axes, not the x one; the
  per-axis RSS combines only the terms that move that axis.
* Worst case: every tolerance at its extreme, composed as 3-D rotations
  (:func:`mechanics.assembly.worst_case_per_axis`).
* Monte Carlo: every tolerance drawn from its distribution
  (:func:`mechanics.montecarlo.monte_carlo`), attached with
  ``budget(m).replace(monte_carlo=monte_carlo(m, n))``.

The :class:`Budget` is a registered result (``imu-align.budget``, see
:mod:`align.results`), its Monte Carlo part included when one was run.

Public names
------------
Budget, budget, FORMAT, BASES
"""

from __future__ import annotations

from dataclasses import field

import numpy as np

from align import CONVENTION
from align.errors import InputError
from align.results import Result
from align.units import DEG
from align.wellformed import malformed
from mechanics.assembly import skew_limit, worst_case_per_axis
from mechanics.formulas import rss, screw_radius, skew_from_screws, tilt_from_ledges
from mechanics.montecarlo import MonteCarlo
from mechanics.mount import Mount

FORMAT = "imu-align.budget"
BUDGET_CONVENTION = CONVENTION + "; misalignment = angle between each gyro axis and its system axis"
#: budget figures :meth:`Budget.elements` can give
BASES = ("rss", "worst")


def _xyz_deg(values: np.ndarray) -> dict:
    return dict(zip("xyz", (np.asarray(values) / DEG).tolist()))


def _xyz_rad(d: dict) -> np.ndarray:
    return np.array([d[a] for a in "xyz"], dtype=float) * DEG


#: the keys of a budget file after its envelope
FILE_KEYS = ("tilt_x_deg", "tilt_y_deg", "skew_z_deg", "imu_deg", "mounting_deg", "total_deg", "sum_deg", "per_axis_deg",
             "worst_case_deg", "worst_case_per_axis_deg", "skew_worst_deg", "method", "mount", "monte_carlo", "inputs")


class Budget(Result, format=FORMAT, convention=BUDGET_CONVENTION):
    """The mounting-misalignment budget of a mount (all angles in rad).

    Attributes
    ----------
    tilt_x, tilt_y, skew_z : float
        Eq 2, Eq 3 and Eq 4.
    imu : float
        Largest datasheet axis-to-package term.
    mounting : float
        The largest of the three mounting terms (the source's choice).
    total : float
        RSS of ``imu``, ``mounting`` and the extras (Eq 1).
    plain_sum : float
        Their plain sum.
    per_axis : ndarray, shape (3,)
        RSS of the terms that move each gyro axis.
    worst_case_per_axis : ndarray, shape (3,)
        Every tolerance at its extreme, composed in 3-D, plus the datasheet and extras.
    skew_worst : float
        Skew limit with the screw position tolerance.
    mount : Mount
    monte_carlo : MonteCarlo or None
        Set with ``replace(monte_carlo=monte_carlo(mount, n))``.
    inputs : dict
    """

    tilt_x: float
    tilt_y: float
    skew_z: float
    imu: float
    mounting: float
    total: float
    plain_sum: float
    per_axis: np.ndarray
    worst_case_per_axis: np.ndarray
    skew_worst: float
    mount: Mount
    monte_carlo: MonteCarlo | None = None
    inputs: dict = field(default_factory=dict)


    @property
    def worst_case(self) -> float:
        """Largest worst-case misalignment over the three axes, rad."""
        return float(self.worst_case_per_axis.max())

    def elements(self, basis: str = "rss") -> dict:
        """Predicted size of each misalignment element (rad), named as in :mod:`align.sensitivity`.

        ``psi_i`` is the per-axis figure; ``phi_ij`` (gyro ``i`` leaning toward
        axis ``j``) combines the mounting rotation about the third axis ``k``
        (tilt x, tilt y or skew z) with the datasheet term of gyro ``i`` and the
        extras; by RSS (``basis="rss"``, Eq 1) or added (``"worst"``).
        """
        if basis not in BASES:
            raise InputError(f"choose rss or worst (got {basis!r})", "{basis}")
        about = {0: self.tilt_x, 1: self.tilt_y, 2: self.skew_z}
        extras = list(self.mount.extras.values())
        out = {}
        for i, a in enumerate("xyz"):
            out[f"psi_{a}"] = float(self.per_axis[i] if basis == "rss" else self.worst_case_per_axis[i])
            for j, b in enumerate("xyz"):
                if i == j:
                    continue
                terms = [about[3 - i - j], self.mount.axis_to_package[i], *extras]
                out[f"phi_{a}{b}"] = rss(*terms) if basis == "rss" else float(sum(terms))
        return out

    def to_dict(self) -> dict:
        """The versioned JSON form: angles in deg, lengths in mm."""
        d = {
            **self.envelope({"angles": "deg", "lengths": "mm"}),
            "tilt_x_deg": self.tilt_x / DEG, "tilt_y_deg": self.tilt_y / DEG, "skew_z_deg": self.skew_z / DEG,
            "imu_deg": self.imu / DEG, "mounting_deg": self.mounting / DEG, "total_deg": self.total / DEG,
            "sum_deg": self.plain_sum / DEG,
            "per_axis_deg": _xyz_deg(self.per_axis),
            "worst_case_deg": self.worst_case / DEG,
            "worst_case_per_axis_deg": _xyz_deg(self.worst_case_per_axis),
            "skew_worst_deg": self.skew_worst / DEG,
            "method": {
                "source": ("Eq 2-3 tilts from the full height band, Eq 4 skew, mounting = max, "
                           "total = RSS with axis-to-package (Eq 1)"),
                "per_axis": ("RSS of the terms that move each gyro axis (x: tilt_y, skew, imu_x, extras; "
                             "y: tilt_x, skew, imu_y, extras; z: tilt_x, tilt_y, imu_z, extras)"),
                "worst_case": ("corners of the ledge-height box through the rest model and the skew limit "
                               "(with screw position tolerance), composed in 3-D, plus datasheet and extra terms"),
            },
            "mount": self.mount.to_dict(),
        }
        if self.monte_carlo is not None:
            d["monte_carlo"] = self.monte_carlo.to_dict()
        d["inputs"] = dict(self.inputs)
        return d

    @classmethod
    def from_dict(cls, d: dict, where: str = "result") -> Budget:
        """Read the form written by :meth:`to_dict`; a key it does not know is refused (a misspelling)."""
        cls.check_envelope(d, where, keys=FILE_KEYS)
        try:
            mc = d.get("monte_carlo")
            return cls(
                d["tilt_x_deg"] * DEG, d["tilt_y_deg"] * DEG, d["skew_z_deg"] * DEG, d["imu_deg"] * DEG,
                d["mounting_deg"] * DEG, d["total_deg"] * DEG, d["sum_deg"] * DEG,
                _xyz_rad(d["per_axis_deg"]), _xyz_rad(d["worst_case_per_axis_deg"]),
                d["skew_worst_deg"] * DEG, Mount.from_dict(d["mount"], f"{where}: mount"),
                None if mc is None else MonteCarlo.from_dict(mc), dict(d.get("inputs", {})),
            )
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise InputError(f"malformed budget result ({malformed(exc)}); regenerate it with imu-align budget",
                             where) from None


def budget(m: Mount) -> Budget:
    """The deterministic budget: source formulas, per-axis RSS and the 3-D worst case.

    Eq 2 and Eq 3 (``atan((H2 - H1) / (W - W1))``) give the tilts, Eq 4 (``asin((D_H - D_M) / (2 R_S))``)
    the skew and Eq 1 (``sqrt(theta_IMU^2 + theta_SYS^2)``) the total.

    Parameters
    ----------
    m : Mount
        Package, ledge, screw and datasheet dimensions, SI (m, rad).

    Returns
    -------
    Budget
        Angles in rad: ``tilt_x``, ``tilt_y``, ``skew_z``, ``total``, ``per_axis`` (3,),
        ``worst_case_per_axis`` (3,).

    Examples
    --------
    The reference's Example 1 (ADIS16485 on 6 mm ledges): skew 0.8374 deg, total 1.3043 deg.

    >>> from pathlib import Path
    >>> import mechanics
    >>> from align.io import read_toml
    >>> from mechanics.mount import mount_from_dict
    >>> path = Path(mechanics.__file__).parents[1] / "examples" / "budget" / "example1.toml"
    >>> b = budget(mount_from_dict(read_toml(path), str(path), path.parent))
    >>> round(b.skew_z * 57.29577951308232, 4), round(b.total * 57.29577951308232, 4)
    (0.8374, 1.3043)
    """
    size_x, size_y = m.package[:2]
    tilt_x = tilt_from_ledges(m.height_tolerance, size_y, m.ledge_size)       # Eq 2 (span W = size_y)
    tilt_y = tilt_from_ledges(m.height_tolerance, size_x, m.ledge_size)       # Eq 3 (span L = size_x)
    skew = skew_from_screws(m.hole_diameter, m.screw_diameter, screw_radius(m.spacing_x, m.spacing_y))  # Eq 4
    imu = float(m.axis_to_package.max())
    mounting = max(tilt_x, tilt_y, skew)
    extras = list(m.extras.values())
    total = rss(imu, mounting, *extras)                                      # Eq 1
    moves = ((tilt_y, skew), (tilt_x, skew), (tilt_x, tilt_y))
    per_axis = np.array([rss(*moves[i], m.axis_to_package[i], *extras) for i in range(3)])
    worst = worst_case_per_axis(m)
    return Budget(tilt_x, tilt_y, skew, imu, mounting, total, imu + mounting + sum(extras), per_axis, worst,
                  skew_limit(m), m)
