"""Earth rotation rate as seen on a rate table (reference section 4, last item).

Public names
------------
EARTH_RATE, earth_rate_enu
"""

from __future__ import annotations

import numpy as np

#: Earth's sidereal rotation rate, rad/s (WGS-84), 15.041 deg/h
EARTH_RATE = 7.2921150e-5


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
