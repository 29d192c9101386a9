"""Numba kernel of the per-axis Kalman tracker (imported only where it runs)."""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def track_kernel(z: np.ndarray, Phi: np.ndarray, Qd: np.ndarray, R: float, x: np.ndarray,
                 P: np.ndarray, x_out: np.ndarray, P_out: np.ndarray, innov_out: np.ndarray,
                 S_out: np.ndarray, store_P: bool) -> None:  # pragma: no cover - numba
    """Kalman predict/update of ``X = [θ, ω, α]`` with the scalar measurement ``z_k = θ_k + v``.

    ``x`` (3,), ``P`` (3, 3): the posterior before the first sample, updated in place to
    the posterior after the last. Writes the posterior states ``x_out`` (N, 3), covariances
    ``P_out`` (N, 3, 3) when `store_P`, innovations and their variances (N,). Same equations
    as :func:`gcalign.estimation.kalman.predict` / ``update`` (Joseph form).
    """
    n = z.shape[0]
    xp = np.empty(3)
    Pp = np.empty((3, 3))
    T = np.empty((3, 3))
    K = np.empty(3)
    for k in range(n):
        # x⁻ = Φ x ;  P⁻ = Φ P Φᵀ + Q_d
        for i in range(3):
            acc = 0.0
            for j in range(3):
                acc += Phi[i, j] * x[j]
            xp[i] = acc
        for i in range(3):
            for j in range(3):
                acc = 0.0
                for m in range(3):
                    acc += Phi[i, m] * P[m, j]
                T[i, j] = acc
        for i in range(3):
            for j in range(3):
                acc = Qd[i, j]
                for m in range(3):
                    acc += T[i, m] * Phi[j, m]
                Pp[i, j] = acc
        for i in range(3):
            for j in range(i + 1, 3):
                s = 0.5 * (Pp[i, j] + Pp[j, i])
                Pp[i, j] = s
                Pp[j, i] = s
        # y = z − θ⁻ ;  S = P⁻₀₀ + R ;  K = P⁻ Hᵀ / S   (H = [1, 0, 0])
        y = z[k] - xp[0]
        S = Pp[0, 0] + R
        for i in range(3):
            K[i] = Pp[i, 0] / S
        # P = (I − K H) P⁻ (I − K H)ᵀ + K R Kᵀ   (Joseph form: stays PSD)
        # (I − K H) P⁻ has rows  P⁻_i· − K_i P⁻_0·
        for i in range(3):
            for j in range(3):
                T[i, j] = Pp[i, j] - K[i] * Pp[0, j]
        for i in range(3):
            for j in range(3):
                P[i, j] = T[i, j] - T[i, 0] * K[j] + K[i] * R * K[j]
        for i in range(3):
            for j in range(i + 1, 3):
                s = 0.5 * (P[i, j] + P[j, i])
                P[i, j] = s
                P[j, i] = s
        for i in range(3):
            x[i] = xp[i] + K[i] * y
            x_out[k, i] = x[i]
        if store_P:
            for i in range(3):
                for j in range(3):
                    P_out[k, i, j] = P[i, j]
        innov_out[k] = y
        S_out[k] = S
