"""Inputs of a calibration run as plain arrays: truth, measured increments, segments.

Any motion source fills these: the ``moving`` motion of :mod:`gcalign.sim.motions` today
(:func:`simulate_flight`), a flight motion or recorded data (:func:`zero_velocity_data`)
later. Times run from ``t[0]`` (the navigation start); increment k covers
``(t[k], t[k+1]]`` (PSINS layout).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gcalign.estimation.ins_error import DB, DKA, DKG, DP, DV, EB, N_STATES, PHI
from gcalign.nav.rotation import euler_to_quat, quat_mult, quat_to_dcm, rotvec_to_quat
from gcalign.nav.strapdown import NavState
from gcalign.units import ARCMIN, ARCSEC, DPH, PPM, UG


@dataclass(frozen=True)
class Span:
    """A named stretch of the run (a manoeuvre): start and end time (s)."""

    name: str
    start: float
    end: float


@dataclass(frozen=True)
class Trajectory:
    """Truth at the navigation rate (SI).

    t (N+1,) s; att (N+1, 3) ``[pitch, roll, yaw]`` rad; v_n (N+1, 3) ENU m/s;
    pos (N+1, 3) ``[L, λ, h]`` rad, rad, m; f_b (N, 3) m/s² and omega_ib_b (N, 3) rad/s:
    the mean specific force and body rate over each increment (ideal Δv/ts, Δθ/ts).
    """

    t: np.ndarray
    att: np.ndarray
    v_n: np.ndarray
    pos: np.ndarray
    f_b: np.ndarray
    omega_ib_b: np.ndarray

    @property
    def ts(self) -> float:
        return float(self.t[1] - self.t[0])

    def midpoints(self, k=None):
        """Kinematics at the middle of increments `k` (default all): ``C_nb (K, 3, 3)``,
        f_b, ω_ib^b, v_n, pos (K, 3). The attitude is the start attitude turned by half
        the body increment (the navigation-frame turn, ≤ 1e-6 rad, is left out)."""
        k = np.arange(len(self.f_b)) if k is None else np.asarray(k)
        half = rotvec_to_quat(0.5 * self.omega_ib_b[k] * self.ts)
        q = quat_mult(euler_to_quat(self.att[k]), half)
        return (quat_to_dcm(q), self.f_b[k], self.omega_ib_b[k],
                0.5 * (self.v_n[k] + self.v_n[k + 1]), 0.5 * (self.pos[k] + self.pos[k + 1]))


@dataclass(frozen=True)
class FlightData:
    """Everything :func:`gcalign.calibrate.calibrate` needs (SI).

    t : (N+1,) navigation times, s. dtheta, dv : (N, 3) measured increments, rad, m/s.
    start : the INS state at ``t[0]`` (truth plus the initial errors in a simulation).
    ref_v_n, ref_pos : (N+1, 3) what the aiding source measures without noise: the true
        velocity and position (simulated DGNSS), or zero velocity and the site (ZUPT).
    segments : the manoeuvres, for tables.
    truth : the true trajectory (observability, NEES), or None for recorded data.
    x_true : (21,) the true initial navigation errors and IMU errors (state order of
        :data:`gcalign.estimation.ins_error.STATE_NAMES`), or None when unknown.
    """

    t: np.ndarray
    dtheta: np.ndarray
    dv: np.ndarray
    start: NavState
    ref_v_n: np.ndarray
    ref_pos: np.ndarray
    segments: tuple[Span, ...] = ()
    truth: Trajectory | None = None
    x_true: np.ndarray | None = None

    @property
    def ts(self) -> float:
        return float(self.t[1] - self.t[0])


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


def simulate_flight(motion, site, ts: float, x_true: np.ndarray, arw: float, vrw: float,
                    rng: np.random.Generator, names=None, substeps: int = 4) -> FlightData:
    """Truth, ideal and measured increments of `motion` with the errors `x_true` (SI).

    The IMU errors of `x_true` enter :func:`gcalign.sim.imu.apply_errors` as constant bias
    and diagonal scale factor (``ω̃ = (I + diag δKg) ω + ε + w_g``, likewise f̃), with white
    noise of density `arw` (rad/√s) and `vrw` (m/s/√s); the INS starts from the truth
    perturbed by ``x_true[:9]``. Segments follow ``motion.segments`` (named by `names`).
    """
    from gcalign.sim.imu import ideal_imu

    truth, ideal = ideal_imu(motion, site, ts, substeps=substeps)
    segs = motion.segments or ()
    # the last segment is held to the end of the motion; segments past the end are dropped
    bounds = np.minimum(np.concatenate([[0.0], np.cumsum([s.duration for s in segs])]),
                        motion.duration)
    if len(segs):
        bounds[-1] = motion.duration
    names = names or [f"segment {i + 1}" for i in range(len(segs))]
    spans = tuple(Span(str(n), float(a), float(b))
                  for n, a, b in zip(names, bounds[:-1], bounds[1:], strict=True) if b > a)
    return flight_from_ideal(truth, ideal, x_true, arw, vrw, rng, spans)


def flight_from_ideal(truth, ideal, x_true: np.ndarray, arw: float, vrw: float,
                      rng: np.random.Generator, segments: tuple[Span, ...] = ()) -> FlightData:
    """:class:`FlightData` from a truth and its ideal increments (``ideal_imu``'s pair) with
    the errors `x_true`: the Monte Carlo path (simulate the motion once, corrupt per run)."""
    from gcalign.sim.imu import ImuErrors, SensorErrors, apply_errors

    ts = ideal.ts
    errors = ImuErrors(
        gyro=SensorErrors(bias=x_true[EB], noise=np.full(3, arw), scale=x_true[DKG]),
        accel=SensorErrors(bias=x_true[DB], noise=np.full(3, vrw), scale=x_true[DKA]),
    )
    measured = apply_errors(ideal, errors, rng)
    traj = Trajectory(t=truth.t, att=truth.att, v_n=truth.v_n, pos=truth.pos,
                      f_b=ideal.dv / ts, omega_ib_b=ideal.dtheta / ts)
    start = NavState.from_euler(truth.att[0], truth.v_n[0], truth.pos[0])
    return FlightData(t=truth.t, dtheta=measured.dtheta, dv=measured.dv,
                      start=perturb(start, x_true), ref_v_n=truth.v_n, ref_pos=truth.pos,
                      segments=segments, truth=traj, x_true=np.array(x_true, dtype=float))


def zero_velocity_data(t, dtheta, dv, start: NavState) -> FlightData:
    """Recorded increments on a parked vehicle: the aiding measures zero velocity at the
    start position (zero-velocity fine alignment). `t` (N+1,) from the navigation start."""
    n = len(t)
    return FlightData(t=np.asarray(t, float), dtheta=np.asarray(dtheta, float),
                      dv=np.asarray(dv, float), start=start, ref_v_n=np.zeros((n, 3)),
                      ref_pos=np.tile(np.asarray(start.pos, float), (n, 1)),
                      segments=(Span("static", float(t[0]), float(t[-1])),))
