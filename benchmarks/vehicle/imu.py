"""IMU increments of the vehicle: the ideal ones integrated from the closed-form rates, and
the sensor errors of a KF-GINS-grade IMU drawn on top.

Ideal: Δθ_k = ∫ ω_ib^b dt and Δv_k = ∫ f^b dt over (t_{k−1}, t_k], what a strapdown IMU
outputs (the integrals of its rates in the body frame; coning and sculling are the
navigation's work). Each interval is cut at the motion's joins (where a derivative jumps)
and each piece integrated by 5-point Gauss-Legendre: the integrands are smooth on every
piece, so the sums are exact to round-off.

Errors (:class:`ImuErrors`, KF-GINS's model and units): per axis a gyro bias, an
accelerometer bias and the two scale factors, each a first-order Gauss-Markov process of
standard deviation σ and correlation time τ (stationary: the start drawn from N(0, σ²),
then x_{k+1} = e^{−Δt/τ} x_k + σ √(1 − e^{−2Δt/τ}) w_k), and white noise from the angle and
velocity random walks (σ √Δt per sample). Measured::

    Δθ_m = (1 + s_g) ∘ Δθ + b_g Δt + n_g        Δv_m = (1 + s_a) ∘ Δv + b_a Δt + n_a

(KF-GINS compensates Δθ = (Δθ_m − b_g Δt) / (1 + s_g), the same model.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from benchmarks.vehicle.trajectory import Trajectory

_GL_X, _GL_W = np.polynomial.legendre.leggauss(5)
DEG, HOUR = np.pi / 180.0, 3600.0
MGAL, PPM = 1e-5, 1e-6


@dataclass(frozen=True)
class ImuErrors:
    """A KF-GINS ``imunoise`` block in its units: ARW °/√h, VRW m/s/√h, bias std °/h and
    mGal, scale-factor std ppm, correlation time h (default: KF-GINS's Leador-A15 values)."""

    arw: float = 0.003
    vrw: float = 0.03
    gbstd: float = 0.027
    abstd: float = 15.0
    gsstd: float = 300.0
    asstd: float = 300.0
    corrtime: float = 4.0

    def si(self) -> dict[str, float]:
        """The same in SI: rad/√s, m/s/√s, rad/s, m/s², −, −, s."""
        return {"arw": self.arw * DEG / 60.0, "vrw": self.vrw / 60.0,
                "gbstd": self.gbstd * DEG / HOUR, "abstd": self.abstd * MGAL,
                "gsstd": self.gsstd * PPM, "asstd": self.asstd * PPM,
                "corrtime": self.corrtime * HOUR}


def ideal_increments(traj: Trajectory, t: np.ndarray, chunk: int = 20000
                     ) -> tuple[np.ndarray, np.ndarray]:
    """``(Δθ, Δv)`` (N, 3) over the intervals (t[k−1], t[k]], k = 1 … N (`t` (N+1,) s from
    the route's start), body FRD, rad and m/s."""
    joins = traj.join_times()
    dtheta = np.empty((len(t) - 1, 3))
    dv = np.empty((len(t) - 1, 3))
    for k0 in range(0, len(t) - 1, chunk):
        k1 = min(k0 + chunk, len(t) - 1)
        edges = t[k0:k1 + 1]
        inner = joins[(joins > edges[0]) & (joins < edges[-1])]
        cuts = np.union1d(edges, inner)
        lo, hi = cuts[:-1], cuts[1:]
        nodes = 0.5 * (lo + hi)[:, None] + 0.5 * (hi - lo)[:, None] * _GL_X[None, :]
        st = traj.state(nodes.ravel())
        wgt = (0.5 * (hi - lo)[:, None] * _GL_W[None, :]).ravel()[:, None]
        w_int = (st.omega_ib_b * wgt).reshape(len(lo), len(_GL_X), 3).sum(1)
        f_int = (st.f_b * wgt).reshape(len(lo), len(_GL_X), 3).sum(1)
        owner = np.searchsorted(edges, lo, side="right") - 1  # interval of each piece
        starts = np.flatnonzero(np.r_[True, owner[1:] != owner[:-1]])
        dtheta[k0:k1] = np.add.reduceat(w_int, starts, axis=0)
        dv[k0:k1] = np.add.reduceat(f_int, starts, axis=0)
    return dtheta, dv


def gauss_markov(rng: np.random.Generator, n: int, sigma: float, tau: float, dt: float,
                 width: int = 3) -> np.ndarray:
    """(n, width) samples of `width` stationary first-order Gauss-Markov processes of
    standard deviation `sigma` and correlation time `tau` s, sampled every `dt` s."""
    phi = np.exp(-dt / tau)
    drive = sigma * np.sqrt(1.0 - phi * phi) * rng.standard_normal((n, width))
    drive[0] = sigma * rng.standard_normal(width)
    out = np.empty((n, width))
    x = np.zeros(width)
    # x_k = φ x_{k−1} + w_k: a linear recursion, run as a scaled cumulative sum in blocks
    # short enough that φ^−k stays finite (φ^−k ≤ e^{block Δt/τ})
    block = max(1, int(50.0 * tau / dt))
    for b0 in range(0, n, block):
        w = drive[b0:b0 + block]
        k = np.arange(len(w))[:, None]
        out[b0:b0 + len(w)] = phi ** (k + 1) * x + phi**k * np.cumsum(w * phi ** -k, axis=0)
        x = out[b0 + len(w) - 1]
    return out


@dataclass(frozen=True)
class SensorTruth:
    """The errors drawn for every sample (N, 3) in SI: gyro bias rad/s, accelerometer bias
    m/s², scale factors (−)."""

    gyro_bias: np.ndarray
    accel_bias: np.ndarray
    gyro_scale: np.ndarray
    accel_scale: np.ndarray


def sensor_processes(n: int, dt: float, errors: ImuErrors, rng: np.random.Generator
                     ) -> SensorTruth:
    """The four Gauss–Markov processes (gyro bias, accelerometer bias, gyro and
    accelerometer scale factors) over `n` samples, drawn in that order from `rng`."""
    e = errors.si()
    return SensorTruth(*(gauss_markov(rng, n, e[k], e["corrtime"], dt)
                         for k in ("gbstd", "abstd", "gsstd", "asstd")))


def measured(dtheta: np.ndarray, dv: np.ndarray, dt: float, errors: ImuErrors,
             rng_processes: np.random.Generator, rng_noise: np.random.Generator
             ) -> tuple[np.ndarray, np.ndarray, SensorTruth]:
    """``(Δθ_m, Δv_m, truth)``: the ideal increments with the drawn errors (module
    docstring)."""
    e = errors.si()
    n = len(dtheta)
    truth = sensor_processes(n, dt, errors, rng_processes)
    noise = rng_noise.standard_normal((n, 6))
    dth = ((1.0 + truth.gyro_scale) * dtheta + truth.gyro_bias * dt
           + e["arw"] * np.sqrt(dt) * noise[:, :3])
    dvm = ((1.0 + truth.accel_scale) * dv + truth.accel_bias * dt
           + e["vrw"] * np.sqrt(dt) * noise[:, 3:])
    return dth, dvm, truth
