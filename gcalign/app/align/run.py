"""Gyrocompass alignment of a scenario: coarse on [0, T1], passes on [T1, T2], T2 → T3.

Seed 000; DESIGN.md "Gyrocompass fine alignment". Returns an :class:`AlignRun` of plain
arrays; the CLI writes and prints it.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from gcalign.align import coarse as coarse_mod
from gcalign.align import kernel as K
from gcalign.align.compensate import compensate
from gcalign.align.cycles import Block, PassRecord, run_passes
from gcalign.app.data import RunData, Stream, scenario_data, scenario_stream, stream_of
from gcalign.app.registry import Outcome
from gcalign.errors import ScenarioError
from gcalign.io.scenario import Scenario
from gcalign.io.scenario.align import AlignConfig
from gcalign.nav.earth import WGS84, EarthModel
from gcalign.nav.rotation import (
    attitude_error,
    euler_to_dcm,
    euler_to_quat,
    misalignment,
    misalignment_q,
    quat_to_dcm,
    quat_to_euler,
)


@dataclass(frozen=True)
class AlignRun:
    """Everything an alignment produced (SI). Truth-dependent fields are None without truth."""

    cfg: AlignConfig
    azimuth_poles: str
    t1: float
    t2: float
    t3: float
    coarse_att: np.ndarray
    passes: list[PassRecord]
    pass_truth: list[np.ndarray] | None  # true attitude along each pass (rad), if known
    att_t2: np.ndarray
    att_t3: np.ndarray
    truth_t2: np.ndarray | None
    truth_t3: np.ndarray | None
    compute_s: float
    equivalent_s: float
    index_offset: int  # data sample index of alignment time 0
    t3_source: str  # "configured" or "measured"
    warnings: tuple[str, ...] = ()

    @property
    def error_t2(self):
        return None if self.truth_t2 is None else attitude_error(self.att_t2, self.truth_t2)

    @property
    def error_t3(self):
        return None if self.truth_t3 is None else attitude_error(self.att_t3, self.truth_t3)

    @cached_property
    def pass_att(self) -> list[np.ndarray]:
        """Euler angles (n, 3) rad along each pass (its stored rows)."""
        return [quat_to_euler(r.q_nb) for r in self.passes]

    @cached_property
    def pass_errors(self) -> list[np.ndarray | None]:
        """Euler-angle error (n, 3) rad along each pass; computed when first asked for
        (a batch needs only the end of each pass)."""
        if self.pass_truth is None:
            return [None] * len(self.passes)
        return [attitude_error(a, tr) for a, tr in zip(self.pass_att, self.pass_truth,
                                                         strict=True)]

    @cached_property
    def pass_phi(self) -> list[np.ndarray | None]:
        """Misalignment φ (n+1, 3) rad, ENU, along each pass."""
        if self.pass_truth is None:
            return [None] * len(self.passes)
        return [
            misalignment_q(r.q_nb, euler_to_quat(tr))
            for r, tr in zip(self.passes, self.pass_truth, strict=True)
        ]

    def pass_end_error(self, i: int) -> np.ndarray | None:
        """Euler-angle error at the end of pass i (rad)."""
        if self.pass_truth is None:
            return None
        return attitude_error(quat_to_euler(self.passes[i].q_nb[-1]), self.pass_truth[i][-1])

    def last_pass_spread(self) -> dict | None:
        """The error's spread over the second half of the last pass (where a pass has
        settled; the first half of a conventional run's only pass holds the coarse
        transient): mean, std (ddof 0) and max |·| per angle (rad) of the stored rows, and
        the window's first and last data times (s). None without truth."""
        if self.pass_truth is None:
            return None
        r, tr = self.passes[-1], self.pass_truth[-1]
        h = len(r.t) // 2
        err = attitude_error(quat_to_euler(r.q_nb[h:]), tr[h:])
        return {"mean": err.mean(0), "std": err.std(0), "max": np.abs(err).max(0),
                "t_from": float(min(r.t[h], r.t[-1])), "t_to": float(max(r.t[h], r.t[-1])),
                "rows": len(err)}

    @property
    def phi_t2(self):
        """Misalignment φ at T2 (rad, ENU): C_nb,est C_nb,true^T = exp(−[φ×])."""
        return None if self.truth_t2 is None else _phi(self.att_t2, self.truth_t2)

    @property
    def phi_t3(self):
        return None if self.truth_t3 is None else _phi(self.att_t3, self.truth_t3)


def _phi(att_est, att_true):
    return misalignment(euler_to_dcm(att_est), euler_to_dcm(att_true))


MEASURED_MAX_S = 600.0  #: data kept after T2 for a 'measured' T3 (the computing latency)


@dataclass(frozen=True)
class AlignInputs:
    """The part of a run's data an alignment needs, collected from a stream in one go (SI).

    Samples lo .. hi-1 of the increments, the reference velocity at samples lo .. hi, the
    true attitude at the samples in `truth_idx` (every stored pass row, T1, T2, T3) and the
    true position at T1; the rest of the run is never held in memory.
    """

    ts: float
    t0: float  # data time of sample 0
    samples: int
    lo: int
    dtheta: np.ndarray
    dv: np.ndarray
    vref: np.ndarray
    vref_body: bool
    truth_idx: np.ndarray | None
    truth_att: np.ndarray | None
    pos_t1: np.ndarray
    site: np.ndarray
    earth: EarthModel
    seed: int | None
    source: str
    motion_kind: str | None

    def att_at(self, k) -> np.ndarray:
        """True attitude at sample indices k (they must be among `truth_idx`)."""
        assert self.truth_idx is not None and self.truth_att is not None
        j = np.searchsorted(self.truth_idx, k)
        return self.truth_att[j]

    def block(self, a: int, b: int) -> Block:
        """Increments a .. b-1 and the reference at samples a .. b, as the passes take them."""
        i, j = a - self.lo, b - self.lo
        return Block(t=self.t0 + np.arange(a, b + 1) * self.ts, dtheta=self.dtheta[i:j],
                     dv=self.dv[i:j], vref=self.vref[i:j + 1], vref_body=self.vref_body,
                     ts=self.ts)


def _index(stream: Stream, cfg: AlignConfig, t: float, field: str) -> int:
    """Data sample index of alignment time t (s); ScenarioError if outside the data."""
    k = int(round((cfg.start_s + t) / stream.ts))
    if k > stream.samples:
        raise ScenarioError(
            f"align.{field}: {t} s (+ start_s {cfg.start_s} s) is past the end of the data "
            f"({stream.samples * stream.ts:.2f} s); lengthen motion.duration_s or choose an "
            f"earlier time"
        )
    return k


def _reference(cfg: AlignConfig, att, v_n, rng: np.random.Generator, body: bool):
    """Reference velocity of samples with true attitude att and velocity v_n (n, 3).

    nav: the true ENU velocity plus white noise. odometer: the body-frame forward speed
    plus white noise (seed §1: converted to the navigation frame with the computed attitude
    inside the loop). The noise of successive blocks continues one stream.
    """
    noise = cfg.aiding.noise_mps
    if not body:
        return v_n + noise * rng.standard_normal(v_n.shape)
    speed = np.einsum("kji,kj->ki", euler_to_dcm(att), v_n)[:, 1]
    speed = speed + noise * rng.standard_normal(len(speed))
    z = np.zeros_like(speed)
    return np.stack([z, speed, z], -1)


def collect(stream: Stream, cfg: AlignConfig, lo: int, hi: int, truth_rows,
            progress=None) -> AlignInputs:
    """One pass over the stream: increments lo .. hi-1, reference velocity at lo .. hi,
    true attitude where `truth_rows(k)` (sample indices, bool array) says, position at T1.
    `progress(done_s, total_s, what)` hears of every block (the simulation, if it is one,
    is most of an alignment's time)."""
    source = cfg.aiding.source
    has_truth = stream.truth0 is not None
    if source != "none" and not has_truth:
        raise ScenarioError(
            f"align.aiding.source: {source!r} needs a simulated motion (truth); "
            "recorded data supports 'none'"
        )
    body = source == "odometer"
    rng = np.random.default_rng([0 if stream.seed is None else stream.seed, 1])
    m = hi - lo
    dtheta, dv = np.empty((m, 3)), np.empty((m, 3))
    vref = np.zeros((m + 1, 3))
    idx_parts, att_parts = [], []
    i1 = _index(stream, cfg, cfg.t1_s, "t1_s")
    pos_t1 = stream.site.copy()

    def take(k0: int, att, v_n, pos):
        """Truth rows of samples k0 .. k0+len-1: reference velocity, stored attitudes."""
        nonlocal pos_t1
        k = k0 + np.arange(len(att))
        if source != "none":
            ref = _reference(cfg, att, v_n, rng, body)
            sel = (k >= lo) & (k <= hi)
            vref[k[sel] - lo] = ref[sel]
        keep = truth_rows(k)
        idx_parts.append(k[keep])
        att_parts.append(att[keep])
        if k[0] <= i1 <= k[-1]:
            pos_t1 = pos[i1 - k[0]].copy()

    if has_truth:
        tr0 = stream.truth0
        assert tr0 is not None
        take(0, tr0.att, tr0.v_n, tr0.pos)
    for b in stream.blocks():
        n = len(b.t)
        a, c = max(lo - b.k0, 0), min(hi - b.k0, n)
        if a < c:
            dtheta[b.k0 + a - lo:b.k0 + c - lo] = b.dtheta[a:c]
            dv[b.k0 + a - lo:b.k0 + c - lo] = b.dv[a:c]
        if b.truth is not None:
            take(b.k0 + 1, b.truth.att, b.truth.v_n, b.truth.pos)
        if progress is not None:
            what = "simulating (data s)" if has_truth else "reading (data s)"
            progress(min(b.k0 + n, hi) * stream.ts, hi * stream.ts, what)
        if b.k0 + n >= hi and (source == "none" or b.k0 + 1 + n > hi):
            break  # everything needed is in; the rest of the run is never generated
    kind = stream.header.meta.get("motion_kind") if stream.header is not None else None
    return AlignInputs(
        ts=stream.ts, t0=stream.t0, samples=stream.samples, lo=lo, dtheta=dtheta, dv=dv,
        vref=vref, vref_body=body,
        truth_idx=np.concatenate(idx_parts) if has_truth else None,
        truth_att=np.concatenate(att_parts) if has_truth else None,
        pos_t1=pos_t1, site=stream.site, earth=stream.earth, seed=stream.seed,
        source=stream.source, motion_kind=kind)


def coarse_attitude(data: AlignInputs, cfg: AlignConfig, i0: int, i1: int):
    """Attitude at T1 from the coarse method (rad): the truth plus ``error_deg`` (given), or
    the analytic / inertial result over [0, T1] plus ``offset_deg``; and the warnings."""
    c = cfg.coarse
    if c.method == "given":
        if data.truth_idx is None:
            raise ScenarioError(
                "align.coarse.method: 'given' needs truth; use 'analytic' or "
                "'inertial' for recorded data"
            )
        return data.att_at(i1) + np.radians(c.error_deg), []
    offset = np.radians(c.offset_deg)
    dth, dv = data.dtheta[i0 - data.lo:i1 - data.lo], data.dv[i0 - data.lo:i1 - data.lo]
    ts, site = data.ts, data.site
    try:
        if c.method == "analytic":
            att = coarse_mod.analytic_coarse(dth, dv, ts, site[0], data.earth) + offset
            return att, still_base_warnings(dth, dv, ts, site[0], data.earth)
        return coarse_mod.inertial_frame_coarse(dth, dv, ts, site[0], site[1], site[2],
                                                earth=data.earth) + offset, []
    except ValueError as err:  # too short a window
        raise ScenarioError(
            f"align.t1_s: the coarse window [0, {(i1 - i0) * ts:g}] s does not fit method "
            f"{c.method!r}: {err}"
        ) from None


#: The share of the signal an excursion of the base may reach before the analytic coarse
#: alignment is warned about: 1 % of the horizontal earth rotation over the window (the
#: heading signal) and an equivalent tilt of 1e-4 rad for the specific force (20″).
STILL_SHARE = 0.01
STILL_TILT_RAD = 1e-4


def still_base_warnings(dtheta: np.ndarray, dv: np.ndarray, ts: float, lat: float,
                        earth: EarthModel) -> list[str]:
    """Is the base still enough for the analytic coarse alignment?

    The analytic (static double-vector) method takes the block-averaged angular rate for
    the earth rate and the averaged specific force for gravity; a base that turns or
    accelerates and comes back biases both averages (a swing of a few degrees turns the
    heading by more than 100°). Measure it: the largest excursion of the integrated
    increments about their mean trend (sensor noise only, on a still base), against 1 % of
    the horizontal earth rotation over the window (ω_ie cos L · T) and against the velocity
    a tilt of 1e-4 rad would give (1e-4 · g · T).
    """
    T = len(dtheta) * ts
    k = np.arange(1, len(dtheta) + 1)[:, None]

    def excursion(inc: np.ndarray) -> float:
        wander = np.cumsum(inc, axis=0) - k * inc.mean(axis=0)
        return float(np.max(np.linalg.norm(wander, axis=1))) if len(inc) else 0.0

    def angle(rad: float) -> str:  # in the unit that reads best for its size
        deg = math.degrees(rad)
        return (f"{deg:.3g}°" if deg >= 1.0 else f"{deg * 60:.3g}′" if deg * 60 >= 1.0
                else f"{deg * 3600:.3g}″")

    turn, limit = excursion(dtheta), STILL_SHARE * earth.omega_ie * math.cos(lat) * T
    if turn > limit:
        return [f"align.coarse.method: 'analytic' assumes a still base, but the base turned "
                f"by up to {angle(turn)} about its mean rate during the {T:g} s coarse "
                f"window (1 % of the earth's rotation over it: {angle(limit)}); expect "
                "a wrong heading: use 'inertial' on a moving or swinging base"]
    shift, limit = excursion(dv), STILL_TILT_RAD * float(earth.gravity(lat)) * T
    if shift > limit:
        return [f"align.coarse.method: 'analytic' assumes a still base, but its velocity "
                f"changed by up to {shift:.3g} m/s during the {T:g} s coarse window (a tilt "
                f"of 1e-4 rad gives {limit:.3g} m/s); expect wrong tilts: use 'inertial' on a "
                "moving or swinging base"]
    return []


def warm_up() -> None:
    """Load the compiled kernel (numba cache) before the computation is timed."""
    state = K.new_state(np.array([1.0, 0.0, 0.0, 0.0]), np.zeros(3), np.array([0.7, 0.0, 0.0]))
    K.gyrocompass_block(state, np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((2, 3)), False,
                        0.01, 1.0, WGS84.params(), np.zeros(K.GAINS_SIZE), K.ATTITUDE,
                        np.empty((2, 4)))


def run_alignment(sc: Scenario, stream: Stream | RunData, progress=None) -> AlignRun:
    """Coarse alignment, the passes of the mode, and the T2 → T3 compensation, on a stream
    of the run's data (or the whole run in memory)."""
    if isinstance(stream, RunData):
        stream = stream_of(stream)
    cfg = sc.align or AlignConfig()
    warm_up()
    if abs(stream.site[0]) > math.radians(85.0):
        raise ScenarioError(
            f"site.lat_deg: gyrocompassing needs |latitude| < 85°, got "
            f"{math.degrees(stream.site[0]):.4f}° (the horizontal earth rate vanishes)"
        )
    # The motion kind picks the default pole set; data simulated earlier carry it along.
    kind = sc.motion.kind if sc.motion else (
        stream.header.meta.get("motion_kind") if stream.header is not None else None)
    poles = cfg.poles_for(kind)
    warnings = []
    if kind == "moving" and cfg.aiding.source == "none":
        warnings.append(
            "a moving base with align.aiding.source 'none': the loops take the "
            "vehicle's accelerations for tilt; expect degrees of error"
        )
    ts = stream.ts
    i0 = _index(stream, cfg, 0.0, "start_s")
    i1 = _index(stream, cfg, cfg.t1_s, "t1_s")
    i2 = _index(stream, cfg, cfg.t2_s, "t2_s")
    realtime = cfg.realtime_conventional
    if cfg.t3_s == "measured":
        i3 = i2 if realtime else None
        hi = i2 if realtime else min(stream.samples, i2 + int(round(MEASURED_MAX_S / ts)))
    else:
        i3 = _index(stream, cfg, cfg.t3_s, "t3_s")
        hi = i3
    try:
        stride = sc.output.stride(1.0 / ts, stream.samples * ts)
    except ValueError as err:
        raise ScenarioError(str(err)) from None
    lo = i0 if cfg.coarse.method != "given" else i1
    ends = {i1, i2, hi} | ({i3} if i3 is not None else set())

    def truth_rows(k):
        """Samples whose true attitude is kept: the stored pass rows and the ends."""
        return ((k >= i1) & (k <= hi) & ((k - i1) % stride == 0)) | np.isin(k, list(ends))

    data = collect(stream, cfg, lo, hi, truth_rows, progress)
    att1, coarse_warnings = coarse_attitude(data, cfg, i0, i1)
    warnings += coarse_warnings
    q1 = euler_to_quat(att1)
    v1 = quat_to_dcm(q1) @ data.vref[i1 - lo] if data.vref_body else data.vref[i1 - lo]
    state0 = K.new_state(q1, v1, data.pos_t1)

    # Real-time conventional: one forward pass over live data to T3, no latency to
    # compensate ('measured' then means T3 = T2). Otherwise the passes run over the stored
    # block [T1, T2] and the compensation carries the attitude on to T3.
    t_start = time.perf_counter()
    state_end, records = run_passes(
        state0, data.block(i1, i3 if realtime else i2),  # type: ignore[arg-type]
        cfg.mode, cfg.pass_count, cfg.stage_list(), poles,
        cfg.level_phase_s, data.earth, stride,
    )
    compute = time.perf_counter() - t_start
    if realtime:
        assert i3 is not None
        rec = records[0]
        q2 = rec.q_nb[np.searchsorted(rec.t, data.t0 + i2 * ts - 1e-9 * ts)]
        q3 = state_end[K.ATT].copy()
        equivalent = (i3 - i0) * ts
    else:
        if i3 is None:
            i3 = i2 + math.ceil(compute / ts)
            if i3 > hi:
                raise ScenarioError("align.t3_s: 'measured' latency runs past the end of the data")
        q2 = state_end[K.ATT].copy()
        q3 = compensate(cfg.compensation, state_end, data.block(i2, i3), data.earth)
        equivalent = (i1 - i0) * ts + cfg.pass_count * (i2 - i1) * ts

    has_truth = data.truth_idx is not None
    pass_truth = None
    if has_truth:
        pass_truth = [data.att_at(np.rint((rec.t - data.t0) / ts).astype(int))
                      for rec in records]
    return AlignRun(
        cfg=cfg,
        azimuth_poles=poles,
        t1=(i1 - i0) * ts,  # the sample times actually used
        t2=(i2 - i0) * ts,
        t3=(i3 - i0) * ts,
        coarse_att=att1,
        passes=records,
        pass_truth=pass_truth,
        att_t2=quat_to_euler(q2),
        att_t3=quat_to_euler(q3),
        truth_t2=data.att_at(i2) if has_truth else None,
        truth_t3=data.att_at(i3) if has_truth and i3 in ends else (
            _truth_at(stream, i3) if has_truth else None),
        compute_s=compute,
        equivalent_s=equivalent,
        index_offset=i0,
        t3_source="measured" if cfg.t3_s == "measured" else "configured",
        warnings=tuple(warnings),
    )


def _truth_at(stream: Stream, k: int):
    tr = stream.truth_at(k)
    return None if tr is None else np.asarray(tr[0], float)


def _deg(x):
    return None if x is None else np.degrees(x).tolist()


def alignment_summary(run: AlignRun, stream: Stream | RunData, name: str) -> dict:
    """Plain-number summary (degrees, seconds): the JSON contract of `gcalign align --json`."""
    if isinstance(stream, RunData):
        stream = stream_of(stream)
    cfg = run.cfg
    realtime = cfg.realtime_conventional
    start, ts = stream.t0, stream.ts  # data time of sample 0

    def aligned_time(t_data: float) -> float:
        return (round((t_data - start) / ts) - run.index_offset) * ts

    spread = run.last_pass_spread()
    last = None if spread is None else {
        "window_s": [aligned_time(spread["t_from"]), aligned_time(spread["t_to"])],
        "rows": spread["rows"],
        **{f"{k}_deg": _deg(spread[k]) for k in ("mean", "std", "max")}}
    stages = cfg.stage_list()
    return {
        "scenario": name,
        "seed": stream.seed,
        "source": stream.source,
        "mode": cfg.mode,
        "compensation": "real time" if realtime else cfg.compensation,
        "azimuth_poles": run.azimuth_poles,
        "stages": [{"stage": i + 1, "t_xy_s": s.t_xy, "t_z_s": s.t_z, "xi": s.xi,
                    "passes": s.passes} for i, s in enumerate(stages)],
        "t1_s": run.t1,
        "t2_s": run.t2,
        "t3_s": run.t3,
        "t3_source": run.t3_source,
        "coarse_attitude_deg": _deg(run.coarse_att),
        "attitude_t2_deg": _deg(run.att_t2),
        "truth_t2_deg": _deg(run.truth_t2),
        "error_t2_deg": _deg(run.error_t2),
        "attitude_t3_deg": _deg(run.att_t3),
        "truth_t3_deg": _deg(run.truth_t3),
        "error_t3_deg": _deg(run.error_t3),
        "misalignment_t2_deg": _deg(run.phi_t2),
        "misalignment_t3_deg": _deg(run.phi_t3),
        "last_pass_error": last,
        "passes": [
            {
                "pass": r.index + 1,
                "direction": r.direction,
                "kind": r.kind,
                "stage": r.stage + 1,
                "t_end_s": aligned_time(float(r.t[-1])),
                "error_deg": _deg(run.pass_end_error(r.index)),
                "attitude_deg": np.degrees(quat_to_euler(r.q_nb[-1])).tolist(),
            }
            for r in run.passes
        ],
        "equivalent_s": run.equivalent_s,
        "data_used_s": run.t3 if realtime else run.t2,
        "compute_s": run.compute_s,
        "warnings": list(run.warnings),
    }


def execute(sc: Scenario, seed: int | None = None, cache_key: str | None = None,
            progress=None) -> Outcome:
    """Simulate (or read) the data, align, summarise; the registry's entry point."""
    if sc.align is not None and sc.align.mode == "transfer":  # spec 006: its own room
        from gcalign.app.align import transfer
        return transfer.execute(sc, seed, cache_key, progress)
    from gcalign.app.align.hdf5 import write_alignment

    if cache_key is not None:  # a batch: the noise-free simulation is shared by the seeds
        stream = stream_of(scenario_data(sc, seed, cache_key))
    else:
        stream = scenario_stream(sc, seed)
    run = run_alignment(sc, stream, progress)
    return Outcome(alignment_summary(run, stream, sc.name),
                   lambda f: write_alignment(f, run, stream), None, stream.seed, run.warnings)
