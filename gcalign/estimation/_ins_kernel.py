"""Numba kernel: Φ and Q_d of the 21-state error model over one filter step (the hot loop).

It repeats :func:`gcalign.estimation.ins_error.error_matrix`, ``noise_matrix`` and
``accumulate`` on the block structure of F (rows 9–20 are zero, so
``Φ = [[Φ_nn, Φ_ni], [0, I]]`` and Q_d lives in the 9×9 navigation block);
``tests/test_ins_error.py`` holds the two routes together to 1e-12.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

Array = NDArray[np.float64]


@njit(cache=True)
def _radii(params: Array, lat: float) -> tuple[float, float]:
    s2 = math.sin(lat) ** 2
    if params[0] == 1.0:  # first order (EarthModel FIRST_ORDER)
        a, f = params[1], params[2]
        return a * (1.0 - 2.0 * f + 3.0 * f * s2), a * (1.0 + f * s2)
    a, e2 = params[1], params[2]
    w = 1.0 - e2 * s2
    r_n = a / math.sqrt(w)
    return r_n * (1.0 - e2) / w, r_n


@njit(cache=True)
def _nav_rows(C: Array, f_b: Array, w_b: Array, v: Array, pos: Array, params: Array,
              F: Array) -> None:
    """Rows 0–8 of F (9, 21) at one point (spec 002 §2; PSINS etm + diagonal kffk 34)."""
    lat, h = pos[0], pos[2]
    wie = params[3]
    g0, g1, g2, g3 = params[4], params[5], params[6], params[7]
    sl, cl = math.sin(lat), math.cos(lat)
    tl, secl = sl / cl, 1.0 / cl
    r_m, r_n = _radii(params, lat)
    rmh, rnh = r_m + h, r_n + h
    ve, vn, vu = v[0], v[1], v[2]
    F[:, :] = 0.0
    win = (-vn / rmh, wie * cl + ve / rnh, wie * sl + ve * tl / rnh)  # ω_in
    # Maa = −[ω_in×]
    F[0, 1], F[0, 2] = win[2], -win[1]
    F[1, 0], F[1, 2] = -win[2], win[0]
    F[2, 0], F[2, 1] = win[1], -win[0]
    # Mav
    F[0, 4] = -1.0 / rmh
    F[1, 3] = 1.0 / rnh
    F[2, 3] = tl / rnh
    # Map = M1 + M2
    F[0, 8] = vn / rmh**2
    F[1, 6], F[1, 8] = -wie * sl, -ve / rnh**2
    F[2, 6], F[2, 8] = wie * cl + ve * secl**2 / rnh, -ve * tl / rnh**2
    # f^n = C f^b; Mva = [f^n×]
    fe = C[0, 0] * f_b[0] + C[0, 1] * f_b[1] + C[0, 2] * f_b[2]
    fn = C[1, 0] * f_b[0] + C[1, 1] * f_b[1] + C[1, 2] * f_b[2]
    fu = C[2, 0] * f_b[0] + C[2, 1] * f_b[1] + C[2, 2] * f_b[2]
    F[3, 1], F[3, 2] = -fu, fn
    F[4, 0], F[4, 2] = fu, -fe
    F[5, 0], F[5, 1] = -fn, fe
    # Mvv = [v×] Mav − [(2ω_ie + ω_en)×];  Mvp = [v×](2 M1 + M2) with gravity terms
    we = -vn / rmh
    wn = 2.0 * wie * cl + ve / rnh
    wu = 2.0 * wie * sl + ve * tl / rnh
    Vx = ((0.0, -vu, vn), (vu, 0.0, -ve), (-vn, ve, 0.0))
    Mav = ((0.0, -1.0 / rmh, 0.0), (1.0 / rnh, 0.0, 0.0), (tl / rnh, 0.0, 0.0))
    W = ((0.0, -wu, wn), (wu, 0.0, -we), (-wn, we, 0.0))
    M = ((0.0, 0.0, vn / rmh**2), (-2.0 * wie * sl, 0.0, -ve / rnh**2),
         (2.0 * wie * cl + ve * secl**2 / rnh, 0.0, -ve * tl / rnh**2))
    for i in range(3):
        for j in range(3):
            a = 0.0
            b = 0.0
            for k in range(3):
                a += Vx[i][k] * Mav[k][j]
                b += Vx[i][k] * M[k][j]
            F[3 + i, 3 + j] = a - W[i][j]
            F[3 + i, 6 + j] = b
    F[5, 6] -= g0 * (2.0 * g1 + 4.0 * g2 * sl * sl) * sl * cl
    F[5, 8] += g3
    # Mpv, Mpp
    F[6, 4] = 1.0 / rmh
    F[7, 3] = secl / rnh
    F[8, 5] = 1.0
    F[6, 8] = -vn / rmh**2
    F[7, 6], F[7, 8] = ve * secl * tl / rnh, -ve * secl / rnh**2
    # sensor columns: −C, −C diag(ω), C, C diag(f)
    for i in range(3):
        for j in range(3):
            F[i, 9 + j] = -C[i, j]
            F[i, 15 + j] = -C[i, j] * w_b[j]
            F[3 + i, 12 + j] = C[i, j]
            F[3 + i, 18 + j] = C[i, j] * f_b[j]


@njit(cache=True, inline="always")
def _dcm_mid(q: Array, r: Array) -> Array:
    """DCM of q ⊗ q(r), r a small rotation vector (the attitude half-way through a step)."""
    t2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2]
    if t2 < 1e-8:
        c, s = 1.0 - t2 / 8.0, 0.5 - t2 / 48.0
    else:
        t = math.sqrt(t2)
        c, s = math.cos(0.5 * t), math.sin(0.5 * t) / t
    bw, bx, by, bz = c, s * r[0], s * r[1], s * r[2]
    aw, ax, ay, az = q[0], q[1], q[2], q[3]
    w = aw * bw - ax * bx - ay * by - az * bz
    x = aw * bx + ax * bw + ay * bz - az * by
    y = aw * by - ax * bz + ay * bw + az * bx
    z = aw * bz + ax * by - ay * bx + az * bw
    n = 1.0 / (w * w + x * x + y * y + z * z)
    C = np.empty((3, 3))
    C[0, 0] = (w * w + x * x - y * y - z * z) * n
    C[0, 1] = 2.0 * (x * y - w * z) * n
    C[0, 2] = 2.0 * (x * z + w * y) * n
    C[1, 0] = 2.0 * (x * y + w * z) * n
    C[1, 1] = (w * w - x * x + y * y - z * z) * n
    C[1, 2] = 2.0 * (y * z - w * x) * n
    C[2, 0] = 2.0 * (x * z - w * y) * n
    C[2, 1] = 2.0 * (y * z + w * x) * n
    C[2, 2] = (w * w - x * x - y * y + z * z) * n
    return C


@njit(cache=True)
def transition_block(q_nb: Array, v_n: Array, pos: Array, dtheta: Array, dv: Array, ts: float,
                     qc: Array, params: Array, Phi: Array, Qd: Array, F_mean: Array,
                     G_mean: Array) -> None:
    """Φ, Q_d (21, 21) over the S navigation steps of one filter step, and the mean F, G.

    q_nb (S+1, 4), v_n, pos (S+1, 3): the navigation states; dtheta, dv (S, 3): the
    compensated increments; qc (6,): diagonal of Qc; params: ``EarthModel.params()``.
    Per step, at the mid-step state: ``A = I + F ts + (F ts)²/2``, ``Φ ← A Φ``,
    ``Q_d ← A (Q_d + ½ G Qc Gᵀ ts) Aᵀ + ½ G Qc Gᵀ ts`` (as
    :func:`gcalign.estimation.ins_error.accumulate`).
    """
    S = dtheta.shape[0]
    n = 21
    Fn = np.zeros((9, n))
    A = np.zeros((9, n))
    Pnn = np.eye(9)
    Pni = np.zeros((9, 12))
    Q = np.zeros((9, 9))
    F_mean[:, :] = 0.0
    G_mean[:, :] = 0.0
    fb = np.empty(3)
    wb = np.empty(3)
    vm = np.empty(3)
    pm = np.empty(3)
    half = np.empty(3)
    for k in range(S):
        for i in range(3):
            fb[i] = dv[k, i] / ts
            wb[i] = dtheta[k, i] / ts
            vm[i] = 0.5 * (v_n[k, i] + v_n[k + 1, i])
            pm[i] = 0.5 * (pos[k, i] + pos[k + 1, i])
            half[i] = 0.5 * dtheta[k, i]
        C = _dcm_mid(q_nb[k], half)
        _nav_rows(C, fb, wb, vm, pm, params, Fn)
        # A = I + F ts + (F ts)²/2 on rows 0–8; (F²)[:, j] = F_nn F[0:9, j] (rows 9+ of F are 0)
        for i in range(9):
            for j in range(n):
                s2 = 0.0
                for m in range(9):
                    s2 += Fn[i, m] * Fn[m, j]
                A[i, j] = Fn[i, j] * ts + 0.5 * ts * ts * s2
            A[i, i] += 1.0
        # Φ ← A Φ:  Φ_nn ← A_nn Φ_nn,  Φ_ni ← A_nn Φ_ni + A_ni
        Ann = np.ascontiguousarray(A[:, :9])
        Pnn, Pni = Ann @ Pnn, Ann @ Pni + A[:, 9:]
        # Q ← A_nn (Q + ½ G Qc Gᵀ ts) A_nnᵀ + ½ G Qc Gᵀ ts  (G rows: φ −C on w_g, δv +C on w_a)
        GQG = np.zeros((9, 9))
        for i in range(3):
            for j in range(3):
                sg = 0.0
                sa = 0.0
                for m in range(3):
                    sg += C[i, m] * qc[m] * C[j, m]
                    sa += C[i, m] * qc[3 + m] * C[j, m]
                GQG[i, j] = 0.5 * ts * sg
                GQG[3 + i, 3 + j] = 0.5 * ts * sa
        Q = Ann @ (Q + GQG) @ Ann.T + GQG
        for i in range(9):
            for j in range(n):
                F_mean[i, j] += Fn[i, j] / S
        for i in range(3):
            for j in range(3):
                G_mean[i, j] -= C[i, j] / S
                G_mean[3 + i, 3 + j] += C[i, j] / S
    Phi[:, :] = 0.0
    Qd[:, :] = 0.0
    for i in range(12):
        Phi[9 + i, 9 + i] = 1.0
    for i in range(9):
        for j in range(9):
            Phi[i, j] = Pnn[i, j]
            Qd[i, j] = 0.5 * (Q[i, j] + Q[j, i])
        for j in range(12):
            Phi[i, 9 + j] = Pni[i, j]
