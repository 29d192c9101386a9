"""The vehicle's truth at any time, in closed form: geodetic position, NED velocity and its
rate, attitude (roll, pitch, yaw: FRD body, NED, ZYX as KF-GINS), body rates ω_ib^b and
specific force f^b, all from the route (:mod:`.route`) on the WGS-84 ellipsoid
(:mod:`.earth`).

The planar path (x north, y east, m) is laid on the ellipsoid with constant scales:
``L = L0 + x/ρ_N``, ``λ = λ0 + y/ρ_E``, ``h = h0 + z``, ρ_N = R_M(L0) + h0,
ρ_E = (R_N(L0) + h0) cos L0. So L̇ = ẋ/ρ_N and L̈ = ẍ/ρ_N exactly, and the NED velocity and
its rate of change follow from the radii and their latitude derivatives with nothing left
to integrate but x(s), y(s) (∫cos ψ, ∫sin ψ: Gauss-Legendre on pieces of at most half a
radian of heading, to round-off)::

    v_N = (R_M + h) L̇           v̇_N = (R_M' L̇ + ḣ) L̇ + (R_M + h) L̈
    v_E = (R_N + h) cos L λ̇     v̇_E = ((R_N' L̇ + ḣ) cos L − (R_N + h) sin L L̇) λ̇
                                        + (R_N + h) cos L λ̈
    v_D = −ḣ                    v̇_D = −ḧ
    f^n = v̇ + (2ω_ie^n + ω_en^n) × v − [0, 0, g]          (g: normal gravity, down)
    ω_en^n = [λ̇ cos L, −L̇, −λ̇ sin L]

The body: yaw ψ(s) (the path's heading), pitch atan z'(s) + c_p s̈ (the road's slope, the
nose up when speeding up), roll −c_r κ ṡ² (leaning out of a turn); with the ZYX Euler
rates, ω_nb^b = [φ̇ − ψ̇ sin θ, θ̇ cos φ + ψ̇ cos θ sin φ, −θ̇ sin φ + ψ̇ cos θ cos φ] and
ω_ib^b = C_n^b (ω_ie^n + ω_en^n) + ω_nb^b, f^b = C_n^b f^n.
(The velocity heading differs from ψ by the scales' change over the drive, < 2e-4 rad: a
sideslip no filter here models or needs.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from benchmarks.vehicle import earth
from benchmarks.vehicle.route import Route, Terrain

_GL_X, _GL_W = np.polynomial.legendre.leggauss(16)


@dataclass(frozen=True)
class Site:
    """The start: latitude, longitude (deg), height (m)."""

    lat_deg: float = 30.52
    lon_deg: float = 114.36
    h_m: float = 25.0


@dataclass(frozen=True)
class State:
    """Truth at times t (M,): lat, lon (rad), h (m); v_ned (M, 3) m/s; a_ned (M, 3) m/s²
    (d/dt of the NED components); euler (M, 3) roll, pitch, yaw (rad); C_nb (M, 3, 3);
    omega_ib_b (M, 3) rad/s; f_b (M, 3) m/s²."""

    t: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    h: np.ndarray
    v_ned: np.ndarray
    a_ned: np.ndarray
    euler: np.ndarray
    C_nb: np.ndarray
    omega_ib_b: np.ndarray
    f_b: np.ndarray


def euler_to_dcm(roll, pitch, yaw):
    """C_b^n = Rz(yaw) Ry(pitch) Rx(roll), (..., 3, 3) (FRD body, NED)."""
    cr, sr, cp, sp, cy, sy = (np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch),
                              np.cos(yaw), np.sin(yaw))
    return np.stack([
        np.stack([cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr], -1),
        np.stack([sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr], -1),
        np.stack([-sp, cp * sr, cp * cr], -1)], -2)


def dcm_to_euler(C):
    """roll, pitch, yaw (rad, yaw in (−π, π]) of C_b^n (..., 3, 3)."""
    return (np.arctan2(C[..., 2, 1], C[..., 2, 2]), -np.arcsin(np.clip(C[..., 2, 0], -1, 1)),
            np.arctan2(C[..., 1, 0], C[..., 0, 0]))


class Trajectory:
    """Closed-form truth of a route on the ellipsoid (module docstring).

    Parameters
    ----------
    route : the drive (speed in time, curvature in distance)
    site : the start (latitude, longitude, height)
    terrain : height against distance
    roll_per_mps2, pitch_per_mps2 : body roll per m/s² of lateral acceleration (out of the
        turn) and pitch per m/s² of forward acceleration (nose up), rad/(m/s²)
    """

    def __init__(self, route: Route, site: Site | None = None, terrain: Terrain | None = None,
                 roll_per_mps2: float = np.radians(0.5),
                 pitch_per_mps2: float = np.radians(0.3)) -> None:
        site = Site() if site is None else site
        self.route, self.site = route, site
        self.terrain = Terrain() if terrain is None else terrain
        self.c_roll, self.c_pitch = roll_per_mps2, pitch_per_mps2
        self.lat0, self.lon0 = np.radians(site.lat_deg), np.radians(site.lon_deg)
        r_m, r_n = earth.radii(self.lat0)
        self.rho_n = r_m + site.h_m
        self.rho_e = (r_n + site.h_m) * np.cos(self.lat0)
        a = route.arrays()
        # x, y at the start of every curvature piece (Gauss-Legendre over each piece)
        xy = self._piece_integral(np.arange(len(a["c_s0"])), a["c_len"])
        self._x0 = np.concatenate([[0.0], np.cumsum(xy[0])[:-1]])
        self._y0 = np.concatenate([[0.0], np.cumsum(xy[1])[:-1]])

    @property
    def duration(self) -> float:
        return self.route.duration

    def _piece_integral(self, i, sig):
        """(∫cos ψ, ∫sin ψ) over [c_s0[i], c_s0[i] + sig] (M,), 16-point Gauss-Legendre."""
        a = self.route.arrays()
        s = a["c_s0"][i][:, None] + 0.5 * sig[:, None] * (1.0 + _GL_X[None, :])
        psi = self.route.heading(s.ravel())[0].reshape(s.shape)
        return (0.5 * sig * (np.cos(psi) @ _GL_W), 0.5 * sig * (np.sin(psi) @ _GL_W))

    def planar(self, s):
        """x, y (m) at distances `s` (M,)."""
        a = self.route.arrays()
        s = np.asarray(s, float)
        i = np.clip(np.searchsorted(a["c_s0"], s, side="right") - 1, 0, len(a["c_s0"]) - 1)
        dx, dy = self._piece_integral(i, s - a["c_s0"][i])
        return self._x0[i] + dx, self._y0[i] + dy

    def join_times(self) -> np.ndarray:
        """Times (s) where some derivative of the motion jumps: the speed law's changes and
        the moments the curvature's pieces begin (sorted, inside the drive)."""
        t_speed, s_curv = self.route.joins()
        s_end = self.route.speed(self.duration)[0]
        t_curv = self.route.time_at(s_curv[s_curv < s_end])
        t = np.unique(np.concatenate([t_speed, t_curv]))
        return t[(t > 0) & (t < self.duration)]

    def position(self, t):
        """lat, lon (rad), h (m) at times `t` (M,) s."""
        s = self.route.speed(t)[0]
        x, y = self.planar(s)
        return (self.lat0 + x / self.rho_n, self.lon0 + y / self.rho_e,
                self.site.h_m + self.terrain.height(s)[0])

    def state(self, t) -> State:
        """Everything at times `t` (M,) s (module docstring)."""
        t = np.asarray(t, float)
        s, sd, sdd, sddd = self.route.speed(t)
        psi, kappa, dkappa = self.route.heading(s)
        z, z1, z2, _ = self.terrain.height(s)
        x, y = self.planar(s)
        c, sn = np.cos(psi), np.sin(psi)
        xd, yd = c * sd, sn * sd
        xdd = -sn * kappa * sd**2 + c * sdd
        ydd = c * kappa * sd**2 + sn * sdd
        zd, zdd = z1 * sd, z2 * sd**2 + z1 * sdd
        lat = self.lat0 + x / self.rho_n
        lon = self.lon0 + y / self.rho_e
        h = self.site.h_m + z
        Ld, Ldd = xd / self.rho_n, xdd / self.rho_n
        ld, ldd = yd / self.rho_e, ydd / self.rho_e
        r_m, r_n = earth.radii(lat)
        dr_m, dr_n = earth.radii_dlat(lat)
        cl, sl = np.cos(lat), np.sin(lat)
        v = np.column_stack([(r_m + h) * Ld, (r_n + h) * cl * ld, -zd])
        a = np.column_stack([
            (dr_m * Ld + zd) * Ld + (r_m + h) * Ldd,
            ((dr_n * Ld + zd) * cl - (r_n + h) * sl * Ld) * ld + (r_n + h) * cl * ldd,
            -zdd])
        w_ie = earth.omega_ie_n(lat)
        w_en = np.column_stack([ld * cl, -Ld, -ld * sl])
        g = np.column_stack([np.zeros_like(h), np.zeros_like(h), earth.gravity(lat, h)])
        f_n = a + np.cross(2 * w_ie + w_en, v) - g
        # body attitude and its Euler rates
        lat_acc = kappa * sd**2
        roll = -self.c_roll * lat_acc
        roll_d = -self.c_roll * (dkappa * sd**3 + 2 * kappa * sd * sdd)
        pitch = np.arctan(z1) + self.c_pitch * sdd
        pitch_d = z2 * sd / (1 + z1**2) + self.c_pitch * sddd
        yaw, yaw_d = psi, kappa * sd
        C_nb = euler_to_dcm(roll, pitch, yaw)
        cr, sr, cp, sp = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch)
        w_nb_b = np.column_stack([roll_d - yaw_d * sp, pitch_d * cr + yaw_d * cp * sr,
                                  -pitch_d * sr + yaw_d * cp * cr])
        C_bn = np.swapaxes(C_nb, -1, -2)
        w_ib_b = np.einsum("kij,kj->ki", C_bn, w_ie + w_en) + w_nb_b
        f_b = np.einsum("kij,kj->ki", C_bn, f_n)
        return State(t, lat, lon, h, v, a, np.column_stack([roll, pitch, yaw]), C_nb,
                     w_ib_b, f_b)
