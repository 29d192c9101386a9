"""Earth models as values: radii, normal gravity, earth and transport rates (ENU frame).

An :class:`EarthModel` is a frozen value passed to every function and kernel that needs
the earth; two are built in and chosen in a scenario by ``earth: wgs84 | seed004``:

* :data:`WGS84` (default): a = 6378137 m, f = 1/298.257223563, ω_ie = 7.2921151467e-5
  rad/s; exact radii of curvature ``R_N = a/√(1 − e² sin²L)``, ``R_M = R_N (1 − e²)/(1 −
  e² sin²L)``; normal gravity ``g0 (1 + c1 sin²L + c2 sin⁴L) − c3 h`` (PSINS constants).
* :data:`SEED004` (spec 004 §4, the patent's VC++ simulation): Re = 6378393.0 m, flattening
  e = 3.367e-3, ω_ie = 7.2921158e-5 rad/s; first-order radii ``R_M = Re(1 − 2e + 3e sin²L)``,
  ``R_N = Re(1 + e sin²L)``; gravity ``9.78049 (1 + 0.0052884 sin²L − 0.0000059 sin²2L)``,
  written in the same polynomial as WGS-84's (sin²2L = 4 sin²L − 4 sin⁴L). The seed gives
  no height term; ours keeps the free-air gradient 3.086e-6 /s² so that a height is never
  silently ignored.

The functions take latitude in radians and height in metres, broadcast over arrays, and
default to WGS-84. The same formulas run inside the numba kernels from
:meth:`EarthModel.params` (:func:`gcalign.nav._kernels.earth_at`); a test keeps them in step.

>>> lat = np.radians(45.7796)
>>> r_m, r_n = SEED004.radii(lat)
>>> round(float(r_m), 1), round(float(r_n), 1), round(float(SEED004.gravity(lat)), 6)
(6368531.5, 6389423.2, 9.806998)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

EXACT, FIRST_ORDER = 0, 1  # forms of the radii of curvature (EarthModel.radii_form)

#: a latitude (rad) or an array of them; radii and gravity come back in the same form
Lat = TypeVar("Lat", float, NDArray[np.float64])


@dataclass(frozen=True)
class EarthModel:
    """An earth model (SI): ellipsoid, rotation rate and normal gravity.

    a : equatorial radius, m. f : flattening. omega_ie : rotation rate, rad/s.
    g0, g1, g2, g3 : normal gravity ``g0 (1 + g1 sin²L + g2 sin⁴L) − g3 h`` (m/s², −, −, 1/s²).
    radii_form : :data:`EXACT` (ellipsoid radii of curvature) or :data:`FIRST_ORDER`
        (``R_M = a(1 − 2f + 3f sin²L)``, ``R_N = a(1 + f sin²L)``).
    """

    name: str
    a: float
    f: float
    omega_ie: float
    g0: float
    g1: float
    g2: float
    g3: float
    radii_form: int = EXACT

    @property
    def e2(self) -> float:
        """First eccentricity squared, f (2 − f)."""
        return self.f * (2.0 - self.f)

    def params(self) -> NDArray[np.float64]:
        """The model as the float64 vector the numba kernels take:
        ``[form, a, e2 (exact) or f (first order), ω_ie, g0, g1, g2, g3]``."""
        shape = self.e2 if self.radii_form == EXACT else self.f
        return np.array([self.radii_form, self.a, shape, self.omega_ie,
                         self.g0, self.g1, self.g2, self.g3], dtype=float)

    def radii(self, lat: Lat) -> tuple[Lat, Lat]:
        """Meridian and prime-vertical radii of curvature R_M, R_N (m) at latitude `lat` (rad)."""
        s2 = np.sin(lat) ** 2
        if self.radii_form == FIRST_ORDER:
            return (self.a * (1.0 - 2.0 * self.f + 3.0 * self.f * s2),
                    self.a * (1.0 + self.f * s2))
        e2 = self.e2
        w = 1.0 - e2 * s2
        r_n = self.a / np.sqrt(w)
        return r_n * (1.0 - e2) / w, r_n

    def gravity(self, lat: Lat, h: float | NDArray[np.float64] = 0.0) -> Lat:
        """Normal gravity (m/s², pointing down) at latitude `lat` (rad) and height `h` (m)."""
        s2 = np.sin(lat) ** 2
        return self.g0 * (1.0 + self.g1 * s2 + self.g2 * s2 * s2) - self.g3 * h

    def omega_ie_n(self, lat: ArrayLike) -> NDArray[np.float64]:
        """Earth rate in ENU, shape (..., 3): ω_ie^n = ω_ie [0, cos L, sin L]."""
        lat = np.asarray(lat, dtype=float)
        return self.omega_ie * np.stack([np.zeros_like(lat), np.cos(lat), np.sin(lat)], axis=-1)

    def omega_en_n(self, lat: Lat, h: float | NDArray[np.float64],
                   v_n: ArrayLike) -> NDArray[np.float64]:
        """Transport rate in ENU, shape (..., 3), from ENU velocity `v_n` (m/s)."""
        v_n = np.asarray(v_n, dtype=float)
        r_m, r_n = self.radii(lat)
        ve, vn = v_n[..., 0], v_n[..., 1]
        return np.stack([-vn / (r_m + h), ve / (r_n + h), ve * np.tan(lat) / (r_n + h)], axis=-1)

    def schuler_rate(self, lat: float, h: float = 0.0) -> float:
        """Schuler angular frequency ω_s = √(g / √(R_M R_N)) (rad/s) at the site."""
        r_m, r_n = self.radii(lat)
        return float(np.sqrt(self.gravity(lat, h) / np.sqrt((r_m + h) * (r_n + h))))


WGS84 = EarthModel("wgs84", a=6378137.0, f=1.0 / 298.257223563, omega_ie=7.2921151467e-5,
                   g0=9.7803267715, g1=5.27094e-3, g2=2.32718e-5, g3=3.086e-6)
SEED004 = EarthModel("seed004", a=6378393.0, f=3.367e-3, omega_ie=7.2921158e-5, g0=9.78049,
                     g1=0.0052884 - 4.0 * 0.0000059, g2=4.0 * 0.0000059, g3=3.086e-6,
                     radii_form=FIRST_ORDER)
MODELS = {m.name: m for m in (WGS84, SEED004)}

# WGS-84 constants and functions, as before models were values (the default everywhere).
A, F, E2, OMEGA_IE = WGS84.a, WGS84.f, WGS84.e2, WGS84.omega_ie
GE, G_C1, G_C2, G_C3 = WGS84.g0, WGS84.g1, WGS84.g2, WGS84.g3


def radii(lat: Lat, earth: EarthModel = WGS84) -> tuple[Lat, Lat]:
    """R_M, R_N (m) at latitude `lat` (rad); see :meth:`EarthModel.radii`."""
    return earth.radii(lat)


def gravity(lat: Lat, h: float | NDArray[np.float64] = 0.0,
            earth: EarthModel = WGS84) -> Lat:
    """Normal gravity (m/s², down) at `lat` (rad), `h` (m); see :meth:`EarthModel.gravity`."""
    return earth.gravity(lat, h)


def omega_ie_n(lat: ArrayLike, earth: EarthModel = WGS84) -> NDArray[np.float64]:
    """Earth rate in ENU, shape (..., 3)."""
    return earth.omega_ie_n(lat)


def omega_en_n(lat: Lat, h: float | NDArray[np.float64], v_n: ArrayLike,
               earth: EarthModel = WGS84) -> NDArray[np.float64]:
    """Transport rate in ENU, shape (..., 3)."""
    return earth.omega_en_n(lat, h, v_n)


def C_en(lat: ArrayLike, lon: ArrayLike) -> NDArray[np.float64]:
    """C_n^e: columns are the E, N, U axes resolved in the ECEF frame, shape (..., 3, 3)."""
    sl, cl = np.sin(lat), np.cos(lat)
    so, co = np.sin(lon), np.cos(lon)
    z = np.zeros_like(sl * so)
    east = np.stack([-so, co, z + 0.0], axis=-1)
    north = np.stack([-sl * co, -sl * so, cl + z], axis=-1)
    up = np.stack([cl * co, cl * so, sl + z], axis=-1)
    return np.stack([east, north, up], axis=-1)
