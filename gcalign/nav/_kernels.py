"""Numba kernels: the strapdown update over whole blocks (the hot loop).

Scalar helpers here are inlined into the kernels by LLVM; they repeat the vectorised
formulas of :mod:`gcalign.nav.earth` and :mod:`gcalign.nav.rotation`, and
``tests/test_strapdown.py`` holds the two in step (kernel vs slow NumPy reference, 1e-12).

One update serves both directions (DESIGN.md "Reverse navigation"): a reverse pass feeds
time-reversed data with negated gyro increments, negated velocity and ``earth_sign = -1``.
Every approximation in the step is evaluated at the middle of the interval, so the
reverse step undoes the forward step to second order in the step size.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from gcalign.nav.earth import E2, G_C1, G_C2, G_C3, GE, OMEGA_IE
from gcalign.nav.earth import A as EARTH_A


@njit(cache=True, inline="always")
def earth_at(lat, h):
    """R_M, R_N (m), normal gravity g (m/s²), sin L, cos L at latitude `lat`, height `h`."""
    sl = math.sin(lat)
    cl = math.cos(lat)
    s2 = sl * sl
    w = 1.0 - E2 * s2
    r_n = EARTH_A / math.sqrt(w)
    r_m = r_n * (1.0 - E2) / w
    g = GE * (1.0 + G_C1 * s2 + G_C2 * s2 * s2) - G_C3 * h
    return r_m, r_n, g, sl, cl


@njit(cache=True, inline="always")
def rv2q(rx, ry, rz):
    """Quaternion of a rotation vector; series below 1e-4 rad where it is exact in float64."""
    t2 = rx * rx + ry * ry + rz * rz
    if t2 < 1e-8:
        c = 1.0 - t2 / 8.0 + t2 * t2 / 384.0
        s = 0.5 - t2 / 48.0
    else:
        t = math.sqrt(t2)
        c = math.cos(0.5 * t)
        s = math.sin(0.5 * t) / t
    return c, s * rx, s * ry, s * rz


@njit(cache=True, inline="always")
def qmul(aw, ax, ay, az, bw, bx, by, bz):
    """Hamilton product a ⊗ b."""
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


@njit(cache=True, inline="always")
def qrot(qw, qx, qy, qz, vx, vy, vz):
    """Rotate v by unit quaternion q: q ⊗ v ⊗ q* (as C(q) @ v)."""
    # t = 2 q_v × v;  v' = v + w t + q_v × t
    tx = 2.0 * (qy * vz - qz * vy)
    ty = 2.0 * (qz * vx - qx * vz)
    tz = 2.0 * (qx * vy - qy * vx)
    return (
        vx + qw * tx + qy * tz - qz * ty,
        vy + qw * ty + qz * tx - qx * tz,
        vz + qw * tz + qx * ty - qy * tx,
    )


@njit(cache=True, inline="always")
def rotate_small(rx, ry, rz, vx, vy, vz):
    """R(r) v for a small rotation vector r (Rodrigues, series to 4th order: |r| < 0.05)."""
    t2 = rx * rx + ry * ry + rz * rz
    a = 1.0 - t2 / 6.0 + t2 * t2 / 120.0  # sin t / t
    b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0  # (1 - cos t) / t²
    cx = ry * vz - rz * vy
    cy = rz * vx - rx * vz
    cz = rx * vy - ry * vx
    return (
        vx + a * cx + b * (ry * cz - rz * cy),
        vy + a * cy + b * (rz * cx - rx * cz),
        vz + a * cz + b * (rx * cy - ry * cx),
    )


@njit(cache=True, inline="always")
def transport_rate(ve, vn, r_m, r_n, h, sl, cl):
    """ω_en^n = [-v_N/(R_M+h), v_E/(R_N+h), v_E tan L/(R_N+h)]."""
    return -vn / (r_m + h), ve / (r_n + h), ve * sl / (cl * (r_n + h))


@njit(cache=True, inline="always")
def strapdown_step(q, v, p, dth, dvb, ts, earth_sign):
    """One strapdown update in place: q (4,) q_nb, v (3,) ENU m/s, p (3,) [lat, lon, h].

    Velocity:  v_k = v_{k-1} + R(-ω_in T/2) C_nb(k-1) R(Δθ/2) Δv + (g_n - (2ω_ie + ω_en) × v_mid) T
               (the specific-force increment resolved at mid-interval; Coriolis at a
               predicted mid-interval velocity)
    Attitude:  q_k = q(-ω_in T) ⊗ q_{k-1} ⊗ q(Δθ_k),  ω_in = ω_ie + ω_en(v_mid)
    Position:  trapezoid in velocity, radii at the mid-interval latitude.
    """
    lat, h = p[0], p[2]
    r_m, r_n, g, sl, cl = earth_at(lat, h)
    wie = earth_sign * OMEGA_IE
    wie_n, wie_u = wie * cl, wie * sl
    ve, vn, vu = v[0], v[1], v[2]

    # Specific-force increment at mid-interval: body half-rotation, then nav half-rotation.
    bx, by, bz = rotate_small(0.5 * dth[0], 0.5 * dth[1], 0.5 * dth[2], dvb[0], dvb[1], dvb[2])
    fx, fy, fz = qrot(q[0], q[1], q[2], q[3], bx, by, bz)
    tx, ty, tz = transport_rate(ve, vn, r_m, r_n, h, sl, cl)
    wx, wy, wz = tx * ts, (wie_n + ty) * ts, (wie_u + tz) * ts
    fx, fy, fz = rotate_small(-0.5 * wx, -0.5 * wy, -0.5 * wz, fx, fy, fz)

    # Predict the mid-interval velocity, then Coriolis/transport and gravity there.
    me = ve + 0.5 * fx
    mn = vn + 0.5 * fy
    mu = vu + 0.5 * (fz - g * ts)
    tx, ty, tz = transport_rate(me, mn, r_m, r_n, h, sl, cl)
    cx, cy, cz = tx, 2.0 * wie_n + ty, 2.0 * wie_u + tz
    ae = -(cy * mu - cz * mn)
    an = -(cz * me - cx * mu)
    au = -(cx * mn - cy * me) - g
    v[0] = ve + fx + ae * ts
    v[1] = vn + fy + an * ts
    v[2] = vu + fz + au * ts

    # Attitude: body rotation on the right, navigation-frame rotation on the left.
    aw, ax, ay, az = rv2q(dth[0], dth[1], dth[2])
    nw, nx, ny, nz = rv2q(-tx * ts, -(wie_n + ty) * ts, -(wie_u + tz) * ts)
    q0, q1, q2, q3 = qmul(q[0], q[1], q[2], q[3], aw, ax, ay, az)
    q0, q1, q2, q3 = qmul(nw, nx, ny, nz, q0, q1, q2, q3)
    nq = 1.0 / math.sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
    q[0], q[1], q[2], q[3] = q0 * nq, q1 * nq, q2 * nq, q3 * nq

    # Position by the trapezoid rule in velocity; radii at the mid-interval latitude.
    ue, un, uu = 0.5 * (ve + v[0]), 0.5 * (vn + v[1]), 0.5 * (vu + v[2])
    h_mid = h + 0.5 * uu * ts
    lat_mid = lat + 0.5 * un * ts / (r_m + h_mid)
    r_m, r_n, g, sl, cl = earth_at(lat_mid, h_mid)
    p[0] = lat + un * ts / (r_m + h_mid)
    p[1] = p[1] + ue * ts / ((r_n + h_mid) * cl)
    p[2] = h + uu * ts


@njit(cache=True)
def strapdown_block(q0, v0, p0, dtheta, dv, ts, earth_sign, q_out, v_out, p_out):
    """Integrate N increments from the state (q0, v0, p0); write N+1 states (row 0 = start).

    q_out (N+1, 4), v_out (N+1, 3), p_out (N+1, 3) are preallocated by the caller.
    """
    q = q0.copy()
    v = v0.copy()
    p = p0.copy()
    q_out[0], v_out[0], p_out[0] = q, v, p
    for k in range(dtheta.shape[0]):
        strapdown_step(q, v, p, dtheta[k], dv[k], ts, earth_sign)
        q_out[k + 1], v_out[k + 1], p_out[k + 1] = q, v, p


def empty_states(n: int):
    """Preallocated (q, v, p) outputs for n increments: (n+1, 4), (n+1, 3), (n+1, 3)."""
    return np.empty((n + 1, 4)), np.empty((n + 1, 3)), np.empty((n + 1, 3))
