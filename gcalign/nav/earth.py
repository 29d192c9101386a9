"""WGS-84 earth model: radii, normal gravity, earth and transport rates (ENU frame).

All functions take latitude in radians and height in metres and broadcast over arrays.
The same formulas are repeated as scalar numba functions in :mod:`gcalign.nav._kernels`;
a test keeps the two in step.
"""

from __future__ import annotations

import numpy as np

A = 6378137.0  #: semi-major axis, m
F = 1.0 / 298.257223563  #: flattening
E2 = F * (2.0 - F)  #: first eccentricity squared
OMEGA_IE = 7.2921151467e-5  #: earth rotation rate, rad/s
# Normal gravity (Somigliana series with height term, as PSINS): g0 (1 + c1 sin²L + c2 sin⁴L) - c3 h
GE = 9.7803267715
G_C1 = 5.27094e-3
G_C2 = 2.32718e-5
G_C3 = 3.086e-6


def radii(lat):
    """Meridian and prime-vertical radii of curvature R_M, R_N (m) at latitude `lat` (rad)."""
    s2 = np.sin(lat) ** 2
    w = 1.0 - E2 * s2
    r_n = A / np.sqrt(w)
    r_m = r_n * (1.0 - E2) / w
    return r_m, r_n


def gravity(lat, h=0.0):
    """Normal gravity (m/s², pointing down) at latitude `lat` (rad) and height `h` (m)."""
    s2 = np.sin(lat) ** 2
    return GE * (1.0 + G_C1 * s2 + G_C2 * s2 * s2) - G_C3 * h


def omega_ie_n(lat):
    """Earth rate in ENU, shape (..., 3): ω_ie^n = ω_ie [0, cos L, sin L]."""
    lat = np.asarray(lat, dtype=float)
    return OMEGA_IE * np.stack([np.zeros_like(lat), np.cos(lat), np.sin(lat)], axis=-1)


def omega_en_n(lat, h, v_n):
    """Transport rate in ENU, shape (..., 3), from ENU velocity `v_n` (m/s)."""
    v_n = np.asarray(v_n, dtype=float)
    r_m, r_n = radii(lat)
    ve, vn = v_n[..., 0], v_n[..., 1]
    return np.stack([-vn / (r_m + h), ve / (r_n + h), ve * np.tan(lat) / (r_n + h)], axis=-1)


def C_en(lat, lon):
    """C_n^e: columns are the E, N, U axes resolved in the ECEF frame, shape (..., 3, 3)."""
    sl, cl = np.sin(lat), np.cos(lat)
    so, co = np.sin(lon), np.cos(lon)
    z = np.zeros_like(sl * so)
    east = np.stack([-so, co, z + 0.0], axis=-1)
    north = np.stack([-sl * co, -sl * so, cl + z], axis=-1)
    up = np.stack([cl * co, cl * so, sl + z], axis=-1)
    return np.stack([east, north, up], axis=-1)
