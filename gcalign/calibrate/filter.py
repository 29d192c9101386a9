"""The 21-state calibration Kalman filter over a navigation run (seed 002 §2, §5.2; spec §2),
which is also the loosely coupled GNSS/INS filter of a recording with aiding files.

Navigation runs at the data rate (25 Hz in the seed) with the sensors compensated by the
current estimates. The filter steps from one epoch to the next: on the seed's schedule
every ``1/filter_rate`` (1 Hz, dividing the navigation rate) with the reference at that
sample; with measured fixes (:class:`gcalign.calibrate.fixes.Fixes`), to the navigation
sample that closes each fix's time, and where no fix comes within a filter period (an
outage), predict-only steps of one filter period. Per step:

1. compensate the increments (PSINS ``ω = Kg ω̃ − ε``, per axis, written in the sensor
   model's own parameters): ``Δθ = (Δθ̃ − ε̂ ts)/(1 + δK̂g)``, ``Δv = (Δṽ − ∇̂ ts)/(1 + δK̂a)``;
2. navigate the step with :func:`gcalign.nav.strapdown.navigate` from the corrected state;
3. Φ, Q_d from F (:func:`gcalign.estimation.ins_error.error_matrix`) at the middle of each
   navigation step, either accumulated step by step (default) or by Van Loan on the mean F
   over the step (spec §2 [X] offers both; on a 9°/s turn the accumulated Φ matches the
   nonlinear mechanisation to 1e-4 of the one-second change and Van Loan on the mean F
   to 1e-2, ``tests/test_ins_error.py``); sensor states that are Gauss–Markov processes or
   random walks add their own decay and noise
   (:func:`gcalign.estimation.ins_error.with_processes`), and in closed loop the
   parameters in force decay as their model says;
4. predict, and with a measurement update in Joseph form
   (:func:`gcalign.estimation.kalman.update`) with z = INS − reference (+ noise in a
   simulation): velocity, position in metres, or both; horizontal (the seed) or with the
   vertical components; a fix taken between two navigation samples is compared with the
   INS interpolated to its time; R from the fix's own σ when it has them; an aiding antenna
   at a lever arm adds the INS's prediction of the antenna's offset to z and its φ, ε,
   δKg columns to H (:func:`gcalign.estimation.ins_error.lever_arm_terms`, where the terms
   are derived);
5. closed loop (default): feed the estimate back and reset it, ``C_nb ← exp([φ̂×]) C_nb``,
   ``v −= δv̂``, ``p −= δp̂``, and for the sensors the exact composition
   ``ε̂ += (1 + δK̂g) x_ε``, ``1 + δK̂g ← (1 + δK̂g)(1 + x_δKg)`` (likewise ∇, δKa), so that
   the reported ε̂, δK̂g are directly the parameters of ``ω̃ = (I + diag δKg) ω + ε``
   (PSINS ``Kg = (I − dKg) Kg``, ``eb += x`` is its first-order form).
   Feed-forward: the INS runs free and the state is not reset.

The filter's state is then always the error of the current INS solution and of the
compensation in force; with the truth known, the same quantity gives NEES. The solution at
every navigation sample goes out as the run goes (``on_rows``); the run keeps only what
each epoch needs.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from gcalign.calibrate.data import FlightData, Trajectory
from gcalign.calibrate.fixes import Fixes
from gcalign.errors import ScenarioError
from gcalign.estimation import ins_error as ie
from gcalign.estimation.calibration import CalibrationResult, Smoothed
from gcalign.estimation.ins_error import (
    DB,
    DKA,
    DKG,
    DP,
    DV,
    EB,
    IMU,
    N_STATES,
    NAV,
    PHI,
    SensorProcesses,
)
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
    components : "horizontal" (the seed's eqs. 5–7) or "3d" (with the vertical velocity
        and height: the aiding holds the vertical channel).
    processes : the sensor states' dynamics (:class:`~gcalign.estimation.ins_error.
        SensorProcesses`); None: random constants (the seed).
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
    components: str = "horizontal"
    processes: SensorProcesses | None = None

    def steps_per_update(self, ts: float) -> int:
        """Navigation steps per filter step; checks every setting (ScenarioError, one line)."""
        ie.measurement_noise(self.measure, self.sigma_v, self.sigma_p, self.components)
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
                ie.measurement_noise(self.measure, self.sigma_v, self.sigma_p, self.components))


def _transition(q_nb: np.ndarray, v_n: np.ndarray, pos: np.ndarray, dtheta: np.ndarray,
                dv: np.ndarray, ts: float, Qc: np.ndarray, method: str,
                E: np.ndarray, processes: SensorProcesses | None = None
                ) -> tuple[np.ndarray, np.ndarray]:
    """Φ, Q_d over one filter step from the navigation states (S+1, …) and the compensated
    increments (S, 3) (numba kernel; the NumPy route is ``ins_error.accumulate``); `E` is
    ``EarthModel.params()``; `processes` the sensor states' dynamics (None: constants)."""
    from gcalign.estimation._ins_kernel import transition_block

    Phi, Qd = np.empty((N_STATES, N_STATES)), np.empty((N_STATES, N_STATES))
    F_mean, G_mean = np.empty((N_STATES, N_STATES)), np.empty((N_STATES, 6))
    transition_block(q_nb, v_n, pos, dtheta, dv, ts, np.ascontiguousarray(np.diag(Qc)),
                     E, Phi, Qd, F_mean, G_mean)
    dt = len(dtheta) * ts
    if method == "van_loan":
        if processes is not None:
            return van_loan(*processes.augment(F_mean, G_mean, Qc), dt)
        return van_loan(F_mean, G_mean, Qc, dt)
    if processes is not None:
        return ie.with_processes(Phi, Qd, processes, dt)
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
    (..., 21) and the true sensor errors `x_true` (..., 21) or (21,)): with
    ``ω̃ = (1 + δKg) ω + ε`` and ``ω_c = (ω̃ − ε̂)/(1 + δK̂g)``, ``ω_c = (1 + x_δKg) ω + x_ε``
    holds exactly for ``x_ε = (ε − ε̂)/(1 + δK̂g)``, ``x_δKg = (1 + δKg)/(1 + δK̂g) − 1``."""
    r = np.zeros(np.shape(imu))
    r[..., EB] = (x_true[..., EB] - imu[..., EB]) / (1.0 + imu[..., DKG])
    r[..., DB] = (x_true[..., DB] - imu[..., DB]) / (1.0 + imu[..., DKA])
    r[..., DKG] = (1.0 + x_true[..., DKG]) / (1.0 + imu[..., DKG]) - 1.0
    r[..., DKA] = (1.0 + x_true[..., DKA]) / (1.0 + imu[..., DKA]) - 1.0
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


def _measurement(measure: str, components: str, v_n: np.ndarray, pos: np.ndarray,
                 ref_v: np.ndarray, ref_pos: np.ndarray, earth: EarthModel) -> np.ndarray:
    """z = INS − reference (seed eqs. 5–7, with the vertical components for "3d"):
    velocity east, north (up); position north, east (up) in metres."""
    n = 3 if components == "3d" else 2
    dv = v_n[:n] - ref_v[:n]
    if measure == "velocity":
        return dv
    r_m, r_n = earth.radii(pos[0])
    dp = [(pos[0] - ref_pos[0]) * (r_m + pos[2]),
          (pos[1] - ref_pos[1]) * (r_n + pos[2]) * np.cos(pos[0])]
    if n == 3:
        dp.append(pos[2] - ref_pos[2])
    return np.array(dp) if measure == "position" else np.concatenate([dv, dp])


def _lever_arm(value: np.ndarray, which: str) -> np.ndarray:
    """A lever arm of FlightData as (3,) finite metres; ScenarioError (one line) otherwise."""
    lever = np.asarray(value, dtype=float)
    if lever.shape != (3,) or not np.isfinite(lever).all():
        raise ScenarioError(f"lever_arm_{which}_b: must be 3 finite numbers (body x right, "
                            f"y forward, z up; m), got {np.ravel(lever).tolist()}")
    return lever


def _noise_sigma(s: Settings) -> np.ndarray:
    n = 3 if s.components == "3d" else 2
    return np.array({"velocity": [s.sigma_v] * n, "position": [s.sigma_p] * n,
                     "both": [s.sigma_v] * n + [s.sigma_p] * n}[s.measure])


@dataclass(frozen=True)
class _Stop:
    """The end of one filter step: navigation sample `end` (index into ``data.t``); with a
    measurement, its fix (index into the fixes, or -1 for the reference at `end`) and where
    its time lies in the last navigation step (``frac`` 1: at the sample itself)."""

    end: int
    fix: int | None = None
    frac: float = 1.0


def _grid_stops(N: int, S: int) -> list[_Stop]:
    """The seed's schedule: an update with the reference every S navigation steps (a tail
    shorter than S is not used)."""
    return [_Stop((k + 1) * S, -1) for k in range(N // S)]


def _fix_stops(t: np.ndarray, fixes: Fixes, S: int) -> tuple[list[_Stop], int]:
    """Steps ending at the navigation sample that closes each fix's time, and, where no fix
    comes within S steps, predict-only steps of S (outages keep their filter epochs); a
    last step to the end of the data. Returns the stops and the number of fixes left out
    (outside the run, or a second fix within one navigation step: the later one is used)."""
    ts = float(t[1] - t[0])
    N = len(t) - 1
    pos = (np.asarray(fixes.t, float) - t[0]) / ts
    end = np.ceil(pos - 1e-9).astype(np.int64)
    ok = (end >= 1) & (end <= N)
    idx = np.flatnonzero(ok)
    # one fix per navigation step: the latest
    keep = idx[np.append(end[idx][1:] != end[idx][:-1], True)] if len(idx) else idx
    stops: list[_Stop] = []
    k = 0
    for j in keep:
        e = int(end[j])
        while e - k > S:
            k += S
            stops.append(_Stop(k))
        frac = float(pos[j] - (e - 1))
        stops.append(_Stop(e, int(j), 1.0 if frac > 1.0 - 1e-9 else frac))
        k = e
    while N - k > 0:
        k = min(k + S, N)
        stops.append(_Stop(k))
    return stops, len(fixes.t) - len(keep)


@dataclass
class _History:
    """What the RTS smoother needs from the filter (kept only when it is asked for)."""

    Phi: list[np.ndarray] = field(default_factory=list)  # transition k → k+1
    P_prior: list[np.ndarray] = field(default_factory=list)  # prediction at k+1
    x_prior: list[np.ndarray] = field(default_factory=list)
    P_post: list[np.ndarray] = field(default_factory=list)  # posterior at k (k = 0: P0)
    x_post: list[np.ndarray] = field(default_factory=list)
    imu_pre: list[np.ndarray] = field(default_factory=list)  # in force in the step ending at k


Rows = Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray], None]
"""``on_rows(t (n,), q_nb (n, 4), v_n (n, 3), pos (n, 3))``: the navigation solution at
every navigation sample, as the run goes (at an epoch: after its correction)."""


def calibrate(data: FlightData, settings: Settings | None = None,
              rng: np.random.Generator | None = None, on_rows: Rows | None = None
              ) -> CalibrationResult:
    """Run the calibration filter over `data` (see the module docstring for the steps).

    `rng` draws the measurement noise (needed when ``settings.gnss_noise``). `on_rows`, if
    given, receives the navigation solution at every navigation sample (:data:`Rows`), the
    start included, so a caller can store it as it comes without the run holding it.

    On the seed's schedule (a reference at every filter period, no lever arm, random-constant
    sensor states, accumulated Φ, no smoother) the epochs run in one numba kernel
    (:mod:`gcalign.calibrate._kernel`, the one :func:`gcalign.calibrate.lockstep.
    calibrate_runs` steps several seeds through); otherwise in the loop below.
    """
    plan = _plan(data, settings or Settings(), rng)
    if kernel_route(plan):
        ep = _kernel_epochs([plan], on_rows)[0]
        if isinstance(ep, Exception):
            raise ep
    else:
        ep = _loop(plan, on_rows)
    return _finish(plan, ep)


@dataclass
class _Plan:
    """A run's inputs as the epochs take them (:func:`_plan`)."""

    data: FlightData
    s: Settings
    S: int
    stops: list[_Stop]
    dropped: int
    P0: np.ndarray
    Qc: np.ndarray
    R_fixed: np.ndarray
    names: tuple[str, ...]
    procs: SensorProcesses | None
    noise: np.ndarray
    truth: Trajectory | None
    lever_v: np.ndarray
    lever_p: np.ndarray

    @property
    def levered(self) -> bool:
        return bool(self.lever_v.any() or self.lever_p.any())


def _plan(data: FlightData, s: Settings, rng: np.random.Generator | None) -> _Plan:
    """Check the run's inputs and set up what its epochs need (the noise drawn)."""
    ts = data.ts
    S = s.steps_per_update(ts)
    N = len(data.dtheta)
    fixes = data.fixes
    if fixes is None:
        if data.ref_v_n is None or data.ref_pos is None:
            raise ValueError("calibrate: data need fixes or ref_v_n and ref_pos")
        stops, dropped = _grid_stops(N, S), 0
    else:
        if s.gnss_noise:
            raise ScenarioError("calibrate.gnss_noise: adds simulated noise to a reference; "
                                "measured fixes carry their own (set it false)")
        stops, dropped = _fix_stops(data.t, fixes, S)
    K = len(stops)
    if K < 1:
        raise ScenarioError(f"data: {N} navigation steps are fewer than one "
                            f"filter step ({S})")
    P0, Qc, R_fixed = s.covariances(data.start.pos, data.earth)
    names = ie.measurement_names(s.measure, s.components)
    m = len(names)
    procs = s.processes if s.processes is not None and not s.processes.constant else None
    noise = np.zeros((K, m))
    if s.gnss_noise:
        if rng is None:
            raise ValueError("calibrate: gnss_noise needs an rng (numpy.random.Generator)")
        noise = rng.standard_normal((K, m)) * _noise_sigma(s)
    truth = data.truth if data.truth is not None and data.x_true is not None else None
    if fixes is None:
        lever_v = _lever_arm(data.lever_arm_v_b, "v")
        lever_p = _lever_arm(data.lever_arm_p_b, "p")
    else:
        lever_v = _lever_arm(fixes.lever_arm_v_b, "v")
        lever_p = _lever_arm(fixes.lever_arm_p_b, "p")
    need_v, need_p = s.measure != "position", s.measure != "velocity"
    if fixes is not None and ((need_v and fixes.v_n is None) or (need_p and fixes.pos is None)):
        raise ScenarioError(f"calibrate.measure: {s.measure!r} needs "
                            f"{'velocities' if need_v and fixes.v_n is None else 'positions'}"
                            " the aiding does not have")
    return _Plan(data, s, S, stops, dropped, P0, Qc, R_fixed, names, procs, noise, truth,
                 lever_v, lever_p)


def kernel_route(plan: _Plan) -> bool:
    """Do the run's epochs go through the kernel (:func:`calibrate`)?"""
    s = plan.s
    return (plan.data.fixes is None and not plan.levered and plan.procs is None
            and s.discretization == "accumulated" and not s.smoother)


@dataclass
class _Epochs:
    """What the epochs leave for :func:`_finish` (rows 0 … K: the start, then each epoch)."""

    index: np.ndarray
    updated: np.ndarray
    est: np.ndarray
    sig: np.ndarray
    innov: np.ndarray  # (U, m) at the U updates, and stdz, nis, r_sig alike
    stdz: np.ndarray
    nis: np.ndarray
    r_sig: np.ndarray
    corrected: np.ndarray  # (K+1, 10) q_nb, v_n, pos after each correction
    pre: np.ndarray  # (K+1, 10) before it
    in_force: np.ndarray
    x_all: np.ndarray
    P_all: np.ndarray | None
    hist: _History | None = None


def _loop(plan: _Plan, on_rows: Rows | None) -> _Epochs:
    """The epochs one by one, every option (fixes at their own epochs, lever arms, sensor
    processes, Van Loan, the smoother's history)."""
    data, s, stops = plan.data, plan.s, plan.stops
    ts, earth, fixes = data.ts, data.earth, data.fixes
    E = earth.params()
    K, m = len(stops), len(plan.names)
    procs, noise, R_fixed = plan.procs, plan.noise, plan.R_fixed
    index = np.zeros(K + 1, np.int64)
    updated = np.zeros(K + 1, dtype=bool)
    est, sig = np.zeros((K + 1, N_STATES)), np.zeros((K + 1, N_STATES))
    innov, stdz, nis, r_sig = [], [], [], []
    corrected, pre = np.zeros((K + 1, 10)), np.zeros((K + 1, 10))
    # what the errors against the truth need, evaluated after the loop in whole arrays:
    # the INS solution before each correction, the compensation in force, x⁺ and (with a
    # truth only: a recording's run keeps no P per epoch) P⁺ for the NEES
    in_force, x_all = np.zeros((K + 1, N_STATES)), np.zeros((K + 1, N_STATES))
    P_all = np.zeros((K + 1, N_STATES, N_STATES)) if plan.truth is not None else None
    hist = _History() if s.smoother else None

    q, v, p = (np.asarray(data.start.q_nb, float), np.asarray(data.start.v_n, float),
               np.asarray(data.start.pos, float))
    x, P = np.zeros(N_STATES), plan.P0
    imu = np.zeros(N_STATES)  # sensor parameters in force (closed loop), states 9–20
    sig[0] = np.sqrt(np.diag(P))
    corrected[0] = pre[0] = np.concatenate([q, v, p])
    if P_all is not None:
        P_all[0] = P
    if hist is not None:
        hist.P_post.append(P)
        hist.x_post.append(np.zeros(N_STATES))
        hist.imu_pre.append(np.zeros(N_STATES))
    if on_rows is not None:
        on_rows(data.t[:1], q[None], v[None], p[None])

    b = 0
    for k, stop in enumerate(stops):
        e = stop.end
        blk = slice(b, e)
        # 1–2. compensate with the parameters in force, navigate to the stop
        dth = (data.dtheta[blk] - imu[EB] * ts) / (1.0 + imu[DKG])
        dvb = (data.dv[blk] - imu[DB] * ts) / (1.0 + imu[DKA])
        sol = navigate(data.t[b + 1: e + 1], dth, dvb, ts, NavState(q, v, p), earth=earth)
        q, v, p = sol.q_nb[-1], sol.v_n[-1], sol.pos[-1]
        # 3–4. Φ, Q_d along the navigation (and the sensors' own processes); predict
        Phi, Qd = _transition(sol.q_nb, sol.v_n, sol.pos, dth, dvb, ts, plan.Qc,
                              s.discretization, E, procs)
        x_prior, P_prior = predict(x, P, Phi, Qd)
        if procs is not None and s.feedback:  # the parameters in force follow their model
            imu = imu.copy()
            imu[IMU] *= procs.discrete((e - b) * ts)[0]
        imu_step = imu  # the compensation the state x⁻ is the error of
        index[k + 1], pre[k + 1] = e, np.concatenate([q, v, p])
        x_post, P = x_prior, P_prior
        if stop.fix is not None:
            # the INS at the fix's time: inside the last navigation step, linearly (a few ms;
            # the error state is the same at both ends to far below its σ)
            if stop.frac == 1.0:
                v_f, p_f = v, p
            else:
                w = stop.frac
                v_f = sol.v_n[-2] + w * (v - sol.v_n[-2])
                p_f = sol.pos[-2] + w * (p - sol.pos[-2])
            if stop.fix < 0:
                assert data.ref_v_n is not None and data.ref_pos is not None
                ref_v, ref_p = data.ref_v_n[e], data.ref_pos[e]
                R = R_fixed
            else:
                assert fixes is not None
                j = stop.fix
                ref_v = None if fixes.v_n is None else fixes.v_n[j]
                ref_p = None if fixes.pos is None else fixes.pos[j]
                R = _fix_noise(s, fixes, j, R_fixed)
            z = _measurement(s.measure, s.components, v_f, p_f,
                             np.zeros(3) if ref_v is None else ref_v,
                             np.zeros(3) if ref_p is None else ref_p, earth) - noise[k]
            H = ie.measurement_matrix(s.measure, p, earth, s.components)
            if plan.levered:  # the fixes are the antenna's: z and H of the INS's antenna
                off, H_l = ie.lever_arm_terms(s.measure, quat_to_dcm(q), dth[-1] / ts,
                                              earth.omega_ie_n(p[0]), plan.lever_v,
                                              plan.lever_p, s.components)
                z, H = z + off, H + H_l
            u = update(x_prior, P_prior, z, H, R)
            innov.append(u.innovation)
            stdz.append(u.standardized)
            nis.append(u.nis)
            r_sig.append(np.sqrt(np.diag(R)))
            updated[k + 1] = True
            x_post, P = u.x, u.P
        sig[k + 1] = np.sqrt(np.diag(P))
        est[k + 1, NAV] = x_post[NAV]
        in_force[k + 1], x_all[k + 1] = imu_step, x_post
        if P_all is not None:
            P_all[k + 1] = P
        if hist is not None:
            hist.Phi.append(Phi)
            hist.P_prior.append(P_prior)
            hist.x_prior.append(x_prior)
            hist.P_post.append(P)
            hist.x_post.append(x_post)
            hist.imu_pre.append(imu_step)
        # 5. closed loop: correct the INS and the sensors, reset; feed-forward: keep x
        q_c = quat_mult(rotvec_to_quat(x_post[PHI]), q)
        v_c, p_c = v - x_post[DV], p - x_post[DP]
        if s.feedback:
            q, v, p = q_c, v_c, p_c
            imu = _compose(imu, x_post)
            est[k + 1, IMU] = imu[IMU]
            x = np.zeros(N_STATES)
        else:
            est[k + 1, IMU] = x_post[IMU]
            x = x_post
        corrected[k + 1] = np.concatenate([q_c, v_c, p_c])
        if on_rows is not None:
            rq, rv, rp = sol.q_nb[1:].copy(), sol.v_n[1:].copy(), sol.pos[1:].copy()
            rq[-1], rv[-1], rp[-1] = q_c, v_c, p_c
            on_rows(data.t[b + 1: e + 1], rq, rv, rp)
        b = e
    rows = (np.array(innov), np.array(stdz)) if innov else (np.zeros((0, m)),) * 2
    return _Epochs(index, updated, est, sig, rows[0], rows[1], np.array(nis, float),
                   np.array(r_sig) if r_sig else np.zeros((0, m)), corrected, pre, in_force,
                   x_all, P_all, hist)


#: filter epochs per kernel call when the solution goes out as the run goes (``on_rows``)
ROWS_EPOCHS = 64


def _kernel_epochs(plans: list[_Plan], on_rows: Rows | None = None
                   ) -> list[_Epochs | Exception]:
    """The epochs of runs that share their schedule, reference, settings and earth model
    (one run, or the seeds of a variant: :func:`gcalign.calibrate.lockstep.calibrate_runs`)
    in the kernel, all lanes at once; `on_rows` (one run) hears of the solution every
    :data:`ROWS_EPOCHS` epochs. A run whose update failed (S not positive definite) has
    numpy.linalg.LinAlgError in its place."""
    from gcalign.calibrate._kernel import epochs

    p0 = plans[0]
    data, s = p0.data, p0.s
    assert data.ref_v_n is not None and data.ref_pos is not None
    L, K, m = len(plans), len(p0.stops), len(p0.names)
    ends = np.array([0] + [st.end for st in p0.stops], np.int64)
    N = int(ends[-1])
    if L == 1:  # the run's own arrays (a long recording is not copied)
        dtheta = np.ascontiguousarray(data.dtheta[:N], float)[None]
        dv = np.ascontiguousarray(data.dv[:N], float)[None]
    else:
        dtheta, dv = np.empty((L, N, 3)), np.empty((L, N, 3))
        for ln, pl in enumerate(plans):
            dtheta[ln], dv[ln] = pl.data.dtheta[:N], pl.data.dv[:N]
    noise = np.empty((L, K, m))
    nav = np.empty((L, 10))
    P = np.empty((L, N_STATES, N_STATES))
    for ln, pl in enumerate(plans):
        noise[ln] = pl.noise
        st = pl.data.start
        nav[ln] = np.concatenate([np.asarray(st.q_nb, float), np.asarray(st.v_n, float),
                                  np.asarray(st.pos, float)])
        P[ln] = pl.P0
    x, imu = np.zeros((L, N_STATES)), np.zeros((L, N_STATES))
    est, sig = np.zeros((L, K + 1, N_STATES)), np.zeros((L, K + 1, N_STATES))
    in_force, x_all = np.zeros((L, K + 1, N_STATES)), np.zeros((L, K + 1, N_STATES))
    innov, stdz, nis = np.zeros((L, K, m)), np.zeros((L, K, m)), np.zeros((L, K))
    corrected, pre = np.zeros((L, K + 1, 10)), np.zeros((L, K + 1, 10))
    P_all = np.zeros((L, K + 1 if p0.truth is not None else 0, N_STATES, N_STATES))
    for ln, pl in enumerate(plans):
        sig[ln, 0] = np.sqrt(np.diag(pl.P0))
        corrected[ln, 0] = pre[ln, 0] = nav[ln]
        if P_all.shape[1]:
            P_all[ln, 0] = pl.P0
    alive = np.ones(L, dtype=bool)
    rv, rp = (np.array(r, np.int64) for r in ie._rows(s.measure, s.components))
    args = (ends, dtheta, dv, data.ts, data.earth.params(),
            np.ascontiguousarray(np.diag(p0.Qc)), rv, rp,
            np.ascontiguousarray(data.ref_v_n, float), np.ascontiguousarray(data.ref_pos, float),
            noise, np.ascontiguousarray(p0.R_fixed), s.feedback, 2.0, alive,
            nav, x, P, imu, est, sig, innov, stdz, nis, corrected, pre, in_force, x_all, P_all)
    if on_rows is None:
        epochs(0, K, *args, np.zeros((L, 0, 10)))
    else:
        on_rows(data.t[:1], nav[:1, :4].copy(), nav[:1, 4:7].copy(), nav[:1, 7:].copy())
        for k0 in range(0, K, ROWS_EPOCHS):
            k1 = min(k0 + ROWS_EPOCHS, K)
            rows = np.empty((1, ends[k1] - ends[k0], 10))
            epochs(k0, k1, *args, rows)
            if not alive[0]:
                break
            for k in range(k0, k1):  # as the loop hands them: epoch by epoch
                r = rows[0, ends[k] - ends[k0]: ends[k + 1] - ends[k0]]
                on_rows(data.t[ends[k] + 1: ends[k + 1] + 1], *(np.ascontiguousarray(r[:, a:b])
                        for a, b in ((0, 4), (4, 7), (7, 10))))
    updated = np.ones(K + 1, dtype=bool)
    updated[0] = False
    r_sig = np.broadcast_to(np.sqrt(np.diag(p0.R_fixed)), (K, m)).copy()
    out: list[_Epochs | Exception] = []
    for ln in range(L):
        if not alive[ln]:
            out.append(np.linalg.LinAlgError("Matrix is not positive definite"))
            continue
        out.append(_Epochs(ends.copy(), updated.copy(), est[ln], sig[ln], innov[ln], stdz[ln],
                           nis[ln], r_sig.copy(), corrected[ln], pre[ln], in_force[ln],
                           x_all[ln], P_all[ln] if P_all.shape[1] else None))
    return out


def _finish(plan: _Plan, ep: _Epochs) -> CalibrationResult:
    """The result of a run from its epochs: the truth's filter state and the NEES (with a
    truth), the smoother (with its history)."""
    data, s = plan.data, plan.s
    K = len(plan.stops)
    index, x_true = ep.index, data.x_true
    pre_q, pre_v, pre_p = (np.ascontiguousarray(ep.pre[:, a:b]) for a, b in ((0, 4), (4, 7),
                                                                            (7, 10)))
    smoothed = None if ep.hist is None else _smooth(ep.hist, s.feedback, pre_q, pre_v, pre_p)
    truth = plan.truth
    tru = nees = None
    if truth is not None and x_true is not None and ep.P_all is not None:
        # the true filter state at every epoch: the error of the INS solution before the
        # correction and of the compensation in force; epoch 0 is x_true itself
        sensors = (np.broadcast_to(x_true, (K + 1, N_STATES)) if data.sensor_truth is None
                   else _with_sensors(x_true, data.sensor_truth[index]))
        tru = np.empty((K + 1, N_STATES))
        tru[:, PHI] = _phi(pre_q, euler_to_quat(truth.att[index]))
        tru[:, DV] = pre_v - truth.v_n[index]
        tru[:, DP] = pre_p - truth.pos[index]
        tru[:, IMU] = _imu_residual(sensors, ep.in_force)
        tru[0] = sensors[0]
        nees = nees_of(tru - ep.x_all, ep.P_all)
        tru[:, IMU] = sensors[:, IMU]  # reported: the sensor errors themselves
    c = ep.corrected
    return CalibrationResult(
        t=data.t[index], estimate=ep.est, sigma=ep.sig, truth=tru,
        nees=nees, innovation=ep.innov, standardized=ep.stdz, nis=ep.nis,
        att=quat_to_euler(np.ascontiguousarray(c[:, :4])), v_n=np.ascontiguousarray(c[:, 4:7]),
        pos=np.ascontiguousarray(c[:, 7:]),
        measure_names=plan.names, settings=s, smoothed=smoothed, index=index,
        updated=ep.updated, sigma_z=ep.r_sig, fixes_unused=plan.dropped)


def _fix_noise(s: Settings, fixes: Fixes, j: int, R_fixed: np.ndarray) -> np.ndarray:
    """R of fix j: the fixes' own σ where they have them (position north, east, up from
    σ east, north, up), else the settings' σ (``R_fixed``)."""
    n = 3 if s.components == "3d" else 2
    parts = []
    if s.measure != "position":
        parts.append(R_fixed.diagonal()[:n] if fixes.sigma_v is None
                     else np.square(fixes.sigma_v[j, :n]))
    if s.measure != "velocity":
        parts.append(R_fixed.diagonal()[-n:] if fixes.sigma_pos is None
                     else np.square(fixes.sigma_pos[j, [1, 0, 2][:n]]))
    return np.diag(np.concatenate(parts))


def _with_sensors(x_true: np.ndarray, sensors: np.ndarray) -> np.ndarray:
    """(K, 21): the navigation errors of `x_true` and the sensor errors of each row of
    `sensors` (K, 12)."""
    out = np.tile(np.asarray(x_true, float), (len(sensors), 1))
    out[:, IMU] = sensors
    return out


def _smooth(h: _History, feedback: bool, pre_q: np.ndarray, pre_v: np.ndarray,
            pre_p: np.ndarray) -> Smoothed:
    xs, Ps = rts(np.array(h.Phi), np.array(h.P_prior), np.array(h.x_prior),
                 np.array(h.P_post), np.array(h.x_post))
    est = xs.copy()
    if feedback:  # sensor parameters: the compensation in force, corrected by the smoothed error
        for k in range(len(xs)):
            est[k, IMU] = _compose(h.imu_pre[k], xs[k])[IMU]
    # the smoothed solution: the INS before each correction, less the smoothed error
    q = quat_mult(rotvec_to_quat(xs[:, PHI]), pre_q)
    return Smoothed(estimate=est, sigma=np.sqrt(np.diagonal(Ps, axis1=1, axis2=2)),
                    att=quat_to_euler(q), v_n=pre_v - xs[:, DV], pos=pre_p - xs[:, DP])


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
