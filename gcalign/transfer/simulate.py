"""A simulated transfer-alignment case with the truth known (spec 006, "Tests" 1).

The vehicle drives forward at constant speed and heading while rocking in roll (a triangle
wave of constant roll rates, a :class:`gcalign.sim.motions.Moving` of segments, whose
exact ideal increments come from :func:`gcalign.sim.imu.ideal_imu`). The slave IMU sits on
the same body turned by the mounting misalignment μ: ``q_nb,slave = q_nb ⊗ q(μ)`` (as the
data's ``qnb_mems = qnb_fog ∘ rv2q(mu0)``), so its increments are the body's rotated by
``C(μ)ᵀ`` (a constant rotation), plus constant biases ε, ∇ and white noise (ARW, VRW). The
master is the truth at 10 Hz with white attitude noise (a misalignment, rad) and velocity
noise. The filter settings of the case match that noise, so NEES tests consistency.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike

from gcalign.nav.rotation import (
    euler_to_dcm,
    euler_to_quat,
    misalignment_q,
    quat_mult,
    quat_to_dcm,
    quat_to_euler,
    rotvec_to_quat,
)
from gcalign.sim.imu import ImuData, ideal_imu
from gcalign.sim.motions import Moving, Segment, Truth
from gcalign.transfer.filter import EB, MU, PHI, MasterSeries, TransferResult, TransferSettings
from gcalign.units import ARCMIN, DEG, DPH, DPSH, UG, UGPSHZ

SITE = (np.radians(34.0), np.radians(108.9), 400.0)


@dataclass(frozen=True)
class TransferCase:
    """Slave increments dtheta, dv (N, 3) at t (N,); the master; the truth at the IMU rate
    (N + 1 samples from t = 0, body = master frame); the injected μ (3,) rad, ε (3,) rad/s,
    ∇ (3,) m/s²; att0 (3,) the slave's initial attitude, its error φ0 drawn from the case's
    P0 independently of μ; lever_arm_b (3,) m (slave axes) and v_lever_n (N + 1, 3) the
    slave's velocity relative to the master's; the filter settings that match the case."""

    dtheta: np.ndarray
    dv: np.ndarray
    t: np.ndarray
    master: MasterSeries
    truth: Truth
    mu: np.ndarray
    eb: np.ndarray
    db: np.ndarray
    att0: np.ndarray
    lever_arm_b: np.ndarray
    v_lever_n: np.ndarray
    settings: TransferSettings


def wing_rock(duration: float, speed: float = 12.0, yaw: float = 30 * DEG,
              roll_amplitude: float = 20 * DEG, roll_rate: float = 10 * DEG) -> Moving:
    """Constant speed and heading, roll a triangle wave ±`roll_amplitude` at ±`roll_rate`."""
    quarter = roll_amplitude / roll_rate
    segs = [Segment(quarter, rate=(0.0, roll_rate, 0.0))]
    t = quarter
    sign = -1.0
    while t < duration:
        segs.append(Segment(2 * quarter, rate=(0.0, sign * roll_rate, 0.0)))
        t += 2 * quarter
        sign = -sign
    return Moving(att0=(0.0, 0.0, yaw), duration=duration, segments=tuple(segs), speed0=speed)


@lru_cache(maxsize=4)
def _ideal(duration: float, ts: float) -> tuple[Truth, ImuData]:
    return ideal_imu(wing_rock(duration), SITE, ts)


def transfer_case(rng: np.random.Generator, duration: float = 20.0, ts: float = 0.01,
                  master_every: int = 10, mu_sigma: float = 1 * DEG,
                  eb_sigma: float = 500 * DPH, db_sigma: float = 1000 * UG,
                  arw: float = 0.1 * DPSH, vrw: float = 10 * UGPSHZ,
                  master_att_sigma: float = 1 * ARCMIN, master_v_sigma: float = 0.02,
                  phi0_sigma: float = 0.1 * DEG, lever_arm_b: ArrayLike = (0.0, 0.0, 0.0),
                  settings: TransferSettings | None = None) -> TransferCase:
    """One seeded case: μ, ε, ∇ and the slave's initial attitude error φ0 drawn from
    N(0, σ²) per axis (the filter's P0), then the slave's noise and the master's, in that
    order from `rng`. The master starts one interval after the IMU (as in the real file).

    `lever_arm_b` (3,) m puts the slave at l from the master, in the slave's axes as the
    filter takes it (body axes ``l_b = C(μ) l``): its increments gain
    ``Δ(ω × l_b) + ω × (ω × l_b) T`` per step (ω the step's mean body rate; first order in
    ω T) and its true velocity is ``v + C_nb (ω × l_b)``."""
    truth, ideal = _ideal(float(duration), float(ts))
    mu = rng.normal(0.0, mu_sigma, 3)
    eb = rng.normal(0.0, eb_sigma, 3)
    db = rng.normal(0.0, db_sigma, 3)
    phi0 = rng.normal(0.0, phi0_sigma, 3)
    C_sb = quat_to_dcm(rotvec_to_quat(mu)).T  # body vectors into slave axes: C(μ)ᵀ
    n = len(ideal.t)
    lever = np.asarray(lever_arm_b, dtype=float)
    w = ideal.dtheta / ts
    w_l = np.cross(w, C_sb.T @ lever)  # ω × l_b (N, 3)
    dv_lever = np.diff(w_l, axis=0, prepend=w_l[:1]) + np.cross(w, w_l) * ts
    # the lever-arm velocity at the truth samples (the first takes the first step's rate)
    v_lever = np.einsum("kij,kj->ki", euler_to_dcm(truth.att), np.vstack([w_l[:1], w_l]))
    dtheta = ideal.dtheta @ C_sb.T + eb * ts + arw * np.sqrt(ts) * rng.standard_normal((n, 3))
    dv = (ideal.dv + dv_lever) @ C_sb.T + db * ts + vrw * np.sqrt(ts) * rng.standard_normal((n, 3))
    k = np.arange(master_every, len(truth.t), master_every)
    q_true = euler_to_quat(truth.att[k])
    noise = master_att_sigma * rng.standard_normal((len(k), 3))
    q_m = quat_mult(rotvec_to_quat(-noise), q_true)  # C_m = (I − [n×]) C_true
    v_m = truth.v_n[k] + master_v_sigma * rng.standard_normal((len(k), 3))
    master = MasterSeries(truth.t[k], quat_to_euler(q_m), v_m, truth.pos[k])
    q0_slave = quat_mult(q_true[0], rotvec_to_quat(mu))  # C_est = (I − [φ0×]) C_slave
    att0 = quat_to_euler(quat_mult(rotvec_to_quat(-phi0), q0_slave))
    base = settings or TransferSettings(flexure=False, p0_sigma=_p0(
        phi0_sigma, master_v_sigma, mu_sigma, eb_sigma, db_sigma))
    s = replace(base, arw=arw, vrw=vrw, lever_arm_b=(lever[0], lever[1], lever[2]),
                r_sigma=(master_att_sigma,) * 3 + (master_v_sigma,) * 3)
    return TransferCase(dtheta, dv, ideal.t, master, truth, mu, eb, db, att0, lever, v_lever,
                        s)


def _p0(phi0_sigma: float, dv0_sigma: float, mu_sigma: float, eb_sigma: float,
        db_sigma: float) -> tuple[float, ...]:
    """The case's P0 (15 states): σ of what the case draws. The slave starts on the
    master's velocity, so its δv0 is the master's velocity noise (the demo's 10 m/s would
    leave an unmeasured δv, under attitude matching, at a σ 500× its error)."""
    return ((phi0_sigma,) * 3 + (dv0_sigma,) * 3 + (eb_sigma,) * 3 + (db_sigma,) * 3
            + (mu_sigma,) * 3)


def estimation_error(result: TransferResult, case: TransferCase) -> np.ndarray:
    """``x̂ − x`` (K, 15) at the result's epochs: φ from the corrected slave attitude against
    the slave's true attitude ``q_nb ⊗ q(μ)``, δv from the slave velocity, the biases and μ
    from the injected values."""
    ts = float(np.median(np.diff(case.t)))
    k = np.rint(result.t / ts).astype(int)
    q_true_s = quat_mult(euler_to_quat(case.truth.att[k]), rotvec_to_quat(case.mu))
    e = np.zeros((len(k), 15))
    # the corrected attitude's misalignment is φ − φ̂ (C_est = (I − [φ×]) C_true)
    e[:, PHI] = -misalignment_q(result.q_slave, q_true_s)
    dv_true = result.v_slave - case.truth.v_n[k] - case.v_lever_n[k]
    e[:, 3:6] = result.x[:, 3:6] - dv_true
    e[:, EB] = result.x[:, EB] - case.eb
    e[:, 9:12] = result.x[:, 9:12] - case.db
    e[:, MU] = result.x[:, MU] - case.mu
    return e
