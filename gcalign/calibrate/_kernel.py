"""Numba kernels: the calibration filter's epochs on the seed's schedule, for one run or
several runs in lockstep (the seeds of a Monte Carlo variant), and the navigation
increments combined from IMU ones (:func:`combine`).

Private: :func:`gcalign.calibrate.filter.calibrate` and
:func:`gcalign.calibrate.lockstep.calibrate_runs` call it. One loop over the filter epochs;
inside it, for each run (lane), the steps 1–5 of :mod:`gcalign.calibrate.filter`: the
compensation, :func:`gcalign.nav._kernels.strapdown_block`,
:func:`gcalign.estimation._ins_kernel.transition_block`, the Kalman kernels
(:mod:`gcalign.estimation._kalman_kernel`, the Joseph form) and the feedback. A run is
computed by the same operations whatever lanes run beside it (no sum runs across lanes),
so a seed in lockstep gives its single run's numbers to the bit; and the operations are
those of the filter's general (NumPy) loop, written out in the order NumPy evaluates them:
the norm of φ summed left to right (``np.linalg.norm`` of 3 elements), ``sin(L)²`` of the
radii by the C library's ``pow`` (what NumPy's scalar ``**`` calls; LLVM would turn a
constant exponent 2 into a product, which rounds differently in about one case in a
thousand: the exponent comes in as data, `two`), so that on a machine whose NumPy sine
and cosine are the C library's (checked in ``tests/test_calibrate_lockstep.py``) the
kernel's run is the loop's to the bit.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from gcalign.estimation._ins_kernel import transition_block
from gcalign.estimation._kalman_kernel import predict_kernel, update_kernel
from gcalign.nav._kernels import strapdown_block

#: the navigation state of a lane: q_nb (4), v_n (3), pos (3)
NAV = 10


@njit(cache=True)
def _radii(E: np.ndarray, lat: float, two: float) -> tuple[float, float]:
    """:meth:`gcalign.nav.earth.EarthModel.radii` at one latitude, in its operations."""
    s2 = math.pow(math.sin(lat), two)
    if E[0] == 1.0:  # first order: E[2] is f
        a, f = E[1], E[2]
        return a * (1.0 - 2.0 * f + 3.0 * f * s2), a * (1.0 + f * s2)
    a, e2 = E[1], E[2]
    w = 1.0 - e2 * s2
    r_n = a / math.sqrt(w)
    return r_n * (1.0 - e2) / w, r_n


@njit(cache=True)
def epochs(k0: int, k1: int, ends: np.ndarray, dtheta: np.ndarray, dv: np.ndarray,
           ts: float, E: np.ndarray, qc: np.ndarray, rv: np.ndarray, rp: np.ndarray,
           ref_v: np.ndarray, ref_p: np.ndarray, noise: np.ndarray, R: np.ndarray,
           feedback: bool, two: float, alive: np.ndarray, nav: np.ndarray, x: np.ndarray,
           P: np.ndarray, imu: np.ndarray, est: np.ndarray, sig: np.ndarray,
           innov: np.ndarray, stdz: np.ndarray, nis: np.ndarray, corrected: np.ndarray,
           pre: np.ndarray, in_force: np.ndarray, x_all: np.ndarray, P_all: np.ndarray,
           rows: np.ndarray) -> None:
    """Filter epochs k0 … k1−1 of L lanes (epoch k from navigation sample ``ends[k]`` to
    ``ends[k+1]``, an update with the reference at its end).

    Inputs: dtheta, dv (L, N, 3) each lane's measured increments; ref_v, ref_p (N+1, 3) the
    reference (shared); noise (L, epochs, m) the measurement noise; R (m, m); rv, rp the
    rows of the 3-D velocity [E, N, U] and position [N, E, U] blocks measured; qc (6,) the
    diagonal of Qc; `two` 2.0 (see the module docstring).
    State, carried from call to call (L, …): alive (bool: a lane whose update failed stops
    there), nav (L, 10) q_nb, v_n, pos; x (21,), P (21, 21), imu (21,) the parameters in
    force. Outputs at epoch rows k + 1: est, sig, in_force, x_all (L, K+1, 21), P_all
    (L, K+1, 21, 21) or (L, 0, 21, 21) not kept, corrected and pre (L, K+1, 10) the INS
    after and before the correction; at rows k: innov, stdz (L, K, m), nis (L, K). rows
    (L, n, 10): the navigation solution at every sample of the call's epochs (the last of
    each epoch corrected), or (L, 0, 10) not kept.
    """
    lanes = dtheta.shape[0]
    n_states = x.shape[1]
    m = R.shape[0]
    nv, npos = rv.shape[0], rp.shape[0]
    s_max = 0
    for k in range(k0, k1):
        s_max = max(s_max, ends[k + 1] - ends[k])
    dth = np.empty((s_max, 3))
    dvb = np.empty((s_max, 3))
    out = np.empty((s_max, 11))
    qs = np.empty((s_max + 1, 4))
    vs = np.empty((s_max + 1, 3))
    ps = np.empty((s_max + 1, 3))
    Phi = np.empty((n_states, n_states))
    Qd = np.empty((n_states, n_states))
    F_mean = np.empty((n_states, n_states))
    G_mean = np.empty((n_states, 6))
    vert = np.zeros(4)  # FREE
    s = np.zeros(11)
    href = np.zeros(1)
    z = np.empty(m)
    keep_P = P_all.shape[1] > 0
    keep_rows = rows.shape[1] > 0
    row0 = ends[k0]
    for k in range(k0, k1):
        b, e = ends[k], ends[k + 1]
        S = e - b
        for ln in range(lanes):
            if not alive[ln]:
                continue
            # 1-2. compensate with the parameters in force, navigate to the stop
            for i in range(S):
                for j in range(3):
                    dth[i, j] = ((dtheta[ln, b + i, j] - imu[ln, 9 + j] * ts)
                                 / (1.0 + imu[ln, 15 + j]))
                    dvb[i, j] = (dv[ln, b + i, j] - imu[ln, 12 + j] * ts) / (1.0 + imu[ln, 18 + j])
            for j in range(10):
                s[j] = nav[ln, j]
            s[10] = 0.0
            href[0] = nav[ln, 9]
            strapdown_block(s, dth[:S], dvb[:S], ts, 1.0, E, vert, href, 1, out[:S])
            for j in range(4):
                qs[0, j] = nav[ln, j]
            for j in range(3):
                vs[0, j] = nav[ln, 4 + j]
                ps[0, j] = nav[ln, 7 + j]
            for i in range(S):
                for j in range(4):
                    qs[i + 1, j] = out[i, j]
                for j in range(3):
                    vs[i + 1, j] = out[i, 4 + j]
                    ps[i + 1, j] = out[i, 7 + j]
            # 3-4. Φ, Q_d along the navigation; predict
            transition_block(qs[:S + 1], vs[:S + 1], ps[:S + 1], dth[:S], dvb[:S], ts, qc, E,
                             Phi, Qd, F_mean, G_mean)
            x_prior, P_prior = predict_kernel(x[ln], P[ln], Phi, Qd)
            q0, q1, q2, q3 = qs[S, 0], qs[S, 1], qs[S, 2], qs[S, 3]
            ve, vn, vu = vs[S, 0], vs[S, 1], vs[S, 2]
            lat, lon, h = ps[S, 0], ps[S, 1], ps[S, 2]
            pre[ln, k + 1, 0], pre[ln, k + 1, 1], pre[ln, k + 1, 2], pre[ln, k + 1, 3] = \
                q0, q1, q2, q3
            pre[ln, k + 1, 4], pre[ln, k + 1, 5], pre[ln, k + 1, 6] = ve, vn, vu
            pre[ln, k + 1, 7], pre[ln, k + 1, 8], pre[ln, k + 1, 9] = lat, lon, h
            for j in range(n_states):
                in_force[ln, k + 1, j] = imu[ln, j]
            # z = INS − reference − noise, H (gcalign.calibrate.filter._measurement,
            # gcalign.estimation.ins_error.measurement_matrix)
            H = np.zeros((m, n_states))
            r_m, r_n = 0.0, 0.0
            if npos > 0:
                r_m, r_n = _radii(E, lat, two)
            for a in range(nv):
                c = rv[a]
                z[a] = vs[S, c] - ref_v[e, c]
                H[a, 3 + c] = 1.0
            for a in range(npos):
                c = rp[a]
                if c == 0:
                    z[nv + a] = (lat - ref_p[e, 0]) * (r_m + h)
                    H[nv + a, 6] = r_m + h
                elif c == 1:
                    z[nv + a] = (lon - ref_p[e, 1]) * (r_n + h) * math.cos(lat)
                    H[nv + a, 7] = (r_n + h) * math.cos(lat)
                else:
                    z[nv + a] = h - ref_p[e, 2]
                    H[nv + a, 8] = 1.0
            for a in range(m):
                z[a] = z[a] - noise[ln, k, a]
            ok, x_post, P_post, y, _, _, w, chi2 = update_kernel(x_prior, P_prior, z, H, R)
            if not ok:
                alive[ln] = False
                continue
            for a in range(m):
                innov[ln, k, a] = y[a]
                stdz[ln, k, a] = w[a]
            nis[ln, k] = chi2
            for j in range(n_states):
                P[ln, j] = P_post[j]
                sig[ln, k + 1, j] = math.sqrt(P_post[j, j])
                x_all[ln, k + 1, j] = x_post[j]
            for j in range(9):
                est[ln, k + 1, j] = x_post[j]
            if keep_P:
                P_all[ln, k + 1] = P_post
            # 5. the corrected solution: q(φ) ⊗ q, v − δv, p − δp (nav.rotation.rotvec_to_quat)
            rx, ry, rz = x_post[0], x_post[1], x_post[2]
            th = math.sqrt(rx * rx + ry * ry + rz * rz)
            half = 0.5 * th
            ratio = 0.5 - th * th / 48.0 if th < 1e-4 else math.sin(half) / th
            pw, px, py, pz = math.cos(half), rx * ratio, ry * ratio, rz * ratio
            c0 = pw * q0 - px * q1 - py * q2 - pz * q3
            c1 = pw * q1 + px * q0 + py * q3 - pz * q2
            c2 = pw * q2 - px * q3 + py * q0 + pz * q1
            c3 = pw * q3 + px * q2 - py * q1 + pz * q0
            cor = corrected[ln, k + 1]
            cor[0], cor[1], cor[2], cor[3] = c0, c1, c2, c3
            cor[4], cor[5], cor[6] = ve - x_post[3], vn - x_post[4], vu - x_post[5]
            cor[7], cor[8], cor[9] = lat - x_post[6], lon - x_post[7], h - x_post[8]
            if keep_rows:
                r0 = b - row0
                for i in range(S - 1):
                    for j in range(10):
                        rows[ln, r0 + i, j] = out[i, j]
                for j in range(10):
                    rows[ln, r0 + S - 1, j] = cor[j]
            if feedback:
                for j in range(10):
                    nav[ln, j] = cor[j]
                for j in range(3):  # the exact composition (filter._compose)
                    g, a_ = imu[ln, 15 + j], imu[ln, 18 + j]
                    imu[ln, 9 + j] = imu[ln, 9 + j] + (1.0 + g) * x_post[9 + j]
                    imu[ln, 12 + j] = imu[ln, 12 + j] + (1.0 + a_) * x_post[12 + j]
                    imu[ln, 15 + j] = (1.0 + g) * (1.0 + x_post[15 + j]) - 1.0
                    imu[ln, 18 + j] = (1.0 + a_) * (1.0 + x_post[18 + j]) - 1.0
                for j in range(9, n_states):
                    est[ln, k + 1, j] = imu[ln, j]
                for j in range(n_states):
                    x[ln, j] = 0.0
            else:
                nav[ln, 0], nav[ln, 1], nav[ln, 2], nav[ln, 3] = q0, q1, q2, q3
                nav[ln, 4], nav[ln, 5], nav[ln, 6] = ve, vn, vu
                nav[ln, 7], nav[ln, 8], nav[ln, 9] = lat, lon, h
                for j in range(9, n_states):
                    est[ln, k + 1, j] = x_post[j]
                for j in range(n_states):
                    x[ln, j] = x_post[j]


@njit(cache=True, inline="always")
def _rotvec_quat(rx: float, ry: float, rz: float) -> tuple[float, float, float, float]:
    """:func:`gcalign.nav.rotation.rotvec_to_quat` of one vector, in its operations."""
    th = math.sqrt(rx * rx + ry * ry + rz * rz)
    half = 0.5 * th
    ratio = 0.5 - th * th / 48.0 if th < 1e-4 else math.sin(half) / th
    return math.cos(half), rx * ratio, ry * ratio, rz * ratio


@njit(cache=True, inline="always")
def _turn(w: float, x: float, y: float, z: float, v0: float, v1: float,
          v2: float) -> tuple[float, float, float]:
    """The DCM of q = (w, x, y, z) (:func:`gcalign.nav.rotation.quat_to_dcm`) times v, each
    row's sum in the order ``np.einsum("...ij,...j->...i")`` takes (its two-lane pairs:
    (c0 v0 + c2 v2) + c1 v1)."""
    c00, c01, c02 = w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)
    c10, c11, c12 = 2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)
    c20, c21, c22 = 2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z
    return ((c00 * v0 + c02 * v2) + c01 * v1, (c10 * v0 + c12 * v2) + c11 * v1,
            (c20 * v0 + c22 * v2) + c21 * v1)


@njit(cache=True)
def combine(dtheta: np.ndarray, dv: np.ndarray, n: int, phi: np.ndarray,
            out: np.ndarray) -> None:
    """:func:`gcalign.calibrate.data.combine_increments` for n ≥ 2 into phi, out (N // n, 3):
    per group, ``ΔV = Σ_i C(q_{i−1}) R(θ_i/2) Δv_i`` with ``q_i = q_{i−1} ⊗ q(θ_i)``, then
    ``φ = rotvec(q_n)`` and ``Δv = R(−φ/2) ΔV``, in the NumPy form's operations and order."""
    for g in range(dtheta.shape[0] // n):
        qw, qx, qy, qz = 1.0, 0.0, 0.0, 0.0
        V0 = V1 = V2 = 0.0
        for i in range(n):
            r = g * n + i
            w0, w1, w2 = dtheta[r, 0], dtheta[r, 1], dtheta[r, 2]
            hw, hx, hy, hz = _rotvec_quat(0.5 * w0, 0.5 * w1, 0.5 * w2)
            u0, u1, u2 = _turn(hw, hx, hy, hz, dv[r, 0], dv[r, 1], dv[r, 2])
            t0, t1, t2 = _turn(qw, qx, qy, qz, u0, u1, u2)
            V0, V1, V2 = V0 + t0, V1 + t1, V2 + t2
            pw, px, py, pz = _rotvec_quat(w0, w1, w2)
            qw, qx, qy, qz = (qw * pw - qx * px - qy * py - qz * pz,
                              qw * px + qx * pw + qy * pz - qz * py,
                              qw * py - qx * pz + qy * pw + qz * px,
                              qw * pz + qx * py - qy * px + qz * pw)
        # φ = rotvec(q) (gcalign.nav.rotation.quat_to_rotvec)
        sgn = -1.0 if qw < 0 else 1.0
        qw, qx, qy, qz = qw * sgn, qx * sgn, qy * sgn, qz * sgn
        nn = math.sqrt(qx * qx + qy * qy + qz * qz)
        th = 2.0 * math.atan2(nn, qw)
        ratio = 2.0 / qw if nn < 1e-12 else th / nn
        f0, f1, f2 = qx * ratio, qy * ratio, qz * ratio
        phi[g, 0], phi[g, 1], phi[g, 2] = f0, f1, f2
        bw, bx, by, bz = _rotvec_quat(-0.5 * f0, -0.5 * f1, -0.5 * f2)
        out[g, 0], out[g, 1], out[g, 2] = _turn(bw, bx, by, bz, V0, V1, V2)
