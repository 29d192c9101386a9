"""WGS-84 for the vehicle simulator: radii and their latitude derivatives, normal gravity,
earth rate, geodetic <-> ECEF. NED navigation frame, SI units and radians.

Written for the simulator alone (it must stay an independent route to the truth, so it
shares nothing with ``gcalign.nav``). Normal gravity is Somigliana's closed form on the
ellipsoid with the WGS-84 height series (NIMA TR8350.2, eqs. 4-1 and 4-3), pointing down
(its horizontal part above the ellipsoid, below 1e-7 m/s² at the heights used here, is left
out, by the simulator and by its strapdown check alike).
"""

from __future__ import annotations

import numpy as np

A = 6378137.0  #: semi-major axis, m
F = 1.0 / 298.257223563  #: flattening
E2 = F * (2.0 - F)  #: first eccentricity squared
B = A * (1.0 - F)  #: semi-minor axis, m
OMEGA_IE = 7.2921151467e-5  #: earth rate, rad/s
GM = 3.986004418e14  #: m³/s²
GAMMA_E = 9.7803253359  #: normal gravity at the equator, m/s²
K_SOMIGLIANA = 0.00193185265241
M_RATIO = OMEGA_IE**2 * A**2 * B / GM


def radii(lat):
    """Meridian and prime-vertical radii ``(R_M, R_N)`` (m) at geodetic latitude `lat` (rad)."""
    w = 1.0 - E2 * np.sin(lat) ** 2
    return A * (1.0 - E2) / w**1.5, A / np.sqrt(w)


def radii_dlat(lat):
    """``(dR_M/dL, dR_N/dL)`` (m/rad): exact derivatives of :func:`radii`."""
    s, c = np.sin(lat), np.cos(lat)
    w = 1.0 - E2 * s**2
    return 3.0 * A * (1.0 - E2) * E2 * s * c / w**2.5, A * E2 * s * c / w**1.5


def gravity(lat, h):
    """Normal gravity magnitude (m/s², down) at latitude `lat` (rad), height `h` (m)."""
    s2 = np.sin(lat) ** 2
    g0 = GAMMA_E * (1.0 + K_SOMIGLIANA * s2) / np.sqrt(1.0 - E2 * s2)
    return g0 * (1.0 - 2.0 / A * (1.0 + F + M_RATIO - 2.0 * F * s2) * h + 3.0 * h**2 / A**2)


def omega_ie_n(lat):
    """Earth rate in NED, (..., 3) rad/s."""
    lat = np.asarray(lat, float)
    return OMEGA_IE * np.stack([np.cos(lat), np.zeros_like(lat), -np.sin(lat)], axis=-1)


def omega_en_n(lat, h, v_ned):
    """Transport rate in NED, (..., 3) rad/s, of ground velocity `v_ned` (..., 3) m/s."""
    r_m, r_n = radii(lat)
    v = np.asarray(v_ned, float)
    return np.stack([v[..., 1] / (r_n + h), -v[..., 0] / (r_m + h),
                     -v[..., 1] * np.tan(lat) / (r_n + h)], axis=-1)


def C_en(lat, lon):
    """C_n^e (..., 3, 3): NED axes in ECEF."""
    sl, cl, so, co = np.sin(lat), np.cos(lat), np.sin(lon), np.cos(lon)
    z = np.zeros_like(sl)
    return np.stack([np.stack([-sl * co, -so, -cl * co], -1),
                     np.stack([-sl * so, co, -cl * so], -1),
                     np.stack([cl, z, -sl], -1)], -2)


def to_ecef(lat, lon, h):
    """ECEF position (..., 3) m of geodetic `lat`, `lon` (rad), `h` (m)."""
    _, r_n = radii(lat)
    cl = np.cos(lat)
    return np.stack([(r_n + h) * cl * np.cos(lon), (r_n + h) * cl * np.sin(lon),
                     (r_n * (1.0 - E2) + h) * np.sin(lat)], axis=-1)


def to_geodetic(r_e):
    """Geodetic ``(lat, lon, h)`` (rad, rad, m) of ECEF `r_e` (..., 3): Bowring's start and
    fixed-point steps until the height changes by < 1e-9 m (a few steps near the ground)."""
    r = np.asarray(r_e, float)
    x, y, z = r[..., 0], r[..., 1], r[..., 2]
    p = np.hypot(x, y)
    lon = np.arctan2(y, x)
    lat = np.arctan2(z, p * (1.0 - E2))
    h = np.zeros_like(p)
    for _ in range(20):
        _, r_n = radii(lat)
        h_new = p / np.cos(lat) - r_n
        lat = np.arctan2(z, p * (1.0 - E2 * r_n / (r_n + h_new)))
        done = np.max(np.abs(h_new - h)) < 1e-9
        h = h_new
        if done:
            break
    _, r_n = radii(lat)
    return lat, lon, p / np.cos(lat) - r_n
