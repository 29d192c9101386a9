"""Linear Kalman filter steps (filterpy style: plain functions on arrays), discretisation and
the RTS smoother.

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
from typing import Any

import numpy as np


def van_loan(F: np.ndarray, G: np.ndarray, Qc: np.ndarray,
             dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact discretisation of ``ẋ = F x + G w``, ``E[w wᵀ] = Qc δ(t − s)`` over `dt` (Van Loan).

    ``expm([[−F, G Qc Gᵀ], [0, Fᵀ]] dt) = [[·, Φ⁻¹ Q_d], [0, Φᵀ]]`` gives
    ``Φ = e^{F dt}`` and ``Q_d = ∫₀^dt e^{F s} G Qc Gᵀ e^{Fᵀ s} ds``. Returns ``(Φ, Q_d)``.
    """
    from scipy.linalg import expm  # scipy.linalg only where used (start-up)

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


def _f64(a: Any) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=float)


def predict(x: np.ndarray, P: np.ndarray, Phi: np.ndarray,
            Qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``x⁻ = Φ x``, ``P⁻ = Φ P Φᵀ + Q_d`` (symmetrised: ½(P⁻ + P⁻ᵀ)). A numba kernel
    (:mod:`gcalign.estimation._kalman_kernel`); the NumPy expressions give the same numbers
    to round-off."""
    from gcalign.estimation._kalman_kernel import predict_kernel

    return predict_kernel(_f64(x), _f64(P), _f64(Phi), _f64(Qd))


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
    symmetric positive semi-definite for any gain), ``K = P⁻ Hᵀ S⁻¹``, S⁻¹ = L⁻ᵀ L⁻¹ from
    the Cholesky factor of ½(S + Sᵀ) (one small inversion serves the gain and the whitened
    innovation w = L⁻¹ y). A numba kernel (:mod:`gcalign.estimation._kalman_kernel`, which
    evaluates the Joseph product in O(n² m)); LinAlgError when S is not positive definite.
    """
    from gcalign.estimation._kalman_kernel import update_kernel

    ok, x_new, P_new, y, S, K, w, nis = update_kernel(_f64(x), _f64(P), _f64(z), _f64(H),
                                                      _f64(R))
    if not ok:
        raise np.linalg.LinAlgError("Matrix is not positive definite")
    return Update(x=x_new, P=P_new, innovation=y, S=S, K=K, nis=nis, standardized=w)


def solve_spd(P: np.ndarray, B: np.ndarray) -> np.ndarray:
    """``P⁻¹ B`` for a covariance P (n, n) whose diagonal spans many decades (an INS error
    state mixes rad² and m²): solved on the correlation matrix ``D⁻¹ P D⁻¹``, D = √diag P.
    B is (n,) or (n, k)."""
    P, B = np.asarray(P, dtype=float), np.asarray(B, dtype=float)
    d = np.sqrt(np.diag(P))
    dd = d[:, None] if B.ndim == 2 else d
    return np.linalg.solve(P / np.outer(d, d), B / dd) / dd


def nees(error: np.ndarray, P: np.ndarray) -> Any:  # float or (K,): by the input shapes
    """Normalised estimation error squared ``eᵀ P⁻¹ e`` (χ²_n for a consistent filter):
    a float for error (n,) and P (n, n), or (K,) for stacks (K, n) and (K, n, n) (one
    batched solve on the correlation matrices)."""
    e, P = np.asarray(error, dtype=float), np.asarray(P, dtype=float)
    if e.ndim == 1:
        return float(e @ solve_spd(P, e))
    d = np.sqrt(np.diagonal(P, axis1=-2, axis2=-1))
    r = e / d
    return np.einsum("ki,ki->k", r, np.linalg.solve(P / (d[:, :, None] * d[:, None, :]),
                                                    r[..., None])[..., 0])


def rts(Phis: np.ndarray, P_prior: np.ndarray, x_prior: np.ndarray, P_post: np.ndarray,
        x_post: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rauch–Tung–Striebel smoother over K filter steps.

    Phis (K, n, n): transition from epoch k to k+1; x_prior, P_prior (K, …): the prediction
    at epoch k+1; x_post, P_post (K+1, …): the posterior at epoch k (epoch 0: the prior).
    ``C_k = P⁺_k Φ_kᵀ (P⁻_{k+1})⁻¹``, ``x^s_k = x⁺_k + C_k (x^s_{k+1} − x⁻_{k+1})``,
    ``P^s_k = P⁺_k + C_k (P^s_{k+1} − P⁻_{k+1}) C_kᵀ``. A closed-loop (error-state) filter
    whose state is reset after each update smooths with the same recursion: the reset is a
    known input, its x⁻ is zero. Returns ``(x_s (K+1, n), P_s (K+1, n, n))``.
    """
    xs, Ps = np.array(x_post, dtype=float), np.array(P_post, dtype=float)
    for k in range(len(Phis) - 1, -1, -1):
        C = solve_spd(P_prior[k], Phis[k] @ P_post[k]).T
        xs[k] = x_post[k] + C @ (xs[k + 1] - x_prior[k])
        Pk = P_post[k] + C @ (Ps[k + 1] - P_prior[k]) @ C.T
        Ps[k] = 0.5 * (Pk + Pk.T)
    return xs, Ps
