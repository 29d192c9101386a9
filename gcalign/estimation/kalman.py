"""Linear Kalman filter steps (filterpy style: plain functions on arrays) and discretisation.

Shapes: state x (n,), covariance P (n, n), transition Φ (n, n), process noise Q_d (n, n),
measurement z (m,), H (m, n), R (m, m). Nothing is modified in place.

>>> import numpy as np
>>> F = np.array([[0.0, 1.0], [0.0, 0.0]])           # position, velocity
>>> Phi, Qd = van_loan(F, np.array([[0.0], [1.0]]), np.array([[1.0]]), 1.0)
>>> Phi.tolist(), np.round(Qd, 12).tolist()
([[1.0, 1.0], [0.0, 1.0]], [[0.333333333333, 0.5], [0.5, 1.0]])
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm


def van_loan(F: np.ndarray, G: np.ndarray, Qc: np.ndarray, dt: float):
    """Exact discretisation of ``ẋ = F x + G w``, ``E[w wᵀ] = Qc δ(t − s)`` over `dt` (Van Loan).

    ``expm([[−F, G Qc Gᵀ], [0, Fᵀ]] dt) = [[·, Φ⁻¹ Q_d], [0, Φᵀ]]`` gives
    ``Φ = e^{F dt}`` and ``Q_d = ∫₀^dt e^{F s} G Qc Gᵀ e^{Fᵀ s} ds``. Returns ``(Φ, Q_d)``.
    """
    F = np.asarray(F, dtype=float)
    n = F.shape[0]
    GQG = np.asarray(G, dtype=float) @ np.asarray(Qc, dtype=float) @ np.asarray(G, dtype=float).T
    M = np.zeros((2 * n, 2 * n))
    M[:n, :n] = -F
    M[:n, n:] = GQG
    M[n:, n:] = F.T
    E = expm(M * dt)
    Phi = E[n:, n:].T
    Qd = Phi @ E[:n, n:]
    return Phi, 0.5 * (Qd + Qd.T)


def predict(x: np.ndarray, P: np.ndarray, Phi: np.ndarray, Qd: np.ndarray):
    """``x⁻ = Φ x``, ``P⁻ = Φ P Φᵀ + Q_d``."""
    P = Phi @ P @ Phi.T + Qd
    return Phi @ x, 0.5 * (P + P.T)


@dataclass(frozen=True)
class Update:
    """One measurement update: the posterior, and what consistency checks need.

    innovation y = z − H x⁻ (m,); S = H P⁻ Hᵀ + R; gain K (n, m); nis = yᵀ S⁻¹ y;
    standardized = L⁻¹ y with S = L Lᵀ (each ~ N(0, 1) for a consistent filter).
    """

    x: np.ndarray
    P: np.ndarray
    innovation: np.ndarray
    S: np.ndarray
    K: np.ndarray
    nis: float
    standardized: np.ndarray


def update(x: np.ndarray, P: np.ndarray, z: np.ndarray, H: np.ndarray, R: np.ndarray) -> Update:
    """Kalman update in Joseph form: ``P = (I − K H) P⁻ (I − K H)ᵀ + K R Kᵀ`` (stays
    symmetric positive semi-definite for any gain), ``K = P⁻ Hᵀ S⁻¹``."""
    y = np.asarray(z, dtype=float) - H @ x
    S = H @ P @ H.T + R
    L = np.linalg.cholesky(0.5 * (S + S.T))
    # K = P Hᵀ S⁻¹ through the Cholesky factor (no explicit inverse)
    PHt = P @ H.T
    K = np.linalg.solve(L.T, np.linalg.solve(L, PHt.T)).T
    I_KH = np.eye(len(x)) - K @ H
    P_new = I_KH @ P @ I_KH.T + K @ R @ K.T
    w = np.linalg.solve(L, y)
    return Update(x=x + K @ y, P=0.5 * (P_new + P_new.T), innovation=y, S=S, K=K,
                  nis=float(w @ w), standardized=w)


def nees(error: np.ndarray, P: np.ndarray) -> float:
    """Normalised estimation error squared ``eᵀ P⁻¹ e`` (χ²_n for a consistent filter)."""
    e = np.asarray(error, dtype=float)
    return float(e @ np.linalg.solve(P, e))
