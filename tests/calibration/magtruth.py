"""An independent simulator of magnetometer captures of known truth, apart from the estimator.

Truth: Earth's field ``F`` (T) with dip ``dip`` in a north-east-down frame, hard iron ``h``, symmetric
soft iron ``S`` (the iron's distortion), and the magnetometer mounted turned by ``R`` from the body:
``raw = S R m_body + h + noise``, ``m_body = C^T f_ned`` for the attitude ``C`` (body to NED).
The ideal calibration is then ``W = S^-1`` and ``misalignment = R^T`` (``m_body = R^T W (raw - h)``);
the accelerometer reads the specific force ``C^T (0, 0, -g)``.
"""

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

G = 9.80665


@dataclass
class Truth:
    field: float
    dip: float
    hard: np.ndarray
    soft: np.ndarray  # S, symmetric positive definite
    mount: np.ndarray  # R, rotation: magnetometer axes from the body's

    @property
    def f_ned(self) -> np.ndarray:
        return self.field * np.array([np.cos(self.dip), 0.0, np.sin(self.dip)])

    def w_true(self, unit_det: bool) -> np.ndarray:
        w = np.linalg.inv(self.soft)
        return w / np.linalg.det(w) ** (1 / 3) if unit_det else w

    def readings(self, att: Rotation, rng: np.random.Generator, noise: float) -> tuple[np.ndarray, np.ndarray]:
        """Raw readings and accelerometer (m/s^2) at the attitudes ``att`` (body to NED)."""
        body = att.inv().apply(self.f_ned)
        raw = body @ (self.soft @ self.mount).T + self.hard + rng.normal(0, noise, body.shape)
        return raw, att.inv().apply([0.0, 0.0, -G])


def draw_truth(rng: np.random.Generator, mount_deg: float = 3.0, dip_deg: float | None = None) -> Truth:
    a = rng.normal(0, 0.08, (3, 3))
    dip = np.radians(dip_deg if dip_deg is not None else rng.uniform(45, 70) * rng.choice([-1, 1]))
    mount = Rotation.from_rotvec(rng.normal(0, np.radians(mount_deg), 3)).as_matrix()
    return Truth(field=rng.uniform(45e-6, 55e-6), dip=dip, hard=rng.normal(0, 20e-6, 3),
                 soft=np.eye(3) + 0.5 * (a + a.T), mount=mount)


def tumble(truth: Truth, rng: np.random.Generator, n: int, coverage: str, noise: float) -> np.ndarray:
    """Raw readings over ``n`` attitudes: ``"sphere"`` uniform over all attitudes, ``"hemisphere"`` only the
    attitudes that put the body-frame field in one (random) hemisphere."""
    keep = np.random.default_rng(rng.integers(2**32)).normal(size=3)
    out = []
    while sum(len(o) for o in out) < n:
        att = Rotation.random(4 * n, random_state=int(rng.integers(2**32)))
        if coverage == "hemisphere":
            att = att[att.inv().apply(truth.f_ned) @ keep > 0]
        out.append(att)
    att = Rotation.concatenate(out)[:n]
    return truth.readings(att, rng, noise)[0]


def axis_down_turn(truth: Truth, axis: int, rng: np.random.Generator, n: int = 200, noise: float = 0.5e-6,
                   arc_deg: float = 360.0, table_tilt_deg: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """Body axis ``axis`` pointing down, the device turned about it (on a slightly tilted table) through
    ``arc_deg`` of headings; raw readings and accelerometer."""
    e = np.eye(3)[axis]
    down = Rotation.align_vectors([[0.0, 0.0, 1.0]], [e])[0]  # body axis -> NED down
    table = Rotation.from_rotvec(np.r_[rng.normal(0, np.radians(table_tilt_deg), 2), 0.0])
    start = rng.uniform(0, 360)
    heading = Rotation.from_euler("z", (start + np.sort(rng.uniform(0, arc_deg, n)))[:, None], degrees=True)
    att = table * heading * down
    return truth.readings(att, rng, noise)
