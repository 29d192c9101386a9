"""Numba kernels of the Kalman predict and the Joseph-form update (the filter's epoch).

Private: :mod:`gcalign.estimation.kalman` holds the public functions and their contracts;
``tests/test_kalman.py`` holds each kernel to the plain NumPy form of the same equations
(1e-12). Every product is a loop whose innermost level runs along a row of the result
(no reduction in it, so the compiler vectorises it), and the Joseph form is evaluated
without forming I − KH (n × n):

    (I − KH) P⁻ (I − KH)ᵀ + K R Kᵀ = A − (A Hᵀ) Kᵀ + K R Kᵀ,   A = P⁻ − K (H P⁻),

the same product, a congruence of P⁻ plus K R Kᵀ (symmetric positive semi-definite for any
gain), in O(n² m) operations instead of O(n³).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _mul_into(out: np.ndarray, A: np.ndarray, B: np.ndarray, sign: float) -> None:
    """``out += sign · A @ B`` for (p, q) @ (q, r), row by row of `out`."""
    for i in range(A.shape[0]):
        for k in range(A.shape[1]):
            a = sign * A[i, k]
            for j in range(B.shape[1]):
                out[i, j] += a * B[k, j]


@njit(cache=True, inline="always")
def _symmetric(M: np.ndarray) -> np.ndarray:
    """½ (M + Mᵀ)."""
    n = M.shape[0]
    out = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            out[i, j] = 0.5 * (M[i, j] + M[j, i])
    return out


@njit(cache=True, error_model="numpy")
def predict_kernel(x: np.ndarray, P: np.ndarray, Phi: np.ndarray,
                   Qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``x⁻ = Φ x``, ``P⁻ = ½(M + Mᵀ)`` with ``M = Φ P Φᵀ + Q_d`` (x (n,), the rest (n, n),
    C-contiguous float64)."""
    n = x.shape[0]
    T = np.zeros((n, n))
    _mul_into(T, Phi, P, 1.0)  # Φ P
    M = Qd.copy()
    _mul_into(M, T, np.ascontiguousarray(Phi.T), 1.0)  # + (Φ P) Φᵀ
    xn = np.zeros(n)
    for i in range(n):
        for k in range(n):
            xn[i] += Phi[i, k] * x[k]
    return xn, _symmetric(M)


@njit(cache=True, error_model="numpy")
def update_kernel(x: np.ndarray, P: np.ndarray, z: np.ndarray, H: np.ndarray,
                  R: np.ndarray) -> tuple[bool, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                          np.ndarray, np.ndarray, float]:
    """Joseph-form update (see :func:`gcalign.estimation.kalman.update`): returns
    ``(ok, x⁺, P⁺, y, S, K, w, nis)`` with w = L⁻¹ y (S = L Lᵀ) and nis = w·w; ok False
    (and the rest unset) when ½(S + Sᵀ) is not positive definite. C-contiguous float64
    inputs."""
    n, m = x.shape[0], z.shape[0]
    y = z.copy()  # y = z − H x
    for a in range(m):
        for k in range(n):
            y[a] -= H[a, k] * x[k]
    HP = np.zeros((m, n))
    _mul_into(HP, H, P, 1.0)  # H P⁻
    PHt = np.zeros((n, m))
    Ht = np.ascontiguousarray(H.T)
    _mul_into(PHt, P, Ht, 1.0)  # P⁻ Hᵀ
    S = R.copy()
    _mul_into(S, H, PHt, 1.0)  # H P⁻ Hᵀ + R
    # Cholesky factor of ½(S + Sᵀ), then its inverse (lower triangular, m ≤ a few)
    Ss = _symmetric(S)
    L = np.zeros((m, m))
    for j in range(m):
        d = Ss[j, j]
        for k in range(j):
            d -= L[j, k] * L[j, k]
        if not d > 0.0:
            return (False, x, P, y, S, PHt, y, 0.0)
        L[j, j] = math.sqrt(d)
        for i in range(j + 1, m):
            s = Ss[i, j]
            for k in range(j):
                s -= L[i, k] * L[j, k]
            L[i, j] = s / L[j, j]
    Li = np.zeros((m, m))
    for j in range(m):
        Li[j, j] = 1.0 / L[j, j]
        for i in range(j + 1, m):
            s = 0.0
            for k in range(j, i):
                s -= L[i, k] * Li[k, j]
            Li[i, j] = s / L[i, i]
    Si = np.zeros((m, m))  # S⁻¹ = L⁻ᵀ L⁻¹
    _mul_into(Si, np.ascontiguousarray(Li.T), Li, 1.0)
    K = np.zeros((n, m))
    _mul_into(K, PHt, Si, 1.0)  # K = P⁻ Hᵀ S⁻¹
    A = P.copy()
    _mul_into(A, K, HP, -1.0)  # A = P⁻ − K (H P⁻) = (I − K H) P⁻
    AHt = np.zeros((n, m))
    _mul_into(AHt, A, Ht, 1.0)
    KR = np.zeros((n, m))
    _mul_into(KR, K, R, 1.0)
    Kt = np.ascontiguousarray(K.T)
    _mul_into(A, AHt, Kt, -1.0)  # A (I − K H)ᵀ
    _mul_into(A, KR, Kt, 1.0)  # + K R Kᵀ
    xn = x.copy()
    for i in range(n):
        for a in range(m):
            xn[i] += K[i, a] * y[a]
    w = np.zeros(m)
    for a in range(m):
        for b in range(m):
            w[a] += Li[a, b] * y[b]
    nis = 0.0
    for a in range(m):
        nis += w[a] * w[a]
    return (True, xn, _symmetric(A), y, S, K, w, nis)
