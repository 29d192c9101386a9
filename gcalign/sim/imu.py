"""IMU data blocks, ideal increments from truth, and the sensor error model.

Increments follow PSINS: sample k holds the gyro angle increment Δθ_k (rad) and the
velocity increment Δv_k (m/s) over (t_k - T, t_k], both in the body frame.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from gcalign.nav import earth
from gcalign.nav.rotation import dcm_to_quat, quat_conj, quat_mult, quat_to_rotvec


@dataclass(frozen=True)
class ImuData:
    """A block of IMU increments.

    Attributes
    ----------
    t : (N,) float, s. End time of each increment.
    dtheta : (N, 3) float, rad. Gyro angle increments in the body frame.
    dv : (N, 3) float, m/s. Velocity increments (integrated specific force) in the body frame.
    ts : float, s. Sample interval.
    site : (3,) float or None. ``[lat (rad), lon (rad), height (m)]`` if the source gives it.
    att0 : (3,) float or None. Initial ``[pitch, roll, yaw]`` (rad) if the source gives it.
    v0_n : (3,) float or None. Initial ENU velocity (m/s) if the source gives it.
    source : str. Where the data came from (file path or "simulated").
    """

    t: np.ndarray
    dtheta: np.ndarray
    dv: np.ndarray
    ts: float
    site: np.ndarray | None = None
    att0: np.ndarray | None = None
    v0_n: np.ndarray | None = None
    source: str = "simulated"
    meta: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.t)


@dataclass(frozen=True)
class SensorErrors:
    """Errors of one sensor triad (SI).

    bias : (3,) rad/s (gyro) or m/s² (accel).
    noise : (3,) white-noise density: ARW in rad/√s or VRW in m/s/√s; per-sample std of an
        increment is ``noise * sqrt(ts)``.
    scale : (3,) scale-factor errors (fraction).
    misalignment : (3, 3) small-angle non-orthogonality; zero diagonal. The measured
        increment is ``(I + diag(scale) + misalignment) @ ideal``.
    quantum : increment quantisation step (rad or m/s); 0 disables it.
    """

    bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    noise: np.ndarray = field(default_factory=lambda: np.zeros(3))
    scale: np.ndarray = field(default_factory=lambda: np.zeros(3))
    misalignment: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    quantum: float = 0.0

    def matrix(self) -> np.ndarray:
        """``I + diag(scale) + misalignment``, shape (3, 3)."""
        return np.eye(3) + np.diag(self.scale) + self.misalignment


@dataclass(frozen=True)
class ImuErrors:
    gyro: SensorErrors = field(default_factory=SensorErrors)
    accel: SensorErrors = field(default_factory=SensorErrors)


def _corrupt(ideal, err: SensorErrors, ts: float, rng: np.random.Generator):
    out = ideal @ err.matrix().T + err.bias * ts
    out = out + rng.standard_normal(ideal.shape) * (np.asarray(err.noise) * np.sqrt(ts))
    if err.quantum > 0:
        # A quantiser keeps its remainder: quantise the running sum, then difference it.
        total = np.round(np.cumsum(out, axis=0) / err.quantum) * err.quantum
        out = np.diff(total, axis=0, prepend=np.zeros((1, 3)))
    return out


def apply_errors(ideal: ImuData, errors: ImuErrors, rng: np.random.Generator) -> ImuData:
    """Measured increments from ideal ones: scale/misalignment, bias, white noise, quantum.

    Gyro noise is drawn before accelerometer noise, so a seed fixes both.
    """
    dtheta = _corrupt(ideal.dtheta, errors.gyro, ideal.ts, rng)
    dv = _corrupt(ideal.dv, errors.accel, ideal.ts, rng)
    return replace(ideal, dtheta=dtheta, dv=dv)


def ideal_imu(motion, site, ts: float, substeps: int = 2):
    """Truth and exact ideal increments for `motion` at `site` ``[lat, lon, h]`` (rad, m).

    Gyro: ``Δθ_k = rotvec(q_ib(k-1)^* ⊗ q_ib(k))`` with ``q_ib = q_ie(t) ⊗ q_en(L, λ) ⊗ q_nb``
    (inertial frame = ECEF at t = 0), so an ideal strapdown update reproduces truth.
    Accelerometer: ``Δv_k = ∫ f_b dt`` by Simpson's rule on `substeps` (even) sub-intervals,
    with ``f_n = v̇_n + (2ω_ie^n + ω_en^n) × v_n - g_n`` (the specific force at rest points up).
    Segment boundaries fall on sample times (the config enforces it), so f_b is smooth
    inside every sample and Simpson's error is below 1e-12 m/s per sample here.

    Returns ``(Truth, ImuData)``; truth has N+1 samples from t = 0, the IMU N increments.
    """
    from gcalign.sim.motions import Truth, integrate_position, kinematics, sample_count, sample_grid

    if substeps % 2:
        raise ValueError(f"substeps must be even for Simpson's rule, got {substeps}")
    n = sample_count(motion.duration, ts)
    grid, mid = sample_grid(n, ts, substeps)
    m = substeps + 1
    att, C_nb, v_n, a_n = kinematics(motion, grid.ravel(), np.repeat(mid, m))
    # Attitude and velocity are continuous: one time line of sub-points for the position.
    line = np.r_[(np.arange(n)[:, None] * m + np.arange(substeps)).ravel(), n * m - 1]
    pos_line = integrate_position(grid.ravel()[line], v_n[line], site)
    pos = np.concatenate(
        [pos_line[:-1].reshape(n, substeps, 3), pos_line[substeps::substeps][:, None]], 1
    ).reshape(-1, 3)
    lat, h = pos[:, 0], pos[:, 2]
    w = 2.0 * earth.omega_ie_n(lat) + earth.omega_en_n(lat, h, v_n)
    f_n = a_n + np.cross(w, v_n)
    f_n[:, 2] += earth.gravity(lat, h)
    f_b = np.einsum("kji,kj->ki", C_nb, f_n).reshape(n, m, 3)
    # Composite Simpson over each sample's sub-intervals.
    weights = np.ones(m)
    weights[1:-1:2], weights[2:-1:2] = 4.0, 2.0
    weights *= (ts / substeps) / 3.0
    dv = np.einsum("j,kjc->kc", weights, f_b)

    k = np.r_[np.arange(n) * m, n * m - 1]  # sample times: row starts, then the last end
    t, att_s, pos_s = grid.ravel()[k], att[k], pos[k]
    half = 0.5 * earth.OMEGA_IE * t
    q_ie = np.stack([np.cos(half), 0 * half, 0 * half, np.sin(half)], -1)
    q_ib = quat_mult(
        quat_mult(q_ie, dcm_to_quat(earth.C_en(pos_s[:, 0], pos_s[:, 1]))), dcm_to_quat(C_nb[k])
    )
    dtheta = quat_to_rotvec(quat_mult(quat_conj(q_ib[:-1]), q_ib[1:]))

    truth = Truth(t=t, att=att_s, v_n=v_n[k].copy(), pos=pos_s)
    return truth, ImuData(t=t[1:], dtheta=dtheta, dv=dv, ts=ts, site=np.asarray(site, float))
