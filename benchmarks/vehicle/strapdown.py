"""A plain strapdown in the earth frame, to check the simulator's increments: from the
truth at the first sample, integrate the ideal increments and compare with the truth.

Written for this check alone (ECEF, not the NED mechanisations of KF-GINS or gcalign), so
that agreement says the increments, the truth and the earth model fit together::

    C_eb(k) = Rz(−ω_ie Δt) C_eb(k−1) R(Δθ_k + Δθ_{k−1} × Δθ_k / 12)       (two-sample coning)
    Δv_b   = Δv_k + Δθ_k × Δv_k / 2 + Δθ_k × (Δθ_k × Δv_k) / 6
             + (Δθ_{k−1} × Δv_k + Δv_{k−1} × Δθ_k) / 12                    (rotation, sculling)
    v_e(k) = v_e(k−1) + (I − [ω_ie^e Δt ×] / 2) C_eb(k−1) Δv_b
             + (g_e(r_mid) − 2 ω_ie^e × v_mid) Δt
    r_e(k) = r_e(k−1) + (v_e(k−1) + v_e(k)) Δt / 2

with the mid-interval position and velocity from a predictor step. (The Δθ × (Δθ × Δv) / 6
term is the third-order part of the rotation of Δv in a turn: without it a 5 m/s turn of
radius 15 m leaves 3e-6 m/s behind.) Python floats in a loop, about 30 µs a sample.
"""

from __future__ import annotations

import math

import numpy as np

from benchmarks.vehicle import earth


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _rot(p):
    """Rotation matrix (row tuples) of rotation vector `p` (Rodrigues)."""
    a2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2]
    if a2 < 1e-16:
        s, c = 1.0 - a2 / 6.0, 0.5 - a2 / 24.0
    else:
        a = math.sqrt(a2)
        s, c = math.sin(a) / a, (1.0 - math.cos(a)) / a2
    x, y, z = p
    return ((1.0 - c * (y * y + z * z), -s * z + c * x * y, s * y + c * x * z),
            (s * z + c * x * y, 1.0 - c * (x * x + z * z), -s * x + c * y * z),
            (-s * y + c * x * z, s * x + c * y * z, 1.0 - c * (x * x + y * y)))


def _mm(A, B):
    return tuple(tuple(A[i][0] * B[0][j] + A[i][1] * B[1][j] + A[i][2] * B[2][j]
                       for j in range(3)) for i in range(3))


def _mv(A, v):
    return tuple(A[i][0] * v[0] + A[i][1] * v[1] + A[i][2] * v[2] for i in range(3))


def _gravity_e(r, lat):
    """Normal gravity in ECEF at `r` and the latitude there (a warm-started solve from
    `lat`: three fixed-point steps, 1e-15 rad near the ground)."""
    x, y, z = r
    p = math.hypot(x, y)
    for _ in range(3):
        r_n = earth.A / math.sqrt(1.0 - earth.E2 * math.sin(lat) ** 2)
        h = p / math.cos(lat) - r_n
        lat = math.atan2(z, p * (1.0 - earth.E2 * r_n / (r_n + h)))
    r_n = earth.A / math.sqrt(1.0 - earth.E2 * math.sin(lat) ** 2)
    h = p / math.cos(lat) - r_n
    s2 = math.sin(lat) ** 2  # earth.gravity, in floats
    g = (earth.GAMMA_E * (1.0 + earth.K_SOMIGLIANA * s2) / math.sqrt(1.0 - earth.E2 * s2)
         * (1.0 - 2.0 / earth.A * (1.0 + earth.F + earth.M_RATIO - 2.0 * earth.F * s2) * h
            + 3.0 * h * h / earth.A**2))
    cl, sl = math.cos(lat), math.sin(lat)
    co, so = x / p, y / p
    # the down axis in ECEF: −(cos L cos λ, cos L sin λ, sin L)
    return (-cl * co * g, -cl * so * g, -sl * g), lat


def navigate(C_eb0, v_e0, r_e0, dtheta, dv, dt):
    """ECEF attitude C_eb (N+1, 3, 3), velocity and position (N+1, 3) from the start
    (C_eb0, v_e0, r_e0) and increments (N, 3) at interval `dt` s."""
    n = len(dtheta)
    C_out = np.empty((n + 1, 3, 3))
    V_out = np.empty((n + 1, 3))
    R_out = np.empty((n + 1, 3))
    C_out[0], V_out[0], R_out[0] = C_eb0, v_e0, r_e0
    w = earth.OMEGA_IE
    ca, sa = math.cos(w * dt), math.sin(w * dt)
    Rz = ((ca, sa, 0.0), (-sa, ca, 0.0), (0.0, 0.0, 1.0))  # Rz(−ω_ie Δt)
    hw = 0.5 * dt * w
    th_all, dv_all = dtheta.tolist(), dv.tolist()
    th_prev, dv_prev = th_all[0], dv_all[0]  # the first step: as if the previous was the same
    c = tuple(tuple(row) for row in np.asarray(C_eb0).tolist())
    v = tuple(np.asarray(v_e0, float).tolist())
    r = tuple(np.asarray(r_e0, float).tolist())
    lat = math.atan2(r[2], math.hypot(r[0], r[1]))
    for k in range(n):
        th, dvk = th_all[k], dv_all[k]
        a1, a2 = _cross(th, dvk), _cross(th_prev, dvk)
        a3, a4 = _cross(dv_prev, th), _cross(th, _cross(th, dvk))
        scul = tuple(dvk[i] + 0.5 * a1[i] + a4[i] / 6.0 + (a2[i] + a3[i]) / 12.0
                     for i in range(3))
        u = _mv(c, scul)
        dv_e = (u[0] + hw * u[1], u[1] - hw * u[0], u[2])  # (I − [ω_ie Δt/2 ×]) u
        g0, lat = _gravity_e(r, lat)
        v_pred = tuple(v[i] + dv_e[i] + g0[i] * dt for i in range(3))
        v_pred = (v_pred[0] + 2 * w * v[1] * dt, v_pred[1] - 2 * w * v[0] * dt, v_pred[2])
        r_mid = tuple(r[i] + 0.25 * (v[i] + v_pred[i]) * dt for i in range(3))
        g_mid, lat = _gravity_e(r_mid, lat)
        vm = tuple(0.5 * (v[i] + v_pred[i]) for i in range(3))
        v_new = (v[0] + dv_e[0] + (g_mid[0] + 2 * w * vm[1]) * dt,
                 v[1] + dv_e[1] + (g_mid[1] - 2 * w * vm[0]) * dt,
                 v[2] + dv_e[2] + g_mid[2] * dt)
        r = tuple(r[i] + 0.5 * (v[i] + v_new[i]) * dt for i in range(3))
        v = v_new
        cone = _cross(th_prev, th)
        c = _mm(_mm(Rz, c), _rot(tuple(th[i] + cone[i] / 12.0 for i in range(3))))
        C_out[k + 1], V_out[k + 1], R_out[k + 1] = c, v, r
        th_prev, dv_prev = th, dvk
    return C_out, V_out, R_out
