"""Numba kernel of the transfer-alignment filter between two master epochs (private).

The slave's strapdown step is the one of :mod:`gcalign.nav._kernels` (its
``specific_force_increment`` and ``attitude_update``): ``C_nb R(Δθ/2) Δv`` resolved at
mid-interval and ``q(−ω_in T) ⊗ q ⊗ q(Δθ)``. PSINS's demo writes ``C_nb (Δv + ½ Δθ × Δv)``
and ``q ⊗ q(Δθ − C_nbᵀ ω_in T)``; the two differ by terms of second order in ω_in T
(≈ 1e-6 rad here) and in the change of Δθ within a step, and
``tests/test_transfer_real.py`` shows the difference on the real file (a plain NumPy loop
of the demo's lines). The covariance step is :func:`gcalign.estimation.kalman.predict`
(``x = Φ x``, ``P = Φ P Φᵀ + Q_d``, symmetrised) with the Φ of spec 006 rebuilt per step.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

from gcalign.nav._kernels import attitude_update, specific_force_increment

Array = NDArray[np.float64]


@njit(cache=True, inline="always")
def _step(q: Array, v: Array, dtheta: Array, dv: Array, k: int, fed: Array, g_cc: Array,
          ts: float, wx: float, wy: float,
          wz: float) -> tuple[float, float, float, float, float, float, float]:
    """One strapdown step of sample k, in place on q (4,) and v (3,), the increments
    corrected by the biases fed back. Returns the attitude at its start (q0 … q3) and its
    Δv^n (fx, fy, fz)."""
    bx, by, bz = dtheta[k, 0] - fed[0] * ts, dtheta[k, 1] - fed[1] * ts, \
        dtheta[k, 2] - fed[2] * ts
    dx, dy, dz = dv[k, 0] - fed[3] * ts, dv[k, 1] - fed[4] * ts, dv[k, 2] - fed[5] * ts
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    fx, fy, fz = specific_force_increment(q0, q1, q2, q3, bx, by, bz, dx, dy, dz, wx, wy, wz)
    v[0] += fx + g_cc[0] * ts
    v[1] += fy + g_cc[1] * ts
    v[2] += fz + g_cc[2] * ts
    q[0], q[1], q[2], q[3] = attitude_update(q0, q1, q2, q3, bx, by, bz, wx, wy, wz)
    return q0, q1, q2, q3, fx, fy, fz


@njit(cache=True)
def propagate(q: Array, v: Array, x: Array, P: Array, dtheta: Array, dv: Array, k_from: int,
              k_to: int, fed: Array, w_in: Array, g_cc: Array, ts: float, Phi: Array,
              Qd: Array, C_nb: Array, dv_n: Array) -> None:
    """Steps k_from … k_to − 1, in place on q (4,), v (3,), x (n,), P (n, n) and Phi (n, n)
    (its flexure block and identity set by the caller). On return C_nb (3, 3) holds the
    slave attitude at the start of the last step (the demo's ``Cnbs`` of its update) and
    dv_n (3,) the sum of the steps' Δv^n (the specific force of their Φ, for the
    observability of the run)."""
    dv_n[:] = 0.0
    wx, wy, wz = w_in[0] * ts, w_in[1] * ts, w_in[2] * ts
    for k in range(k_from, k_to):
        q0, q1, q2, q3, fx, fy, fz = _step(q, v, dtheta, dv, k, fed, g_cc, ts, wx, wy, wz)
        C_nb[0, 0] = q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3
        C_nb[0, 1] = 2 * (q1 * q2 - q0 * q3)
        C_nb[0, 2] = 2 * (q1 * q3 + q0 * q2)
        C_nb[1, 0] = 2 * (q1 * q2 + q0 * q3)
        C_nb[1, 1] = q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3
        C_nb[1, 2] = 2 * (q2 * q3 - q0 * q1)
        C_nb[2, 0] = 2 * (q1 * q3 - q0 * q2)
        C_nb[2, 1] = 2 * (q2 * q3 + q0 * q1)
        C_nb[2, 2] = q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3
        dv_n[0] += fx
        dv_n[1] += fy
        dv_n[2] += fz
        # spec 006: Φ(φ,φ) = I − [ω_in T×], Φ(δv,φ) = [Δv^n×], Φ(φ,ε) = −C_nb T, Φ(δv,∇) = C_nb T
        Phi[0, 1], Phi[0, 2], Phi[1, 2] = wz, -wy, wx
        Phi[1, 0], Phi[2, 0], Phi[2, 1] = -wz, wy, -wx
        Phi[3, 1], Phi[3, 2], Phi[4, 2] = -fz, fy, -fx
        Phi[4, 0], Phi[5, 0], Phi[5, 1] = fz, -fy, fx
        for i in range(3):
            for j in range(3):
                Phi[i, 6 + j] = -C_nb[i, j] * ts
                Phi[3 + i, 9 + j] = C_nb[i, j] * ts
        x[:] = Phi @ x
        Pn = Phi @ P @ Phi.T + Qd
        P[:, :] = 0.5 * (Pn + Pn.T)


@njit(cache=True)
def mechanise(q: Array, v: Array, dtheta: Array, dv: Array, k_from: int, k_to: int,
              fed: Array, w_in: Array, g_cc: Array, ts: float) -> None:
    """The strapdown steps of :func:`propagate` alone, in place on q (4,), v (3,): the
    slave's own solution when the filter's corrections are not fed back into it."""
    wx, wy, wz = w_in[0] * ts, w_in[1] * ts, w_in[2] * ts
    for k in range(k_from, k_to):
        _step(q, v, dtheta, dv, k, fed, g_cc, ts, wx, wy, wz)
