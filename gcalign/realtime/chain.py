"""One case end to end (seed 003 Fig. 2; spec 003 §1–§4), streamed in blocks.

truth θ(t) from a :class:`~gcalign.sim.schedule.Schedule` → ideal increments at f1 = 5 kHz
→ gyro channel (noise, dither, quantised counts) → composite filter (notch + FIR) →
attitude at f2 = 1 kHz → per-axis tracker → at each sync pulse: latch, Δt, predictors →
errors against the truth at the pulse time and against the INS's own output T later (the
seed's semi-physical reference).

Timing. Sensor sample i is taken at ``t_i = i/f1``; solution k at ``t_k = kτ`` uses the
filtered increments up to sample ``k·f1/f2`` and describes the body at ``t_k − T``. Before
t = 0 the table is at rest and the INS is aligned (attitude exact at t = 0); its gyro
channel and filters have run at rest for ``warmup_s`` (dither and noise only), so the
run starts in steady state without invented motion history.

Attitude. Phase 1 integrates the filtered increments of the single turn axis directly:
``θ_INS,k = θ_INS,k−1 + Σ (five filtered increments)``, exact for a rotation about a fixed
axis without earth rate (no coning). The multi-axis attitude-only kernel with sub-sample
coning correction (``gcalign.nav``: ``integrate_attitude(q0, dtheta, ts, omega_in_n,
subsamples, ...)``) replaces :func:`_integrate_axis` in phase 2; everything after the
attitude (Euler angles, unwrapping, tracker, pulses) stays as it is.

Memory: every block (``chunk_s``) is generated, filtered, solved and tracked, the pulses
whose inputs are complete are evaluated, and only the last few solutions are carried
over; a run holds its pulse records (and, with ``keep_series``, the 1 kHz series).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gcalign.nav.rotation import quat_mult, quat_to_euler, rotvec_to_quat, wrap_pi
from gcalign.realtime.cases import Case, check_case
from gcalign.realtime.filters import FilterChain, alignment_chain, navigation_chain
from gcalign.realtime.predict import Track, TrackerModel, run_predictor, track, unwrap
from gcalign.realtime.pulses import Pulses, make_pulses
from gcalign.realtime.sensor import GyroChannel, axis_angle
from gcalign.realtime.settings import Settings

__all__ = ["CaseResult", "Series", "build_chain", "run_case"]

METRICS = ("truth", "seed")  #: error references: θ(t_p), and the INS's output at t_p + T


@dataclass(frozen=True)
class Series:
    """The 1 kHz series of a run (only with ``keep_series``): t (K,) s; att (K, 3) INS
    [pitch, roll, yaw] unwrapped (rad); x (K, 3, 3) tracker states per axis [θ, ω, α]."""

    t: np.ndarray
    att: np.ndarray
    x: np.ndarray


@dataclass(frozen=True)
class CaseResult:
    """Everything stored per pulse for one case (SI, rad; Euler ``[pitch, roll, yaw]``).

    Attributes
    ----------
    case, settings
    chain_delay : float, s
        Low-frequency group delay of the filter chain (the true T of the data).
    delay : float, s
        T the predictors use (``settings.delay_s``, or `chain_delay`).
    pulses : Pulses
        Edge times, latched solution index k, Δt (true and as measured).
    t_update : (P,) s
        ``kτ``, when the latched attitude was updated.
    t_valid : (P,) s
        Time of validity of the latched attitude, ``kτ − T``; that of a prediction is the
        pulse time itself (``pulses.t``).
    latched : (P, 3)
        The latched INS attitude (unwrapped).
    predicted : dict of (P, 3)
        Prediction to the pulse time per predictor (extrapolated outputs; unwrapped).
    truth : (P, 3)
        True attitude at the pulse time.
    ins_ref : (P, 3)
        The seed's reference: the INS's own output at ``t_p + T`` (cubic interpolation of
        the 1 kHz solutions; exact on the solution instants).
    series : Series or None
    """

    case: Case
    settings: Settings
    chain_delay: float
    delay: float
    pulses: Pulses
    t_update: np.ndarray
    t_valid: np.ndarray
    latched: np.ndarray
    predicted: dict[str, np.ndarray]
    truth: np.ndarray
    ins_ref: np.ndarray
    series: Series | None = None

    def error(self, predictor: str, metric: str = "truth") -> np.ndarray:
        """Prediction error (P, 3) (rad, wrapped to ±π) of `predictor` against ``truth``
        (θ(t_p)) or ``seed`` (the INS's output T later, the seed's semi-physical metric)."""
        if metric not in METRICS:
            raise ValueError(f"metric must be one of {METRICS}, got {metric!r}")
        ref = self.truth if metric == "truth" else self.ins_ref
        # ``none`` is the latched attitude, there whichever predictors ran
        pred = self.latched if predictor == "none" else self.predicted[predictor]
        return wrap_pi(pred - ref)

    @property
    def component(self) -> int:
        """Euler component that the turn moves: x → pitch, y → roll, z → yaw (heading)."""
        return int(np.argmax(np.abs(self.case.axis)))


def build_chain(settings: Settings) -> FilterChain:
    """The filter chain selected by ``settings.filter.chain``."""
    f = settings.filter
    return navigation_chain(f) if f.chain == "navigation" else alignment_chain(f)


def _integrate_axis(theta_prev: float, y: np.ndarray, per_solution: int) -> np.ndarray:
    """Phase-1 attitude solution: the turn angle at each solution instant from the filtered
    increments `y` (M·n,) of the turn axis — exact for a fixed axis; replaced in phase 2 by
    the multi-axis attitude-only kernel with coning correction."""
    return theta_prev + np.cumsum(y.reshape(-1, per_solution).sum(axis=1))


def _lagrange4(u: np.ndarray) -> np.ndarray:
    """Cubic Lagrange weights (P, 4) on nodes −1, 0, 1, 2 at u ∈ [0, 1)."""
    return np.stack([-u * (u - 1) * (u - 2) / 6, (u + 1) * (u - 1) * (u - 2) / 2,
                     -(u + 1) * u * (u - 2) / 2, (u + 1) * u * (u - 1) / 6], -1)


def run_case(case: Case, settings: Settings, rng: np.random.Generator, *,
             keep_series: bool = False) -> CaseResult:
    """Run `case` with `settings` (see the module docstring); `rng` draws, in this order,
    the counter and dither phases, the asynchronous pulse clock, the warm-up noise, and
    block by block the gyro noise (the same numbers, to round-off, for any ``chunk_s``)."""
    check_case(case, settings)
    chain = build_chain(settings)
    T = chain.delay if settings.delay_s is None else float(settings.delay_s)
    f2, tau, per = settings.solution_hz, settings.tau, settings.samples_per_solution
    f1 = settings.filter.fs_hz
    schedule = case.schedule(settings.duration_s)
    u_axis = np.asarray(case.axis, dtype=float)
    q0 = np.asarray(schedule.q0, dtype=float)
    n_sol = int(math.floor(settings.duration_s * f2 + 1e-9))
    block = max(1, round(settings.chunk_s * f2))

    gyro = GyroChannel.start(settings.sensor, rng)
    pulses = make_pulses(case.pulses or settings.pulses, settings.duration_s, f2, rng)
    # usable pulses: three states for the LS fit, and the seed's reference inside the run
    s_ref = pulses.t * f2 + T * f2
    j_ref = np.floor(s_ref + 1e-9).astype(np.int64)
    ok = (pulses.k >= 2) & (j_ref + 2 <= n_sol)
    pulses = pulses.select(ok)
    s_ref, j_ref = s_ref[ok], j_ref[ok]

    ts = settings.tracker
    model = TrackerModel.of(ts.qc, ts.r, tau)
    P0 = np.diag(np.square(ts.sigma0))

    def attitude(theta: np.ndarray) -> np.ndarray:
        q = quat_mult(np.broadcast_to(q0, (len(theta), 4)),
                      rotvec_to_quat(u_axis[None, :] * theta[:, None]))
        return quat_to_euler(q)

    # solution 0: the aligned attitude at rest, plus what the filter leaves of the dither
    # at t = 0 (alignment averages the dither; navigation sees its filtered residual)
    theta_ins = float(axis_angle(schedule, np.array([0.0]))[0]) + gyro.dither_residual(
        chain.response(np.array([settings.sensor.dither_hz]))[0], 0.0)
    att0 = attitude(np.array([theta_ins]))
    tracks = [track(att0[:, a], model, np.array([att0[0, a], 0.0, 0.0]), P0) for a in range(3)]
    x_carry = [tr.x_last for tr in tracks]
    P_carry = [tr.P_last for tr in tracks]
    hist_att, hist_x, hist_k0 = att0, np.stack([tr.x for tr in tracks], 1), 0
    fstate = chain.initial_state(1)
    n_warm = int(round(settings.warmup_s * f1))
    if n_warm:  # at rest before t = 0: only dither and noise reach the counter and filters
        t_warm = np.arange(-n_warm + 1, 1) / f1
        _, fstate = chain.apply(gyro.measure(t_warm, np.zeros(n_warm), 1.0 / f1, rng)[:, None],
                                fstate)

    P = len(pulses)
    latched = np.empty((P, 3))
    states = np.empty((P, 3, 3, 3))  # pulse, axis, lag (k−2, k−1, k), [θ, ω, α]
    ins_ref = np.empty((P, 3))
    series: list[tuple[np.ndarray, np.ndarray]] = [(att0, hist_x)] if keep_series else []
    done = 0

    for k0 in range(0, n_sol, block):
        k1 = min(k0 + block, n_sol)
        i = np.arange(k0 * per, k1 * per + 1)
        t = i / f1
        ideal = np.diff(axis_angle(schedule, t))
        counts = gyro.measure(t[1:], ideal, 1.0 / f1, rng)
        y, fstate = chain.apply(counts[:, None], fstate)
        theta = _integrate_axis(theta_ins, y[:, 0], per)
        theta_ins = float(theta[-1])
        att = unwrap(attitude(theta), hist_att[-1])
        new_tracks: list[Track] = []
        for a in range(3):
            tr = track(att[:, a], model, x_carry[a], P_carry[a])
            x_carry[a], P_carry[a] = tr.x_last, tr.P_last
            new_tracks.append(tr)
        x_new = np.stack([tr.x for tr in new_tracks], 1)
        if keep_series:
            series.append((att, x_new))
        buf_att = np.concatenate([hist_att, att])
        buf_x = np.concatenate([hist_x, x_new])
        # pulses whose seed reference (j_ref + 2) is now solved
        end = done + int(np.searchsorted(j_ref[done:] + 2, k1, side="right"))
        if end > done:
            sl = slice(done, end)
            kk = pulses.k[sl] - hist_k0
            latched[sl] = buf_att[kk]
            states[sl] = np.stack([buf_x[kk - 2], buf_x[kk - 1], buf_x[kk]], 2)
            jj = j_ref[sl] - hist_k0
            w = _lagrange4(np.maximum(s_ref[sl] - j_ref[sl], 0.0))
            ins_ref[sl] = np.einsum("pn,pna->pa", w,
                                    np.stack([buf_att[jj + d] for d in (-1, 0, 1, 2)], 1))
            done = end
        keep = int(math.ceil(T / tau)) + 8
        hist_att, hist_x = buf_att[-keep:], buf_x[-keep:]
        hist_k0 = k1 + 1 - len(hist_att)

    horizon = (T + pulses.dt)[:, None]  # Tdelay = T + Δt (measured), per axis
    predicted = {name: latched.copy() if name == "none" else
                 run_predictor(name, states, horizon, tau) for name in settings.predictors}
    truth = quat_to_euler(schedule.quat(pulses.t))
    out_series = None
    if keep_series:
        out_series = Series(t=np.arange(n_sol + 1) * tau,
                            att=np.concatenate([s[0] for s in series]),
                            x=np.concatenate([s[1] for s in series]))
    t_update = pulses.k * tau
    return CaseResult(case=case, settings=settings, chain_delay=chain.delay, delay=T,
                      pulses=pulses, t_update=t_update, t_valid=t_update - T, latched=latched,
                      predicted=predicted, truth=truth, ins_ref=ins_ref, series=out_series)
