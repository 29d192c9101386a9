"""One case end to end on the navigation core (seed 003 Fig. 2; spec 003 §1–§4), streamed.

turntable truth (:class:`~gcalign.sim.motions.Turntable`) → exact ideal increments of the
gyro triad at f1 = 5 kHz, earth rate included (:func:`gcalign.sim.ideal.ideal_blocks`, the
numba fixed-site route) → gyro triad (noise, dither, quantised counts) → composite filter
(notch + FIR, three channels) → attitude-only strapdown at f2 = 1 kHz with coning correction
over the f1/f2 sub-increments (:func:`gcalign.nav.strapdown.integrate_attitude`) → Euler
angles → per-axis tracker → at each sync pulse: latch, Δt, predictors → errors against the
truth at the pulse time and against the INS's own output T later (the seed's semi-physical
reference).

Earth rate. The gyros sense ω_ib = ω_nb + C_bn ω_ie^n. The INS removes it the way a
strapdown INS at a fixed site does: ``integrate_attitude(..., w_in_n=ω_ie^n)`` rotates the
navigation frame at ω_in^n = ω_ie^n (v = 0, so ω_en = 0) while the body increments rotate
the body, ``q ← q(−ω_ie^n τ) ⊗ q ⊗ q(φ)`` (exact for the constant rate about the earth axis).
With the filter's delay T the body increments are those of ``C_ib(t − T)``, and the INS
attitude is ``C_ni(t) C_ib(t − T) C_ib(−T)^T C_ib(0) = C_nb(t − T)``: the initial alignment
at t = 0 absorbs the earth's turn during T (the filters ran at rest before t = 0), so the
INS attitude is the delayed truth with no earth-rate offset. Tested against a single-axis
route without earth rate (headings agree to 2e-13 rad) and, about a tilted axis, against
the truth T earlier (2.5e-12 rad).

Timing. Sensor sample i is taken at ``t_i = i/f1``; solution k at ``t_k = kτ`` uses the
filtered increments up to sample ``k·f1/f2`` and describes the body at ``t_k − T``. Before
t = 0 the table is at rest and the INS is aligned (attitude exact at t = 0); its gyros and
filters have run at rest for ``warmup_s`` (earth rate, dither and noise only), so the run
starts in steady state without invented motion history.

Memory: every block (``chunk_s``) is generated, filtered, solved and tracked, the pulses
whose inputs are complete are evaluated, and only the last few solutions are carried
over; a run holds its pulse records (and, with ``keep_series``, the 1 kHz series).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence

import numpy as np

from gcalign.nav.earth import WGS84, EarthModel
from gcalign.nav.rotation import (
    euler_to_dcm,
    euler_to_quat,
    quat_mult,
    quat_to_euler,
    rotvec_to_quat,
)
from gcalign.nav.strapdown import integrate_attitude
from gcalign.realtime.cases import Case, check_case
from gcalign.realtime.filters import FilterChain, alignment_chain, navigation_chain
from gcalign.realtime.predict import Track, TrackerModel, run_predictor, track, unwrap
from gcalign.realtime.pulses import make_pulses
from gcalign.realtime.result import METRICS, CaseResult, Series
from gcalign.realtime.sensor import GyroChannel
from gcalign.realtime.settings import Settings
from gcalign.sim.ideal import ideal_blocks
from gcalign.units import DEG

__all__ = ["METRICS", "SITE", "CaseResult", "Series", "build_chain", "coning_groups", "run_case"]

#: Site of the turntable when none is given, ``[lat, lon (rad), h (m)]`` (the seed names
#: none; 34.25° N 108.9° E, 400 m).
SITE = (34.25 * DEG, 108.9 * DEG, 400.0)


def build_chain(settings: Settings) -> FilterChain:
    """The filter chain selected by ``settings.filter.chain``."""
    f = settings.filter
    return navigation_chain(f) if f.chain == "navigation" else alignment_chain(f)


def coning_groups(per_solution: int) -> tuple[int, int]:
    """``(subsamples, stride)`` of :func:`integrate_attitude` for `per_solution` sensor
    samples per solution: the largest group of at most 5 sub-increments (the kernel's cone
    factors) that divides it, and the updates per solution (seed: 5 → (5, 1))."""
    sub = max(d for d in range(1, 6) if per_solution % d == 0)
    return sub, per_solution // sub


@functools.lru_cache(maxsize=16)
def _tracker_model(qc: float, r: float, tau: float) -> TrackerModel:
    """The discretised tracker, once per (Qc, R, τ) (Van Loan's expm is the costly part)."""
    return TrackerModel.of(qc, r, tau)


def _lagrange4(u: np.ndarray) -> np.ndarray:
    """Cubic Lagrange weights (P, 4) on nodes −1, 0, 1, 2 at u ∈ [0, 1)."""
    return np.stack([-u * (u - 1) * (u - 2) / 6, (u + 1) * (u - 1) * (u - 2) / 2,
                     -(u + 1) * u * (u - 2) / 2, (u + 1) * u * (u - 1) / 6], -1)


def run_case(case: Case, settings: Settings, rng: np.random.Generator, *,
             site: Sequence[float] | np.ndarray = SITE, earth: EarthModel = WGS84,
             keep_series: bool = False) -> CaseResult:
    """Run `case` with `settings` at `site` ``[lat, lon (rad), h (m)]`` on `earth` (see the
    module docstring); `rng` draws, in this order, the counter and dither phases, the
    asynchronous pulse clock, the warm-up noise, and block by block the gyro noise (the
    same numbers, to round-off, for any ``chunk_s``)."""
    check_case(case, settings)
    chain = build_chain(settings)
    T = chain.delay if settings.delay_s is None else float(settings.delay_s)
    f2, tau, per = settings.solution_hz, settings.tau, settings.samples_per_solution
    f1 = settings.filter.fs_hz
    ts = 1.0 / f1
    sub, stride = coning_groups(per)
    site = np.asarray(site, dtype=float)
    motion = case.motion()
    duration = case.duration
    n_sol = int(math.floor(duration * f2 + 1e-9))
    block = max(1, round(settings.chunk_s * f2))
    w_ie_n = earth.omega_ie_n(site[0])
    att0 = np.asarray(case.att0, dtype=float)
    q_nb0 = euler_to_quat(att0)

    gyro = GyroChannel.start(settings.sensor, rng)
    pulses = make_pulses(case.pulses or settings.pulses, duration, f2, rng)
    # usable pulses: three states for the LS fit, and the seed's reference inside the run
    s_ref = pulses.t * f2 + T * f2
    j_ref = np.floor(s_ref + 1e-9).astype(np.int64)
    ok = (pulses.k >= 2) & (j_ref + 2 <= n_sol)
    pulses = pulses.select(ok)
    s_ref, j_ref = s_ref[ok], j_ref[ok]

    tr_set = settings.tracker
    model = _tracker_model(tr_set.qc, tr_set.r, tau)
    P0 = np.diag(np.square(tr_set.sigma0))

    # solution 0: the aligned attitude at rest, plus what the filter leaves of the dither
    # at t = 0 (alignment averages the dither; navigation sees its filtered residual)
    residual = gyro.dither_residual(chain.response(np.array([settings.sensor.dither_hz]))[0],
                                    0.0)
    q_ins = quat_mult(q_nb0, rotvec_to_quat(residual))
    att_first = quat_to_euler(q_ins)[None]
    tracks = [track(att_first[:, a], model, np.array([att_first[0, a], 0.0, 0.0]), P0)
              for a in range(3)]
    x_carry = [tr.x_last for tr in tracks]
    P_carry = [tr.P_last for tr in tracks]
    hist_att, hist_x, hist_k0 = att_first, np.stack([tr.x for tr in tracks], 1), 0
    # at rest the exact body increment is the earth rate, C_bn ω_ie^n ts (a constant rotation)
    at_rest = euler_to_dcm(att0).T @ w_ie_n * ts
    fstate = chain.initial_state(3, at_rest)
    n_warm = int(round(settings.warmup_s * f1))
    if n_warm:  # at rest before t = 0: earth rate, dither and noise reach the filters
        t_warm = np.arange(-n_warm + 1, 1) * ts
        _, fstate = chain.apply(gyro.measure(t_warm, np.tile(at_rest, (n_warm, 1)), ts, rng),
                                fstate)

    P = len(pulses)
    latched = np.empty((P, 3))
    states = np.empty((P, 3, 3, 3))  # pulse, axis, lag (k−2, k−1, k), [θ, ω, α]
    ins_ref = np.empty((P, 3))
    series: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    if keep_series:
        series.append((q_ins[None], att_first, hist_x))
    done, k1 = 0, 0
    keep = int(math.ceil(T / tau)) + 8

    for blk in ideal_blocks(motion, site, ts, earth, block=block * per):
        k0 = k1
        k1 = min(k0 + len(blk.t) // per, n_sol)
        if k1 <= k0:
            break
        n = (k1 - k0) * per
        counts = gyro.measure(blk.t[:n], blk.dtheta[:n], ts, rng)
        y, fstate = chain.apply(counts, fstate)
        q = integrate_attitude(q_ins, y, ts, w_ie_n, subsamples=sub, stride=stride)[1:]
        q_ins = q[-1]
        att = unwrap(quat_to_euler(q), hist_att[-1])
        new_tracks: list[Track] = []
        for a in range(3):
            tr = track(att[:, a], model, x_carry[a], P_carry[a])
            x_carry[a], P_carry[a] = tr.x_last, tr.P_last
            new_tracks.append(tr)
        x_new = np.stack([tr.x for tr in new_tracks], 1)
        if keep_series:
            series.append((q, att, x_new))
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
        hist_att, hist_x = buf_att[-keep:], buf_x[-keep:]
        hist_k0 = k1 + 1 - len(hist_att)
    if done != P:  # the blocks ended before the run's last solution
        raise RuntimeError(f"case {case.name!r}: {P - done} pulse(s) left unevaluated")

    horizon = (T + pulses.dt)[:, None]  # Tdelay = T + Δt (measured), per axis
    predicted = {name: latched.copy() if name == "none" else
                 run_predictor(name, states, horizon, tau) for name in settings.predictors}
    truth = motion.kinematics(pulses.t, site, earth).att
    # the truth comes wrapped to ±π: bring it onto the branch of the (unwrapped) INS output
    truth = truth + 2.0 * np.pi * np.round((latched - truth) / (2.0 * np.pi))
    out_series = None
    if keep_series:
        out_series = Series(t=np.arange(n_sol + 1) * tau,
                            q_nb=np.concatenate([s[0] for s in series]),
                            att=np.concatenate([s[1] for s in series]),
                            x=np.concatenate([s[2] for s in series]))
    t_update = pulses.k * tau
    return CaseResult(case=case, settings=settings, site=site, earth=earth,
                      chain_delay=chain.delay, delay=T, pulses=pulses, t_update=t_update,
                      t_valid=t_update - T, latched=latched, predicted=predicted, truth=truth,
                      ins_ref=ins_ref, series=out_series)
