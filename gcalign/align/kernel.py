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
"""

from __future__ import annotations

import numpy as np
from numba import njit

from gcalign.nav._kernels import (
    attitude_update,
    earth_at,
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
    ke1, ke2, ke3 = gains[0], gains[1], gains[2]
    kn1, kn2, kn3 = gains[3], gains[4], gains[5]
    ku1, ku2, ku3, ku4 = gains[6], gains[7], gains[8], gains[9]
    q0, q1, q2, q3 = state[0], state[1], state[2], state[3]
    ve, vn = state[4], state[5]
    ie, inn = state[6], state[7]
    wcu = state[8]
    lat, lon, h = state[9], state[10], state[11]
    n = hi - lo
    # sample j of the range in processing order: forward lo + j, reverse hi − j
    first = hi if reverse else lo
    step = -1 if reverse else 1
    idx_out[0] = first
    q_out[0, 0], q_out[0, 1], q_out[0, 2], q_out[0, 3] = q0, q1, q2, q3
    row = 1
    # the next multiple of the stride after the first sample, in processing order
    keep = (first - 1) // stride * stride if reverse else (first // stride + 1) * stride
    # Reference velocity at the start of the first step.
    sg = data_sign
    re, rn, ru = sg * vref[first, 0], sg * vref[first, 1], sg * vref[first, 2]
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
    for k in range(n):
        j = hi - 1 - k if reverse else lo + k  # the increment
        nxt = first + step * (k + 1)  # the sample at the end of the step
        bx, by, bz = sg * dtheta[j, 0], sg * dtheta[j, 1], sg * dtheta[j, 2]
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
            q0, q1, q2, q3, bx, by, bz, dv[j, 0], dv[j, 1], dv[j, 2], wx, wy, wz,
        )
        q0, q1, q2, q3 = attitude_update(q0, q1, q2, q3, bx, by, bz, wx, wy, wz)

        # Reference velocity at the end of the step, and position along it.
        ne, nn, nu = sg * vref[nxt, 0], sg * vref[nxt, 1], sg * vref[nxt, 2]
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
        if nxt == keep or k == n - 1:
            if nxt == keep:
                keep += step * stride
            idx_out[row] = nxt
            q_out[row, 0], q_out[row, 1], q_out[row, 2], q_out[row, 3] = q0, q1, q2, q3
            row += 1

    state[0], state[1], state[2], state[3] = q0, q1, q2, q3
    state[4], state[5], state[6], state[7], state[8] = ve, vn, ie, inn, wcu
    state[9], state[10], state[11] = lat, lon, h
    return row


@njit(cache=True)
def attitude_errors(q: np.ndarray, samples: np.ndarray, truth_samples: np.ndarray,
                    truth_att: np.ndarray, out: np.ndarray) -> int:
    """Euler-angle errors of the attitudes `q` (m, 4) kept at record `samples` (m,) against
    the true attitude `truth_att` (M, 3) given at the increasing record samples
    `truth_samples` (M,), into `out` (m, 3): est − true with roll and yaw wrapped to
    [−π, π), as ``rotation.attitude_error(rotation.quat_to_euler(q), truth)`` computes
    them, to the bit (the same operations in the same order, and libm's asin and atan2).

    Each row's truth is found by bisection (no gathered copy of the truth). Returns m, or
    the index of the first row whose sample has no truth row (the rows before it written).
    """
    m, big = samples.shape[0], truth_samples.shape[0]
    for i in range(m):
        k = np.searchsorted(truth_samples, samples[i])
        if k >= big or truth_samples[k] != samples[i]:
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
