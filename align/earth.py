"""Earth rotation rate as seen on a rate table (reference section 4, last item).

Public names
------------
EARTH_RATE, vertical_rate, earth_rate_enu, earth_rate_in_frame
"""

from __future__ import annotations

import numpy as np

#: Earth's sidereal rotation rate, rad/s (WGS-84), 15.041 deg/h
EARTH_RATE = 7.2921150e-5


def vertical_rate(latitude: float) -> float:
    """Vertical (up) component of Earth rate: ``Omega sin(latitude)`` (reference section 4, last item).

    Parameters
    ----------
    latitude : float
        Geodetic latitude, rad (north positive).

    Returns
    -------
    float
        rad/s; 7.29e-5 rad/s (15.041 deg/h) at the pole.
    """
    return EARTH_RATE * np.sin(latitude)


def earth_rate_enu(latitude: float) -> np.ndarray:
    """Earth rate in the local level frame (east, north, up): ``Omega (0, cos L, sin L)``.

    Parameters
    ----------
    latitude : float
        Geodetic latitude ``L``, rad.

    Returns
    -------
    ndarray, shape (3,)
        rad/s.
    """
    return EARTH_RATE * np.array([0.0, np.cos(latitude), np.sin(latitude)])


def earth_rate_in_frame(latitude: float, up: np.ndarray, heading: np.ndarray) -> np.ndarray:
    """Earth rate in a frame whose ``up`` axis is vertical, turned by ``heading`` (reference section 4).

    Parameters
    ----------
    latitude : float
        rad.
    up : ndarray, shape (3,)
        Unit vector of the local vertical in the frame (the table spin axis).
    heading : ndarray, shape (n,)
        Table angle about ``up``, rad; 0 puts the frame's first horizontal axis
        (``p``, perpendicular to ``up``) north.

    Returns
    -------
    ndarray, shape (n, 3)
        ``Omega sin(lat) up + Omega cos(lat) (cos(h) p - sin(h) q)``, rad/s.
    """
    up = np.asarray(up, float)
    helper = np.array([1.0, 0.0, 0.0]) if abs(up[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    p = np.cross(up, helper)
    p /= np.linalg.norm(p)
    q = np.cross(up, p)
    h = np.asarray(heading, float)[:, None]
    horiz = EARTH_RATE * np.cos(latitude) * (np.cos(h) * p - np.sin(h) * q)
    return vertical_rate(latitude) * up + horiz
