r"""Attitude tracking and prediction to the pulse time (seed 003 §2.3; spec 003 §3).

Per axis (pitch, roll, yaw separately, yaw unwrapped) the INS attitude ``z_k`` at the
solution instants ``t_k = kτ`` (it describes the body at ``t_k − T``) feeds a Kalman filter
on ``X = [θ, ω, α]`` (seed eqs. 2–9): ``θ̇ = ω, ω̇ = α, α̇ = W`` with W white of intensity
Qc, ``z = θ + V``, ``Var V = R``. Discretised exactly (Van Loan, seed eq. 4):

    Φ = [[1, τ, τ²/2], [0, 1, τ], [0, 0, 1]],
    Q_k = Qc [[τ⁵/20, τ⁴/8, τ³/6], [τ⁴/8, τ³/3, τ²/2], [τ³/6, τ²/2, τ]].

Least squares (seed eqs. 10–12): the latest three estimates of ω (and separately of α)
are fitted by ``f(x) = a0 + a1 x + a2 x²``. Three points, three coefficients: the fit is
the interpolating parabola. In local time ``x ∈ {−2τ, −τ, 0}`` its value ``m`` steps ahead
is (Lagrange) ``½m(m+1)·y_{k−2} − m(m+2)·y_{k−1} + ½(m+1)(m+2)·y_k``; in absolute time
(``x = t``, as the seed's eq. 12 reads) the normal equations lose every digit at
t = 1e5 s (:func:`ls_fit`, tested).

Prediction over ``Tdelay = T + Δt`` (the seed's eq. 13 is lost; reconstructed [R]): with
``n = ⌊Tdelay/τ⌋`` whole steps and the remainder ``r = Tdelay − nτ`` (= Δt when T = nτ),

    θ̂(t_p) = θ̂_k + Σ_{i=0}^{n−1} (ω_{k+i} τ + ½ α_{k+i} τ²) + ω_{k+n} r + ½ α_{k+n} r²,

``ω_{k+i}, α_{k+i}`` from the fitted parabolas. Exact for quadratic θ (each term is the
exact increment of a quadratic); for cubic θ with jerk j each step misses ``j s³/6``, so
the error is ``j (nτ³ + r³)/6`` (= j·T·τ²/6 for Δt = 0), against ``j·Tdelay³/6`` for the
plain Taylor step ``θ + ω Tdelay + ½ α Tdelay²`` (``taylor``; PSINS ``insextrap`` is its
first-order version). ``none`` outputs the latched INS attitude itself (no tracker), and is
handled where the latched attitude is (:mod:`gcalign.realtime.chain`).

>>> import numpy as np
>>> ls_weights(4.0).tolist()
[10.0, -24.0, 15.0]
>>> tau, T = 1e-3, 4e-3
>>> t = np.array([-2, -1, 0]) * tau                      # exact states of θ = 3 + 2t + t²/2
>>> states = np.stack([3 + 2 * t + t**2 / 2, 2 + t, np.ones(3)], -1)
>>> float(predict_kalman_ls(states, T, tau)) == 3 + 2 * T + T**2 / 2
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gcalign.estimation.kalman import predict as kf_predict
from gcalign.estimation.kalman import update as kf_update
from gcalign.estimation.kalman import van_loan

__all__ = [
    "Track",
    "TrackerModel",
    "horizon_weights",
    "ls_fit",
    "ls_weights",
    "predict_kalman_ls",
    "predict_taylor",
    "prediction_response",
    "run_predictor",
    "steady_state",
    "swing_residual",
    "track",
    "track_reference",
    "unwrap",
]

_H = np.array([[1.0, 0.0, 0.0]])
#: F and G of ``θ̇ = ω, ω̇ = α, α̇ = W`` (seed eq. 2)
_F = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])
_G = np.array([[0.0], [0.0], [1.0]])


@dataclass(frozen=True)
class TrackerModel:
    """The discretised tracker model: τ (s), Φ (3, 3), Q_d (3, 3), R (rad²), Qc (rad²/s⁵)."""

    tau: float
    Phi: np.ndarray
    Qd: np.ndarray
    R: float
    qc: float

    @classmethod
    def of(cls, qc: float, r: float, tau: float) -> TrackerModel:
        """Van Loan discretisation of seed eq. (2) over τ (seed eq. 4)."""
        Phi, Qd = van_loan(_F, _G, np.array([[qc]]), tau)
        return cls(tau=tau, Phi=Phi, Qd=Qd, R=float(r), qc=float(qc))


@dataclass(frozen=True)
class Track:
    """Output of the tracker over N measurements.

    x : (N, 3) posterior [θ, ω, α]; P : (N, 3, 3) posterior covariances or None;
    innovation : (N,) ``z − θ⁻``; S : (N,) innovation variances; x_last (3,), P_last (3, 3):
    the final posterior (the state to carry into the next chunk).
    """

    x: np.ndarray
    P: np.ndarray | None
    innovation: np.ndarray
    S: np.ndarray
    x_last: np.ndarray
    P_last: np.ndarray

    @property
    def standardized(self) -> np.ndarray:
        """Innovations divided by their predicted standard deviations, (N,)."""
        return self.innovation / np.sqrt(self.S)


def track(z: np.ndarray, model: TrackerModel, x0: np.ndarray, P0: np.ndarray, *,
          store_covariance: bool = False) -> Track:
    """Run the tracker over the measurements `z` (N,) (rad) from the posterior `x0` (3,),
    `P0` (3, 3) one step before the first measurement (seed eqs. 5–9; numba kernel)."""
    from gcalign.realtime._kernel import track_kernel

    z = np.ascontiguousarray(z, dtype=float)
    n = len(z)
    x = np.array(x0, dtype=float)
    P = np.array(P0, dtype=float)
    x_out = np.empty((n, 3))
    P_out = np.empty((n if store_covariance else 0, 3, 3))
    innov, S = np.empty(n), np.empty(n)
    track_kernel(z, model.Phi, model.Qd, model.R, x, P, x_out, P_out, innov, S,
                 store_covariance)
    return Track(x=x_out, P=P_out if store_covariance else None, innovation=innov, S=S,
                 x_last=x, P_last=P)


def track_reference(z: np.ndarray, model: TrackerModel, x0: np.ndarray,
                    P0: np.ndarray) -> Track:
    """The same tracker through :func:`gcalign.estimation.kalman.predict` and ``update``
    (slow; the reference the numba kernel is checked against)."""
    x, P = np.array(x0, dtype=float), np.array(P0, dtype=float)
    Rm = np.array([[model.R]])
    xs, Ps, ys, Ss = [], [], [], []
    for zk in np.asarray(z, dtype=float):
        x, P = kf_predict(x, P, model.Phi, model.Qd)
        u = kf_update(x, P, np.array([zk]), _H, Rm)
        x, P = u.x, u.P
        xs.append(x)
        Ps.append(P)
        ys.append(u.innovation[0])
        Ss.append(u.S[0, 0])
    return Track(x=np.array(xs), P=np.array(Ps), innovation=np.array(ys), S=np.array(Ss),
                 x_last=x, P_last=P)


def steady_state(model: TrackerModel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Steady-state prior covariance P⁻ (3, 3), gain K (3,) and posterior P⁺ (3, 3).

    P⁻ solves the filter Riccati equation ``P = Φ P Φᵀ − Φ P Hᵀ (H P Hᵀ + R)⁻¹ H P Φᵀ + Q``
    (``scipy.linalg.solve_discrete_are`` with ``a = Φᵀ``, ``b = Hᵀ``). The entries of P span
    eleven decades (θ in rad, α in rad/s²), so the equation is solved for the state scaled
    by ``D = diag(1, τ, τ²)`` and the result polished by iterating the Riccati map (a
    contraction at the steady state) until it no longer changes.
    """
    from scipy.linalg import solve_discrete_are  # scipy.linalg only where used (start-up)

    d = np.array([1.0, model.tau, model.tau**2]) / math.sqrt(model.R)
    D = np.diag(d)
    Phi_s, Q_s = D @ model.Phi @ np.linalg.inv(D), D @ model.Qd @ D
    Pm = solve_discrete_are(Phi_s.T, _H.T, Q_s, np.array([[1.0]]))
    Pm = np.linalg.inv(D) @ Pm @ np.linalg.inv(D)
    for _ in range(10000):
        K = Pm[:, 0] / (Pm[0, 0] + model.R)
        nxt = model.Phi @ (Pm - np.outer(K, Pm[0])) @ model.Phi.T + model.Qd
        nxt = 0.5 * (nxt + nxt.T)
        done = np.all(np.abs(nxt - Pm) <= 1e-14 * np.abs(Pm))
        Pm = nxt
        if done:
            break
    K = Pm[:, 0] / (Pm[0, 0] + model.R)
    Pp = Pm - np.outer(K, Pm[0])
    return Pm, K, 0.5 * (Pp + Pp.T)


def unwrap(angles: np.ndarray, previous: np.ndarray | None = None) -> np.ndarray:
    """Unwrap angle series (N, 3) (rad) along time, continuing from `previous` (3,) — the
    last unwrapped value of the preceding chunk — so that chunks join without jumps."""
    a = np.asarray(angles, dtype=float)
    if previous is None:
        return np.unwrap(a, axis=0)
    prev = np.asarray(previous, dtype=float)
    # np.unwrap keeps the first element (`previous`) and moves each later one by 2πk
    return np.unwrap(np.concatenate([prev[None], a]), axis=0)[1:]


# ---------------------------------------------------------------------------- least squares

def ls_weights(m: float | np.ndarray) -> np.ndarray:
    """Weights of ``(y_{k−2}, y_{k−1}, y_k)`` giving the interpolating parabola at local time
    ``m τ`` (seed eqs. 10–12 in local time ``x ∈ {−2τ, −τ, 0}``), shape (..., 3)."""
    m = np.asarray(m, dtype=float)
    return np.stack([0.5 * m * (m + 1), -m * (m + 2), 0.5 * (m + 1) * (m + 2)], -1)


def ls_fit(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Seed eq. (12) as printed: ``a = (XᵀX)⁻¹ XᵀY`` with rows ``[1, x, x²]`` (absolute x).

    Kept to show why gcalign fits in local time: at t ≈ 1e5 s the normal equations have a
    condition number of ~1e40 and the coefficients are noise (tested).
    """
    x = np.asarray(x, dtype=float)
    X = np.stack([np.ones_like(x), x, x * x], -1)
    return np.linalg.solve(X.T @ X, X.T @ np.asarray(y, dtype=float))


def horizon_weights(horizon: np.ndarray, tau: float) -> tuple[np.ndarray, np.ndarray]:
    """Weights ``(W_ω, W_α)``, each (..., 3), of ``(·_{k−2}, ·_{k−1}, ·_k)`` such that the
    reconstructed seed eq. (13) reads ``θ̂ = θ_k + W_ω·ω + W_α·α``.

    With n = ⌊H/τ⌋ and r = H − nτ: ``W_ω = τ Σ_{i<n} L(i) + r L(n)`` and
    ``W_α = ½τ² Σ_{i<n} L(i) + ½r² L(n)``, L the weights of :func:`ls_weights`; the sums in
    closed form from ``Σ i = n(n−1)/2`` and ``Σ i² = (n−1)n(2n−1)/6``.
    """
    h = np.asarray(horizon, dtype=float)
    if np.any(h < 0):
        raise ValueError(f"prediction horizon must be ≥ 0, got min {float(h.min())!r}")
    n = np.floor(h / tau + 1e-9)
    r = np.maximum(h - n * tau, 0.0)
    s1 = 0.5 * n * (n - 1)
    s2 = (n - 1) * n * (2 * n - 1) / 6.0
    sum_L = np.stack([0.5 * (s2 + s1), -(s2 + 2 * s1), 0.5 * (s2 + 3 * s1 + 2 * n)], -1)
    Ln = ls_weights(n)
    W_omega = tau * sum_L + r[..., None] * Ln
    W_alpha = 0.5 * tau * tau * sum_L + 0.5 * (r * r)[..., None] * Ln
    return W_omega, W_alpha


# ---------------------------------------------------------------------------- predictors

def predict_kalman_ls(states: np.ndarray, horizon: np.ndarray | float, tau: float) -> np.ndarray:
    """The seed's predictor: reconstructed eq. (13) on the LS-extrapolated ω, α.

    Parameters
    ----------
    states : (..., 3, 3) float
        Tracker states ``[θ, ω, α]`` at steps k−2, k−1, k (axis −2), rad, rad/s, rad/s².
    horizon : (...,) float, s
        ``Tdelay = T + Δt``.
    tau : float, s

    Returns
    -------
    (...,) predicted θ at the pulse time (rad).
    """
    s = np.asarray(states, dtype=float)
    W_omega, W_alpha = horizon_weights(np.broadcast_to(horizon, s.shape[:-2]), tau)
    return (s[..., 2, 0] + np.sum(W_omega * s[..., 1], -1)
            + np.sum(W_alpha * s[..., 2], -1))


def predict_taylor(states: np.ndarray, horizon: np.ndarray | float, tau: float) -> np.ndarray:
    """``θ_k + ω_k H + ½ α_k H²`` from the latest state (baseline; PSINS ``insextrap`` is the
    first-order term). Same shapes as :func:`predict_kalman_ls`."""
    s = np.asarray(states, dtype=float)[..., 2, :]
    h = np.asarray(horizon, dtype=float)
    return s[..., 0] + s[..., 1] * h + 0.5 * s[..., 2] * h * h


#: predictors that extrapolate the tracker's states; ``none`` is the latched attitude itself
_PREDICT = {"taylor": predict_taylor, "kalman-ls": predict_kalman_ls}


def run_predictor(name: str, states: np.ndarray, horizon: np.ndarray | float,
                  tau: float) -> np.ndarray:
    """Dispatch to an extrapolating predictor by name (``taylor``, ``kalman-ls``)."""
    try:
        f = _PREDICT[name]
    except KeyError:
        raise ValueError(f"predictor must be one of {tuple(_PREDICT)}, got {name!r}") from None
    return f(states, horizon, tau)


# ---------------------------------------------------------------------------- frequency domain

def prediction_response(freq_hz: np.ndarray, model: TrackerModel, horizon: float,
                        predictor: str = "kalman-ls") -> np.ndarray:
    """Transfer function G(e^{jωτ}) from the observation z_k to the prediction, with the
    steady-state gain (the tracker is then LTI; spec 003 §5 test 8), (F,) complex.

    ``x̂_k = A x̂_{k−1} + K z_k`` with ``A = (I − K H) Φ``, so ``X = (I − A z⁻¹)⁻¹ K Z``; the
    prediction is ``c_0 X + c_1 z⁻¹ X + c_2 z⁻² X`` with rows c from the predictor's weights.
    """
    _, K, _ = steady_state(model)
    A = (np.eye(3) - np.outer(K, _H[0])) @ model.Phi
    tau = model.tau
    c = np.zeros((3, 3))  # c[lag] · x̂_{k−lag}
    if predictor == "kalman-ls":
        W_omega, W_alpha = horizon_weights(np.array(horizon), tau)
        for lag in range(3):
            c[lag, 1] = W_omega[2 - lag]
            c[lag, 2] = W_alpha[2 - lag]
        c[0, 0] = 1.0
    elif predictor == "taylor":
        c[0] = [1.0, horizon, 0.5 * horizon**2]
    elif predictor == "none":  # the observation itself, without the tracker
        return np.ones(np.size(freq_hz), dtype=complex)
    else:
        raise ValueError(f"predictor must be one of {tuple(_PREDICT)}, got {predictor!r}")
    zinv = np.exp(-2j * np.pi * np.atleast_1d(np.asarray(freq_hz, dtype=float)) * tau)
    out = np.empty(len(zinv), dtype=complex)
    for i, zi in enumerate(zinv):
        X = np.linalg.solve(np.eye(3) - A * zi, K)
        out[i] = (c[0] + c[1] * zi + c[2] * zi * zi) @ X
    return out


def swing_residual(freq_hz: np.ndarray, amplitude: float, model: TrackerModel, delay: float,
                   dt: float = 0.0, predictor: str = "kalman-ls",
                   observation: np.ndarray | None = None) -> np.ndarray:
    """Residual amplitude (rad) of the prediction of a swing ``A sin ωt`` with pulses Δt =
    `dt` after the solution instants: ``A |G(e^{jωτ}) · O(f) · e^{−jωΔt} − 1|``.

    ``O(f)`` is the response of the observation z_k to the truth at the solution instants:
    by default a pure delay by `delay` (the T the predictor assumes), ``e^{−jωT}``, as in
    spec 003 §5 test 8; pass ``FilterChain.response(f)`` for the real chain (its phase and
    its passband droop). Shape (F,).
    """
    f = np.atleast_1d(np.asarray(freq_hz, dtype=float))
    w = 2.0 * np.pi * f
    O = np.exp(-1j * w * delay) if observation is None else np.asarray(observation)
    G = prediction_response(f, model, delay + dt, predictor)
    return amplitude * np.abs(G * O * np.exp(-1j * w * dt) - 1.0)
