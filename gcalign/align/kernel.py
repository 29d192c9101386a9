"""Numba kernel of the strapdown gyrocompass (seed 000 eqs. 1-4, discrete form eqs. 11-13).

The loop state is one float64 vector so that passes can hand it on (indices below)::

    q_nb (0:4) | v_E, v_N (4:6) | ∫δv_E, ∫δv_N (6:8) | ω_cU (8) | lat, lon, h (9:12)

Per step (data transformed for a reverse pass: gyro negated, velocity negated,
``earth_sign = -1``, so Ω = earth_sign·ω_ie·cos L changes sign with the data; the kernel
reads the stored block backwards and applies the signs as it reads):

- attitude ``q ← q(−ω_in T) ⊗ q ⊗ q(Δθ)`` with ``ω_in = ω_ie + ω_en(v_R) + ω_c``;
- position along v_R by the trapezoid rule, radii at mid-interval (the strapdown step's);
- horizontal velocity ``v ← v + C_nb Δv − ((2ω_ie + ω_en [+ ω_c]) × v_R,mid) T − K1 δv T``
  (eqs. 11-13; the Coriolis and frame-rate terms are those of the reference velocity v_R;
  ω_c is included for an odometer reference, which is resolved with the computed attitude
  and so turns with the computed frame);
- control rates from ``δv = v − v_R``:
  east level   ``ω_cN = δv_E (1 + K_E2)/(R_N + h) + K_E3 ∫δv_E dt``      (eq. 1)
  north level  ``ω_cE = −δv_N (1 + K_N2)/(R_M + h) − K_N3 ∫δv_N dt``     (eq. 2, level mode)
  compass      ``ω_cE = −δv_N (1 + K_U2)/(R_M + h)``,
               ``ω_cU ← (ω_cU + K_U3 δv_N T/Ω)/(1 + K_U4 T)``              (eqs. 3-4, 13)

Modes: ``ATTITUDE`` (no loops: the attitude-only strapdown of a half-cycle reverse pass and
of the T2→T3 update), ``LEVEL`` (both level loops, azimuth free) and ``COMPASS``.

One step (:func:`_loop_step`) serves :func:`gyrocompass_range` (one run) and
:func:`gyrocompass_range_lanes` (:data:`LANES` runs side by side, vectorised over the runs:
the seeds of a Monte Carlo variant); ``tests/test_align_lockstep.py`` holds the two to the
bit and ``tests/test_kernels_bit_identical.py`` the single kernel to its previous form.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from gcalign.nav._kernels import (
    EarthParams,
    attitude_update,
    earth_at,
    earth_sc,
    euler_of,
    position_update,
    qrot,
    specific_force_increment,
    transport_rate,
    wrap_pi,
)

ATTITUDE, LEVEL, COMPASS = 0, 1, 2
STATE_SIZE = 12
ATT = slice(0, 4)  #: q_nb
VEL = slice(4, 6)  #: v_E, v_N (m/s)
INTEGRALS = slice(6, 8)  #: ∫δv_E, ∫δv_N (m)
WCU = 8  #: ω_cU (rad/s)
POS = slice(9, 12)  #: lat, lon (rad), h (m)
# Loop states that are velocities or rates: they change sign with the data at a change
# of pass direction (DESIGN.md); the attitude and the position are kept.
FLIP = slice(4, 9)
# Gains vector: K_E1, K_E2, K_E3, K_N1, K_N2, K_N3, K_U1, K_U2, K_U3, K_U4.
GAINS_SIZE = 10


#: The loop's carried values, in local variables (registers) from step to step: the 12
#: floats of the state vector in its order, then the reference velocity at the start of
#: the step (v_R,E, v_R,N, v_R,U) and the control rates ω_cE, ω_cN.
LoopTuple = tuple[float, float, float, float, float, float, float, float, float, float, float,
                  float, float, float, float, float, float]
CARRIED = STATE_SIZE + 5  #: floats of a LoopTuple
Gains = tuple[float, float, float, float, float, float, float, float, float, float]


@njit(cache=True, inline="always")
def _gains(g: np.ndarray) -> Gains:
    """The gains vector as locals (loaded once, not at every step)."""
    return g[0], g[1], g[2], g[3], g[4], g[5], g[6], g[7], g[8], g[9]


@njit(cache=True, inline="always")
def _loop_start(q0: float, q1: float, q2: float, q3: float, ve: float, vn: float, ie: float,
                inn: float, wcu: float, lat: float, lon: float, h: float, re: float, rn: float,
                ru: float, vref_body: bool, E: EarthParams, gk: Gains,
                mode: int) -> LoopTuple:
    """The carried values at the start of a range: the state, the reference velocity at its
    first sample (signed, not yet resolved) and the control rates of the incoming state."""
    if vref_body:
        re, rn, ru = qrot(q0, q1, q2, q3, re, rn, ru)
    wce = wcn = 0.0
    r_m, r_n, g, sl, cl = earth_at(E, lat, h)
    if mode != ATTITUDE:
        # Control rates of the incoming state.
        dve, dvn = ve - re, vn - rn
        wcn = dve * (1.0 + gk[1]) / (r_n + h) + gk[2] * ie
        if mode == LEVEL:
            wce = -dvn * (1.0 + gk[4]) / (r_m + h) - gk[5] * inn
        else:
            wce = -dvn * (1.0 + gk[7]) / (r_m + h)
    return q0, q1, q2, q3, ve, vn, ie, inn, wcu, lat, lon, h, re, rn, ru, wce, wcn


@njit(cache=True, inline="always")
def _loop_step(x: LoopTuple, bx: float, by: float, bz: float, dx: float, dy: float, dz: float,
               ne: float, nn: float, nu: float, vref_body: bool, ts: float, earth_sign: float,
               E: EarthParams, gk: Gains, mode: int) -> LoopTuple:
    """One step of the loops: increments Δθ = (bx, by, bz), Δv = (dx, dy, dz) (signed for the
    pass direction), reference velocity (ne, nn, nu) at the end of the step (signed, not yet
    resolved); returns the carried values after it (see the module docstring)."""
    lat = x[9]
    return _loop_step_sc(x, math.sin(lat), math.cos(lat), bx, by, bz, dx, dy, dz, ne, nn, nu,
                         vref_body, ts, earth_sign, E, gk, mode != ATTITUDE, mode == LEVEL,
                         mode == COMPASS, False)[0]


@njit(cache=True, inline="always")
def _loop_step_sc(x: LoopTuple, sl: float, cl: float, bx: float, by: float, bz: float,
                  dx: float, dy: float, dz: float, ne: float, nn: float, nu: float,
                  vref_body: bool, ts: float, earth_sign: float, E: EarthParams, gk: Gains,
                  loops: bool, level: bool, compass: bool,
                  series: bool) -> tuple[LoopTuple, float]:
    """:func:`_loop_step` given sin L and cos L of the latitude at the start of the step and
    the mode as three flags (loops: not ATTITUDE; LEVEL; COMPASS: independent values, which
    a compiler cannot fold into a multi-way branch that its vectoriser refuses); also
    returns the larger squared angle of the step's two rotation vectors (`series`: their
    quaternions by the series whatever the angle, right below 2.5e-3 rad²)."""
    q0, q1, q2, q3, ve, vn, ie, inn, wcu, lat, lon, h, re, rn, ru, wce, wcn = x
    r_m, r_n, g, sl, cl = earth_sc(E, sl, cl, h)
    rmh, rnh = r_m + h, r_n + h  # radii at the start of the step
    wie = earth_sign * E[3]
    wie_n, wie_u = wie * cl, wie * sl
    te, tn, tu = transport_rate(re, rn, r_m, r_n, h, sl, cl)
    cu = wcu if compass else 0.0
    wx = (te + wce) * ts
    wy = (wie_n + tn + wcn) * ts
    wz = (wie_u + tu + cu) * ts

    # Specific-force increment at mid-interval, and the attitude update with the
    # platform rate including the control rates: the pieces of the strapdown step.
    fx, fy, fz = specific_force_increment(q0, q1, q2, q3, bx, by, bz, dx, dy, dz, wx, wy, wz)
    q0, q1, q2, q3 = attitude_update(q0, q1, q2, q3, bx, by, bz, wx, wy, wz, series)
    angle2 = max(bx * bx + by * by + bz * bz, wx * wx + wy * wy + wz * wz)

    # Reference velocity at the end of the step, and position along it.
    if vref_body:
        ne, nn, nu = qrot(q0, q1, q2, q3, ne, nn, nu)
    lat_new, lon, h_new = position_update(
        E, lat, lon, h, 0.5 * (re + ne), 0.5 * (rn + nn), 0.5 * (ru + nu), ts, r_m, sl, cl
    )

    if loops:
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
        k1e = gk[0]
        k1n = gk[3] if level else gk[6]
        ve = ve + fx + ae * ts - k1e * (ve - re) * ts
        vn = vn + fy + an * ts - k1n * (vn - rn) * ts
        dve, dvn = ve - ne, vn - nn
        ie += dve * ts
        wcn = dve * (1.0 + gk[1]) / rnh + gk[2] * ie  # eq. 1
        if level:
            inn += dvn * ts
            wce = -dvn * (1.0 + gk[4]) / rmh - gk[5] * inn  # eq. 2
        else:
            omega = wie_n  # Ω = ω_ie cos L, signed with the pass direction
            wcu = (wcu + gk[8] * dvn * ts / omega) / (1.0 + gk[9] * ts)  # eqs. 4, 13
            wce = -dvn * (1.0 + gk[7]) / rmh  # eq. 3
    else:
        ve, vn = ne, nn
    return (q0, q1, q2, q3, ve, vn, ie, inn, wcu, lat_new, lon, h_new, ne, nn, nu, wce,
            wcn), angle2


@njit(cache=True, error_model="numpy")
def gyrocompass_range(state: np.ndarray, dtheta: np.ndarray, dv: np.ndarray, vref: np.ndarray,
                      vref_body: bool, ts: float, lo: int, hi: int, reverse: bool,
                      data_sign: float, earth_sign: float, E: np.ndarray, gains: np.ndarray,
                      mode: int, stride: int, idx_out: np.ndarray, q_out: np.ndarray) -> int:
    """Run the loops over increments lo … hi−1 of a stored block, updating `state` (12,) in
    place, and write the attitude at the samples kept; returns the number of rows written.

    dtheta, dv : (N, 3) body increments (rad, m/s) in forward time order; vref : (N+1, 3)
        the reference velocity at the samples (ENU, or body frame if `vref_body`).
    reverse : process hi−1 … lo (sample hi first) instead of lo … hi−1.
    data_sign : multiplies the gyro increments and the reference velocity as they are read
        (−1 in a reverse pass: the data transform of DESIGN.md, applied on reading, so no
        reversed and negated copy of the block is made); earth_sign : that of the earth rate.
    Kept: the first and the last sample of the range and every sample that is a multiple of
    `stride` (block indices), in processing order, into `idx_out` (their block indices) and
    `q_out` (q_nb), both preallocated for :func:`stored_rows` rows.
    (error_model "numpy": a division by zero would give inf instead of raising; none of
    the step's divisors can be zero, and the test before each division is gone.)
    """
    gk = _gains(gains)
    n = hi - lo
    # sample j of the range in processing order: forward lo + j, reverse hi − j
    first = hi if reverse else lo
    step = -1 if reverse else 1
    sg = data_sign
    x = _loop_start(state[0], state[1], state[2], state[3], state[4], state[5], state[6],
                    state[7], state[8], state[9], state[10], state[11], sg * vref[first, 0],
                    sg * vref[first, 1], sg * vref[first, 2], vref_body, E, gk, mode)
    idx_out[0] = first
    q_out[0, 0], q_out[0, 1], q_out[0, 2], q_out[0, 3] = x[0], x[1], x[2], x[3]
    row = 1
    # the next multiple of the stride after the first sample, in processing order
    keep = (first - 1) // stride * stride if reverse else (first // stride + 1) * stride
    for k in range(n):
        j = hi - 1 - k if reverse else lo + k  # the increment
        nxt = first + step * (k + 1)  # the sample at the end of the step
        x = _loop_step(x, sg * dtheta[j, 0], sg * dtheta[j, 1], sg * dtheta[j, 2], dv[j, 0],
                       dv[j, 1], dv[j, 2], sg * vref[nxt, 0], sg * vref[nxt, 1],
                       sg * vref[nxt, 2], vref_body, ts, earth_sign, E, gk, mode)
        if nxt == keep or k == n - 1:
            if nxt == keep:
                keep += step * stride
            idx_out[row] = nxt
            q_out[row, 0], q_out[row, 1], q_out[row, 2], q_out[row, 3] = x[0], x[1], x[2], x[3]
            row += 1
    for i in range(STATE_SIZE):
        state[i] = x[i]
    return row


#: Runs a lockstep kernel steps side by side: sixteen keep a 4-wide vector unit's loop
#: above the compiler's "tiny trip count" (below 16 it declines the loop: its check that the
#: arrays do not overlap would cost more than the loop) and fill an 8-wide one twice.
LANES = 16
#: Rows of a sample in the data of :func:`gyrocompass_range_lanes`: Δθ (3), Δv (3), v_R (3),
#: each row LANES wide.
DATA_ROWS = 9
#: Below this squared angle (rad²) both rotation vectors of a step take the series of
#: :func:`gcalign.nav._kernels.rv2q`; a run whose step is above it has the step redone alone.
SERIES_ANGLE2 = 2.5e-3


@njit(cache=True, error_model="numpy")
def _lanes_step(X: np.ndarray, Y: np.ndarray, T: np.ndarray, dj: np.ndarray, dn: np.ndarray,
                sg: float, vref_body: bool, ts: float, earth_sign: float, E: EarthParams,
                gk: Gains, loops: bool, level: bool, compass: bool) -> None:
    """One step of LANES runs: carried values X → Y ((CARRIED·LANES,), value i of run s at
    i·LANES + s), sin L and cos L of each run in T[0:2·LANES] (its squared angle out into
    T[2·LANES:]), the increments of the step in `dj` and the reference at its end in `dn`
    (rows of :func:`gyrocompass_range_lanes`'s data). The loop has no call and no branch on
    the data, and its arrays are few, with constant offsets: the compiler vectorises it."""
    L = LANES
    for s in range(L):
        y, a2 = _loop_step_sc(
            (X[s], X[L + s], X[2 * L + s], X[3 * L + s], X[4 * L + s], X[5 * L + s],
             X[6 * L + s], X[7 * L + s], X[8 * L + s], X[9 * L + s], X[10 * L + s],
             X[11 * L + s], X[12 * L + s], X[13 * L + s], X[14 * L + s], X[15 * L + s],
             X[16 * L + s]),
            T[s], T[L + s], sg * dj[s], sg * dj[L + s], sg * dj[2 * L + s], dj[3 * L + s],
            dj[4 * L + s], dj[5 * L + s], sg * dn[6 * L + s], sg * dn[7 * L + s],
            sg * dn[8 * L + s], vref_body, ts, earth_sign, E, gk, loops, level, compass, True)
        Y[s], Y[L + s], Y[2 * L + s], Y[3 * L + s] = y[0], y[1], y[2], y[3]
        Y[4 * L + s], Y[5 * L + s], Y[6 * L + s], Y[7 * L + s] = y[4], y[5], y[6], y[7]
        Y[8 * L + s], Y[9 * L + s], Y[10 * L + s], Y[11 * L + s] = y[8], y[9], y[10], y[11]
        Y[12 * L + s], Y[13 * L + s], Y[14 * L + s] = y[12], y[13], y[14]
        Y[15 * L + s], Y[16 * L + s] = y[15], y[16]
        T[2 * L + s] = a2


@njit(cache=True, error_model="numpy")
def gyrocompass_range_lanes(states: np.ndarray, data: np.ndarray, vref_body: bool, ts: float,
                            lo: int, hi: int, reverse: bool, data_sign: float,
                            earth_sign: float, E: np.ndarray, gains: np.ndarray, mode: int,
                            stride: int, row_from: int, idx_out: np.ndarray,
                            q_out: np.ndarray) -> int:
    """:func:`gyrocompass_range` for LANES runs in lockstep (the seeds of one Monte Carlo
    variant: the same block, timeline and gains, their own data). Each run's numbers are
    those of :func:`gyrocompass_range` on its own data, to the bit: the same step, the
    same operations in the same order, for all runs at once, so that the processor's
    vector units take several runs per instruction. The sines and cosines of the
    latitudes are taken in a loop of their own; a step whose rotation vector is above the
    series' range (never an IMU increment at a realistic rate) is redone alone by the
    scalar step, from the values before it.

    states : (LANES, 12), updated in place. data : (N+1, DATA_ROWS·LANES): at sample j,
    Δθ and Δv of increment j and the reference velocity at sample j, each component a row
    of LANES runs side by side (what one step of all runs reads is one contiguous piece).
    Rows are kept as :func:`gyrocompass_range` keeps them, but only those from row
    `row_from` on are written: block indices into `idx_out` (m,), attitudes into `q_out`
    (m, 4, LANES), from their row 0 (a Monte Carlo summary needs the end of most passes
    only). Returns the number of rows the single kernel would have written.
    """
    L = LANES
    gk = _gains(gains)
    Et = (E[0], E[1], E[2], E[3], E[4], E[5], E[6], E[7])
    loops, level, compass = mode != ATTITUDE, mode == LEVEL, mode == COMPASS
    n = hi - lo
    first = hi if reverse else lo
    step = -1 if reverse else 1
    sg = data_sign
    X, Y = np.empty(CARRIED * L), np.empty(CARRIED * L)
    T = np.empty(3 * L)
    d0 = data[first]
    for s in range(L):
        x = _loop_start(states[s, 0], states[s, 1], states[s, 2], states[s, 3], states[s, 4],
                        states[s, 5], states[s, 6], states[s, 7], states[s, 8], states[s, 9],
                        states[s, 10], states[s, 11], sg * d0[6 * L + s], sg * d0[7 * L + s],
                        sg * d0[8 * L + s], vref_body, Et, gk, mode)
        for i in range(CARRIED):
            X[i * L + s] = x[i]
    if row_from <= 0:
        idx_out[0] = first
        for i in range(4):
            for s in range(L):
                q_out[0, i, s] = X[i * L + s]
    row = 1
    keep = (first - 1) // stride * stride if reverse else (first // stride + 1) * stride
    for k in range(n):
        j = hi - 1 - k if reverse else lo + k  # the increment
        nxt = first + step * (k + 1)  # the sample at the end of the step
        dj, dn = data[j], data[nxt]
        for s in range(L):
            T[s] = math.sin(X[9 * L + s])
            T[L + s] = math.cos(X[9 * L + s])
        _lanes_step(X, Y, T, dj, dn, sg, vref_body, ts, earth_sign, Et, gk, loops, level,
                    compass)
        for s in range(L):
            if not T[2 * L + s] < SERIES_ANGLE2:  # the exact branch of rv2q (NaN too)
                z = _loop_step(
                    (X[s], X[L + s], X[2 * L + s], X[3 * L + s], X[4 * L + s], X[5 * L + s],
                     X[6 * L + s], X[7 * L + s], X[8 * L + s], X[9 * L + s], X[10 * L + s],
                     X[11 * L + s], X[12 * L + s], X[13 * L + s], X[14 * L + s],
                     X[15 * L + s], X[16 * L + s]),
                    sg * dj[s], sg * dj[L + s], sg * dj[2 * L + s], dj[3 * L + s],
                    dj[4 * L + s], dj[5 * L + s], sg * dn[6 * L + s], sg * dn[7 * L + s],
                    sg * dn[8 * L + s], vref_body, ts, earth_sign, Et, gk, mode)
                for i in range(CARRIED):
                    Y[i * L + s] = z[i]
        X, Y = Y, X
        if nxt == keep or k == n - 1:
            if nxt == keep:
                keep += step * stride
            if row >= row_from:
                w = row - max(row_from, 0)
                idx_out[w] = nxt
                for i in range(4):
                    for s in range(L):
                        q_out[w, i, s] = X[i * L + s]
            row += 1
    for s in range(L):
        for i in range(STATE_SIZE):
            states[s, i] = X[i * L + s]
    return row


@njit(cache=True)
def pack_lanes(dtheta: tuple, dv: tuple, vref: tuple, out: np.ndarray) -> None:
    """The data of LANES runs as :func:`gyrocompass_range_lanes` reads it: `dtheta`, `dv`
    (N, 3) and `vref` (N+1, 3) of each run (tuples of LANES arrays) into `out`
    (N+1, DATA_ROWS·LANES), sample by sample (written in order: a copy run by run into
    the interleaved layout touches a new page at every few samples and is ten times
    slower); the increment rows of sample N are zero."""
    n = dtheta[0].shape[0]
    L = LANES
    for j in range(n + 1):
        for s in range(L):
            a, b, r = dtheta[s], dv[s], vref[s]
            for c in range(3):
                out[j, c * L + s] = a[j, c] if j < n else 0.0
                out[j, (3 + c) * L + s] = b[j, c] if j < n else 0.0
                out[j, (6 + c) * L + s] = r[j, c]


@njit(cache=True)
def attitude_errors(q: np.ndarray, samples: np.ndarray, truth_samples: np.ndarray,
                    truth_att: np.ndarray, out: np.ndarray) -> int:
    """Euler-angle errors of the attitudes `q` (m, 4) kept at record `samples` (m,) against
    the true attitude `truth_att` (M, 3) given at the increasing record samples
    `truth_samples` (M,), into `out` (m, 3): est − true with roll and yaw wrapped to
    [−π, π), as ``rotation.attitude_error(rotation.quat_to_euler(q), truth)`` computes
    them, to the bit (the same operations in the same order, and libm's asin and atan2).

    Each row's truth is found next to the previous row's (the rows of a pass are
    consecutive samples, forward or reverse) or else by bisection (no gathered copy of the
    truth). Returns m, or the index of the first row whose sample has no truth row (the
    rows before it written).
    """
    m, big = samples.shape[0], truth_samples.shape[0]
    k = -2
    for i in range(m):
        want = samples[i]
        if 0 <= k + 1 < big and truth_samples[k + 1] == want:
            k += 1
        elif 1 <= k <= big and truth_samples[k - 1] == want:
            k -= 1
        else:
            k = np.searchsorted(truth_samples, want)
            if k >= big or truth_samples[k] != want:
                return i
        pitch, roll, yaw = euler_of(q[i, 0], q[i, 1], q[i, 2], q[i, 3])
        out[i, 0] = pitch - truth_att[k, 0]
        out[i, 1] = wrap_pi(roll - truth_att[k, 1])
        out[i, 2] = wrap_pi(yaw - truth_att[k, 2])
    return m


@njit(cache=True)
def column_spread(e: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mean, standard deviation (ddof 0) and max |·| of the columns of `e` (n, 3), as
    ``e.mean(0)``, ``e.std(0)``, ``np.abs(e).max(0)`` give them, to the bit: NumPy reduces
    the rows of an (n, 3) array in order, and its variance is the mean of the squared
    deviations from the mean. One pass for the sums and maxima, one for the deviations,
    and no temporary array."""
    n = e.shape[0]
    total, peak, dev = np.zeros(3), np.zeros(3), np.zeros(3)
    for i in range(n):
        for c in range(3):
            total[c] += e[i, c]
            a = abs(e[i, c])
            if a > peak[c] or a != a:  # a NaN stays, as in NumPy
                peak[c] = a
    mean = total / n
    for i in range(n):
        for c in range(3):
            d = e[i, c] - mean[c]
            dev[c] += d * d
    return mean, np.sqrt(dev / n), peak


def stored_rows(lo: int, hi: int, stride: int) -> int:
    """Rows :func:`gyrocompass_range` writes over samples lo … hi: both ends and the
    multiples of `stride` between them."""
    if hi == lo:
        return 1
    return 2 + (hi - 1) // stride - lo // stride  # the ends, the multiples in (lo, hi)


@njit(cache=True)
def gyrocompass_block(state: np.ndarray, dtheta: np.ndarray, dv: np.ndarray, vref: np.ndarray,
                      vref_body: bool, ts: float, earth_sign: float, E: np.ndarray,
                      gains: np.ndarray, mode: int, q_out: np.ndarray) -> None:
    """Run the loops over N increments, updating `state` (12,) in place.

    dtheta, dv : (N, 3) body increments (rad, m/s), in processing order.
    vref : (N+1, 3) reference velocity at the start (row 0) and at the end of each step
        (m/s); ENU, or body frame (odometer) if `vref_body`, then resolved with the
        computed attitude.
    E : earth model vector (:meth:`gcalign.nav.earth.EarthModel.params`).
    gains : (10,) loop gains; mode : ATTITUDE, LEVEL or COMPASS.
    q_out : (N+1, 4) attitude after each step, row 0 = start (preallocated).
    (:func:`gyrocompass_range` with every sample kept, on data already in processing order.)
    """
    n = dtheta.shape[0]
    gyrocompass_range(state, dtheta, dv, vref, vref_body, ts, 0, n, False, 1.0, earth_sign,
                      E, gains, mode, 1, np.empty(n + 1, np.int64), q_out)


def new_state(q_nb: np.ndarray, v_n: np.ndarray, pos: np.ndarray) -> np.ndarray:
    """Loop state vector from attitude, horizontal velocity and position; loop states zero."""
    s = np.zeros(STATE_SIZE)
    s[ATT] = q_nb
    s[VEL] = np.asarray(v_n, float)[:2]
    s[POS] = pos
    return s
