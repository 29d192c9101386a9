"""Inputs of a calibration run as plain arrays: truth, measured increments, segments.

A flight (:func:`gcalign.sim.motions.flight`) or any other motion fills these through
:func:`flight_from_ideal` (its truth and ideal increments at the IMU rate, the injected
errors, the navigation rate); recorded data on a parked vehicle through
:func:`zero_velocity_data`. Times run from ``t[0]`` (the navigation start); increment k
covers ``(t[k], t[k+1]]`` (PSINS layout).

The navigation may run slower than the IMU: ``n`` IMU increments become one navigation
increment (:func:`combine_increments`: the strapdown step's rotation and rotation
compensation chained over the group), as the seed's 25 Hz navigation of a 100 Hz IMU.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from gcalign.calibrate.fixes import Fixes
from gcalign.estimation.ins_error import DB, DKA, DKG, DP, DV, EB, N_STATES, PHI
from gcalign.nav.earth import WGS84, EarthModel
from gcalign.nav.rotation import (
    euler_to_quat,
    quat_mult,
    quat_to_dcm,
    quat_to_rotvec,
    rotvec_to_quat,
)
from gcalign.nav.strapdown import NavState
from gcalign.schema import stored
from gcalign.sim.errors import ErrorStream, ImuErrors, SensorErrors
from gcalign.sim.imu import ImuData
from gcalign.sim.motions import MotionType, Truth
from gcalign.units import ARCMIN, ARCSEC, DPH, PPM, UG


@dataclass(frozen=True)
class Span:
    """A named stretch of the run (a manoeuvre): start and end time (s)."""

    name: str = field(metadata=stored(None, summary=""))
    start: float = field(metadata=stored("s", summary="s", label="t0"))
    end: float = field(metadata=stored("s", summary="s", label="t1"))


@dataclass(frozen=True)
class Trajectory:
    """Truth at the navigation rate (SI).

    t (N+1,) s; att (N+1, 3) ``[pitch, roll, yaw]`` rad; v_n (N+1, 3) ENU m/s;
    pos (N+1, 3) ``[L, λ, h]`` rad, rad, m; f_b (N, 3) m/s² and omega_ib_b (N, 3) rad/s:
    the mean specific force and body rate over each increment (ideal Δv/ts, Δθ/ts of the
    navigation increments, combined from IMU ones when the navigation runs slower);
    earth: the model the truth was simulated in.
    """

    t: np.ndarray
    att: np.ndarray
    v_n: np.ndarray
    pos: np.ndarray
    f_b: np.ndarray
    omega_ib_b: np.ndarray
    earth: EarthModel = WGS84

    @property
    def ts(self) -> float:
        return float(self.t[1] - self.t[0])

    def midpoints(self, k: np.ndarray | None = None) -> tuple[np.ndarray, ...]:
        """Kinematics at the middle of increments `k` (default all): ``C_nb (K, 3, 3)``,
        f_b, ω_ib^b, v_n, pos (K, 3). The attitude is the start attitude turned by half
        the body increment (the navigation-frame turn, ≤ 1e-6 rad, is left out)."""
        k = np.arange(len(self.f_b)) if k is None else np.asarray(k)
        half = rotvec_to_quat(0.5 * self.omega_ib_b[k] * self.ts)
        q = quat_mult(euler_to_quat(self.att[k]), half)
        return (quat_to_dcm(q), self.f_b[k], self.omega_ib_b[k],
                0.5 * (self.v_n[k] + self.v_n[k + 1]), 0.5 * (self.pos[k] + self.pos[k + 1]))

    def index(self, t: float) -> int:
        """The last sample not after `t` (s)."""
        return int(np.searchsorted(self.t, t + 1e-9 * self.ts, side="right")) - 1

    def between(self, t0: float, t1: float) -> Trajectory:
        """The samples from the last one not after `t0` to the last one not after `t1`."""
        a, b = self.index(t0), self.index(t1) + 1
        return replace(self, t=self.t[a:b], att=self.att[a:b], v_n=self.v_n[a:b],
                       pos=self.pos[a:b], f_b=self.f_b[a:b - 1],
                       omega_ib_b=self.omega_ib_b[a:b - 1])


@dataclass(frozen=True)
class FlightData:
    """Everything :func:`gcalign.calibrate.calibrate` needs (SI).

    t : (N+1,) navigation times, s. dtheta, dv : (N, 3) measured increments, rad, m/s.
    start : the INS state at ``t[0]`` (truth plus the initial errors in a simulation).
    ref_v_n, ref_pos : (N+1, 3) what the aiding source measures without noise at every
        navigation sample: the true velocity and position (simulated DGNSS), or zero
        velocity and the site (ZUPT); the filter takes them every filter period. None with
        `fixes`.
    fixes : measurements at their own epochs (a recording's GNSS fixes, velocities), or
        None: the filter updates at each fix and only predicts between them.
    segments : the manoeuvres, for tables.
    truth : the true trajectory (observability, NEES), or None for recorded data.
    x_true : (21,) the true initial navigation errors and IMU errors (state order of
        :data:`gcalign.estimation.ins_error.STATE_NAMES`), or None when unknown.
    earth : the earth model the INS navigates in.
    lever_arm_v_b, lever_arm_p_b : (3,) the points whose velocity and whose position the
        aiding measures (a GNSS antenna), from the IMU in body axes (x right, y forward,
        z up), m; zero: the IMU itself. The filter applies them
        (:func:`gcalign.estimation.ins_error.lever_arm_terms`); ref_v_n, ref_pos are then
        the antenna's. (Fixes carry their own lever arms.)
    sensor_truth : (N+1, 12) the true sensor errors during the increment ending at each
        sample (row 0: at the start) when they vary (Gauss–Markov, random walk), or None
        (the constants of ``x_true``).
    """

    t: np.ndarray
    dtheta: np.ndarray
    dv: np.ndarray
    start: NavState
    ref_v_n: np.ndarray | None
    ref_pos: np.ndarray | None
    segments: tuple[Span, ...] = ()
    truth: Trajectory | None = None
    x_true: np.ndarray | None = None
    earth: EarthModel = field(default=WGS84)
    lever_arm_v_b: np.ndarray = field(default_factory=lambda: np.zeros(3))
    lever_arm_p_b: np.ndarray = field(default_factory=lambda: np.zeros(3))
    fixes: Fixes | None = None
    sensor_truth: np.ndarray | None = None

    @property
    def ts(self) -> float:
        return float(self.t[1] - self.t[0])

    def between(self, t0: float, t1: float) -> FlightData:
        """The data from the last sample not after `t0` to the last one not after `t1` (s):
        the same flight, shorter (the seed's conventional take-off is the first 6 stages of
        the designed one). A simulated run starts again from the truth there with the
        initial errors of ``x_true``."""
        dt = self.ts
        a = int(np.searchsorted(self.t, t0 + 1e-9 * dt, side="right")) - 1
        b = int(np.searchsorted(self.t, t1 + 1e-9 * dt, side="right"))
        start = self.start
        if a > 0 and self.truth is not None and self.x_true is not None:
            k = self.truth.index(float(self.t[a]))
            true = NavState.from_euler(self.truth.att[k], self.truth.v_n[k], self.truth.pos[k])
            start = perturb(true, self.x_true)
        elif a > 0:
            raise ValueError("between: a later start needs the truth to start from")
        lo, hi = float(self.t[a]), float(self.t[b - 1])
        segs = tuple(Span(s.name, max(s.start, lo), min(s.end, hi))
                     for s in self.segments if s.end > lo + 1e-9 and s.start < hi - 1e-9)
        if self.fixes is not None:
            raise ValueError("between: cut the data before making its fixes")
        assert self.ref_v_n is not None and self.ref_pos is not None
        return replace(self, t=self.t[a:b], dtheta=self.dtheta[a:b - 1], dv=self.dv[a:b - 1],
                       start=start, ref_v_n=self.ref_v_n[a:b], ref_pos=self.ref_pos[a:b],
                       segments=segs,
                       truth=None if self.truth is None else self.truth.between(lo, hi),
                       sensor_truth=None if self.sensor_truth is None
                       else self.sensor_truth[a:b])


def proposed_truth() -> np.ndarray:
    """The injected errors proposed by spec 002 §2 [X] (21,), SI: the seed's P0 list with
    mixed signs. φ0 = [20″, −20″, 30′]; ε = [+, −, +] 0.01°/h; ∇ = [+, −, +] 50 µg;
    δKg = [+, −, +] 100 ppm; δKa = [−, +, −] 100 ppm; no initial velocity or position error.
    """
    x = np.zeros(N_STATES)
    x[PHI] = [20 * ARCSEC, -20 * ARCSEC, 30 * ARCMIN]
    x[EB] = np.array([1, -1, 1]) * 0.01 * DPH
    x[DB] = np.array([1, -1, 1]) * 50 * UG
    x[DKG] = np.array([1, -1, 1]) * 100 * PPM
    x[DKA] = np.array([-1, 1, -1]) * 100 * PPM
    return x


def draw_truth(P0: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A truth error vector x ~ N(0, P0) (21,): the Monte Carlo draw of spec 002 §6 item 10."""
    return np.linalg.cholesky(P0) @ rng.standard_normal(P0.shape[0])


def perturb(state: NavState, x: np.ndarray) -> NavState:
    """The INS state with errors ``x[:9] = [φ, δv, δp]`` on top of the true `state`:
    ``C_nb,INS = exp(−[φ×]) C_nb`` (≈ (I − [φ×]) C_nb), ``v + δv``, ``p + δp``."""
    q = quat_mult(rotvec_to_quat(-np.asarray(x[PHI], float)), state.q_nb)
    return NavState(q, state.v_n + x[DV], state.pos + x[DP])


def imu_errors(x_true: np.ndarray, base: ImuErrors | None = None) -> ImuErrors:
    """The sensor errors of `x_true` (biases and diagonal scale factors, the filter's model
    ``ω̃ = (I + diag δKg) ω + ε + w_g``, likewise f̃) on top of `base`, whose noise,
    misalignment, asymmetry and quantisation are kept (errors the filter does not model)."""
    base = base or ImuErrors()
    return ImuErrors(
        gyro=replace(base.gyro, bias=np.array(x_true[EB], float),
                     scale=np.array(x_true[DKG], float)),
        accel=replace(base.accel, bias=np.array(x_true[DB], float),
                      scale=np.array(x_true[DKA], float)),
    )


def white_noise(arw: float, vrw: float) -> ImuErrors:
    """Only white noise: ARW (rad/√s) on every gyro, VRW (m/s/√s) on every accelerometer."""
    return ImuErrors(gyro=SensorErrors(noise=np.full(3, arw)),
                     accel=SensorErrors(noise=np.full(3, vrw)))


def _rotate(r: np.ndarray, v: np.ndarray) -> np.ndarray:
    """R(r) v for rotation vectors r and vectors v (..., 3) (Rodrigues)."""
    return np.einsum("...ij,...j->...i", quat_to_dcm(rotvec_to_quat(r)), v)


def combine_increments(dtheta: np.ndarray, dv: np.ndarray,
                       n: int) -> tuple[np.ndarray, np.ndarray]:
    """Groups of `n` increments (N, 3) as one navigation increment each ((N // n, 3) twice):
    the strapdown step's own body-frame algebra chained over the group, so that one step
    with the result does in the body frame exactly what n steps would.

    Attitude: ``q(φ) = q(θ_1) ⊗ … ⊗ q(θ_n)`` (the step turns the body by ``q(Δθ)``).
    Velocity: the step resolves ``R(Δθ/2) Δv`` in its start frame, so the group's increment
    in the first frame is ``ΔV = Σ_i R(θ_1) ⋯ R(θ_{i−1}) R(θ_i/2) Δv_i`` and the combined
    ``Δv = R(−φ/2) ΔV``. What changes against n steps is only the navigation-frame part
    (earth rate, transport rate, gravity and Coriolis per ``n·ts``).

    Why not PSINS ``cnscl``'s cone and sculling factors: they correct *raw* increments
    (``∫ω dt``) for the coning within the group; gcalign's simulated gyro increments are the
    exact rotation vectors between samples (a one-sample step reproduces the truth), for
    which the composition is exact and the cone factors over-correct by θ_i × θ_j / 6
    (``tests/test_calibrate.py``). A trailing incomplete group is dropped. A numba kernel
    (:func:`gcalign.calibrate._kernel.combine`) with the operations of the NumPy form
    (:func:`combine_increments_numpy`), in its order.
    """
    if n < 1:
        raise ValueError(f"subsamples: at least 1 IMU increment per navigation step, got {n}")
    k = len(dtheta) // n
    if n == 1:  # the increments themselves (views: a long recording is not copied)
        return np.asarray(dtheta, float)[:k], np.asarray(dv, float)[:k]
    from gcalign.calibrate._kernel import combine

    phi, out = np.empty((k, 3)), np.empty((k, 3))
    combine(np.ascontiguousarray(dtheta, float), np.ascontiguousarray(dv, float), n, phi, out)
    return phi, out


def combine_increments_numpy(dtheta: np.ndarray, dv: np.ndarray,
                             n: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`combine_increments` as NumPy expressions (its numba kernel's reference, n ≥ 2;
    ``tests/test_calibrate_lockstep.py``)."""
    k = len(dtheta) // n
    w = np.asarray(dtheta, float)[: k * n].reshape(k, n, 3)
    v = np.asarray(dv, float)[: k * n].reshape(k, n, 3)
    q = np.zeros((k, 4))
    q[:, 0] = 1.0
    V = np.zeros((k, 3))
    for i in range(n):
        V += np.einsum("kij,kj->ki", quat_to_dcm(q), _rotate(0.5 * w[:, i], v[:, i]))
        q = quat_mult(q, rotvec_to_quat(w[:, i]))
    phi = quat_to_rotvec(q)
    return phi, _rotate(-0.5 * phi, V)


def trajectory(t: np.ndarray, att: np.ndarray, v_n: np.ndarray, pos: np.ndarray,
               dtheta: np.ndarray, dv: np.ndarray, earth: EarthModel = WGS84,
               subsamples: int = 1) -> Trajectory:
    """The :class:`Trajectory` at the navigation rate from a truth (N+1 samples) and its
    ideal increments (N, 3) at the IMU rate, `subsamples` IMU increments per step."""
    n = subsamples
    dth, dvb = combine_increments(dtheta, dv, n)
    k = len(dth)
    t = np.asarray(t, float)[: k * n + 1 : n]
    T = float(t[1] - t[0])
    return Trajectory(t=t, att=np.asarray(att)[: k * n + 1 : n],
                      v_n=np.asarray(v_n)[: k * n + 1 : n], pos=np.asarray(pos)[: k * n + 1 : n],
                      f_b=dvb / T, omega_ib_b=dth / T, earth=earth)


def flight_from_ideal(truth: Truth, ideal: ImuData, x_true: np.ndarray, errors: ImuErrors,
                      rng: np.random.Generator, segments: tuple[Span, ...] = (),
                      subsamples: int = 1, earth: EarthModel = WGS84,
                      traj: Trajectory | None = None) -> FlightData:
    """:class:`FlightData` from a truth (``Truth``, N+1 samples) and its ideal increments
    (``ImuData``, N) at the IMU rate with the errors `x_true`: its biases and scale factors
    replace those of `errors` (whose noise and unmodelled terms stay), the measured
    increments are combined `subsamples` to a navigation step, and the INS starts from the
    truth perturbed by ``x_true[:9]``. The Monte Carlo path: simulate once, corrupt per run.
    `traj`: the truth's :func:`trajectory` (the part no run changes) if the caller has it.
    """
    stream = ErrorStream(imu_errors(x_true, errors), ideal.ts, rng, len(ideal.dtheta))
    dtheta, dv = combine_increments(*stream.apply(ideal.dtheta, ideal.dv), subsamples)
    if traj is None:
        traj = trajectory(truth.t, truth.att, truth.v_n, truth.pos, ideal.dtheta, ideal.dv,
                          earth, subsamples)
    start = NavState.from_euler(traj.att[0], traj.v_n[0], traj.pos[0])
    return FlightData(t=traj.t, dtheta=dtheta, dv=dv, start=perturb(start, x_true),
                      ref_v_n=traj.v_n, ref_pos=traj.pos, segments=segments, truth=traj,
                      x_true=np.array(x_true, dtype=float), earth=earth,
                      sensor_truth=_sensor_truth(stream, x_true, len(dtheta), subsamples))


def _sensor_truth(stream: ErrorStream, x_true: np.ndarray, steps: int,
                  n: int) -> np.ndarray | None:
    """(steps+1, 12) the true sensor errors during the last IMU increment of each navigation
    step (row 0: the first increment) when a process makes them vary, else None."""
    g, a = stream.gyro.last, stream.accel.last
    if g is None and a is None:
        return None
    rows = np.concatenate([[0], np.arange(1, steps + 1) * n - 1])
    out = np.tile(np.asarray(x_true, float)[9:21], (steps + 1, 1))
    for part, cols in ((g, (slice(0, 3), slice(6, 9))), (a, (slice(3, 6), slice(9, 12)))):
        if part is not None:
            out[:, cols[0]] += part[0][rows]
            out[:, cols[1]] += part[1][rows]
    return out


def motion_spans(motion: MotionType, t_end: float | None = None) -> tuple[Span, ...]:
    """The manoeuvres of a motion as :class:`Span` s: one per segment of a moving base (a
    flight target reached early and held, ``"X (held)"``, stays part of manoeuvre X;
    unnamed segments are ``"segment i"``), the whole run for the other kinds. `t_end`
    (the last sample time, s) clips them to the data: a flight of 590.00015 s sampled at
    100 Hz ends at 590 s."""
    end_all = float(motion.duration) if t_end is None else min(float(t_end), motion.duration)
    segs = getattr(motion, "segments", None) or ()
    if not segs:
        return (Span(getattr(motion, "kind", "run"), 0.0, end_all),)
    spans: list[Span] = []
    t = 0.0
    for i, s in enumerate(segs):
        end = min(t + s.duration, end_all)
        if i == len(segs) - 1:
            end = end_all  # the last segment is held to the end
        name = s.name or f"segment {i + 1}"
        if end > t + 1e-9:
            if name.endswith(" (held)") and spans and spans[-1].name == name[:-7]:
                spans[-1] = Span(spans[-1].name, spans[-1].start, float(end))
            else:
                spans.append(Span(name, float(t), float(end)))
        t = end
    return tuple(spans)


def sampled_truth(traj: Trajectory, spans: Sequence[Span]) -> Truth:
    """The trajectory as a :class:`gcalign.sim.motions.Truth` with the span of each sample
    (a sample on a boundary ends the earlier span's last increment, so belongs to it)."""
    seg = np.zeros(len(traj.t), np.int64)
    for i, sp in enumerate(spans):
        seg[(traj.t > sp.start + 1e-9) & (traj.t <= sp.end + 1e-9)] = i
    return Truth(traj.t, traj.att, traj.v_n, traj.pos, seg)


def zero_velocity_data(t: np.ndarray, dtheta: np.ndarray, dv: np.ndarray, start: NavState,
                       earth: EarthModel = WGS84) -> FlightData:
    """Recorded increments on a parked vehicle: the aiding measures zero velocity at the
    start position (zero-velocity fine alignment). `t` (N+1,) from the navigation start."""
    n = len(t)
    return FlightData(t=np.asarray(t, float), dtheta=np.asarray(dtheta, float),
                      dv=np.asarray(dv, float), start=start, ref_v_n=np.zeros((n, 3)),
                      ref_pos=np.tile(np.asarray(start.pos, float), (n, 1)),
                      segments=(Span("static", float(t[0]), float(t[-1])),), earth=earth)


def zero_velocity_aiding(data: FlightData) -> FlightData:
    """The same data aided by zero velocity at the start position (a parked vehicle: the
    aiding source measures v = 0 and the start position at every epoch)."""
    n = len(data.t)
    return replace(data, ref_v_n=np.zeros((n, 3)),
                   ref_pos=np.tile(np.asarray(data.start.pos, float), (n, 1)))


def parked_data(dtheta: np.ndarray, dv: np.ndarray, ts: float, att0: np.ndarray,
                site: np.ndarray, *, t0: float = 0.0, subsamples: int = 1,
                earth: EarthModel = WGS84) -> FlightData:
    """Recorded IMU increments (N, 3) at interval `ts` (s) of a parked vehicle, from the
    attitude `att0` ``[pitch, roll, yaw]`` (rad; e.g. a coarse alignment) at `site`
    ``[L, λ, h]`` and data time `t0` (s): the navigation increments (`subsamples` IMU
    increments per step, :func:`combine_increments`) aided by zero velocity at the site
    (:func:`zero_velocity_data`). The array route of ``gcalign calibrate`` on recorded data."""
    dth, dvb = combine_increments(dtheta, dv, subsamples)
    t = t0 + np.arange(len(dth) + 1) * subsamples * ts
    start = NavState.from_euler(np.asarray(att0, float), np.zeros(3), np.asarray(site, float))
    return zero_velocity_data(t, dth, dvb, start, earth)
