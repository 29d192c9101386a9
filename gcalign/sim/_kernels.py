"""Numba kernels of the simulation: rotation schedules and the ideal increments of a base at a
fixed site (static or on a turntable), with or without a mechanism turning the IMU.

The vectorised NumPy route (:func:`gcalign.sim.ideal.ideal_blocks`) serves every motion; this
one serves the long runs (72 h on a mechanism, 5 kHz turntables) where a NumPy temporary per
operation costs more than the arithmetic. ``tests/test_ideal.py`` holds the two equal.

A schedule enters as the tuple :meth:`gcalign.sim.schedule.Schedule.kernel_tables`:
``(t0, kind, coef, step, theta0, axis, before, cycle_rotvec, q0, period, repeat)``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit
from numpy.typing import NDArray

from gcalign.nav._kernels import qmul, qrot, rv2q

Array = NDArray[np.float64]
Index = NDArray[np.int64]
Quat = tuple[float, float, float, float]


@njit(cache=True, inline="always")
def schedule_quat(t0: Array, kind: Index, coef: Array, step: Index, theta0: Array, axis: Array,
                  before: Array, cyc: Array, q0: Array, period: float, repeat: bool, t: float,
                  memo: Array) -> Quat:
    """Quaternion of the schedule's rotation at time t (see :class:`Schedule`); the
    arguments before t are :meth:`Schedule.kernel_tables` (passed one by one: a tuple of
    arrays handed to an inlined function costs a reference count per array and call).

    `memo` (7,) = [piece, cycle, q, last piece] remembers the last rest piece (zero
    coefficients): a dwell, most of a modulation cycle, costs a comparison instead of a
    rotation; times that move forward find their piece from the last one.
    """
    if repeat:
        k: float = math.floor(t / period)
        tau = t - k * period
    else:
        k = 0.0
        tau = min(max(t, 0.0), period)
    last = t0.shape[0] - 1
    j = int(memo[6])
    if not (0 <= j <= last and t0[j] <= tau and (j == last or tau < t0[j + 1])):
        lo, hi = 0, last
        while lo < hi:  # last piece with t0 <= tau
            mid = (lo + hi + 1) // 2
            if t0[mid] <= tau:
                lo = mid
            else:
                hi = mid - 1
        j = lo
        memo[6] = j
    if memo[0] == j and memo[1] == k:
        return memo[2], memo[3], memo[4], memo[5]
    x = tau - t0[j]
    c0, c1, c2 = coef[j, 0], coef[j, 1], coef[j, 2]
    if kind[j] == 1:
        th = theta0[j] + c0 * (math.sin(c1 * x + c2) - math.sin(c2))
    else:
        th = theta0[j] + c0 * x + 0.5 * c1 * x * x + c2 * x * x * x / 6.0
    s = step[j]
    aw, ax, ay, az = rv2q(axis[s, 0] * th, axis[s, 1] * th, axis[s, 2] * th)
    bw, bx, by, bz = qmul(before[s, 0], before[s, 1], before[s, 2], before[s, 3],
                          aw, ax, ay, az)
    if repeat and k != 0.0:
        cw, cx, cy, cz = rv2q(k * cyc[0], k * cyc[1], k * cyc[2])
        bw, bx, by, bz = qmul(cw, cx, cy, cz, bw, bx, by, bz)
    rw, rx, ry, rz = qmul(q0[0], q0[1], q0[2], q0[3], bw, bx, by, bz)
    if kind[j] == 0 and c0 == 0.0 and c1 == 0.0 and c2 == 0.0:
        memo[0], memo[1], memo[2], memo[3], memo[4], memo[5] = j, k, rw, rx, ry, rz
    else:
        memo[0] = -1.0
    return rw, rx, ry, rz


@njit(cache=True, inline="always")
def rest_end(t0: Array, period: float, repeat: bool, memo: Array) -> float:
    """The time the rest piece remembered in `memo` (by :func:`schedule_quat`) ends; −∞ if
    the last time looked up was not in a rest piece."""
    if memo[0] < 0.0:
        return -math.inf
    j = int(memo[0])
    if j < t0.shape[0] - 1:
        end = t0[j + 1]
    elif repeat:
        end = period
    else:
        return math.inf  # the schedule is over and rests for ever
    return end + memo[1] * period if repeat else end


@njit(cache=True)
def fixed_site_block(k0: int, n: int, ts: float, m: int, omega_ie: float, q_en: Array,
                     f_n: Array, q_nb0: Array, body: tuple[Any, ...], has_body: bool,
                     mech: tuple[Any, ...], has_mech: bool, mech_nav: bool, dtheta: Array,
                     dv: Array, q_nb_out: Array, q_bs_out: Array) -> None:
    """Ideal increments k0 .. k0+n-1 of a base at a fixed site whose body attitude is q_nb0
    (times the schedule `body` if `has_body`), the IMU turned by `mech` (body- or, with
    `mech_nav`, navigation-referenced) if `has_mech`.

    Gyro: rotvec(q_is(k-1)* q_is(k)), q_is = q_ie(t - t_block) ⊗ q_en ⊗ q_ns.
    Accelerometer: Simpson over `m` (even) sub-intervals of f_s = C_sn f_n (f_n constant).
    Writes dtheta, dv (n, 3), and at each end time q_nb (n, 4) and q_bs = q_nb* ⊗ q_ns.
    """
    h = ts / m
    t_ref = k0 * ts
    memo = np.full((2, 7), -1.0)
    b0, b1, b2, b3, b4, b5, b6, b7, b8, b9, b10 = body
    m0, m1, m2, m3, m4, m5, m6, m7, m8, m9, m10 = mech
    pw = px = py = pz = 0.0  # q_is at the start of the sample
    gx = gy = gz = 0.0  # f_s at the start of the sample
    lw = lx = ly = lz = 0.0  # q_ns at the end of the last sample computed
    rest_dtheta = np.zeros(3)  # the increment at rest (sensor frame)
    inside_before = False  # the previous sample lay inside one rest piece of every schedule
    stale = False  # q_is at the start of the sample not yet known (copied samples before)
    # the end of the rest piece each schedule is in at the last computed sample's end
    body_rest_until = math.inf if not has_body else -math.inf
    mech_rest_until = math.inf if not has_mech else -math.inf
    for i in range(n):
        k = k0 + i
        # Inside one rest piece (of the body's and of the mechanism's schedule) from the
        # sample's start to its end, the sensor attitude is constant and so are the
        # increments: from the second such sample on, Δv and the attitudes are copied and
        # Δθ is the earth rate over ts.
        t_end = (k + 1) * ts
        inside = i > 0 and t_end < body_rest_until and t_end < mech_rest_until
        if inside and inside_before:
            # Δθ = C_sn ω_ie^n ts in closed form: copying a difference of attitudes would
            # repeat its round-off (~1e-16 rad) coherently instead of letting it telescope
            for c in range(3):
                dtheta[i, c] = rest_dtheta[c]
                dv[i, c] = dv[i - 1, c]
            for c in range(4):
                q_nb_out[i, c] = q_nb_out[i - 1, c]
                q_bs_out[i, c] = q_bs_out[i - 1, c]
            stale = True
            continue
        if inside and not inside_before:  # the first sample of a rest: the earth rate
            ux, uy, uz = qrot(q_en[0], -q_en[1], -q_en[2], -q_en[3], 0.0, 0.0, omega_ie * ts)
            rest_dtheta[0], rest_dtheta[1], rest_dtheta[2] = qrot(lw, -lx, -ly, -lz,
                                                                  ux, uy, uz)
        inside_before = inside
        if stale:  # q_is at the start: the earth turned under a constant sensor attitude
            half = 0.5 * omega_ie * (k * ts - t_ref)
            uw, ux, uy, uz = qmul(math.cos(half), 0.0, 0.0, math.sin(half),
                                  q_en[0], q_en[1], q_en[2], q_en[3])
            pw, px, py, pz = qmul(uw, ux, uy, uz, lw, lx, ly, lz)
            stale = False
        j0 = 0 if i == 0 else 1  # a sample starts where the previous one ended
        ax, ay, az = gx, gy, gz
        for j in range(j0, m + 1):
            t = (k * m + j) * h
            # body attitude (a turntable turns it) and sensor attitude (a mechanism)
            bw, bx, by, bz = q_nb0[0], q_nb0[1], q_nb0[2], q_nb0[3]
            if has_body:
                uw, ux, uy, uz = schedule_quat(b0, b1, b2, b3, b4, b5, b6, b7, b8, b9, b10, t,
                                               memo[0])
                bw, bx, by, bz = qmul(bw, bx, by, bz, uw, ux, uy, uz)
            sw, sx, sy, sz = bw, bx, by, bz
            if has_mech:
                uw, ux, uy, uz = schedule_quat(m0, m1, m2, m3, m4, m5, m6, m7, m8, m9, m10, t,
                                               memo[1])
                if mech_nav:
                    sw, sx, sy, sz = uw, ux, uy, uz
                else:
                    sw, sx, sy, sz = qmul(bw, bx, by, bz, uw, ux, uy, uz)
            fx, fy, fz = qrot(sw, -sx, -sy, -sz, f_n[0], f_n[1], f_n[2])
            wgt = 1.0 if (j == 0 or j == m) else (4.0 if j % 2 == 1 else 2.0)
            ax += wgt * fx
            ay += wgt * fy
            az += wgt * fz
            if j == 0 or j == m:
                half = 0.5 * omega_ie * (t - t_ref)
                ew, ez = math.cos(half), math.sin(half)
                # q_is = q_ie ⊗ q_en ⊗ q_ns (q_ie about z)
                uw, ux, uy, uz = qmul(ew, 0.0, 0.0, ez, q_en[0], q_en[1], q_en[2], q_en[3])
                cw, cx, cy, cz = qmul(uw, ux, uy, uz, sw, sx, sy, sz)
                if j == m:
                    # Δθ = rotvec(conj(q_is(start)) ⊗ q_is(end))
                    dw, dx, dy, dz = qmul(pw, -px, -py, -pz, cw, cx, cy, cz)
                    if dw < 0.0:
                        dw, dx, dy, dz = -dw, -dx, -dy, -dz
                    nrm = math.sqrt(dx * dx + dy * dy + dz * dz)
                    r = 2.0 * math.atan2(nrm, dw) / nrm if nrm > 1e-12 else 2.0 / dw
                    dtheta[i, 0], dtheta[i, 1], dtheta[i, 2] = dx * r, dy * r, dz * r
                    q_nb_out[i, 0], q_nb_out[i, 1] = bw, bx
                    q_nb_out[i, 2], q_nb_out[i, 3] = by, bz
                    qw, qx, qy, qz = qmul(bw, -bx, -by, -bz, sw, sx, sy, sz)
                    q_bs_out[i, 0], q_bs_out[i, 1] = qw, qx
                    q_bs_out[i, 2], q_bs_out[i, 3] = qy, qz
                    gx, gy, gz = fx, fy, fz
                    lw, lx, ly, lz = sw, sx, sy, sz
                    if has_body:
                        body_rest_until = rest_end(b0, b9, b10, memo[0])
                    if has_mech:
                        mech_rest_until = rest_end(m0, m9, m10, memo[1])
                pw, px, py, pz = cw, cx, cy, cz
        third = h / 3.0
        dv[i, 0], dv[i, 1], dv[i, 2] = ax * third, ay * third, az * third
