"""The 21-state calibration Kalman filter over a navigation run (seed 002 §2, §5.2; spec §2).

Navigation runs at the data rate (25 Hz in the seed) with the sensors compensated by the
current estimates; the filter predicts and updates at ``filter_rate`` (1 Hz), which must
divide the navigation rate. Per filter step of S navigation steps:

1. compensate the increments (PSINS ``ω = Kg ω̃ − ε``, per axis, written in the sensor
   model's own parameters): ``Δθ = (Δθ̃ − ε̂ ts)/(1 + δK̂g)``, ``Δv = (Δṽ − ∇̂ ts)/(1 + δK̂a)``;
2. navigate the S steps with :func:`gcalign.nav.strapdown.navigate` from the corrected state;
3. Φ, Q_d from F (:func:`gcalign.estimation.ins_error.error_matrix`) at the middle of each
   navigation step, either accumulated step by step (default) or by Van Loan on the mean F
   over the step (spec §2 [X] offers both; on a 9°/s turn the accumulated Φ matches the
   nonlinear mechanisation to 1e-4 of the one-second change and Van Loan on the mean F
   to 1e-2, ``tests/test_ins_error.py``);
4. predict, and update in Joseph form (:func:`gcalign.estimation.kalman.update`) with
   z = INS − reference (+ noise): horizontal velocity, horizontal position in metres, or both;
   an aiding antenna at a lever arm (``FlightData.lever_arm_v_b``, ``lever_arm_p_b``) adds
   the INS's prediction of the antenna's offset to z and its φ, ε, δKg columns to H
   (:func:`gcalign.estimation.ins_error.lever_arm_terms`, where the terms are derived);
5. closed loop (default): feed the estimate back and reset it, ``C_nb ← exp([φ̂×]) C_nb``,
   ``v −= δv̂``, ``p −= δp̂``, and for the sensors the exact composition
   ``ε̂ += (1 + δK̂g) x_ε``, ``1 + δK̂g ← (1 + δK̂g)(1 + x_δKg)`` (likewise ∇, δKa), so that
   the reported ε̂, δK̂g are directly the parameters of ``ω̃ = (I + diag δKg) ω + ε``
   (PSINS ``Kg = (I − dKg) Kg``, ``eb += x`` is its first-order form).
   Feed-forward: the INS runs free and the state is not reset.

The filter's state is then always the error of the current INS solution and of the
compensation in force; with the truth known, the same quantity gives NEES.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gcalign.calibrate.data import FlightData, Trajectory
from gcalign.errors import ScenarioError
from gcalign.estimation import ins_error as ie
from gcalign.estimation.ins_error import DB, DKA, DKG, DP, DV, EB, IMU, N_STATES, NAV, PHI
from gcalign.estimation.kalman import nees as nees_of
from gcalign.estimation.kalman import predict, rts, update, van_loan
from gcalign.nav.earth import WGS84, EarthModel
from gcalign.nav.rotation import (
    euler_to_quat,
    quat_conj,
    quat_mult,
    quat_to_dcm,
    quat_to_euler,
    quat_to_rotvec,
    rotvec_to_quat,
)
from gcalign.nav.strapdown import NavState, navigate

DISCRETIZATIONS = ("accumulated", "van_loan")


@dataclass(frozen=True)
class Settings:
    """Filter settings (SI). Defaults are the seed's numbers and spec 002's proposals.

    measure : "velocity" | "position" | "both" (seed eqs. 5–7).
    sigma_v, sigma_p : measurement standard deviations, m/s and m (R = σ², seed §5.2).
    p0_scale : P0 = diag((p0_scale · σ_listed)²); 10 reads the seed's "×10" (spec §2 [R]).
    p0_sigma : (21,) SI σ replacing the seed's list, or None.
    arw, vrw : white-noise densities for Q, rad/√s and m/s/√s (spec §2 [X]).
    filter_rate : Hz; must divide the navigation rate.
    discretization : "accumulated" (Φ over the navigation steps) or "van_loan".
    feedback : closed loop (True) or feed-forward (False).
    gnss_noise : add measurement noise of σ (sigma_v, sigma_p) to the reference.
    smoother : also run the RTS smoother (keeps Φ and P of every filter step).
    """

    measure: str = "velocity"
    sigma_v: float = 0.2
    sigma_p: float = 1.0
    p0_scale: float = ie.P0_SCALE_DEFAULT
    p0_sigma: tuple[float, ...] | None = None
    arw: float = ie.ARW_DEFAULT
    vrw: float = ie.VRW_DEFAULT
    filter_rate: float = 1.0
    discretization: str = "accumulated"
    feedback: bool = True
    gnss_noise: bool = True
    smoother: bool = False

    def steps_per_update(self, ts: float) -> int:
        """Navigation steps per filter step; checks every setting (ScenarioError, one line)."""
        ie.measurement_noise(self.measure, self.sigma_v, self.sigma_p)
        ie.process_noise_density(self.arw, self.vrw)
        if self.discretization not in DISCRETIZATIONS:
            raise ScenarioError(f"discretization: got {self.discretization!r}, allowed: "
                                f"{', '.join(DISCRETIZATIONS)}")
        rate = 1.0 / ts
        if not (np.isfinite(self.filter_rate) and self.filter_rate > 0):
            raise ScenarioError(f"filter_rate: must be a positive number of Hz, got "
                                f"{self.filter_rate!r}")
        ratio = rate / self.filter_rate
        if ratio < 1.0 - 1e-9 or abs(ratio - round(ratio)) > 1e-6 * ratio:
            divisors = [rate / n for n in range(1, int(rate) + 1) if (rate / n).is_integer()]
            raise ScenarioError(f"filter_rate: must be the navigation rate {rate:g} Hz divided by "
                                f"a whole number (e.g. {', '.join(f'{d:g}' for d in divisors)} Hz),"
                                f" got {self.filter_rate:g}")
        return int(round(ratio))

    def covariances(self, pos: np.ndarray,
                    earth: EarthModel = WGS84) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(P0, Qc, R)`` at the start position `pos`."""
        sigma = None if self.p0_sigma is None else np.asarray(self.p0_sigma, dtype=float)
        return (ie.initial_covariance(pos, self.p0_scale, sigma, earth),
                ie.process_noise_density(self.arw, self.vrw),
                ie.measurement_noise(self.measure, self.sigma_v, self.sigma_p))


@dataclass(frozen=True)
class Smoothed:
    """RTS-smoothed estimates at the filter epochs: estimate and sigma (K+1, 21), as in
    :class:`CalibrationResult` (IMU part: the sensor parameters, navigation part: the error
    of the INS solution before the update at that epoch)."""

    estimate: np.ndarray
    sigma: np.ndarray


@dataclass(frozen=True)
class CalibrationResult:
    """A calibration run at the filter epochs ``t`` (K+1,), t[0] the start (no update).

    estimate, sigma : (K+1, 21). IMU part (states 9–20): the estimated sensor parameters
        ε, ∇, δKg, δKa of ``ω̃ = (I + diag δKg) ω + ε`` after the update at t (feed-forward:
        the filter state). Navigation part: the estimated error of the INS solution at t
        before the correction. σ: posterior standard deviation of the filter state.
    truth : (K+1, 21) the same quantities from the truth (None for recorded data).
    nees : (K+1,) NEES of the filter state against the truth (None without truth).
    innovation, standardized : (K, m) z − H x⁻ and its whitened form (~ N(0, 1)).
    nis : (K,) normalised innovation squared (~ χ²_m).
    att, v_n, pos : (K+1, 3) the corrected INS solution at the epochs.
    measure_names : names of the m measurement components.
    """

    t: np.ndarray
    estimate: np.ndarray
    sigma: np.ndarray
    truth: np.ndarray | None
    nees: np.ndarray | None
    innovation: np.ndarray
    standardized: np.ndarray
    nis: np.ndarray
    att: np.ndarray
    v_n: np.ndarray
    pos: np.ndarray
    measure_names: tuple[str, ...]
    settings: Settings
    smoothed: Smoothed | None = None
    names: tuple[str, ...] = field(default=ie.STATE_NAMES)

    @property
    def error(self) -> np.ndarray | None:
        """estimate − truth (K+1, 21), or None without truth."""
        return None if self.truth is None else self.estimate - self.truth


def _transition(q_nb: np.ndarray, v_n: np.ndarray, pos: np.ndarray, dtheta: np.ndarray,
                dv: np.ndarray, ts: float, Qc: np.ndarray, method: str,
                E: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Φ, Q_d over one filter step from the navigation states (S+1, …) and the compensated
    increments (S, 3) (numba kernel; the NumPy route is ``ins_error.accumulate``); `E` is
    ``EarthModel.params()``."""
    from gcalign.estimation._ins_kernel import transition_block

    Phi, Qd = np.empty((N_STATES, N_STATES)), np.empty((N_STATES, N_STATES))
    F_mean, G_mean = np.empty((N_STATES, N_STATES)), np.empty((N_STATES, 6))
    transition_block(q_nb, v_n, pos, dtheta, dv, ts, np.ascontiguousarray(np.diag(Qc)),
                     E, Phi, Qd, F_mean, G_mean)
    if method == "van_loan":
        return van_loan(F_mean, G_mean, Qc, len(dtheta) * ts)
    return Phi, Qd


def warm_up() -> None:
    """Load the compiled kernels (numba cache) of a filter step before anything is timed."""
    one = np.zeros((1, 3))
    q = np.array([[1.0, 0.0, 0.0, 0.0]] * 2)
    pos = np.array([[0.7, 0.0, 0.0]] * 2)
    _transition(q, np.zeros((2, 3)), pos, one, one, 0.04, np.eye(6), "accumulated",
                WGS84.params())
    navigate(np.array([0.04]), one, one, 0.04, NavState(q[0], np.zeros(3), pos[0]))


def _imu_residual(x_true: np.ndarray, imu: np.ndarray) -> np.ndarray:
    """Error of the compensation in force (IMU part of the state, (..., 12) for `imu`
    (..., 21)): with ``ω̃ = (1 + δKg) ω + ε`` and ``ω_c = (ω̃ − ε̂)/(1 + δK̂g)``,
    ``ω_c = (1 + x_δKg) ω + x_ε`` holds exactly for ``x_ε = (ε − ε̂)/(1 + δK̂g)``,
    ``x_δKg = (1 + δKg)/(1 + δK̂g) − 1``."""
    r = np.zeros(np.shape(imu))
    r[..., EB] = (x_true[EB] - imu[..., EB]) / (1.0 + imu[..., DKG])
    r[..., DB] = (x_true[DB] - imu[..., DB]) / (1.0 + imu[..., DKA])
    r[..., DKG] = (1.0 + x_true[DKG]) / (1.0 + imu[..., DKG]) - 1.0
    r[..., DKA] = (1.0 + x_true[DKA]) / (1.0 + imu[..., DKA]) - 1.0
    return r[..., IMU]


def _compose(imu: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Sensor parameters after feeding back the filter state x (exact; see module doc)."""
    out = imu.copy()
    out[EB] = imu[EB] + (1.0 + imu[DKG]) * x[EB]
    out[DB] = imu[DB] + (1.0 + imu[DKA]) * x[DB]
    out[DKG] = (1.0 + imu[DKG]) * (1.0 + x[DKG]) - 1.0
    out[DKA] = (1.0 + imu[DKA]) * (1.0 + x[DKA]) - 1.0
    return out


def _phi(q_est: np.ndarray, q_true: np.ndarray) -> np.ndarray:
    """Misalignment φ (..., 3) with ``C_nb,est = exp(−[φ×]) C_nb,true``: the rotation vector
    of ``q_true ⊗ q_est*`` (as :func:`gcalign.nav.rotation.misalignment`, on quaternions)."""
    return quat_to_rotvec(quat_mult(q_true, quat_conj(q_est)))


def _measurement(measure: str, v_n: np.ndarray, pos: np.ndarray, ref_v: np.ndarray,
                 ref_pos: np.ndarray, noise: np.ndarray, earth: EarthModel) -> np.ndarray:
    """z = INS − reference − noise (seed eqs. 5–7); position in metres north, east."""
    dv = v_n[:2] - ref_v[:2]
    if measure == "velocity":
        return dv - noise
    r_m, r_n = earth.radii(pos[0])
    dp = np.array([(pos[0] - ref_pos[0]) * (r_m + pos[2]),
                   (pos[1] - ref_pos[1]) * (r_n + pos[2]) * np.cos(pos[0])])
    return (dp if measure == "position" else np.concatenate([dv, dp])) - noise


def _lever_arm(value: np.ndarray, which: str) -> np.ndarray:
    """A lever arm of FlightData as (3,) finite metres; ScenarioError (one line) otherwise."""
    lever = np.asarray(value, dtype=float)
    if lever.shape != (3,) or not np.isfinite(lever).all():
        raise ScenarioError(f"lever_arm_{which}_b: must be 3 finite numbers (body x right, "
                            f"y forward, z up; m), got {np.ravel(lever).tolist()}")
    return lever


def _noise_sigma(s: Settings) -> np.ndarray:
    return np.array({"velocity": [s.sigma_v] * 2, "position": [s.sigma_p] * 2,
                     "both": [s.sigma_v] * 2 + [s.sigma_p] * 2}[s.measure])


@dataclass
class _History:
    """What the RTS smoother needs from the filter (kept only when it is asked for)."""

    Phi: np.ndarray  # (K, n, n) transition k → k+1
    P_prior: np.ndarray  # (K, n, n) prediction at k+1
    x_prior: np.ndarray  # (K, n)
    P_post: np.ndarray  # (K+1, n, n) posterior at k (k = 0: P0)
    x_post: np.ndarray  # (K+1, n)
    imu_pre: np.ndarray  # (K+1, n) sensor parameters in force during the step ending at k

    @classmethod
    def empty(cls, K: int, P0: np.ndarray) -> _History:
        n = N_STATES
        h = cls(np.zeros((K, n, n)), np.zeros((K, n, n)), np.zeros((K, n)),
                np.zeros((K + 1, n, n)), np.zeros((K + 1, n)), np.zeros((K + 1, n)))
        h.P_post[0] = P0
        return h


def calibrate(data: FlightData, settings: Settings | None = None,
              rng: np.random.Generator | None = None) -> CalibrationResult:
    """Run the calibration filter over `data` (see the module docstring for the steps).

    `rng` draws the measurement noise (needed when ``settings.gnss_noise``).
    """
    s = settings or Settings()
    ts = data.ts
    S = s.steps_per_update(ts)
    K = len(data.dtheta) // S
    if K < 1:
        raise ScenarioError(f"data: {len(data.dtheta)} navigation steps are fewer than one "
                            f"filter step ({S})")
    earth = data.earth
    E = earth.params()
    P0, Qc, R = s.covariances(data.start.pos, earth)
    m = R.shape[0]
    noise = np.zeros((K, m))
    if s.gnss_noise:
        if rng is None:
            raise ValueError("calibrate: gnss_noise needs an rng (numpy.random.Generator)")
        noise = rng.standard_normal((K, m)) * _noise_sigma(s)
    truth, x_true = data.truth, data.x_true
    if truth is None or x_true is None:
        truth = x_true = None
    lever_v, lever_p = _lever_arm(data.lever_arm_v_b, "v"), _lever_arm(data.lever_arm_p_b, "p")
    levered = bool(lever_v.any() or lever_p.any())

    est, sig = np.zeros((K + 1, N_STATES)), np.zeros((K + 1, N_STATES))
    innov, stdz, nis = np.zeros((K, m)), np.zeros((K, m)), np.zeros(K)
    quat, vel, posn = np.zeros((K + 1, 4)), np.zeros((K + 1, 3)), np.zeros((K + 1, 3))
    # what the errors against the truth need, evaluated after the loop in whole arrays:
    # the INS solution before each correction, the compensation in force, x⁺ and P⁺
    pre_q, pre_v, pre_p = np.zeros((K + 1, 4)), np.zeros((K + 1, 3)), np.zeros((K + 1, 3))
    in_force, x_all = np.zeros((K + 1, N_STATES)), np.zeros((K + 1, N_STATES))
    P_all = np.zeros((K + 1, N_STATES, N_STATES))
    hist = _History.empty(K, P0) if s.smoother else None

    q, v, p = (np.asarray(data.start.q_nb, float), np.asarray(data.start.v_n, float),
               np.asarray(data.start.pos, float))
    x, P = np.zeros(N_STATES), P0
    imu = np.zeros(N_STATES)  # sensor parameters in force (closed loop), states 9–20
    sig[0] = np.sqrt(np.diag(P0))
    quat[0], vel[0], posn[0] = pre_q[0], pre_v[0], pre_p[0] = q, v, p
    P_all[0] = P0

    for k in range(K):
        blk = slice(k * S, (k + 1) * S)
        j = (k + 1) * S
        # 1–2. compensate with the parameters in force, navigate S steps
        dth = (data.dtheta[blk] - imu[EB] * ts) / (1.0 + imu[DKG])
        dvb = (data.dv[blk] - imu[DB] * ts) / (1.0 + imu[DKA])
        sol = navigate(data.t[blk.start + 1: j + 1], dth, dvb, ts, NavState(q, v, p),
                       earth=earth)
        q, v, p = sol.q_nb[-1], sol.v_n[-1], sol.pos[-1]
        # 3–4. Φ, Q_d along the navigation; predict; Joseph update
        Phi, Qd = _transition(sol.q_nb, sol.v_n, sol.pos, dth, dvb, ts, Qc, s.discretization,
                              E)
        x_prior, P_prior = predict(x, P, Phi, Qd)
        z = _measurement(s.measure, v, p, data.ref_v_n[j], data.ref_pos[j], noise[k], earth)
        H = ie.measurement_matrix(s.measure, p, earth)
        if levered:  # the fixes are the antenna's: z and H of the INS's antenna
            off, H_l = ie.lever_arm_terms(s.measure, quat_to_dcm(q), dth[-1] / ts,
                                          earth.omega_ie_n(p[0]), lever_v, lever_p)
            z, H = z + off, H + H_l
        u = update(x_prior, P_prior, z, H, R)
        innov[k], stdz[k], nis[k] = u.innovation, u.standardized, u.nis
        sig[k + 1], P = np.sqrt(np.diag(u.P)), u.P
        est[k + 1, NAV] = u.x[NAV]
        pre_q[k + 1], pre_v[k + 1], pre_p[k + 1] = q, v, p
        in_force[k + 1], x_all[k + 1], P_all[k + 1] = imu, u.x, u.P
        if hist is not None:
            hist.Phi[k], hist.P_prior[k], hist.x_prior[k] = Phi, P_prior, x_prior
            hist.P_post[k + 1], hist.x_post[k + 1], hist.imu_pre[k + 1] = u.P, u.x, imu
        # 5. closed loop: correct the INS and the sensors, reset; feed-forward: keep x
        q_c = quat_mult(rotvec_to_quat(u.x[PHI]), q)
        v_c, p_c = v - u.x[DV], p - u.x[DP]
        if s.feedback:
            q, v, p = q_c, v_c, p_c
            imu = _compose(imu, u.x)
            est[k + 1, IMU] = imu[IMU]
            x = np.zeros(N_STATES)
        else:
            est[k + 1, IMU] = u.x[IMU]
            x = u.x
        quat[k + 1], vel[k + 1], posn[k + 1] = q_c, v_c, p_c

    smoothed = None if hist is None else _smooth(hist, s.feedback)
    tru = nees = None
    if truth is not None and x_true is not None:
        # the true filter state at every epoch: the error of the INS solution before the
        # correction and of the compensation in force; epoch 0 is x_true itself
        tru = np.empty((K + 1, N_STATES))
        tru[:, PHI] = _phi(pre_q, euler_to_quat(truth.att[::S][: K + 1]))
        tru[:, DV] = pre_v - truth.v_n[::S][: K + 1]
        tru[:, DP] = pre_p - truth.pos[::S][: K + 1]
        tru[:, IMU] = _imu_residual(x_true, in_force)
        tru[0] = x_true
        nees = nees_of(tru - x_all, P_all)
        tru[:, IMU] = x_true[IMU]  # reported: the sensor errors themselves
    return CalibrationResult(
        t=data.t[::S][: K + 1], estimate=est, sigma=sig, truth=tru,
        nees=nees, innovation=innov, standardized=stdz, nis=nis,
        att=quat_to_euler(quat), v_n=vel, pos=posn,
        measure_names=ie.MEASUREMENT_NAMES[s.measure], settings=s, smoothed=smoothed)


def _smooth(h: _History, feedback: bool) -> Smoothed:
    xs, Ps = rts(h.Phi, h.P_prior, h.x_prior, h.P_post, h.x_post)
    est = xs.copy()
    if feedback:  # sensor parameters: the compensation in force, corrected by the smoothed error
        for k in range(len(xs)):
            est[k, IMU] = _compose(h.imu_pre[k], xs[k])[IMU]
    return Smoothed(estimate=est, sigma=np.sqrt(np.diagonal(Ps, axis1=1, axis2=2)))


@dataclass(frozen=True)
class CovarianceRun:
    """Covariance analysis along the truth: t (K+1,), sigma (K+1, 21), P (K+1, 21, 21)."""

    t: np.ndarray
    sigma: np.ndarray
    P: np.ndarray
    names: tuple[str, ...] = field(default=ie.STATE_NAMES)

    def at(self, time: float) -> np.ndarray:
        """Covariance at the last epoch not after `time` (21, 21)."""
        return self.P[max(0, int(np.searchsorted(self.t, time + 1e-9, side="right")) - 1)]


def covariance_run(truth: Trajectory, settings: Settings | None = None) -> CovarianceRun:
    """The filter's covariance recursion with F and H on the true trajectory (no data).

    Everything the covariance of a consistent filter depends on, without the linearisation
    point moving with the estimation errors: exact comparisons between measurement sets
    and trajectories (an added measurement never increases P), and PSINS ``kfstat``.
    """
    s = settings or Settings()
    ts = truth.ts
    S = s.steps_per_update(ts)
    K = len(truth.f_b) // S
    earth = truth.earth
    E = earth.params()
    P0, Qc, R = s.covariances(truth.pos[0], earth)
    q_nb = euler_to_quat(truth.att)
    dtheta, dv = truth.omega_ib_b * ts, truth.f_b * ts
    P_all = np.zeros((K + 1, N_STATES, N_STATES))
    P_all[0] = P = P0
    zero_x, zero_z = np.zeros(N_STATES), np.zeros(R.shape[0])
    for k in range(K):
        b, e = k * S, (k + 1) * S
        Phi, Qd = _transition(q_nb[b:e + 1], truth.v_n[b:e + 1], truth.pos[b:e + 1], dtheta[b:e],
                              dv[b:e], ts, Qc, s.discretization, E)
        P = Phi @ P @ Phi.T + Qd
        P = update(zero_x, 0.5 * (P + P.T), zero_z,
                   ie.measurement_matrix(s.measure, truth.pos[(k + 1) * S], earth), R).P
        P_all[k + 1] = P
    return CovarianceRun(t=truth.t[::S][: K + 1],
                         sigma=np.sqrt(np.diagonal(P_all, axis1=1, axis2=2)),
                         P=P_all)
