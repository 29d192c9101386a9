"""The block kernels as they were before their state moved into local variables: the state
read from and written to an array at every step, and the stride tested at every step.

Kept as the reference of ``tests/test_kernels_bit_identical.py`` (the kernels of
:mod:`gcalign.nav._kernels` and :mod:`gcalign.align.kernel` must give the same bits) and as
the "state in an array" contender of ``benchmarks/bench_core.py``. (Compiled once
per checkout, cached as the kernels are).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from gcalign.align.kernel import ATTITUDE, COMPASS, LEVEL
from gcalign.nav._kernels import (
    CONE,
    DA,
    DAMPED,
    HOLD,
    attitude_update,
    earth_at,
    position_update,
    qrot,
    specific_force_increment,
    transport_rate,
)
from gcalign.nav.earth import WGS84


@njit(cache=True, inline="always")
def strapdown_step(s, dth, dvb, ts, earth_sign, E, vertical, h_ref):
    """One strapdown update of the state vector `s` in place (see the module docstring).

    Velocity:  v_k = v_{k-1} + R(-ω_in T/2) C_nb(k-1) R(Δθ/2) Δv + (g_n - (2ω_ie + ω_en) × v_mid) T
               (the specific-force increment resolved at mid-interval; Coriolis at a
               predicted mid-interval velocity, gravity at the height it gives)
    Attitude:  q_k = q(-ω_in T) ⊗ q_{k-1} ⊗ q(Δθ_k),  ω_in = ω_ie + ω_en(v_mid)
    Position:  trapezoid in velocity, radii at the mid-interval latitude.
    Vertical:  HOLD: h = h_ref, v_U = 0; DAMPED: v_U −= (k2 δh + a) T, h −= k1 δh T,
               a += k3 δh T with δh = h − h_ref at the start of the step.
    """
    lat, lon, h = s[7], s[8], s[9]
    r_m, r_n, g, sl, cl = earth_at(E, lat, h)
    wie = earth_sign * E[3]
    wie_n, wie_u = wie * cl, wie * sl
    ve, vn, vu = s[4], s[5], s[6]
    mode = vertical[0]

    inv_m, inv_n = 1.0 / (r_m + h), 1.0 / (r_n + h)  # the transport rate, twice below
    tan_l = sl / cl
    tx, ty, tz = -vn * inv_m, ve * inv_n, ve * tan_l * inv_n
    fx, fy, fz = specific_force_increment(
        s[0], s[1], s[2], s[3], dth[0], dth[1], dth[2], dvb[0], dvb[1], dvb[2],
        tx * ts, (wie_n + ty) * ts, (wie_u + tz) * ts,
    )

    # Predict the mid-interval velocity, then Coriolis/transport and gravity there.
    me = ve + 0.5 * fx
    mn = vn + 0.5 * fy
    mu = 0.0 if mode == HOLD else vu + 0.5 * (fz - g * ts)
    tx, ty, tz = -mn * inv_m, me * inv_n, me * tan_l * inv_n
    cx, cy, cz = tx, 2.0 * wie_n + ty, 2.0 * wie_u + tz
    ve1 = ve + fx - (cy * mu - cz * mn) * ts
    vn1 = vn + fy - (cz * me - cx * mu) * ts
    # gravity at the mid-interval height (g is linear in h): at the start height a climb
    # at v_U would leave a bias of ½ g3 v_U T in the vertical velocity
    vu1 = vu + fz - ((cx * mn - cy * me) + g - E[7] * 0.5 * mu * ts) * ts

    s[0], s[1], s[2], s[3] = attitude_update(
        s[0], s[1], s[2], s[3], dth[0], dth[1], dth[2], tx * ts, (wie_n + ty) * ts,
        (wie_u + tz) * ts,
    )

    dh = h - h_ref
    if mode == HOLD:
        vu, vu1 = 0.0, 0.0
    elif mode == DAMPED:
        vu1 -= (vertical[2] * dh + s[DA]) * ts
        s[DA] += vertical[3] * dh * ts
    lat1, lon1, h1 = position_update(
        E, lat, lon, h, 0.5 * (ve + ve1), 0.5 * (vn + vn1), 0.5 * (vu + vu1), ts, r_m, sl, cl
    )
    if mode == HOLD:
        h1 = h_ref
    elif mode == DAMPED:
        h1 -= vertical[1] * dh * ts
    s[4], s[5], s[6] = ve1, vn1, vu1
    s[7], s[8], s[9] = lat1, lon1, h1


@njit(cache=True)
def strapdown_block(s, dtheta, dv, ts, earth_sign, E, vertical, h_ref, stride, out):
    """Integrate N increments from the state `s` (updated in place); after every `stride`
    steps write the state into the next row of `out` ((N // stride, NAV_STATE)).

    h_ref : (N,) reference height at the start of each step, or (1,) for a constant one.
    """
    nref = h_ref.shape[0]
    row = 0
    for k in range(dtheta.shape[0]):
        strapdown_step(s, dtheta[k], dv[k], ts, earth_sign, E, vertical,
                       h_ref[k if k < nref else nref - 1])
        if (k + 1) % stride == 0:
            out[row, :] = s
            row += 1


@njit(cache=True)
def attitude_block(q, dtheta, ts, w_in, subsamples, stride, out):
    """Attitude-only strapdown over N increments in groups of `subsamples` (N a multiple):
    each group is one update over ``subsamples·ts`` with the coning-corrected rotation
    vector ``φ = Σθ_i + (Σ_{i<n} c_i θ_i) × θ_n`` (:data:`CONE`), and
    ``q ← q(−ω_in T) ⊗ q ⊗ q(φ)`` with the constant navigation-frame rate `w_in` (3,) (rad/s;
    zeros integrates the gyros alone). `q` (4,) is updated in place; after every `stride`
    updates it is written into the next row of `out` ((N // subsamples // stride, 4)).
    """
    n = subsamples
    T = n * ts
    wx, wy, wz = w_in[0] * T, w_in[1] * T, w_in[2] * T
    row = 0
    for k in range(dtheta.shape[0] // n):
        i0 = k * n
        sx = sy = sz = 0.0
        cxs = cys = czs = 0.0
        for i in range(n):
            sx += dtheta[i0 + i, 0]
            sy += dtheta[i0 + i, 1]
            sz += dtheta[i0 + i, 2]
            if i < n - 1:
                c = CONE[n, i]
                cxs += c * dtheta[i0 + i, 0]
                cys += c * dtheta[i0 + i, 1]
                czs += c * dtheta[i0 + i, 2]
        lx, ly, lz = dtheta[i0 + n - 1, 0], dtheta[i0 + n - 1, 1], dtheta[i0 + n - 1, 2]
        px = sx + cys * lz - czs * ly
        py = sy + czs * lx - cxs * lz
        pz = sz + cxs * ly - cys * lx
        q[0], q[1], q[2], q[3] = attitude_update(q[0], q[1], q[2], q[3], px, py, pz,
                                                 wx, wy, wz)
        if (k + 1) % stride == 0:
            out[row, 0], out[row, 1], out[row, 2], out[row, 3] = q[0], q[1], q[2], q[3]
            row += 1


@njit(cache=True)
def gyrocompass_block(state, dtheta, dv, vref, vref_body, ts, earth_sign, E, gains, mode,
                      q_out):
    """Run the loops over N increments, updating `state` (12,) in place.

    dtheta, dv : (N, 3) body increments (rad, m/s), in processing order.
    vref : (N+1, 3) reference velocity at the start (row 0) and at the end of each step
        (m/s); ENU, or body frame (odometer) if `vref_body`, then resolved with the
        computed attitude.
    E : earth model vector (:meth:`gcalign.nav.earth.EarthModel.params`).
    gains : (10,) loop gains; mode : ATTITUDE, LEVEL or COMPASS.
    q_out : (N+1, 4) attitude after each step, row 0 = start (preallocated).
    """
    ke1, ke2, ke3 = gains[0], gains[1], gains[2]
    kn1, kn2, kn3 = gains[3], gains[4], gains[5]
    ku1, ku2, ku3, ku4 = gains[6], gains[7], gains[8], gains[9]
    q0, q1, q2, q3 = state[0], state[1], state[2], state[3]
    ve, vn = state[4], state[5]
    ie, inn = state[6], state[7]
    wcu = state[8]
    lat, lon, h = state[9], state[10], state[11]
    q_out[0, 0], q_out[0, 1], q_out[0, 2], q_out[0, 3] = q0, q1, q2, q3
    # Reference velocity at the start of the first step.
    re, rn, ru = vref[0, 0], vref[0, 1], vref[0, 2]
    if vref_body:
        re, rn, ru = qrot(q0, q1, q2, q3, re, rn, ru)
    wce = wcn = 0.0
    r_m, r_n, g, sl, cl = earth_at(E, lat, h)
    if mode != ATTITUDE:
        # Control rates of the incoming state.
        dve, dvn = ve - re, vn - rn
        wcn = dve * (1.0 + ke2) / (r_n + h) + ke3 * ie
        if mode == LEVEL:
            wce = -dvn * (1.0 + kn2) / (r_m + h) - kn3 * inn
        else:
            wce = -dvn * (1.0 + ku2) / (r_m + h)
    for k in range(dtheta.shape[0]):
        r_m, r_n, g, sl, cl = earth_at(E, lat, h)
        rmh, rnh = r_m + h, r_n + h  # radii at the start of the step
        wie = earth_sign * E[3]
        wie_n, wie_u = wie * cl, wie * sl
        te, tn, tu = transport_rate(re, rn, r_m, r_n, h, sl, cl)
        cu = wcu if mode == COMPASS else 0.0
        wx = (te + wce) * ts
        wy = (wie_n + tn + wcn) * ts
        wz = (wie_u + tu + cu) * ts

        # Specific-force increment at mid-interval, and the attitude update with the
        # platform rate including the control rates: the pieces of the strapdown step.
        fx, fy, fz = specific_force_increment(
            q0, q1, q2, q3, dtheta[k, 0], dtheta[k, 1], dtheta[k, 2], dv[k, 0], dv[k, 1],
            dv[k, 2], wx, wy, wz,
        )
        q0, q1, q2, q3 = attitude_update(
            q0, q1, q2, q3, dtheta[k, 0], dtheta[k, 1], dtheta[k, 2], wx, wy, wz
        )

        # Reference velocity at the end of the step, and position along it.
        ne, nn, nu = vref[k + 1, 0], vref[k + 1, 1], vref[k + 1, 2]
        if vref_body:
            ne, nn, nu = qrot(q0, q1, q2, q3, ne, nn, nu)
        lat_new, lon, h_new = position_update(
            E, lat, lon, h, 0.5 * (re + ne), 0.5 * (rn + nn), 0.5 * (ru + nu), ts, r_m, sl, cl
        )

        if mode != ATTITUDE:
            # Coriolis and frame-rate acceleration of the reference velocity (seed §1). With
            # an odometer the reference is resolved with the computed attitude, so it turns
            # with every azimuth correction; the loop velocity must turn with the computed
            # frame too (ω_c in the frame rate), or the compass loop sees a false
            # δv_N = v_E Δφ_U that detunes it. An ENU (nav) reference does not turn.
            # Evaluated at the mid-step reference velocity, as the strapdown step does.
            cc = 1.0 if vref_body else 0.0
            ce, cn, cu2 = te + cc * wce, 2.0 * wie_n + tn + cc * wcn, 2.0 * wie_u + tu + cc * cu
            me, mn, mu = 0.5 * (re + ne), 0.5 * (rn + nn), 0.5 * (ru + nu)
            ae = -(cn * mu - cu2 * mn)
            an = -(cu2 * me - ce * mu)
            k1e = ke1
            k1n = kn1 if mode == LEVEL else ku1
            ve = ve + fx + ae * ts - k1e * (ve - re) * ts
            vn = vn + fy + an * ts - k1n * (vn - rn) * ts
            dve, dvn = ve - ne, vn - nn
            ie += dve * ts
            wcn = dve * (1.0 + ke2) / rnh + ke3 * ie
            if mode == LEVEL:
                inn += dvn * ts
                wce = -dvn * (1.0 + kn2) / rmh - kn3 * inn
            else:
                omega = wie_n  # Ω = ω_ie cos L, signed with the pass direction
                wcu = (wcu + ku3 * dvn * ts / omega) / (1.0 + ku4 * ts)
                wce = -dvn * (1.0 + ku2) / rmh
        else:
            ve, vn = ne, nn
        lat, h = lat_new, h_new
        re, rn, ru = ne, nn, nu
        q_out[k + 1, 0], q_out[k + 1, 1], q_out[k + 1, 2], q_out[k + 1, 3] = q0, q1, q2, q3

    state[0], state[1], state[2], state[3] = q0, q1, q2, q3
    state[4], state[5], state[6], state[7], state[8] = ve, vn, ie, inn, wcu
    state[9], state[10], state[11] = lat, lon, h


# The passes' driver as it was: reverse passes on reversed and negated copies, the attitude
# at every step into chunks of CHUNK rows, the stored rows picked out afterwards.

def run_block(state, block, lo: int, hi: int, reverse: bool, gains, mode, q_out,
              earth=WGS84) -> None:
    """Kernel over increments lo..hi-1 of the block (forward) or hi-1..lo (reverse)."""
    dth, dv, vref = block.dtheta[lo:hi], block.dv[lo:hi], block.vref[lo : hi + 1]
    sign = 1.0
    if reverse:
        dth, dv, vref, sign = -dth[::-1], dv[::-1], -vref[::-1], -1.0
    gyrocompass_block(state, np.ascontiguousarray(dth), np.ascontiguousarray(dv),
                      np.ascontiguousarray(vref), block.vref_body, block.ts, sign,
                      earth.params(), gains, mode, q_out)


CHUNK = 1 << 16  #: steps per kernel call of a pass (bounds the full-rate attitude buffer)


def run_stored(state, block, lo: int, hi: int, reverse: bool, gains, mode,
               stride: int, earth=WGS84):
    """:func:`run_block` in chunks, keeping the attitude at the block samples that are
    multiples of `stride` from the block's start, and at both ends of the range.

    Returns (block sample indices in processing order, q_nb there (m, 4)).
    """
    idx, qs = [], []
    order = range(hi, lo, -CHUNK) if reverse else range(lo, hi, CHUNK)
    first = True
    for a in order:
        c_lo, c_hi = (max(a - CHUNK, lo), a) if reverse else (a, min(a + CHUNK, hi))
        q = np.empty((c_hi - c_lo + 1, 4))
        run_block(state, block, c_lo, c_hi, reverse, gains, mode, q, earth)
        samples = np.arange(c_hi, c_lo - 1, -1) if reverse else np.arange(c_lo, c_hi + 1)
        keep = samples % stride == 0
        keep[-1] = True  # the end of the chunk: the next chunk's start, or the range's end
        keep[0] = first  # a chunk's start is the previous chunk's end
        first = False
        idx.append(samples[keep])
        qs.append(q[keep])
    if not idx:  # an empty range: the state as it is
        return np.array([hi if reverse else lo]), state[0:4][None].copy()
    return np.concatenate(idx), np.concatenate(qs)


def run_passes(state0, block, mode: str, passes: int, stages, azimuth_poles: str,
               level_s: float, earth=WGS84, stride: int = 1):
    """The passes as they were: each range through :func:`run_stored`, the level phase and
    the compass part of the first pass concatenated, the times picked from an array of the
    block's sample times."""
    from gcalign.align import kernel as K
    from gcalign.align.cycles import PassRecord, loop_gains, pass_plan
    from gcalign.align.stages import stage_of_passes

    state = state0.copy()
    n = len(block.dtheta)
    stage_idx = stage_of_passes(stages, passes)
    lat, h = state[K.POS][0], state[K.POS][2]
    gains_by_stage = [loop_gains(st, lat, h, azimuth_poles, earth) for st in stages]
    records = []
    direction_prev = "forward"
    t_all = block.t
    for i, (direction, kind) in enumerate(pass_plan(mode, passes)):
        reverse = direction == "reverse"
        if direction != direction_prev:
            state[K.FLIP] *= -1.0
        direction_prev = direction
        gains = gains_by_stage[stage_idx[i]]
        if kind == "attitude":
            idx, q = run_stored(state, block, 0, n, reverse, gains, K.ATTITUDE, stride, earth)
        elif i == 0 and level_s > 0:
            n_level = min(int(round(level_s / block.ts)), n)
            i_a, q_a = run_stored(state, block, 0, n_level, False, gains, K.LEVEL, stride, earth)
            i_b, q_b = run_stored(state, block, n_level, n, False, gains, K.COMPASS, stride,
                                  earth)
            idx, q = np.concatenate([i_a, i_b[1:]]), np.concatenate([q_a, q_b[1:]])
        else:
            idx, q = run_stored(state, block, 0, n, reverse, gains, K.COMPASS, stride, earth)
        records.append(PassRecord(i, direction, kind, stage_idx[i], gains, t_all[idx], q,
                                  block.first + idx))
    if direction_prev == "reverse":
        state[K.FLIP] *= -1.0
    return state, records

